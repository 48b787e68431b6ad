#include "harness/dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/trajectory_io.h"

namespace harness {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr double kCalibTolerance = 1e-9;  // text round trip of calibration numbers
constexpr double kPoseTolerance = 1e-9;   // per matrix entry: text round trip + compositions
constexpr double kDepthToleranceM = 0.5e-3 + 1e-5;  // whole millimetres; float resolution at 65 m
constexpr int kNumFrames = 5;

// Entry-wise comparison of two transforms. (vobench_test::IsNearPose measures the angle through
// acos, which cannot resolve rotations below ~2e-8 rad; a text round trip is far more exact.)
MATCHER_P2(IsNearTransform, expected, tol,
           "has every matrix entry within " + ::testing::PrintToString(tol) + " of the expected") {
  const double d = (expected.matrix() - arg.matrix()).cwiseAbs().maxCoeff();
  *result_listener << "largest entry difference " << d;
  return d <= tol;
}

vo::StereoCamera TestCamera() {
  vo::StereoCamera camera;
  camera.width = 64;
  camera.height = 48;
  camera.fx_px = 52.25;
  camera.fy_px = 51.75;
  camera.cx_px = 31.5;
  camera.cy_px = 23.5;
  camera.baseline_m = 0.125;
  return camera;
}

// A deterministic sequence: random textures, depth with holes and out-of-range values, and a
// camera moving along a curve in a world frame away from the origin.
std::vector<DatasetFrame> MakeSequence(int n, bool with_gt, bool with_depth) {
  const vo::StereoCamera camera = TestCamera();
  cv::RNG rng(12345);
  std::vector<DatasetFrame> frames;
  for (int i = 0; i < n; ++i) {
    DatasetFrame f;
    f.time_s = 100.0 + i / 30.0;
    f.left.create(camera.height, camera.width, CV_8UC1);
    f.right.create(camera.height, camera.width, CV_8UC1);
    rng.fill(f.left, cv::RNG::UNIFORM, 0, 256);
    rng.fill(f.right, cv::RNG::UNIFORM, 0, 256);
    if (with_depth) {
      f.depth_m.create(camera.height, camera.width, CV_32FC1);
      rng.fill(f.depth_m, cv::RNG::UNIFORM, 0.3, 70.0);  // some above 65.535 m: stored as 0
      f.depth_m.at<float>(0, 0) = 0.0f;
      f.depth_m.at<float>(1, 0) = std::numeric_limits<float>::quiet_NaN();
      f.depth_m.at<float>(2, 0) = -1.0f;
    }
    f.has_gt = with_gt;
    if (with_gt) {
      f.T_world_cam0.setIdentity();
      f.T_world_cam0.linear() = (Eigen::AngleAxisd(0.1 * i + 0.3, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
      f.T_world_cam0.translation() = Eigen::Vector3d(12.0 + 0.5 * i, -3.0 + 0.1 * i * i, 1.25);
    }
    frames.push_back(f);
  }
  return frames;
}

// A KITTI image's file name: "000042.png".
std::string FrameNameOf(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return name;
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteAll(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

// Relative path -> content of every file under `root`.
// Every file under root but the folder marker (.vobench.json: its creation time and pid differ
// between two writes by design; a test that writes twice across a second boundary saw it).
std::map<std::string, std::string> ReadTree(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file() || e.path().filename() == ".vobench.json") continue;
    files[fs::relative(e.path(), root).string()] = ReadAll(e.path());
  }
  return files;
}

class DatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::path(::testing::TempDir()) /
            ("vobench_dataset_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string Dir(const std::string& name) const { return (root_ / name).string(); }

  // Writes `frames` to root_/name; returns the folder.
  std::string WriteSequence(const std::string& name, const std::vector<DatasetFrame>& frames,
                            DatasetWriter::Options options = {}) {
    DatasetWriter writer(options);
    std::string error;
    EXPECT_TRUE(writer.Open(Dir(name), TestCamera(), &error)) << error;
    for (const DatasetFrame& f : frames) EXPECT_TRUE(writer.Add(f, &error)) << error;
    EXPECT_TRUE(writer.Finish(&error)) << error;
    return Dir(name);
  }

  // Names in root_ that start with `prefix`.
  std::vector<std::string> EntriesStartingWith(const std::string& prefix) const {
    std::vector<std::string> names;
    for (const fs::directory_entry& e : fs::directory_iterator(root_)) {
      const std::string name = e.path().filename().string();
      if (name.rfind(prefix, 0) == 0) names.push_back(name);
    }
    return names;
  }

  fs::path root_;
};

void ExpectSameCamera(const vo::StereoCamera& a, const vo::StereoCamera& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_NEAR(a.fx_px, b.fx_px, kCalibTolerance);
  EXPECT_NEAR(a.fy_px, b.fy_px, kCalibTolerance);
  EXPECT_NEAR(a.cx_px, b.cx_px, kCalibTolerance);
  EXPECT_NEAR(a.cy_px, b.cy_px, kCalibTolerance);
  EXPECT_NEAR(a.baseline_m, b.baseline_m, kCalibTolerance);
}

// --- Round trips --------------------------------------------------------------------------------

TEST_F(DatasetTest, KittiRoundTrip) {
  const std::vector<DatasetFrame> frames = MakeSequence(kNumFrames, true, true);
  const std::string dir = WriteSequence("seq", frames);

  // The layout, exactly.
  for (const char* name :
       {"calib.txt", "times.txt", "poses.txt", "groundtruth_tum.txt", "T_world_cam0first.txt",
        "image_0/000000.png", "image_1/000004.png", "depth/000004.png"})
    EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / name)) << name;
  EXPECT_FALSE(fs::exists(fs::path(dir) / "mav0"));
  EXPECT_EQ(ReadAll(fs::path(dir) / "calib.txt"),
            "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 1 0\n"
            "P1: 52.25 0 31.5 -6.53125 0 51.75 23.5 0 0 0 1 0\n"
            "P2: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 1 0\n"
            "P3: 52.25 0 31.5 -6.53125 0 51.75 23.5 0 0 0 1 0\n"
            "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");  // KITTI odometry's five keys (pykitti needs them)
  EXPECT_THAT(ReadAll(fs::path(dir) / "poses.txt"),
              ::testing::StartsWith("1 0 0 0 0 1 0 0 0 0 1 0\n"));

  KittiReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir, &error)) << error;
  ExpectSameCamera(reader.camera(), TestCamera());
  ASSERT_EQ(reader.size(), frames.size());
  ASSERT_TRUE(reader.has_ground_truth());
  EXPECT_THAT(reader.T_world_cam0first(), IsNearTransform(frames[0].T_world_cam0, kPoseTolerance));
  for (size_t i = 0; i < frames.size(); ++i) {
    DatasetFrame f;
    ASSERT_TRUE(reader.ReadFrame(i, &f, &error)) << error;
    EXPECT_EQ(f.time_s, frames[i].time_s);
    EXPECT_TRUE(SameBytes(f.left, frames[i].left)) << i;
    EXPECT_TRUE(SameBytes(f.right, frames[i].right)) << i;
    ASSERT_TRUE(f.has_gt);
    EXPECT_THAT(f.T_world_cam0, IsNearTransform(frames[i].T_world_cam0, kPoseTolerance));
    // poses.txt is relative to the first left camera.
    EXPECT_THAT(
        reader.poses()[i],
        IsNearTransform(frames[0].T_world_cam0.inverse() * frames[i].T_world_cam0, kPoseTolerance));
    // Depth: millimetres, 0 where there was none or it did not fit.
    ASSERT_EQ(f.depth_m.type(), CV_32FC1);
    ASSERT_EQ(f.depth_m.size(), frames[i].depth_m.size());
    for (int r = 0; r < f.depth_m.rows; ++r) {
      for (int c = 0; c < f.depth_m.cols; ++c) {
        const float in = frames[i].depth_m.at<float>(r, c);
        const float out = f.depth_m.at<float>(r, c);
        if (std::isfinite(in) && in > 0.0f && in <= 65.535f) {
          ASSERT_NEAR(out, in, kDepthToleranceM) << r << "," << c;
        } else if (!(std::isfinite(in) && in > 65.535f && in < 65.5355f)) {
          ASSERT_EQ(out, 0.0f) << r << "," << c << " in " << in;
        }
      }
    }
  }
  // The TUM ground truth holds the same poses with their times.
  std::vector<StampedPose> tum;
  ASSERT_TRUE(ReadTum(dir + "/groundtruth_tum.txt", &tum, &error)) << error;
  ASSERT_EQ(tum.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(tum[i].time_s, frames[i].time_s);
    EXPECT_THAT(tum[i].T_world_cam, IsNearTransform(reader.poses()[i], kPoseTolerance));
  }
  const std::vector<StampedPose> gt = reader.GroundTruth();
  ASSERT_EQ(gt.size(), frames.size());
  EXPECT_THAT(gt.back().T_world_cam, IsNearTransform(frames.back().T_world_cam0, kPoseTolerance));
}

