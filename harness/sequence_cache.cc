#include "harness/sequence_cache.h"

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "harness/interrupt.h"
#include "harness/progress.h"
#include "harness/sim_adapter.h"
#include "harness/suite/spec.h"
#include "sim/floor_plan.h"

namespace harness {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

constexpr const char* kKind = "sequence";
constexpr const char* kIndexFile = "sequence.json";
constexpr const char* kFramesFile = "frames.bin";
constexpr auto kLockPoll = std::chrono::milliseconds(100);  // waiting for a sequence's writer

// Appends the bytes of `path` (or a line saying it is missing: the simulator then fails with
// its own message) and of every MJCF file it includes, to `text`.
void AppendSceneFile(const fs::path& path, int depth, std::string* text) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *text += "missing: " + path.string() + "\n";
    return;
  }
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const std::string content = bytes.str();
  *text += path.string() + " " + std::to_string(content.size()) + "\n" + content;
  if (depth >= 8) return;  // MuJoCo refuses deeper include chains anyway
  static const std::regex kInclude(R"re(<include\s+file\s*=\s*["']([^"']+)["'])re");
  for (std::sregex_iterator it(content.begin(), content.end(), kInclude), end; it != end; ++it)
    AppendSceneFile(path.parent_path() / (*it)[1].str(), depth + 1, text);
}

// FNV-1a of the scene's files as they are now: the MJCF and the files it includes, or the floor
// plan and the robot it includes. The scenario's YAML names the scene by path only; without this
// an entry kept across calls would give the frames of a scene file since edited.
std::string SceneFilesHash(const std::string& scene_path) {
  std::string text;
  AppendSceneFile(scene_path, 0, &text);
  sim::FloorPlan plan;
  std::string ignored;
  if (sim::IsFloorPlanPath(scene_path) && sim::LoadFloorPlan(scene_path, &plan, &ignored))
    AppendSceneFile(plan.robot_path, 0, &text);
  return Fnv1aHex(text);
}

// The scenario as the entry records it: its YAML without the name (the run's id in a suite),
// and the hash of its scene's files.
std::string KeyYaml(const sim::Scenario& scenario) {
  sim::Scenario s = scenario;
  s.name.clear();
  return sim::ScenarioToYaml(s) + "# scene files: " + SceneFilesHash(s.scene_path) + "\n";
}

// --- A frame's record: plain bytes in, plain bytes out. ---

template <typename T>
void Put(std::string* out, const T& value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}
void PutDoubles(std::string* out, const double* values, size_t count) {
  out->append(reinterpret_cast<const char*>(values), count * sizeof(double));
}
void PutPose(std::string* out, const Eigen::Isometry3d& T) { PutDoubles(out, T.data(), 16); }
void PutVector(std::string* out, const Eigen::Vector3d& v) { PutDoubles(out, v.data(), 3); }
void PutImage(std::string* out, const cv::Mat& image) {
  const cv::Mat m = image.isContinuous() ? image : image.clone();
  Put<int32_t>(out, m.rows);
  Put<int32_t>(out, m.cols);
  Put<int32_t>(out, m.type());
  if (!m.empty()) out->append(reinterpret_cast<const char*>(m.data), m.total() * m.elemSize());
}

// Reads what Put wrote; false when the record ends first.
class RecordReader {
 public:
  explicit RecordReader(const std::string& bytes) : bytes_(bytes) {}
  template <typename T>
  bool Get(T* value) {
    return Copy(value, sizeof(T));
  }
  bool GetPose(Eigen::Isometry3d* T) { return Copy(T->data(), 16 * sizeof(double)); }
  bool GetVector(Eigen::Vector3d* v) { return Copy(v->data(), 3 * sizeof(double)); }
  bool GetImage(cv::Mat* image) {
    int32_t rows = 0, cols = 0, type = 0;
    if (!Get(&rows) || !Get(&cols) || !Get(&type) || rows < 0 || cols < 0) return false;
    if (rows == 0 || cols == 0) {
      *image = cv::Mat();
      return true;
    }
    *image = cv::Mat(rows, cols, type);
    return Copy(image->data, image->total() * image->elemSize());
  }
  bool AtEnd() const { return at_ == bytes_.size(); }