TEST_F(DatasetTest, KittiWithoutGroundTruthOrDepth) {
  const std::string dir = WriteSequence("bare", MakeSequence(3, false, false));
  EXPECT_FALSE(fs::exists(dir + "/poses.txt"));
  EXPECT_FALSE(fs::exists(dir + "/groundtruth_tum.txt"));
  EXPECT_FALSE(fs::exists(dir + "/depth"));
  KittiReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir, &error)) << error;
  EXPECT_FALSE(reader.has_ground_truth());
  DatasetFrame f;
  ASSERT_TRUE(reader.ReadFrame(2, &f, &error)) << error;
  EXPECT_FALSE(f.has_gt);
  EXPECT_TRUE(f.depth_m.empty());
  EXPECT_FALSE(reader.ReadFrame(3, &f, &error));
  EXPECT_THAT(error, HasSubstr("out of range"));
  KittiReader::Options options;
  options.require_poses = true;
  EXPECT_FALSE(reader.Open(dir, options, &error));
  EXPECT_THAT(error, HasSubstr(dir + "/poses.txt"));
}

TEST_F(DatasetTest, EurocRoundTrip) {
  const std::vector<DatasetFrame> frames = MakeSequence(kNumFrames, true, false);
  DatasetWriter::Options options;
  options.format = DatasetFormat::kEuroc;
  options.T_body_cam0.linear() =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  options.T_body_cam0.translation() = Eigen::Vector3d(0.05, -0.02, 0.1);
  const std::string dir = WriteSequence("euroc", frames, options);

  // The EuRoC text files, exactly where the format fixes them.
  const std::string cam0_csv = ReadAll(dir + "/mav0/cam0/data.csv");
  EXPECT_THAT(cam0_csv, ::testing::StartsWith("#timestamp [ns],filename\n100000000000,"
                                              "100000000000.png\n100033333333,100033333333.png\n"));
  EXPECT_TRUE(fs::is_regular_file(dir + "/mav0/cam1/data/100133333333.png"));
  EXPECT_TRUE(fs::is_regular_file(dir + "/image_0/000004.png"));  // the KITTI layout as well
  const std::string yaml = ReadAll(dir + "/mav0/cam1/sensor.yaml");
  EXPECT_THAT(yaml, HasSubstr("camera_model: pinhole\n"));
  EXPECT_THAT(yaml, HasSubstr("distortion_model: radial-tangential\n"));
  EXPECT_THAT(yaml, HasSubstr("distortion_coefficients: [0, 0, 0, 0]\n"));
  EXPECT_THAT(yaml, HasSubstr("intrinsics: [52.25, 51.75, 31.5, 23.5]"));
  EXPECT_THAT(yaml, HasSubstr("resolution: [64, 48]\n"));
  EXPECT_THAT(yaml, HasSubstr("rate_hz: 30"));
  const std::string gt_csv = ReadAll(dir + "/mav0/state_groundtruth_estimate0/data.csv");
  EXPECT_THAT(gt_csv, ::testing::StartsWith(
                          "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], "
                          "q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], "
                          "v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
                          "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
                          "b_a_RS_S_z [m s^-2]\n100000000000,"));

  EurocReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir, &error)) << error;
  ASSERT_EQ(reader.size(), frames.size());
  EXPECT_EQ(reader.unpaired_frames(), 0u);
  EXPECT_EQ(reader.cam0().camera_model, "pinhole");
  EXPECT_EQ(reader.cam0().distortion_coefficients, (std::vector<double>{0, 0, 0, 0}));
  EXPECT_EQ(reader.cam0().rate_hz, 30.0);
  EXPECT_THAT(reader.cam0().T_body_cam, IsNearTransform(options.T_body_cam0, 1e-12));
  StereoRectification rect;
  ASSERT_TRUE(reader.Rectification(&rect, &error)) << error;
  EXPECT_TRUE(rect.IsIdentity());
  ExpectSameCamera(rect.camera, TestCamera());
  ASSERT_EQ(reader.ground_truth_body().size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    DatasetFrame f;
    ASSERT_TRUE(reader.ReadFrame(i, &f, &error)) << error;
    EXPECT_EQ(reader.times_ns()[i], TimeToNs(frames[i].time_s));
    EXPECT_NEAR(f.time_s, frames[i].time_s, 1e-9);
    EXPECT_TRUE(SameBytes(f.left, frames[i].left)) << i;
    EXPECT_TRUE(SameBytes(f.right, frames[i].right)) << i;
    EXPECT_TRUE(f.depth_m.empty());
    ASSERT_TRUE(f.has_gt);
    EXPECT_THAT(f.T_world_cam0, IsNearTransform(frames[i].T_world_cam0, kPoseTolerance));
  }
}

TEST_F(DatasetTest, EurocGroundTruthAtAnotherRateIsAssociated) {
  const std::string dir = WriteSequence("euroc_rate", MakeSequence(3, false, false), [] {
    DatasetWriter::Options o;
    o.format = DatasetFormat::kEuroc;
    return o;
  }());
  // Ground truth at 200 Hz starting 1 ms after the first frame (frames at 30 Hz from 100 s):
  // frame k pairs with the 200 Hz sample nearest to it, i.e. row round((k / 30 - 0.001) * 200).
  fs::create_directories(dir + "/mav0/state_groundtruth_estimate0");
  std::string csv = "#timestamp, p_RS_R_x [m], ...\n";
  for (int r = 0; r < 40; ++r)
    csv +=
        std::to_string(100001000000LL + 5000000LL * r) + "," + std::to_string(r) + ",0,0,1,0,0,0\n";
  WriteAll(dir + "/mav0/state_groundtruth_estimate0/data.csv", csv);
  EurocReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir, &error)) << error;
  for (size_t k = 0; k < 3; ++k) {
    DatasetFrame f;
    ASSERT_TRUE(reader.ReadFrame(k, &f, &error)) << error;
    ASSERT_TRUE(f.has_gt) << k;
    EXPECT_EQ(f.T_world_cam0.translation().x(), std::round((k / 30.0 - 0.001) * 200.0)) << k;
  }
}

// --- Determinism ------------------------------------------------------------------------------

TEST_F(DatasetTest, IdenticalInputGivesByteIdenticalFiles) {
  for (DatasetFormat format : {DatasetFormat::kKitti, DatasetFormat::kEuroc, DatasetFormat::kTum}) {
    DatasetWriter::Options options;
    options.format = format;
    const std::string name = DatasetFormatName(format);
    const std::string a = WriteSequence(name + "_a", MakeSequence(kNumFrames, true, true), options);
    const std::string b = WriteSequence(name + "_b", MakeSequence(kNumFrames, true, true), options);
    const std::map<std::string, std::string> files_a = ReadTree(a), files_b = ReadTree(b);
    EXPECT_GT(files_a.size(), 15u);
    ASSERT_EQ(files_a.size(), files_b.size());
    for (const auto& [path, content] : files_a) {
      ASSERT_TRUE(files_b.count(path)) << path;
      EXPECT_TRUE(content == files_b.at(path)) << name << ": " << path << " differs";
    }
  }
}

// --- Atomic output ------------------------------------------------------------------------------

TEST_F(DatasetTest, WriterDestroyedBeforeFinishLeavesNothing) {
  const std::string dir = Dir("unfinished");
  {
    DatasetWriter writer;
    std::string error;
    ASSERT_TRUE(writer.Open(dir, TestCamera(), &error)) << error;
    for (const DatasetFrame& f : MakeSequence(2, true, true)) ASSERT_TRUE(writer.Add(f, &error));
    EXPECT_TRUE(fs::is_directory(writer.partial_dir()));
    EXPECT_FALSE(fs::exists(dir));
  }
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_TRUE(EntriesStartingWith("unfinished").empty());

  // The same when an exception unwinds the writer.
  try {
    DatasetWriter writer;
    std::string error;
    ASSERT_TRUE(writer.Open(dir, TestCamera(), &error)) << error;
    ASSERT_TRUE(writer.Add(MakeSequence(1, false, false)[0], &error));
    throw std::runtime_error("interrupted");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(dir));
  EXPECT_TRUE(EntriesStartingWith("unfinished").empty());
}

TEST_F(DatasetTest, ExistingFolderRefusedUnlessOverwrite) {
  const std::string dir = WriteSequence("out", MakeSequence(2, false, false));
  WriteAll(dir + "/marker.txt", "old");
  DatasetWriter writer;
  std::string error;
  EXPECT_FALSE(writer.Open(dir, TestCamera(), &error));
  EXPECT_THAT(error, HasSubstr(dir + ": output folder already exists"));
  EXPECT_TRUE(fs::exists(dir + "/marker.txt"));

  DatasetWriter::Options options;
  options.overwrite = true;
  WriteSequence("out", MakeSequence(3, false, false), options);
  EXPECT_FALSE(fs::exists(dir + "/marker.txt"));
  EXPECT_TRUE(fs::exists(dir + "/image_0/000002.png"));
  EXPECT_EQ(EntriesStartingWith("out"), std::vector<std::string>{"out"});  // no .old / .partial
}