 private:
  bool Copy(void* to, size_t size) {
    if (bytes_.size() - at_ < size) return false;
    std::memcpy(to, bytes_.data() + at_, size);
    at_ += size;
    return true;
  }
  const std::string& bytes_;
  size_t at_ = 0;
};

std::string EncodeFrame(const DatasetFrame& f) {
  std::string r;
  Put<double>(&r, f.time_s);
  Put<int32_t>(&r, f.has_gt ? 1 : 0);
  PutPose(&r, f.T_world_cam0);
  PutImage(&r, f.left);
  PutImage(&r, f.right);
  PutImage(&r, f.depth_m);
  Put<int64_t>(&r, static_cast<int64_t>(f.imu.size()));
  for (const sim::ImuSample& s : f.imu) {
    Put<double>(&r, s.time_s);
    PutVector(&r, s.gyro_radps);
    PutVector(&r, s.accel_mps2);
    Put<int32_t>(&r, s.has_gt ? 1 : 0);
    PutVector(&r, s.gyro_true_radps);
    PutVector(&r, s.accel_true_mps2);
    PutVector(&r, s.gyro_bias_radps);
    PutVector(&r, s.accel_bias_mps2);
    PutPose(&r, s.T_world_imu);
    PutVector(&r, s.v_world_mps);
  }
  return r;
}

bool DecodeFrame(const std::string& bytes, DatasetFrame* f) {
  RecordReader in(bytes);
  int32_t has_gt = 0;
  int64_t imu_count = 0;
  if (!in.Get(&f->time_s) || !in.Get(&has_gt) || !in.GetPose(&f->T_world_cam0) ||
      !in.GetImage(&f->left) || !in.GetImage(&f->right) || !in.GetImage(&f->depth_m) ||
      !in.Get(&imu_count) || imu_count < 0)
    return false;
  f->has_gt = has_gt != 0;
  f->imu.assign(static_cast<size_t>(imu_count), sim::ImuSample());
  for (sim::ImuSample& s : f->imu) {
    int32_t sample_gt = 0;
    if (!in.Get(&s.time_s) || !in.GetVector(&s.gyro_radps) || !in.GetVector(&s.accel_mps2) ||
        !in.Get(&sample_gt) || !in.GetVector(&s.gyro_true_radps) ||
        !in.GetVector(&s.accel_true_mps2) || !in.GetVector(&s.gyro_bias_radps) ||
        !in.GetVector(&s.accel_bias_mps2) || !in.GetPose(&s.T_world_imu) ||
        !in.GetVector(&s.v_world_mps))
      return false;
    s.has_gt = sample_gt != 0;
  }
  return in.AtEnd();
}

json PoseJson(const Eigen::Isometry3d& T) {
  return std::vector<double>(T.data(), T.data() + 16);  // column-major, as Eigen stores it
}
bool PoseFromJson(const json& j, Eigen::Isometry3d* T) {
  const std::vector<double> v = j.get<std::vector<double>>();
  if (v.size() != 16) return false;
  std::memcpy(T->data(), v.data(), sizeof(double) * 16);
  return true;
}

json CalibrationJson(const sim::StereoCalibration& c) {
  json j;
  j["width"] = c.width;
  j["height"] = c.height;
  j["fx_px"] = c.fx_px;
  j["fy_px"] = c.fy_px;
  j["cx_px"] = c.cx_px;
  j["cy_px"] = c.cy_px;
  j["baseline_m"] = c.baseline_m;
  j["T_body_cam0"] = PoseJson(c.T_body_cam0);
  j["T_body_imu"] = PoseJson(c.T_body_imu);
  return j;
}
bool CalibrationFromJson(const json& j, sim::StereoCalibration* c) {
  c->width = j.at("width").get<int>();
  c->height = j.at("height").get<int>();
  c->fx_px = j.at("fx_px").get<double>();
  c->fy_px = j.at("fy_px").get<double>();
  c->cx_px = j.at("cx_px").get<double>();
  c->cy_px = j.at("cy_px").get<double>();
  c->baseline_m = j.at("baseline_m").get<double>();
  return PoseFromJson(j.at("T_body_cam0"), &c->T_body_cam0) &&
         PoseFromJson(j.at("T_body_imu"), &c->T_body_imu);
}