TEST_F(DatasetTest, OpenRemovesOnlyMarkedPartialFoldersOfDeadWriters) {
  // A writer killed outright leaves DIR.partial-<pid>-XXXXXX with vobench's marker naming it; no
  // process has this pid.
  const fs::path stale = root_ / "seq.partial-2147483646-AbC123";
  fs::create_directories(stale / "image_0");
  char host[256] = {};
  gethostname(host, sizeof(host) - 1);
  const auto marker = [&](long pid) {
    return "{\"vobench_folder\": 1, \"kind\": \"dataset\", \"pid\": " + std::to_string(pid) +
           ", \"host\": \"" + std::string(host) +
           "\", \"work_folder_of_pid\": " + std::to_string(pid) + "}\n";
  };
  WriteAll(stale / ".vobench.json", marker(2147483646));
  // The same without a marker (written by someone else, or by an older vobench): left alone.
  const fs::path foreign = root_ / "seq.partial-old000";
  fs::create_directories(foreign);
  WriteAll(foreign / ".writer_pid", "2147483646\n");
  // A partial folder of a live writer (this process) stays.
  const fs::path live = root_ / "seq.partial-live00";
  fs::create_directories(live);
  WriteAll(live / ".vobench.json", marker(::getpid()));
  WriteSequence("seq", MakeSequence(1, false, false));
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(foreign / ".writer_pid"));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_FALSE(fs::exists(root_ / "seq" / ".writer_pid"));
  EXPECT_TRUE(fs::exists(root_ / "seq" / ".vobench.json"));
}

TEST_F(DatasetTest, OverwriteReplacesOnlyAVobenchDataset) {
  // --overwrite used to remove any folder; now only one with vobench's dataset marker.
  const std::string dir = Dir("mine");
  fs::create_directories(dir);
  WriteAll(dir + "/important.txt", "x");
  DatasetWriter::Options options;
  options.overwrite = true;
  DatasetWriter writer(options);
  std::string error;
  EXPECT_FALSE(writer.Open(dir, TestCamera(), &error));
  EXPECT_THAT(error, HasSubstr(dir + ": exists and was not written by vobench (no .vobench.json)"));
  EXPECT_EQ(ReadAll(dir + "/important.txt"), "x");
  EXPECT_EQ(EntriesStartingWith("mine"), std::vector<std::string>{"mine"});
}

TEST_F(DatasetTest, WriterRejectsBadFrames) {
  DatasetWriter writer;
  std::string error;
  ASSERT_TRUE(writer.Open(Dir("bad"), TestCamera(), &error)) << error;
  std::vector<DatasetFrame> frames = MakeSequence(3, true, false);
  DatasetFrame wrong_size = frames[0];
  wrong_size.right = cv::Mat::zeros(10, 10, CV_8UC1);
  EXPECT_FALSE(writer.Add(wrong_size, &error));
  EXPECT_THAT(error, HasSubstr("right image must be CV_8UC1 64x48"));
  DatasetFrame wrong_type = frames[0];
  wrong_type.left = cv::Mat::zeros(48, 64, CV_8UC3);
  EXPECT_FALSE(writer.Add(wrong_type, &error));
  EXPECT_THAT(error, HasSubstr("left image must be CV_8UC1"));
  ASSERT_TRUE(writer.Add(frames[0], &error)) << error;
  EXPECT_FALSE(writer.Add(frames[0], &error));
  EXPECT_THAT(error, HasSubstr("not after the previous frame"));
  frames[1].has_gt = false;
  EXPECT_FALSE(writer.Add(frames[1], &error));
  EXPECT_THAT(error, HasSubstr("has no ground truth but frame 0 has"));

  DatasetWriter empty;
  ASSERT_TRUE(empty.Open(Dir("empty"), TestCamera(), &error)) << error;
  EXPECT_FALSE(empty.Finish(&error));
  EXPECT_THAT(error, HasSubstr("no frames"));

  DatasetWriter::Options options;
  options.png_compression = 11;
  EXPECT_FALSE(options.IsValid(&error));
  DatasetWriter invalid(options);
  EXPECT_FALSE(invalid.Open(Dir("invalid"), TestCamera(), &error));
  EXPECT_THAT(error, HasSubstr("png_compression"));
  DatasetFormat format;
  EXPECT_TRUE(ParseDatasetFormat("euroc", &format));
  EXPECT_EQ(format, DatasetFormat::kEuroc);
  EXPECT_TRUE(ParseDatasetFormat("tum", &format));
  EXPECT_EQ(format, DatasetFormat::kTum);
  EXPECT_FALSE(ParseDatasetFormat("asl", &format));
}

// --- Malformed input: false and an error that names the file -------------------------------------

class KittiMalformedTest : public DatasetTest {
 protected:
  void SetUp() override {
    DatasetTest::SetUp();
    dir_ = WriteSequence("seq", MakeSequence(kNumFrames, true, false));
  }
  // Opens the dataset and reads every frame; returns the first error (empty when all is well).
  std::string OpenAndReadAll() const {
    KittiReader reader;
    std::string error;
    if (!reader.Open(dir_, &error)) return error.empty() ? "<empty error>" : error;
    for (size_t i = 0; i < reader.size(); ++i) {
      DatasetFrame f;
      if (!reader.ReadFrame(i, &f, &error)) return error.empty() ? "<empty error>" : error;
    }
    return "";
  }
  std::string dir_;
};

TEST_F(KittiMalformedTest, WellFormedReadsCleanly) { EXPECT_EQ(OpenAndReadAll(), ""); }

TEST_F(KittiMalformedTest, MissingCalib) {
  fs::remove(dir_ + "/calib.txt");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt: file not found"));
}