// The follower's report (sim/navigation.h) of the simulation, which a run on the entry reports as
// one that simulates would; NaN as null.
json NumberJson(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
double NumberFromJson(const json& j) {
  return j.is_null() ? std::numeric_limits<double>::quiet_NaN() : j.get<double>();
}
json PlanarJson(const sim::PlanarPose& p) {
  return json::array(
      {NumberJson(p.position.x()), NumberJson(p.position.y()), NumberJson(p.yaw_rad)});
}
sim::PlanarPose PlanarFromJson(const json& j) {
  sim::PlanarPose p;
  p.position = Eigen::Vector2d(NumberFromJson(j.at(0)), NumberFromJson(j.at(1)));
  p.yaw_rad = NumberFromJson(j.at(2));
  return p;
}
json NavigationJson(const sim::NavigationReport& n) {
  json j;
  j["mode"] = n.mode;
  j["reached_goal"] = n.reached_goal;
  j["end_error_m"] = NumberJson(n.end_error_m);
  j["max_waypoint_error_m"] = NumberJson(n.max_waypoint_error_m);
  j["wall_contacts"] = n.wall_contacts;
  j["wall_contact_s"] = NumberJson(n.wall_contact_s);
  json frames = json::array();
  for (const sim::NavigationFrame& f : n.frames)
    frames.push_back({{"time_s", NumberJson(f.time_s)},
                      {"believed", PlanarJson(f.believed)},
                      {"truth", PlanarJson(f.truth)},
                      {"fixed", f.fixed}});
  j["frames"] = frames;
  return j;
}
sim::NavigationReport NavigationFromJson(const json& j) {
  sim::NavigationReport n;
  n.mode = j.at("mode").get<std::string>();
  n.reached_goal = j.at("reached_goal").get<bool>();
  n.end_error_m = NumberFromJson(j.at("end_error_m"));
  n.max_waypoint_error_m = NumberFromJson(j.at("max_waypoint_error_m"));
  n.wall_contacts = j.at("wall_contacts").get<int>();
  n.wall_contact_s = NumberFromJson(j.at("wall_contact_s"));
  for (const json& f : j.at("frames")) {
    sim::NavigationFrame frame;
    frame.time_s = NumberFromJson(f.at("time_s"));
    frame.believed = PlanarFromJson(f.at("believed"));
    frame.truth = PlanarFromJson(f.at("truth"));
    frame.fixed = f.at("fixed").get<bool>();
    n.frames.push_back(frame);
  }
  return n;
}

// One frame's place in frames.bin.
struct RecordPlace {
  uint64_t offset = 0;
  uint64_t size = 0;
  std::string hash;  // Fnv1aHex of the record
};

// What sequence.json says, read and checked against the scenario; false with *why otherwise.
struct CacheIndex {
  sim::StereoCalibration calibration;
  sim::NavigationReport navigation;
  std::vector<RecordPlace> records;
};
bool ReadIndex(const sim::Scenario& scenario, int max_frames, const fs::path& dir,
               CacheIndex* index, std::string* why) {
  if (!HasFolderMarker(dir.string(), kKind)) {
    *why = dir.string() + ": not a sequence cache entry (no marker of kind \"sequence\")";
    return false;
  }
  const fs::path path = dir / kIndexFile;
  std::ifstream in(path);
  json j;
  try {
    if (!in) throw std::runtime_error("cannot open it");
    in >> j;
    if (j.at("format").get<int>() != kSequenceCacheFormat)
      throw std::runtime_error("format " + j.at("format").dump() + ", expected " +
                               std::to_string(kSequenceCacheFormat));
    if (j.at("version").get<std::string>() != VobenchVersion())
      throw std::runtime_error("written by vobench " + j.at("version").get<std::string>() +
                               ", this is " + VobenchVersion());
    if (j.at("scenario_yaml").get<std::string>() != KeyYaml(scenario) ||
        j.at("max_frames").get<int>() != max_frames)
      throw std::runtime_error("simulated for another scenario or max_frames");
    if (!CalibrationFromJson(j.at("calibration"), &index->calibration))
      throw std::runtime_error("calibration: a pose without 16 numbers");
    index->navigation = NavigationFromJson(j.at("navigation"));
    index->records.clear();
    uint64_t end = 0;
    for (const json& r : j.at("frames")) {
      RecordPlace place;
      place.offset = r.at("offset").get<uint64_t>();
      place.size = r.at("size").get<uint64_t>();
      place.hash = r.at("fnv1a").get<std::string>();
      if (place.offset != end) throw std::runtime_error("frames: records not contiguous");
      end += place.size;
      index->records.push_back(place);
    }
    std::error_code ec;
    const uint64_t size = fs::file_size(dir / kFramesFile, ec);
    if (ec) throw std::runtime_error(std::string(kFramesFile) + ": " + ec.message());
    if (size != end)
      throw std::runtime_error(std::string(kFramesFile) + " has " + std::to_string(size) +
                               " bytes, the index " + std::to_string(end));
  } catch (const std::exception& ex) {
    *why = path.string() + ": " + ex.what();
    return false;
  }
  return true;
}

}  // namespace