TEST_F(KittiMalformedTest, MalformedP0Line) {
  WriteAll(dir_ + "/calib.txt",
           "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 1\nP1: 52.25 0 31.5 -6.53125 0 "
           "51.75 23.5 0 0 0 1 0\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt:1: P0: expected 12 numbers, got 11"));
}

TEST_F(KittiMalformedTest, NanInCalibration) {
  WriteAll(dir_ + "/calib.txt",
           "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 1 0\nP1: 52.25 0 nan "
           "-6.53125 0 51.75 23.5 0 0 0 1 0\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/calib.txt:2: P1: field 3 ('nan') is not finite"));
}

TEST_F(KittiMalformedTest, MissingP1) {
  WriteAll(dir_ + "/calib.txt", "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 1 0\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt: no P1: line"));
}

TEST_F(KittiMalformedTest, LeftAndRightSizesDiffer) {
  cv::imwrite(dir_ + "/image_1/000000.png", cv::Mat::zeros(40, 64, CV_8UC1));
  const std::string error = OpenAndReadAll();
  EXPECT_THAT(error, HasSubstr(dir_ + "/image_1/000000.png: size 64x40 differs from the left"));
}

TEST_F(KittiMalformedTest, ImageSizeChangesAcrossFrames) {
  cv::imwrite(dir_ + "/image_0/000003.png", cv::Mat::zeros(48, 60, CV_8UC1));
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/image_0/000003.png: image size 60x48 differs from 64x48"));
}

TEST_F(KittiMalformedTest, FewerPosesThanFrames) {
  std::vector<Eigen::Isometry3d> poses;
  std::string error;
  ASSERT_TRUE(ReadKittiPoses(dir_ + "/poses.txt", &poses, &error)) << error;
  poses.pop_back();
  ASSERT_TRUE(WriteKittiPoses(dir_ + "/poses.txt", poses, &error)) << error;
  const std::string message = OpenAndReadAll();
  EXPECT_THAT(message, HasSubstr(dir_ + "/poses.txt: has 4 poses but"));
  EXPECT_THAT(message, HasSubstr("lists 5 frames"));
  EXPECT_THAT(message, HasSubstr("fewer poses than frames"));
}

TEST_F(KittiMalformedTest, MissingImageFile) {
  fs::remove(dir_ + "/image_1/000002.png");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/image_1/000002.png: missing image file"));
}

TEST_F(KittiMalformedTest, UndecodableImage) {
  WriteAll(dir_ + "/image_0/000001.png", "not a png");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/image_0/000001.png: cannot decode"));
}

TEST_F(KittiMalformedTest, MissingOrMalformedTimes) {
  WriteAll(dir_ + "/times.txt", "0.0\n0.1\nzero\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/times.txt:3: field 1 ('zero') is not a number"));
  fs::remove(dir_ + "/times.txt");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/times.txt: file not found"));
}

// Issue #11: `baseline_m: 1e300` in calib.txt ran and gave inf/NaN metrics.
TEST_F(KittiMalformedTest, ImplausibleBaselineOrFocalLengthIsRefused) {
  WriteAll(dir_ + "/calib.txt",
           "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 1 0\n"
           "P1: 52.25 0 31.5 -5.225e301 0 51.75 23.5 0 0 0 1 0\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt: baseline 1e+300 m is outside the "
                                                 "plausible range 0.001 .. 5 m"));
  WriteAll(dir_ + "/calib.txt",
           "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 1 0\n"
           "P1: 52.25 0 31.5 -0.0261 0 51.75 23.5 0 0 0 1 0\n");  // 0.5 mm
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt: baseline 0.0004995"));
  // fx = 0.5 px over 64 px: a 178 deg field of view, no pinhole camera.
  WriteAll(dir_ + "/calib.txt",
           "P0: 0.5 0 31.5 0 0 51.75 23.5 0 0 0 1 0\n"
           "P1: 0.5 0 31.5 -0.0625 0 51.75 23.5 0 0 0 1 0\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/calib.txt: fx 0.5 px gives a horizontal field of view of"));
}

// Issue #11: time stamps that went backwards were accepted.
TEST_F(KittiMalformedTest, TimesThatGoBackwardsAreRefused) {
  WriteAll(dir_ + "/times.txt", "0.0\n0.2\n0.1\n0.3\n0.4\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/times.txt:3: time stamp 0.1 is before the previous one, 0.2"));
}

TEST_F(KittiMalformedTest, DepthWithWrongType) {
  const std::string dir = WriteSequence("depth", MakeSequence(2, false, true));
  cv::imwrite(dir + "/depth/000001.png", cv::Mat::zeros(48, 64, CV_8UC1));
  KittiReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir, &error)) << error;
  DatasetFrame f;
  EXPECT_FALSE(reader.ReadFrame(1, &f, &error));
  EXPECT_THAT(error, HasSubstr(dir + "/depth/000001.png: expected a 16-bit"));
}

// Issue #31, item 6: a principal point at x = 1e6 px (2590 m error on a 0.98 m path), a
// duplicated P0: line (the last won silently), skew and a non-standard third row ran.
TEST_F(KittiMalformedTest, NonsenseCalibrationsAreRefusedAtTheirLine) {
  const std::string p1 = "P1: 52.25 0 31.5 -6.53125 0 51.75 23.5 0 0 0 1 0\n";
  WriteAll(dir_ + "/calib.txt",
           "P0: 52.25 0 1e6 0 0 51.75 23.5 0 0 0 1 0\n"
           "P1: 52.25 0 1e6 -6.53125 0 51.75 23.5 0 0 0 1 0\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt: principal point (1e+06, 23.5) px "
                                                 "lies outside the 64x48 image"));
  WriteAll(dir_ + "/calib.txt", "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 1 0\n" + p1 +
                                    "P0: 60 0 31.5 0 0 51.75 23.5 0 0 0 1 0\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/calib.txt:3: key 'P0': given twice (a second line would "
                               "silently replace the first)"));
  WriteAll(dir_ + "/calib.txt", "P0: 52.25 0.3 31.5 0 0 51.75 23.5 0 0 0 1 0\n" + p1);
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt:1: key 'P0': skew 0.3"));
  WriteAll(dir_ + "/calib.txt", "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0 0 0.5 0\n" + p1);
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/calib.txt:1: key 'P0': entry 11 is 0.5, expected 1"));
  WriteAll(dir_ + "/calib.txt", "P0: 52.25 0 31.5 0 0 51.75 23.5 0 0.1 0 1 0\n" + p1);
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt:1: key 'P0': entry 9 is 0.1"));
}

// Issue #31, item 13: a times.txt shorter than the image list used 10 of 32 frames silently.
TEST_F(KittiMalformedTest, TimesShorterThanTheImagesIsRefused) {
  WriteAll(dir_ + "/times.txt", "0.0\n0.1\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/times.txt: lists 2 frames but " + dir_ + "/image_0/ holds " +
                        std::to_string(kNumFrames) + " images"));
}

// Issue #31, item 7: 16-bit PNGs were read by their high byte: a 16-bit frame holding 8-bit
// values read black, 12-bit data failed as "black, textureless". Now by their bit depth.
TEST_F(KittiMalformedTest, SixteenBitImagesAreReadByTheirBitDepth) {
  KittiReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  std::vector<DatasetFrame> eight(kNumFrames);
  for (int i = 0; i < kNumFrames; ++i) ASSERT_TRUE(reader.ReadFrame(i, &eight[i], &error));
  // The same images as 16-bit PNGs: 8-bit values, then 12-bit ones (value * 16 + 7).
  for (const int shift : {0, 4}) {
    for (int i = 0; i < kNumFrames; ++i)
      for (int cam = 0; cam < 2; ++cam) {
        cv::Mat wide;
        (cam == 0 ? eight[i].left : eight[i].right).convertTo(wide, CV_16UC1, 1 << shift);
        if (shift > 0) wide += 7;
        cv::imwrite(dir_ + "/image_" + std::to_string(cam) + "/" + FrameNameOf(i), wide);
      }
    KittiReader wide_reader;
    ASSERT_TRUE(wide_reader.Open(dir_, &error)) << error;
    for (int i = 0; i < kNumFrames; ++i) {
      DatasetFrame f;
      ASSERT_TRUE(wide_reader.ReadFrame(i, &f, &error)) << error;
      EXPECT_TRUE(SameBytes(f.left, eight[i].left)) << "shift " << shift << " frame " << i;
      EXPECT_TRUE(SameBytes(f.right, eight[i].right)) << "shift " << shift << " frame " << i;
    }
  }
  // A later frame beyond the sequence's 12 bits is refused with the reason.
  cv::Mat bright(48, 64, CV_16UC1, cv::Scalar(5000));
  cv::imwrite(dir_ + "/image_1/" + FrameNameOf(2), bright);
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/image_1/000002.png: pixel value 5000 exceeds "
                                                 "the 12-bit range of the sequence"));
}

TEST(KittiCalibTest, ReadsKittiOdometryCalibration) {
  const fs::path path = fs::path(::testing::TempDir()) /
                        ("vobench_kitti_calib_" + std::to_string(::getpid()) + ".txt");
  // Sequence 00 of the KITTI odometry benchmark (P2/P3 and Tr are ignored).
  WriteAll(path,
           "P0: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 "
           "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 "
           "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00\n"
           "P1: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 -3.861448000000e+02 "
           "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 "
           "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00\n"
           "P2: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 4.538225000000e+01 "
           "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 -1.130887000000e-01 "
           "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 3.779761000000e-03\n"
           "Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
           "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
           "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01\n");
  vo::StereoCamera camera;
  std::string error;
  ASSERT_TRUE(ReadKittiCalib(path.string(), &camera, &error)) << error;
  EXPECT_DOUBLE_EQ(camera.fx_px, 718.856);
  EXPECT_DOUBLE_EQ(camera.cx_px, 607.1928);
  EXPECT_DOUBLE_EQ(camera.cy_px, 185.2157);
  EXPECT_NEAR(camera.baseline_m, 386.1448 / 718.856, 1e-12);  // 0.537 m
  fs::remove(path);
}

class EurocMalformedTest : public DatasetTest {
 protected:
  void SetUp() override {
    DatasetTest::SetUp();
    DatasetWriter::Options options;
    options.format = DatasetFormat::kEuroc;
    dir_ = WriteSequence("euroc", MakeSequence(3, true, false), options);
  }
  std::string OpenAndReadAll() const {
    EurocReader reader;
    std::string error;
    if (!reader.Open(dir_, &error)) return error.empty() ? "<empty error>" : error;
    for (size_t i = 0; i < reader.size(); ++i) {
      DatasetFrame f;
      if (!reader.ReadFrame(i, &f, &error)) return error.empty() ? "<empty error>" : error;
    }
    return "";
  }
  std::string dir_;
};

TEST_F(EurocMalformedTest, WellFormedReadsCleanly) { EXPECT_EQ(OpenAndReadAll(), ""); }

TEST_F(EurocMalformedTest, MalformedDataCsvLine) {
  WriteAll(dir_ + "/mav0/cam1/data.csv", "#timestamp [ns],filename\n100000000000\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/mav0/cam1/data.csv:2: expected '<timestamp ns>,"));
}

// Issue #11: stamps must increase in cam*/data.csv and in the ground truth.
TEST_F(EurocMalformedTest, StampsThatGoBackwardsOrRepeatAreRefused) {
  WriteAll(dir_ + "/mav0/cam0/data.csv",
           "#timestamp [ns],filename\n100000000000,100000000000.png\n"
           "100066666667,100066666667.png\n100033333333,100033333333.png\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/cam0/data.csv:4: time stamp 100033333333 "
                                                 "is before the previous one, 100066666667"));
  WriteAll(dir_ + "/mav0/cam0/data.csv",
           "#timestamp [ns],filename\n100000000000,100000000000.png\n"
           "100000000000,100033333333.png\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/mav0/cam0/data.csv:3: time stamp 100000000000 repeats"));
}