std::string SequenceCacheKey(const sim::Scenario& scenario, int max_frames) {
  return Fnv1aHex(KeyYaml(scenario) + "max_frames: " + std::to_string(max_frames) + "\n");
}

bool WriteSequenceCache(const sim::Scenario& scenario, int max_frames, const std::string& dir,
                        bool progress, std::string* error) {
  std::unique_ptr<sim::Simulator> simulator = sim::Simulator::Create(scenario, error);
  if (!simulator) return false;
  OutputFolder folder;
  if (!folder.Create(dir, kKind, error)) return false;
  const fs::path frames_path = fs::path(folder.path()) / kFramesFile;
  std::ofstream out(frames_path, std::ios::binary);
  if (!out) {
    *error = frames_path.string() + ": cannot write: " + std::strerror(errno);
    return false;
  }
  int expected = simulator->EstimatedFrames();
  if (max_frames > 0 && expected > max_frames) expected = max_frames;
  Progress bar("simulate " + scenario.name, expected, progress);
  json frames = json::array();
  uint64_t offset = 0;
  sim::StereoFrame frame;
  error->clear();
  for (int index = 0; max_frames == 0 || index < max_frames; ++index) {
    if (!simulator->Next(&frame, error)) break;
    const std::string record = EncodeFrame(ToDatasetFrame(frame));
    out.write(record.data(), static_cast<std::streamsize>(record.size()));
    json place;
    place["offset"] = offset;
    place["size"] = record.size();
    place["fnv1a"] = Fnv1aHex(record);
    frames.push_back(place);
    offset += record.size();
    bar.Update(index + 1);
    if (InterruptSignal() != 0) {
      *error = InterruptedMessage(index + 1, expected, "frames", dir);
      return false;
    }
  }
  if (!error->empty()) return false;
  out.close();
  if (!out) {
    *error = frames_path.string() + ": cannot write (disk full?)";
    return false;
  }
  bar.Finish(static_cast<int>(frames.size()));
  json index;
  index["format"] = kSequenceCacheFormat;
  index["version"] = VobenchVersion();
  index["scenario_yaml"] = KeyYaml(scenario);
  index["max_frames"] = max_frames;
  index["calibration"] = CalibrationJson(simulator->calibration());
  index["navigation"] = NavigationJson(simulator->navigation());
  index["frames"] = frames;
  return WriteTextFile((fs::path(folder.path()) / kIndexFile).string(), index.dump(1) + "\n",
                       error) &&
         folder.Publish(error);
}

bool IsUsableSequenceCache(const sim::Scenario& scenario, int max_frames, const std::string& dir,
                           std::string* why) {
  CacheIndex index;
  return ReadIndex(scenario, max_frames, dir, &index, why);
}

bool OpenCachedSequence(const sim::Scenario& scenario, int max_frames, const std::string& dir,
                        StereoSequence* sequence, std::string* error) {
  auto index = std::make_shared<CacheIndex>();
  if (!ReadIndex(scenario, max_frames, dir, index.get(), error)) return false;
  const fs::path frames_path = fs::path(dir) / kFramesFile;
  auto in = std::make_shared<std::ifstream>(frames_path, std::ios::binary);
  if (!*in) {
    *error = frames_path.string() + ": cannot open: " + std::strerror(errno);
    return false;
  }
  DescribeScenarioSequence(scenario, index->calibration, static_cast<int>(index->records.size()),
                           sequence);
  sequence->navigation = [index] { return index->navigation; };
  sequence->next = [index, in, frames_path, next = size_t{0}, record = std::string()](
                       DatasetFrame* frame, std::string* err) mutable {
    if (next >= index->records.size()) return false;
    const RecordPlace& place = index->records[next];
    record.resize(place.size);
    in->seekg(static_cast<std::streamoff>(place.offset));
    in->read(record.data(), static_cast<std::streamsize>(place.size));
    const std::string what = frames_path.string() + ": frame " + std::to_string(next);
    if (!*in) {
      *err = what + ": cannot read its " + std::to_string(place.size) + " bytes";
      return false;
    }
    if (Fnv1aHex(record) != place.hash) {
      *err = what + " does not match its hash in " + kIndexFile +
             " (the cache entry was changed after it was written; remove " +
             fs::path(frames_path).parent_path().string() + ")";
      return false;
    }
    if (!DecodeFrame(record, frame)) {
      *err = what + ": not a frame record";
      return false;
    }
    ++next;
    return true;
  };
  return RectifyScenarioSequence(scenario, index->calibration, sequence, error);
}

bool LockSharedFolder(const std::string& dir, FolderLock* lock, std::string* error) {
  for (std::string why; !lock->Acquire(dir + ".writer.lock", dir, &why);) {
    if (why.find("another vobench") == std::string::npos) {
      *error = why;
      return false;
    }
    if (InterruptSignal() != 0) {
      *error = "interrupted by signal " + std::to_string(InterruptSignal()) +
               " while waiting for " + dir;
      return false;
    }
    std::this_thread::sleep_for(kLockPoll);
  }
  return true;
}

bool OpenSharedScenarioSequence(const sim::Scenario& scenario, int max_frames,
                                const std::string& cache_dir, bool progress,
                                StereoSequence* sequence, std::string* error) {
  std::error_code ec;
  fs::create_directories(cache_dir, ec);
  if (ec) {
    *error = cache_dir + ": cannot create: " + ec.message();
    return false;
  }
  const std::string dir = (fs::path(cache_dir) / SequenceCacheKey(scenario, max_frames)).string();
  {
    FolderLock lock;
    if (!LockSharedFolder(dir, &lock, error)) return false;
    std::string why;
    if (!IsUsableSequenceCache(scenario, max_frames, dir, &why)) {
      std::printf("sequence cache %s: simulating%s\n", dir.c_str(),
                  fs::exists(dir) ? (" again (" + why + ")").c_str() : "");
      std::fflush(stdout);
      if (!WriteSequenceCache(scenario, max_frames, dir, progress, error)) return false;
    } else {
      std::printf("sequence cache %s: simulated before, reading it\n", dir.c_str());
      std::fflush(stdout);
    }
  }
  return OpenCachedSequence(scenario, max_frames, dir, sequence, error);
}

}  // namespace harness