TEST_F(EurocMalformedTest, GroundTruthStampsThatGoBackwardsAreRefused) {
  WriteAll(dir_ + "/mav0/state_groundtruth_estimate0/data.csv",
           "#t\n100033333333,0,0,0,1,0,0,0\n100000000000,0,0,0,1,0,0,0\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/state_groundtruth_estimate0/data.csv:3: "
                                                 "time stamp 100000000000 is before"));
}

TEST_F(EurocMalformedTest, MissingSensorYaml) {
  fs::remove(dir_ + "/mav0/cam0/sensor.yaml");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/cam0/sensor.yaml: file not found"));
}

TEST_F(EurocMalformedTest, NanInIntrinsics) {
  std::string yaml = ReadAll(dir_ + "/mav0/cam0/sensor.yaml");
  const size_t at = yaml.find("intrinsics: [52.25");
  ASSERT_NE(at, std::string::npos);
  yaml.replace(at, std::string("intrinsics: [52.25").size(), "intrinsics: [.nan");
  WriteAll(dir_ + "/mav0/cam0/sensor.yaml", yaml);
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/cam0/sensor.yaml:"));
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(": key 'intrinsics[0]': expected a finite number, got .nan"));
}

TEST_F(EurocMalformedTest, MissingKeyAndBrokenYaml) {
  std::string yaml = ReadAll(dir_ + "/mav0/cam0/sensor.yaml");
  const size_t at = yaml.find("resolution: [64, 48]\n");
  ASSERT_NE(at, std::string::npos);
  WriteAll(dir_ + "/mav0/cam0/sensor.yaml", yaml.substr(0, at) + yaml.substr(at + 21));
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/cam0/sensor.yaml:"));
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(": key 'resolution': required: [width, height]"));
  WriteAll(dir_ + "/mav0/cam0/sensor.yaml", "T_BS: [1, 2\nintrinsics: {\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/cam0/sensor.yaml:"));
}

// Issue #31, item 4: EuRoC calibration was not checked: a focal length of 5 px on 320x240 (a
// 176 deg field of view) ran to exit 0 with 98 % error; a 10 m baseline failed later as "black,
// textureless". The KITTI and TUM readers refused both; now every layout does.
TEST_F(EurocMalformedTest, ImplausibleCalibrationIsRefusedAtItsLine) {
  const std::string path = dir_ + "/mav0/cam0/sensor.yaml";
  const std::string good = ReadAll(path);
  std::string yaml = good;
  yaml.replace(yaml.find("intrinsics: [52.25"), std::string("intrinsics: [52.25").size(),
               "intrinsics: [2");
  WriteAll(path, yaml);
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(path + ":"));
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(": key 'intrinsics': fx 2 px gives a horizontal field "
                                          "of view of"));
  yaml = good;
  yaml.replace(yaml.find(", 31.5, 23.5]"), std::string(", 31.5, 23.5]").size(), ", 3000, 23.5]");
  WriteAll(path, yaml);
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(": key 'intrinsics': principal point (3000, 23.5) px "
                                          "lies outside the 64x48 image"));
  WriteAll(path, good);
  // cam1 10 m beside cam0.
  const std::string path1 = dir_ + "/mav0/cam1/sensor.yaml";
  yaml = ReadAll(path1);
  const size_t data = yaml.find("data: [");
  ASSERT_NE(data, std::string::npos);
  const size_t first_comma = yaml.find(',', yaml.find(',', yaml.find(',', data) + 1) + 1);
  const size_t fourth = yaml.find(',', first_comma + 1);
  yaml.replace(first_comma + 1, fourth - first_comma - 1, " 10.0");
  WriteAll(path1, yaml);
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(path1 + ":"));
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(": key 'T_BS': the baseline between cam0 and cam1 is "));
  EXPECT_THAT(OpenAndReadAll(), HasSubstr("outside the plausible range 0.001 .. 5 m"));
}

TEST_F(EurocMalformedTest, MissingImageFile) {
  fs::remove(dir_ + "/mav0/cam0/data/100033333333.png");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/mav0/cam0/data/100033333333.png: missing image file"));
}

TEST_F(EurocMalformedTest, MalformedGroundTruth) {
  WriteAll(dir_ + "/mav0/state_groundtruth_estimate0/data.csv", "#t\n100000000000,1,2,3,1,0,0\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/state_groundtruth_estimate0/data.csv:2: "
                                                 "expected at least 8 fields"));
}

TEST_F(EurocMalformedTest, RealEurocSensorYamlReadsAndResolutionsMustAgree) {
  // The shape of EuRoC's cam0/sensor.yaml (V1_01_easy), with distortion.
  WriteAll(dir_ + "/mav0/cam0/sensor.yaml",
           "%YAML:1.0\n"
           "# General sensor definitions.\n"
           "sensor_type: camera\n"
           "comment: VI-Sensor cam0 (MT9M034)\n\n"
           "# Sensor extrinsics wrt. the body-frame.\n"
           "T_BS:\n  cols: 4\n  rows: 4\n"
           "  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,\n"
           "         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,\n"
           "        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,\n"
           "         0.0, 0.0, 0.0, 1.0]\n\n"
           "# Camera specific definitions.\n"
           "rate_hz: 20\n"
           "resolution: [752, 480]\n"
           "camera_model: pinhole\n"
           "intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv\n"
           "distortion_model: radial-tangential\n"
           "distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n");
  EurocCameraCalibration c;
  std::string error;
  ASSERT_TRUE(ReadEurocSensorYaml(dir_ + "/mav0/cam0/sensor.yaml", &c, &error)) << error;
  EXPECT_EQ(c.width, 752);
  EXPECT_EQ(c.height, 480);
  EXPECT_EQ(c.fu_px, 458.654);
  EXPECT_EQ(c.cv_px, 248.375);
  EXPECT_EQ(c.rate_hz, 20.0);
  EXPECT_EQ(c.distortion_model, "radial-tangential");
  ASSERT_EQ(c.distortion_coefficients.size(), 4u);
  EXPECT_EQ(c.distortion_coefficients[3], 1.76187114e-05);
  EXPECT_EQ(c.T_body_cam.translation().z(), 0.00981073058949);
  EurocReader reader;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  StereoRectification rect;
  EXPECT_FALSE(reader.Rectification(&rect, &error));
  EXPECT_THAT(error,
              HasSubstr(dir_ + "/mav0/cam0/sensor.yaml, " + dir_ + "/mav0/cam1/sensor.yaml"));
  EXPECT_THAT(error, HasSubstr("cam0 and cam1 resolutions differ (752x480 vs 64x48)"));
  DatasetFrame f;  // the images are 64x48, the yaml says 752x480
  EXPECT_FALSE(reader.ReadFrame(0, &f, &error));
  EXPECT_THAT(error, HasSubstr("differs from 752x480 (resolution in sensor.yaml)"));
}

TEST_F(EurocMalformedTest, LeftAndRightImagesOfDifferentSizes) {
  cv::imwrite(dir_ + "/mav0/cam1/data/100033333333.png", cv::Mat::zeros(40, 64, CV_8UC1));
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/cam1/data/100033333333.png: image size "
                                                 "64x40 differs from 64x48 (resolution in "
                                                 "sensor.yaml)"));
}

TEST_F(EurocMalformedTest, UndecodableImage) {
  WriteAll(dir_ + "/mav0/cam0/data/100066666667.png", "not a png");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/mav0/cam0/data/100066666667.png: cannot decode the image"));
}

TEST_F(EurocMalformedTest, MissingCameraList) {
  fs::remove(dir_ + "/mav0/cam1/data.csv");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/cam1/data.csv: file not found"));
}

TEST_F(EurocMalformedTest, GroundTruthWithFewerPosesCoversSomeFrames) {
  // Only the first frame's pose: the others have no ground truth (and say so).
  WriteAll(dir_ + "/mav0/state_groundtruth_estimate0/data.csv",
           "#t\n100000000000,1,2,3,1,0,0,0,0,0,0,0,0,0,0,0,0\n");
  EurocReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  EXPECT_EQ(reader.ground_truth_frames(), 1u);
  DatasetFrame f;
  ASSERT_TRUE(reader.ReadFrame(0, &f, &error)) << error;
  EXPECT_TRUE(f.has_gt);
  ASSERT_TRUE(reader.ReadFrame(1, &f, &error)) << error;
  EXPECT_FALSE(f.has_gt);
  // A ground truth that no frame associates with (another clock) is an error naming the file.
  WriteAll(dir_ + "/mav0/state_groundtruth_estimate0/data.csv",
           "#t\n200000000000,1,2,3,1,0,0,0,0,0,0,0,0,0,0,0,0\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/mav0/state_groundtruth_estimate0/data.csv: no "
                                                 "ground-truth pose within 0.003 s of any of the "
                                                 "3 frames"));
}

TEST_F(EurocMalformedTest, GroundTruthFromATumFile) {
  // The clip's arrangement: no state_groundtruth_estimate0, the body trajectory in TUM format in
  // the dataset folder, at 200 Hz with stamps between the frames'.
  EurocReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  std::vector<DatasetFrame> written(3);
  for (size_t i = 0; i < 3; ++i) ASSERT_TRUE(reader.ReadFrame(i, &written[i], &error)) << error;
  fs::remove_all(dir_ + "/mav0/state_groundtruth_estimate0");
  fs::remove(dir_ + "/groundtruth_tum.txt");  // the KITTI-side file: first-camera frame
  std::vector<StampedPose> body;
  const Eigen::Isometry3d T_body_cam0 = reader.cam0().T_body_cam;
  for (int r = 0; r < 20; ++r) {
    StampedPose p;
    p.time_s = 100.0 - 0.001 + 0.005 * r;
    p.T_world_cam.translation() = Eigen::Vector3d(r, 0, 0);
    body.push_back(p);
  }
  ASSERT_TRUE(WriteTum(dir_ + "/groundtruth.txt", body, &error)) << error;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  EXPECT_EQ(reader.ground_truth_path(), dir_ + "/groundtruth.txt");
  EXPECT_EQ(reader.ground_truth_frames(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    DatasetFrame f;
    ASSERT_TRUE(reader.ReadFrame(k, &f, &error)) << error;
    ASSERT_TRUE(f.has_gt);
    // Frame k at 100 + k/30 s pairs with row round((k/30 + 0.001) / 0.005); the camera pose is
    // body * T_BS(cam0).
    Eigen::Isometry3d expected = Eigen::Isometry3d::Identity();
    expected.translation().x() = std::round((k / 30.0 + 0.001) / 0.005);
    EXPECT_THAT(f.T_world_cam0, IsNearTransform(expected * T_body_cam0, 1e-12)) << k;
  }
  // groundtruth_tum.txt is preferred over groundtruth.txt; an explicit file over both; EuRoC's
  // own data.csv over the TUM files.
  ASSERT_TRUE(WriteTum(dir_ + "/groundtruth_tum.txt", body, &error)) << error;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  EXPECT_EQ(reader.ground_truth_path(), dir_ + "/groundtruth_tum.txt");
  ASSERT_TRUE(WriteTum(dir_ + "/other.txt", body, &error)) << error;
  EurocReader::Options options;
  options.gt_path = dir_ + "/other.txt";
  ASSERT_TRUE(reader.Open(dir_, options, &error)) << error;
  EXPECT_EQ(reader.ground_truth_path(), dir_ + "/other.txt");
  options.gt_path = dir_ + "/missing.txt";
  EXPECT_FALSE(reader.Open(dir_, options, &error));
  EXPECT_THAT(error, HasSubstr(dir_ + "/missing.txt: file not found"));
}

}  // namespace
}  // namespace harness
