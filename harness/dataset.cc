#include "harness/dataset.h"

#include <signal.h>
#include <stdlib.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "harness/output_folder.h"
#include "sim/scenario.h"
#include "sim/yaml_input.h"

namespace harness {
namespace fs = std::filesystem;
namespace {

// Tolerances for "is this a rotation" on options and EuRoC extrinsics.
constexpr double kRotationTolerance = 1e-6;  // max |R^T R - I| entry
// A rectified pair must have its baseline along x: |y|, |z| of rect1 in rect0 at most this
// fraction of the baseline (cv::stereoRectify gives ~1e-16).
constexpr double kRectifiedBaselineOffAxisFraction = 1e-6;
// Rectification with alpha 0: the focal length grows by this factor per step until no
// rectified pixel samples outside the raw images, at most kMaxRectificationZoomSteps times.
constexpr double kRectificationZoomStep = 1.001;
constexpr int kMaxRectificationZoomSteps = 200;  // 1.001^200 = 1.22

constexpr const char* kEurocGroundTruthHeader =
    "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
    "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
    "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
    "b_a_RS_S_z [m s^-2]";

bool Fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

std::string Where(const std::string& path, int line) {
  return path + ":" + std::to_string(line) + ": ";
}

std::string Join(const std::string& a, const std::string& b) { return (fs::path(a) / b).string(); }

std::string FrameName(size_t index, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu%s", index, extension);
  return name;
}

std::string SizeText(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

// A rig in the plausible ranges the simulator also keeps (sim/scenario.h): baseline 1 mm .. 5 m,
// horizontal and vertical fields of view from the focal lengths and the image size in
// (1, 170) degrees. A value outside is refused rather than run into inf/NaN metrics.
// Empty when fine, else the problem. Width and height must be known (> 0).
std::string RigProblem(const vo::StereoCamera& c) {
  std::ostringstream e;
  if (!(c.baseline_m >= sim::kMinBaselineM && c.baseline_m <= sim::kMaxBaselineM)) {
    e << "baseline " << FormatDouble(c.baseline_m) << " m is outside the plausible range "
      << FormatDouble(sim::kMinBaselineM) << " .. " << FormatDouble(sim::kMaxBaselineM)
      << " m (1 mm to 5 m)";
    return e.str();
  }
  if (c.width <= 0 || c.height <= 0) return "";
  const double fov_deg[2] = {2.0 * std::atan(c.width / (2.0 * c.fx_px)) * 180.0 / M_PI,
                             2.0 * std::atan(c.height / (2.0 * c.fy_px)) * 180.0 / M_PI};
  for (int k = 0; k < 2; ++k) {
    if (!(fov_deg[k] > sim::kMinFovDeg && fov_deg[k] < sim::kMaxFovDeg)) {
      e << (k == 0 ? "fx " : "fy ") << FormatDouble(k == 0 ? c.fx_px : c.fy_px) << " px gives a "
        << (k == 0 ? "horizontal" : "vertical") << " field of view of " << fov_deg[k]
        << " deg over " << (k == 0 ? c.width : c.height) << " px; expected "
        << sim::kMinFovDeg << " .. " << sim::kMaxFovDeg << " deg";
      return e.str();
    }
  }
  return "";
}

bool IsRotation(const Eigen::Matrix3d& R, double tolerance) {
  if (!R.allFinite()) return false;
  const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  return err <= tolerance && R.determinant() > 0.0;
}

bool WriteBytes(const std::string& path, const std::vector<uchar>& bytes, std::string* error) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Fail(error, path + ": cannot open for writing");
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) return Fail(error, path + ": write error");
  return true;
}

bool MakeDir(const std::string& path, std::string* error) {
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec) return Fail(error, path + ": cannot create folder: " + ec.message());
  return true;
}

// Folder names without a trailing separator ("out/" -> "out"), so "DIR.partial-" is a sibling.
std::string NormalizeDir(const std::string& dir) {
  fs::path p = fs::path(dir).lexically_normal();
  std::string s = p.string();
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}

// z-depth (metres, float) -> millimetres (uint16); 0 where there is no representable depth.
cv::Mat DepthToMillimetres(const cv::Mat& depth_m) {
  cv::Mat mm(depth_m.size(), CV_16UC1);
  for (int r = 0; r < depth_m.rows; ++r) {
    const float* src = depth_m.ptr<float>(r);
    uint16_t* dst = mm.ptr<uint16_t>(r);
    for (int c = 0; c < depth_m.cols; ++c) {
      const double d = src[c];
      long long v = 0;
      if (std::isfinite(d) && d > 0.0) v = std::llround(d * 1000.0);
      dst[c] = (v > 0 && v <= 65535) ? static_cast<uint16_t>(v) : 0;
    }
  }
  return mm;
}

std::string CalibRow(const char* key, const double p[12]) {
  std::string row = key;
  for (int i = 0; i < 12; ++i) row += ' ' + FormatDouble(p[i]);
  return row + '\n';
}

std::string EurocSensorYaml(const std::string& comment, const Eigen::Isometry3d& T_body_cam,
                            const vo::StereoCamera& camera, double rate_hz) {
  const Eigen::Matrix4d& T = T_body_cam.matrix();
  std::string s;
  s += "# General sensor definitions.\n";
  s += "sensor_type: camera\n";
  s += "comment: " + comment + "\n\n";
  s += "# Sensor extrinsics wrt. the body-frame.\n";
  s += "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    if (r > 0) s += "         ";
    for (int c = 0; c < 4; ++c) {
      s += FormatDouble(r == 3 ? (c == 3 ? 1.0 : 0.0) : T(r, c));
      s += (c < 3) ? ", " : (r < 3 ? ",\n" : "]\n");
    }
  }
  s += "\n# Camera specific definitions.\n";
  s += "rate_hz: " + FormatDouble(rate_hz) + "\n";
  s +=
      "resolution: [" + std::to_string(camera.width) + ", " + std::to_string(camera.height) + "]\n";
  s += "camera_model: pinhole\n";
  s += "intrinsics: [" + FormatDouble(camera.fx_px) + ", " + FormatDouble(camera.fy_px) + ", " +
       FormatDouble(camera.cx_px) + ", " + FormatDouble(camera.cy_px) + "] #fu, fv, cu, cv\n";
  s += "distortion_model: radial-tangential\n";
  s += "distortion_coefficients: [0, 0, 0, 0]\n";
  return s;
}

// Splits a CSV line on ',' and trims blanks around each field.
std::vector<std::string_view> SplitCsv(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    std::string_view f =
        line.substr(start, comma == std::string_view::npos ? line.npos : comma - start);
    while (!f.empty() && (f.front() == ' ' || f.front() == '\t')) f.remove_prefix(1);
    while (!f.empty() && (f.back() == ' ' || f.back() == '\t')) f.remove_suffix(1);
    fields.push_back(f);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

bool ParseInt64(std::string_view text, int64_t* value) {
  if (text.empty()) return false;
  const std::from_chars_result r = std::from_chars(text.data(), text.data() + text.size(), *value);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

double NsToSeconds(int64_t t_ns) { return static_cast<double>(t_ns) / 1e9; }

// File name stem of a TUM-style image: the stamp with 9 decimals (the decimal value of the
// double, correctly rounded; t_ns = llround(t * 1e9) is off by ~100 ns at 1.3e9 s).
std::string TumStampName(double time_s) {
  char name[64];
  std::snprintf(name, sizeof(name), "%.9f", time_s);
  return name;
}

// Reads one grey image of a stereo frame and checks its size against `expected`; `origin` says
// where the expected size comes from (e.g. "the size of frame 0"). Error names the file.
bool ReadGreyImage(const std::string& path, const cv::Size& expected, const std::string& origin,
                   cv::Mat* image, std::string* error) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Fail(error, path + ": missing image file");
  *image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image->empty()) return Fail(error, path + ": cannot decode the image");
  if (image->size() != expected)
    return Fail(error, path + ": image size " + SizeText(*image) + " differs from " +
                           std::to_string(expected.width) + "x" +
                           std::to_string(expected.height) + " (" + origin + ")");
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

bool ParseDatasetFormat(const std::string& name, DatasetFormat* format) {
  if (name == "kitti")
    *format = DatasetFormat::kKitti;
  else if (name == "euroc")
    *format = DatasetFormat::kEuroc;
  else if (name == "tum")
    *format = DatasetFormat::kTum;
  else
    return false;
  return true;
}

const char* DatasetFormatName(DatasetFormat format) {
  switch (format) {
    case DatasetFormat::kKitti:
      return "kitti";
    case DatasetFormat::kEuroc:
      return "euroc";
    case DatasetFormat::kTum:
      return "tum";
  }
  return "unknown";
}

int64_t TimeToNs(double time_s) { return std::llround(time_s * 1e9); }

// ---------------------------------------------------------------------------------------------
// DatasetWriter

bool DatasetWriter::Options::IsValid(std::string* error) const {
  if (format != DatasetFormat::kKitti && format != DatasetFormat::kEuroc &&
      format != DatasetFormat::kTum)
    return Fail(error, "format must be kitti, euroc or tum");
  if (png_compression < 0 || png_compression > 9)
    return Fail(error, "png_compression must be in [0, 9], got " + std::to_string(png_compression));
  if (!T_body_cam0.matrix().allFinite() || !IsRotation(T_body_cam0.linear(), kRotationTolerance))
    return Fail(error, "T_body_cam0 must be finite with a rotation in its linear part");
  if (!std::isfinite(rate_hz) || rate_hz < 0.0)
    return Fail(error, "rate_hz must be finite and >= 0, got " + FormatDouble(rate_hz));
  return true;
}

DatasetWriter::~DatasetWriter() { RemovePartial(); }

void DatasetWriter::RemovePartial() {
  if (finished_ || partial_dir_.empty()) return;
  folder_.Discard();
  partial_dir_.clear();
}

bool DatasetWriter::Open(const std::string& dir, const vo::StereoCamera& camera,
                         std::string* error) {
  if (is_open() || finished_) return Fail(error, "DatasetWriter::Open: writer already used");
  std::string why;
  if (!options_.IsValid(&why)) return Fail(error, "DatasetWriter options: " + why);
  if (!camera.IsValid(&why)) return Fail(error, "DatasetWriter camera: " + why);
  if (dir.empty()) return Fail(error, "DatasetWriter: empty output folder name");
  dir_ = NormalizeDir(dir);
  camera_ = camera;

  // The partial folder: a marked, locked, unique sibling (output_folder.h); an existing DIR is
  // replaced only with overwrite, and only when it is a vobench dataset.
  OutputFolder::Options folder_options;
  folder_options.replace_existing = options_.overwrite;
  folder_options.replace_flag = "--overwrite";
  if (!folder_.Create(dir_, "dataset", folder_options, error)) return false;
  partial_dir_ = folder_.path();

  std::vector<std::string> folders = {"image_0", "image_1"};
  if (options_.format == DatasetFormat::kEuroc) {
    folders.push_back("mav0/cam0/data");
    folders.push_back("mav0/cam1/data");
  }
  if (options_.format == DatasetFormat::kTum) {
    folders.push_back("left");
    folders.push_back("right");
  }
  for (const std::string& f : folders) {
    if (!MakeDir(Join(partial_dir_, f), error)) {
      RemovePartial();
      return false;
    }
  }
  compression_params_ = {cv::IMWRITE_PNG_COMPRESSION, options_.png_compression,
                         cv::IMWRITE_PNG_STRATEGY, cv::IMWRITE_PNG_STRATEGY_DEFAULT};
  return true;
}

bool DatasetWriter::Add(const DatasetFrame& frame, std::string* error) {
  if (!is_open()) return Fail(error, "DatasetWriter::Add: writer is not open");
  const size_t index = times_s_.size();
  const std::string what = dir_ + ": frame " + std::to_string(index) + ": ";
  const cv::Size size(camera_.width, camera_.height);
  if (!std::isfinite(frame.time_s)) return Fail(error, what + "time is not finite");
  const int64_t t_ns = TimeToNs(frame.time_s);
  if (index > 0 && t_ns <= times_ns_.back())
    return Fail(error, what + "time " + FormatDouble(frame.time_s) +
                           " s is not after the previous frame's (need strictly increasing ns)");
  if (options_.format == DatasetFormat::kTum && index > 0 &&
      TumStampName(frame.time_s) == TumStampName(times_s_.back()))
    return Fail(error,
                what + "time " + FormatDouble(frame.time_s) +
                    " s gives the previous frame's TUM image name (stamps closer than 1 ns)");
  if (frame.left.type() != CV_8UC1 || frame.left.size() != size)
    return Fail(error, what + "left image must be CV_8UC1 " + std::to_string(size.width) + "x" +
                           std::to_string(size.height) + ", got type " +
                           std::to_string(frame.left.type()) + " " + SizeText(frame.left));
  if (frame.right.type() != CV_8UC1 || frame.right.size() != size)
    return Fail(error, what + "right image must be CV_8UC1 " + std::to_string(size.width) + "x" +
                           std::to_string(size.height) + ", got type " +
                           std::to_string(frame.right.type()) + " " + SizeText(frame.right));
  const bool frame_depth = options_.write_depth && !frame.depth_m.empty();
  if (frame_depth && (frame.depth_m.type() != CV_32FC1 || frame.depth_m.size() != size))
    return Fail(error, what + "depth must be CV_32FC1 of the image size, got type " +
                           std::to_string(frame.depth_m.type()) + " " + SizeText(frame.depth_m));
  if (index == 0) {
    has_gt_ = frame.has_gt;
    has_depth_ = frame_depth;
    if (has_depth_ && !MakeDir(Join(partial_dir_, "depth"), error)) return false;
  } else {
    if (frame.has_gt != has_gt_)
      return Fail(error, what + (has_gt_ ? "has no ground truth but frame 0 has"
                                         : "has ground truth but frame 0 has none"));
    if (frame_depth != has_depth_)
      return Fail(error, what + (has_depth_ ? "has no depth but frame 0 has"
                                            : "has depth but frame 0 has none"));
  }
  if (has_gt_ && !frame.T_world_cam0.matrix().allFinite())
    return Fail(error, what + "ground-truth pose is not finite");

  // Images: encode once, write the same bytes to every layout.
  const std::string png_ns = std::to_string(t_ns) + ".png";
  for (int cam = 0; cam < 2; ++cam) {
    std::vector<uchar> png;
    if (!cv::imencode(".png", cam == 0 ? frame.left : frame.right, png, compression_params_))
      return Fail(error, what + "PNG encoding failed");
    const std::string cam_name = std::to_string(cam);
    if (!WriteBytes(Join(partial_dir_, "image_" + cam_name + "/" + FrameName(index, ".png")), png,
                    error))
      return false;
    if (options_.format == DatasetFormat::kEuroc &&
        !WriteBytes(Join(partial_dir_, "mav0/cam" + cam_name + "/data/" + png_ns), png, error))
      return false;
    if (options_.format == DatasetFormat::kTum &&
        !WriteBytes(Join(partial_dir_,
                         (cam == 0 ? "left/" : "right/") + TumStampName(frame.time_s) + ".png"),
                    png, error))
      return false;
  }
  if (has_depth_) {
    std::vector<uchar> png;
    if (!cv::imencode(".png", DepthToMillimetres(frame.depth_m), png, compression_params_))
      return Fail(error, what + "depth PNG encoding failed");
    if (!WriteBytes(Join(partial_dir_, "depth/" + FrameName(index, ".png")), png, error))
      return false;
  }
  times_s_.push_back(frame.time_s);
  times_ns_.push_back(t_ns);
  if (has_gt_) T_world_cam0_.push_back(frame.T_world_cam0);
  return true;
}

bool DatasetWriter::WriteEurocText(std::string* error) const {
  const size_t n = times_s_.size();
  double rate_hz = options_.rate_hz;
  if (rate_hz == 0.0 && n >= 2) {
    std::vector<double> dt;
    for (size_t i = 1; i < n; ++i) dt.push_back(times_s_[i] - times_s_[i - 1]);
    std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
    rate_hz = std::round(1e3 / dt[dt.size() / 2]) / 1e3;  // to 1 mHz: 30, not 29.99999999997
  }
  Eigen::Isometry3d T_cam0_cam1 = Eigen::Isometry3d::Identity();
  T_cam0_cam1.translation() = Eigen::Vector3d(camera_.baseline_m, 0.0, 0.0);
  const Eigen::Isometry3d T_body_cam[2] = {options_.T_body_cam0,
                                           options_.T_body_cam0 * T_cam0_cam1};
  const char* comments[2] = {"vobench cam0 (left)", "vobench cam1 (right)"};
  for (int cam = 0; cam < 2; ++cam) {
    const std::string base = Join(partial_dir_, "mav0/cam" + std::to_string(cam));
    std::string csv = "#timestamp [ns],filename\n";
    for (int64_t t_ns : times_ns_)
      csv += std::to_string(t_ns) + "," + std::to_string(t_ns) + ".png\n";
    if (!WriteTextFile(Join(base, "data.csv"), csv, error)) return false;
    if (!WriteTextFile(Join(base, "sensor.yaml"),
                       EurocSensorYaml(comments[cam], T_body_cam[cam], camera_, rate_hz), error))
      return false;
  }
  if (!has_gt_) return true;

  // Ground truth: body pose in the world, velocity by finite differences, zero biases.
  const std::string gt_dir = Join(partial_dir_, "mav0/state_groundtruth_estimate0");
  if (!MakeDir(gt_dir, error)) return false;
  const Eigen::Isometry3d T_cam0_body = options_.T_body_cam0.inverse();
  std::vector<Eigen::Isometry3d> T_world_body(n);
  for (size_t i = 0; i < n; ++i) T_world_body[i] = T_world_cam0_[i] * T_cam0_body;
  std::string csv = std::string(kEurocGroundTruthHeader) + "\n";
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    if (n >= 2) {
      const size_t a = i == 0 ? 0 : i - 1, b = i + 1 == n ? n - 1 : i + 1;
      v = (T_world_body[b].translation() - T_world_body[a].translation()) /
          (times_s_[b] - times_s_[a]);
    }
    const Eigen::Vector3d p = T_world_body[i].translation();
    const Eigen::Quaterniond q = CanonicalQuaternion(T_world_body[i].linear());
    csv += std::to_string(times_ns_[i]);
    for (double x : {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), v.x(), v.y(), v.z()})
      csv += "," + FormatDouble(x);
    csv += ",0,0,0,0,0,0\n";
  }
  return WriteTextFile(Join(gt_dir, "data.csv"), csv, error);
}

bool DatasetWriter::WriteTumText(std::string* error) const {
  const char* names[2] = {"left", "right"};
  for (int cam = 0; cam < 2; ++cam) {
    std::string list = std::string("# ") + names[cam] +
                       " images (vobench TUM-style stereo layout)\n# timestamp filename\n";
    for (size_t i = 0; i < times_s_.size(); ++i)
      list +=
          FormatDouble(times_s_[i]) + " " + names[cam] + "/" + TumStampName(times_s_[i]) + ".png\n";
    if (!WriteTextFile(Join(partial_dir_, std::string(names[cam]) + ".txt"), list, error))
      return false;
  }
  if (!has_gt_) return true;
  std::vector<StampedPose> gt;
  for (size_t i = 0; i < times_s_.size(); ++i) gt.push_back({times_s_[i], T_world_cam0_[i]});
  return WriteTum(Join(partial_dir_, "groundtruth.txt"), gt, error);
}

bool DatasetWriter::Finish(std::string* error) {
  if (!is_open()) return Fail(error, "DatasetWriter::Finish: writer is not open");
  if (times_s_.empty()) return Fail(error, dir_ + ": no frames were added");

  // calib.txt: rectified projection matrices, P1 = K [I | (-baseline_m, 0, 0)].
  const double P0[12] = {
      camera_.fx_px, 0, camera_.cx_px, 0, 0, camera_.fy_px, camera_.cy_px, 0, 0, 0, 1, 0};
  double P1[12];
  std::copy(P0, P0 + 12, P1);
  P1[3] = -(camera_.fx_px * camera_.baseline_m);
  if (!WriteTextFile(Join(partial_dir_, "calib.txt"), CalibRow("P0:", P0) + CalibRow("P1:", P1),
                     error) ||
      !WriteKittiTimes(Join(partial_dir_, "times.txt"), times_s_, error))
    return false;

  if (has_gt_) {
    // Ground truth relative to the first left camera, as KITTI's poses.txt.
    const Eigen::Isometry3d T_cam0first_world = T_world_cam0_.front().inverse();
    std::vector<Eigen::Isometry3d> poses;
    std::vector<StampedPose> tum;
    for (size_t i = 0; i < times_s_.size(); ++i) {
      poses.push_back(i == 0 ? Eigen::Isometry3d::Identity()
                             : T_cam0first_world * T_world_cam0_[i]);
      tum.push_back({times_s_[i], poses.back()});
    }
    if (!WriteKittiPoses(Join(partial_dir_, "poses.txt"), poses, error) ||
        !WriteTum(Join(partial_dir_, "groundtruth_tum.txt"), tum, error) ||
        !WriteKittiPoses(Join(partial_dir_, "T_world_cam0first.txt"), {T_world_cam0_.front()},
                         error))
      return false;
  }
  if (options_.format == DatasetFormat::kEuroc && !WriteEurocText(error)) return false;
  if (options_.format == DatasetFormat::kTum && !WriteTumText(error)) return false;

  // Publish: rename the partial folder to DIR (replacing an old vobench dataset when allowed).
  if (!folder_.Publish(error)) return false;
  finished_ = true;
  partial_dir_.clear();
  return true;
}

// ---------------------------------------------------------------------------------------------
// KITTI reader

bool ReadKittiCalib(const std::string& path, vo::StereoCamera* camera, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) {
    if (error) *error += " (expected the KITTI calibration with P0: and P1: lines)";
    return false;
  }
  std::vector<double> P[2];
  std::string what;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon);
    const int k = key == "P0" ? 0 : key == "P1" ? 1 : -1;
    if (k < 0) continue;  // P2, P3, Tr, ...: not used
    if (!ParseNumbers(std::string_view(line).substr(colon + 1), 12, &P[k], &what))
      return Fail(error, Where(path, static_cast<int>(i) + 1) + key + ": " + what +
                             " (expected 12 finite numbers, row-major 3x4 projection matrix)");
  }
  for (int k = 0; k < 2; ++k)
    if (P[k].empty())
      return Fail(error, path + ": no P" + std::to_string(k) + ": line (expected 'P" +
                             std::to_string(k) + ": ' and 12 numbers)");
  // Rectified pair: same intrinsics, only the x offset differs.
  for (int idx : {0, 1, 2, 5, 6, 10}) {
    if (std::abs(P[0][idx] - P[1][idx]) > 1e-9 * std::max(1.0, std::abs(P[0][idx])))
      return Fail(error, path + ": P0 and P1 differ in entry " + std::to_string(idx + 1) +
                             " (expected a rectified pair with equal intrinsics)");
  }
  camera->width = 0;
  camera->height = 0;
  camera->fx_px = P[0][0];
  camera->fy_px = P[0][5];
  camera->cx_px = P[0][2];
  camera->cy_px = P[0][6];
  if (!(camera->fx_px > 0.0) || !(camera->fy_px > 0.0))
    return Fail(error, path + ": P0 focal lengths must be > 0");
  camera->baseline_m = (P[0][3] - P[1][3]) / camera->fx_px;
  if (!(camera->baseline_m > 0.0))
    return Fail(error, path +
                           ": baseline (P0[3] - P1[3]) / fx = " + FormatDouble(camera->baseline_m) +
                           " m, expected > 0 (P1 column 4 holds -fx * baseline)");
  if (const std::string problem = RigProblem(*camera); !problem.empty())
    return Fail(error, path + ": " + problem + " (baseline = (P0[3] - P1[3]) / fx)");
  return true;
}

std::string KittiReader::ImagePath(int cam, size_t index) const {
  return Join(dir_, "image_" + std::to_string(cam) + "/" + FrameName(index, ".png"));
}

bool KittiReader::Open(const std::string& dir, const Options& options, std::string* error) {
  *this = KittiReader();
  options_ = options;
  dir_ = NormalizeDir(dir);
  std::error_code ec;
  if (!fs::is_directory(dir_, ec)) return Fail(error, dir_ + ": dataset folder not found");
  if (!ReadKittiCalib(Join(dir_, "calib.txt"), &camera_, error)) return false;
  const std::string times_path = Join(dir_, "times.txt");
  if (!ReadKittiTimes(times_path, &times_s_, error)) return false;
  if (times_s_.empty()) return Fail(error, times_path + ": no frames (expected one time per line)");

  // Ground truth.
  std::string poses_path = options_.poses_path;
  if (poses_path.empty() && fs::exists(Join(dir_, "poses.txt"), ec))
    poses_path = Join(dir_, "poses.txt");
  if (!poses_path.empty()) {
    if (!ReadKittiPoses(poses_path, &T_cam0first_cam0_, error)) return false;
    if (T_cam0first_cam0_.size() < times_s_.size())
      return Fail(error, poses_path + ": has " + std::to_string(T_cam0first_cam0_.size()) +
                             " poses but " + times_path + " lists " +
                             std::to_string(times_s_.size()) +
                             " frames (expected one pose per frame): fewer poses than frames");
    if (T_cam0first_cam0_.size() > times_s_.size())
      return Fail(error, poses_path + ": has " + std::to_string(T_cam0first_cam0_.size()) +
                             " poses but " + times_path + " lists only " +
                             std::to_string(times_s_.size()) +
                             " frames (expected one pose per frame): more poses than frames");
  } else if (options_.require_poses) {
    return Fail(error, Join(dir_, "poses.txt") + ": ground truth required but not found");
  }
  const std::string world_path = Join(dir_, "T_world_cam0first.txt");
  if (fs::exists(world_path, ec)) {
    std::vector<Eigen::Isometry3d> T;
    if (!ReadKittiPoses(world_path, &T, error)) return false;
    if (T.size() != 1)
      return Fail(error, world_path + ": expected exactly one pose (12 numbers), got " +
                             std::to_string(T.size()));
    T_world_cam0first_ = T[0];
  }

  // Every image must be there; frame 0 gives the image size.
  for (size_t i = 0; i < times_s_.size(); ++i)
    for (int cam = 0; cam < 2; ++cam)
      if (!fs::is_regular_file(ImagePath(cam, i), ec))
        return Fail(error, ImagePath(cam, i) + ": missing image file (frame " + std::to_string(i) +
                               " of " + std::to_string(times_s_.size()) + " in times.txt)");
  const cv::Mat left = cv::imread(ImagePath(0, 0), cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(ImagePath(1, 0), cv::IMREAD_GRAYSCALE);
  if (left.empty()) return Fail(error, ImagePath(0, 0) + ": cannot decode the image");
  if (right.empty()) return Fail(error, ImagePath(1, 0) + ": cannot decode the image");
  if (left.size() != right.size())
    return Fail(error, ImagePath(1, 0) + ": size " + SizeText(right) +
                           " differs from the left image's " + SizeText(left) + " (" +
                           ImagePath(0, 0) + ")");
  camera_.width = left.cols;
  camera_.height = left.rows;
  std::string why;
  if (!camera_.IsValid(&why)) return Fail(error, Join(dir_, "calib.txt") + ": " + why);
  if (const std::string problem = RigProblem(camera_); !problem.empty())
    return Fail(error, Join(dir_, "calib.txt") + ": " + problem);
  has_depth_ = options_.load_depth && fs::is_directory(Join(dir_, "depth"), ec);
  return true;
}

std::vector<StampedPose> KittiReader::GroundTruth() const {
  std::vector<StampedPose> gt;
  for (size_t i = 0; i < T_cam0first_cam0_.size(); ++i)
    gt.push_back({times_s_[i], T_world_cam0first_ * T_cam0first_cam0_[i]});
  return gt;
}

bool KittiReader::ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const {
  if (index >= size())
    return Fail(error, dir_ + ": frame " + std::to_string(index) + " out of range (" +
                           std::to_string(size()) + " frames)");
  const cv::Size size(camera_.width, camera_.height);
  cv::Mat images[2];
  for (int cam = 0; cam < 2; ++cam) {
    if (!ReadGreyImage(ImagePath(cam, index), size, "the size of frame 0", &images[cam], error))
      return false;
  }
  std::error_code ec;
  cv::Mat depth_m;
  if (has_depth_) {
    const std::string path = Join(dir_, "depth/" + FrameName(index, ".png"));
    if (!fs::is_regular_file(path, ec)) return Fail(error, path + ": missing depth image");
    const cv::Mat mm = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (mm.empty() || mm.type() != CV_16UC1)
      return Fail(error, path + ": expected a 16-bit single-channel PNG (depth in millimetres)");
    if (mm.size() != size)
      return Fail(error, path + ": depth size " + SizeText(mm) + " differs from the image size");
    mm.convertTo(depth_m, CV_32FC1, 1e-3);
  }
  frame->time_s = times_s_[index];
  frame->left = images[0];
  frame->right = images[1];
  frame->depth_m = depth_m;
  frame->has_gt = has_ground_truth();
  frame->T_world_cam0 =
      frame->has_gt ? T_world_cam0first_ * T_cam0first_cam0_[index] : Eigen::Isometry3d::Identity();
  return true;
}

// ---------------------------------------------------------------------------------------------
// EuRoC reader

bool ReadEurocSensorYaml(const std::string& path, EurocCameraCalibration* calibration,
                         std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) return false;
  // OpenCV-style files start with "%YAML:1.0", which yaml-cpp rejects: skip it.
  std::string text;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (i == 0 && lines[i].rfind("%YAML:", 0) == 0) {
      text += "\n";
      continue;
    }
    text += lines[i] + "\n";
  }
  // Only the keys below are read; the others of the format (sensor_type, comment, T_BS.rows,
  // T_BS.cols, ...) are not refused.
  EurocCameraCalibration c;
  sim::YamlReader r(path);
  if (!r.Parse(text)) return r.Report(error);
  YAML::Node root = r.root();  // not const: a missing key reads as undefined, not invalid
  if (!root.IsMap()) return Fail(error, path + ": expected a YAML mapping (T_BS, intrinsics, ...)");
  std::vector<double> T, k, res;
  if (!r.Require(root, "", "T_BS", "rows: 4, cols: 4, data: [16 numbers]") ||
      !r.ExpectMap(root["T_BS"], "T_BS", "a map with 'data: [16 numbers]'") ||
      !r.Require(root["T_BS"], "T_BS", "data", "[16 numbers]") ||
      !r.ReadNumbers(root["T_BS"]["data"], "T_BS.data", 16, &T))
    return r.Report(error);
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) c.T_body_cam.matrix()(row, col) = T[4 * row + col];
  if (!r.Check(c.T_body_cam.matrix().row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)) &&
                   IsRotation(c.T_body_cam.linear(), 1e-5),
               root, "", "T_BS", "expected a rigid transform (rotation, last row 0 0 0 1)") ||
      !r.Require(root, "", "intrinsics", "[fu, fv, cu, cv]") ||
      !r.ReadNumbers(root["intrinsics"], "intrinsics", 4, &k))
    return r.Report(error);
  c.fu_px = k[0];
  c.fv_px = k[1];
  c.cu_px = k[2];
  c.cv_px = k[3];
  if (!r.Check(c.fu_px > 0.0 && c.fv_px > 0.0, root, "", "intrinsics",
               "focal lengths fu, fv must be > 0") ||
      !r.Require(root, "", "resolution", "[width, height]") ||
      !r.ReadNumbers(root["resolution"], "resolution", 2, &res))
    return r.Report(error);
  c.width = static_cast<int>(res[0]);
  c.height = static_cast<int>(res[1]);
  r.Check(c.width > 0 && c.height > 0 && c.width == res[0] && c.height == res[1], root, "",
          "resolution", "expected two positive integers [width, height]");
  if (r.Require(root, "", "camera_model", "pinhole"))
    r.String(root, "", "camera_model", &c.camera_model);
  if (r.Require(root, "", "distortion_model", "radial-tangential | equidistant"))
    r.String(root, "", "distortion_model", &c.distortion_model);
  if (r.Require(root, "", "distortion_coefficients", "a list of numbers"))
    r.ReadNumbers(root["distortion_coefficients"], "distortion_coefficients", 0,
                  &c.distortion_coefficients);
  r.Double(root, "", "rate_hz", &c.rate_hz);
  if (!r.Report(error)) return false;
  c.path = path;
  *calibration = c;
  return true;
}

namespace {

// Reads a EuRoC camera data.csv ("#timestamp [ns],filename") into stamp -> image path.
bool ReadEurocCameraCsv(const std::string& path, const std::string& image_dir,
                        std::map<int64_t, std::string>* images, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) return false;
  images->clear();
  IncreasingStamps<int64_t> order(path);
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsBlankOrComment(lines[i])) continue;
    const std::vector<std::string_view> f = SplitCsv(lines[i]);
    int64_t t_ns = 0;
    if (f.size() != 2 || !ParseInt64(f[0], &t_ns) || f[1].empty())
      return Fail(error,
                  Where(path, static_cast<int>(i) + 1) + "expected '<timestamp ns>,<file name>'");
    if (!order.Next(t_ns, f[0], static_cast<int>(i) + 1, error)) return false;
    images->emplace(t_ns, Join(image_dir, std::string(f[1])));  // unique: increasing stamps
  }
  return true;
}

// Reads mav0/state_groundtruth_estimate0/data.csv: stamp, position, quaternion w x y z, ....
bool ReadEurocGroundTruth(const std::string& path, std::vector<int64_t>* t_ns,
                          std::vector<StampedPose>* T_world_body, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) return false;
  std::vector<double> v;
  std::string what;
  IncreasingStamps<int64_t> order(path);
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsBlankOrComment(lines[i])) continue;
    const int line_no = static_cast<int>(i) + 1;
    const size_t comma = lines[i].find(',');
    int64_t stamp = 0;
    std::string_view head = std::string_view(lines[i]).substr(0, comma);
    while (!head.empty() && head.back() == ' ') head.remove_suffix(1);
    if (comma == std::string::npos || !ParseInt64(head, &stamp))
      return Fail(error, Where(path, line_no) +
                             "expected '<timestamp ns>,p_x,p_y,p_z,q_w,q_x,q_y,q_z,...'");
    if (!order.Next(stamp, head, line_no, error)) return false;
    const std::string_view rest = std::string_view(lines[i]).substr(comma + 1);
    const size_t fields = SplitCsv(rest).size();
    if (fields < 7 || !ParseNumbers(rest, fields, &v, &what))
      return Fail(error, Where(path, line_no) + (fields < 7 ? "expected at least 8 fields" : what) +
                             " (timestamp, p_RS_R xyz, q_RS wxyz, ...)");
    Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > kTumQuaternionNormTolerance)
      return Fail(error, Where(path, line_no) + "expected a unit quaternion q_RS (w x y z)");
    q.normalize();
    StampedPose p;
    p.time_s = NsToSeconds(stamp);
    p.T_world_cam.linear() = q.toRotationMatrix();
    p.T_world_cam.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    t_ns->push_back(stamp);
    T_world_body->push_back(p);
  }
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Ground-truth association

std::vector<long> AssociateGroundTruth(const std::vector<double>& frame_times_s,
                                       const std::vector<StampedPose>& ground_truth,
                                       double max_difference_s) {
  std::vector<long> index(frame_times_s.size(), -1);
  if (frame_times_s.empty() || ground_truth.empty()) return index;
  const double t0 = frame_times_s.front();
  std::vector<double> frame_s, gt_s;
  for (double t : frame_times_s) frame_s.push_back(t - t0);
  for (const StampedPose& p : ground_truth) gt_s.push_back(p.time_s - t0);
  AssociateOptions assoc;
  assoc.max_difference_s = max_difference_s;
  for (const AssociatedPair& p : AssociateStamps(frame_s, gt_s, assoc))
    index[p.first] = static_cast<long>(p.second);
  return index;
}

namespace {

size_t CountAssociated(const std::vector<long>& index) {
  return static_cast<size_t>(
      std::count_if(index.begin(), index.end(), [](long i) { return i >= 0; }));
}

// Error for a ground truth that no frame associates with (different clocks, wrong file).
std::string NoAssociationMessage(const std::string& gt_path, const std::vector<double>& frame_s,
                                 const std::vector<StampedPose>& gt, double max_difference_s) {
  std::string m = gt_path + ": no ground-truth pose within " + FormatDouble(max_difference_s) +
                  " s of any of the " + std::to_string(frame_s.size()) + " frames";
  if (!gt.empty() && !frame_s.empty()) {
    const auto [lo, hi] = std::minmax_element(frame_s.begin(), frame_s.end());
    m += " (frames " + FormatDouble(*lo) + " .. " + FormatDouble(*hi) + " s, ground truth " +
         FormatDouble(gt.front().time_s) + " .. " + FormatDouble(gt.back().time_s) +
         " s): a different clock or the wrong file?";
  } else if (gt.empty()) {
    m += " (the file has no poses)";
  }
  return m;
}

// The calibration files, for error messages.
std::string CalibrationFiles(const EurocCameraCalibration& cam0,
                             const EurocCameraCalibration& cam1) {
  const std::string a = cam0.path.empty() ? "cam0 calibration" : cam0.path;
  const std::string b = cam1.path.empty() ? "cam1 calibration" : cam1.path;
  return a + ", " + b;
}

// True when every (x, y) of the maps lies inside the raw image, so bilinear sampling never
// reads the black border: 0 <= x <= width - 1, 0 <= y <= height - 1.
bool MapInside(const cv::Mat& map_x, const cv::Mat& map_y, const cv::Size& raw) {
  double x_min, x_max, y_min, y_max;
  cv::minMaxLoc(map_x, &x_min, &x_max);
  cv::minMaxLoc(map_y, &y_min, &y_max);
  return x_min >= 0.0 && y_min >= 0.0 && x_max <= raw.width - 1 && y_max <= raw.height - 1;
}

cv::Mat CameraMatrix(const EurocCameraCalibration& c) {
  return (cv::Mat_<double>(3, 3) << c.fu_px, 0.0, c.cu_px, 0.0, c.fv_px, c.cv_px, 0.0, 0.0, 1.0);
}

cv::Mat ToCv(const Eigen::Matrix3d& R) {
  cv::Mat m(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m.at<double>(r, c) = R(r, c);
  return m;
}

Eigen::Matrix3d ToEigen3(const cv::Mat& m) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = m.at<double>(r, c);
  return R;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Rectification

bool RectificationOptions::IsValid(std::string* error) const {
  if (!(alpha >= 0.0 && alpha <= 1.0))
    return Fail(error, "rectification alpha must be in [0, 1], got " + FormatDouble(alpha));
  for (double t : {identity_intrinsics_tolerance_px, identity_rotation_tolerance,
                   identity_offset_tolerance_m, identity_distortion_tolerance})
    if (!(t >= 0.0) || !std::isfinite(t))
      return Fail(error, "rectification identity tolerances must be finite and >= 0");
  return true;
}

bool ComputeStereoRectification(const EurocCameraCalibration& cam0,
                                const EurocCameraCalibration& cam1,
                                const RectificationOptions& options,
                                StereoRectification* rectification, std::string* error) {
  std::string why;
  if (!options.IsValid(&why)) return Fail(error, "RectificationOptions: " + why);
  const EurocCameraCalibration* cams[2] = {&cam0, &cam1};
  for (int k = 0; k < 2; ++k) {
    const EurocCameraCalibration& c = *cams[k];
    const std::string where =
        (c.path.empty() ? "cam" + std::to_string(k) + " calibration" : c.path) + ": ";
    if (c.camera_model != "pinhole")
      return Fail(error, where + "camera_model '" + c.camera_model +
                             "' is not supported (expected pinhole)");
    if (c.distortion_model != "radial-tangential" && c.distortion_model != "radtan" &&
        c.distortion_model != "equidistant")
      return Fail(error, where + "distortion_model '" + c.distortion_model +
                             "' is not supported (expected radial-tangential or equidistant)");
    if (c.distortion_coefficients.size() != 4)
      return Fail(error, where + "distortion_coefficients: expected 4 numbers (" +
                             (c.distortion_model == "equidistant" ? "k1 k2 k3 k4" : "k1 k2 p1 p2") +
                             "), got " + std::to_string(c.distortion_coefficients.size()));
    if (!(c.fu_px > 0.0) || !(c.fv_px > 0.0) || !std::isfinite(c.cu_px) ||
        !std::isfinite(c.cv_px) || c.width <= 0 || c.height <= 0)
      return Fail(error, where + "intrinsics and resolution must be finite and positive");
  }
  const std::string where = CalibrationFiles(cam0, cam1) + ": ";
  const bool equidistant = cam0.distortion_model == "equidistant";
  if (equidistant != (cam1.distortion_model == "equidistant"))
    return Fail(error, where + "cam0 and cam1 use different distortion models ('" +
                           cam0.distortion_model + "', '" + cam1.distortion_model +
                           "'); expected the same");
  if (cam0.width != cam1.width || cam0.height != cam1.height)
    return Fail(error, where + "cam0 and cam1 resolutions differ (" + std::to_string(cam0.width) +
                           "x" + std::to_string(cam0.height) + " vs " + std::to_string(cam1.width) +
                           "x" + std::to_string(cam1.height) + ")");
  const Eigen::Isometry3d T_cam0_cam1 = cam0.T_body_cam.inverse() * cam1.T_body_cam;
  const Eigen::Vector3d t = T_cam0_cam1.translation();

  // Already rectified: the identity, images used as they are.
  double max_distortion = 0.0;
  for (const EurocCameraCalibration* c : cams)
    for (double d : c->distortion_coefficients)
      max_distortion = std::max(max_distortion, std::abs(d));
  const double dk =
      std::max({std::abs(cam0.fu_px - cam1.fu_px), std::abs(cam0.fv_px - cam1.fv_px),
                std::abs(cam0.cu_px - cam1.cu_px), std::abs(cam0.cv_px - cam1.cv_px)});
  const double dr = (T_cam0_cam1.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!equidistant && max_distortion <= options.identity_distortion_tolerance &&
      dk <= options.identity_intrinsics_tolerance_px && dr <= options.identity_rotation_tolerance &&
      std::abs(t.y()) <= options.identity_offset_tolerance_m &&
      std::abs(t.z()) <= options.identity_offset_tolerance_m && t.x() > 0.0) {
    StereoRectification r;
    r.camera.width = cam0.width;
    r.camera.height = cam0.height;
    r.camera.fx_px = cam0.fu_px;
    r.camera.fy_px = cam0.fv_px;
    r.camera.cx_px = cam0.cu_px;
    r.camera.cy_px = cam0.cv_px;
    r.camera.baseline_m = t.x();
    if (!r.camera.IsValid(&why)) return Fail(error, where + why);
    *rectification = r;
    return true;
  }
  if (!(t.x() > 0.0) || std::abs(t.x()) <= std::max(std::abs(t.y()), std::abs(t.z())))
    return Fail(error, where + "cam1 sits at (" + FormatDouble(t.x()) + ", " + FormatDouble(t.y()) +
                           ", " + FormatDouble(t.z()) +
                           ") m in cam0: expected it to the right of cam0 (mostly +x); vertical "
                           "or swapped pairs are not supported");

  // OpenCV's R, T map cam0 points into cam1: p_cam1 = R p_cam0 + T.
  const Eigen::Isometry3d T_cam1_cam0 = T_cam0_cam1.inverse();
  const cv::Mat R = ToCv(T_cam1_cam0.linear());
  const cv::Mat T = (cv::Mat_<double>(3, 1) << T_cam1_cam0.translation().x(),
                     T_cam1_cam0.translation().y(), T_cam1_cam0.translation().z());
  const cv::Mat K0 = CameraMatrix(cam0), K1 = CameraMatrix(cam1);
  const cv::Mat D0(cam0.distortion_coefficients, true), D1(cam1.distortion_coefficients, true);
  const cv::Size size(cam0.width, cam0.height);
  cv::Mat R1, R2, P1, P2, Q;
  StereoRectification r;
  try {
    if (equidistant)
      cv::fisheye::stereoRectify(K0, D0, K1, D1, size, R, T, R1, R2, P1, P2, Q,
                                 cv::CALIB_ZERO_DISPARITY, size, options.alpha, 1.0);
    else
      cv::stereoRectify(K0, D0, K1, D1, size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY,
                        options.alpha, size);
    P1.convertTo(P1, CV_64F);
    P2.convertTo(P2, CV_64F);
    R1.convertTo(R1, CV_64F);
    R2.convertTo(R2, CV_64F);
    // alpha 0 promises no invalid pixel, but OpenCV finds its zoom on a sparse grid of points
    // (EuRoC: 26 map entries fall just outside the raw image). Zoom in further, about the
    // principal point, until every rectified pixel samples inside both raw images.
    for (int attempt = 0;; ++attempt) {
      if (equidistant) {
        cv::fisheye::initUndistortRectifyMap(K0, D0, R1, P1, size, CV_32FC1, r.map0_x, r.map0_y);
        cv::fisheye::initUndistortRectifyMap(K1, D1, R2, P2, size, CV_32FC1, r.map1_x, r.map1_y);
      } else {
        cv::initUndistortRectifyMap(K0, D0, R1, P1, size, CV_32FC1, r.map0_x, r.map0_y);
        cv::initUndistortRectifyMap(K1, D1, R2, P2, size, CV_32FC1, r.map1_x, r.map1_y);
      }
      if (options.alpha > 0.0 ||
          (MapInside(r.map0_x, r.map0_y, size) && MapInside(r.map1_x, r.map1_y, size)))
        break;
      if (attempt == kMaxRectificationZoomSteps)
        return Fail(error, where +
                               "rectification: no zoom puts every rectified pixel inside the "
                               "raw images (extreme distortion?); try a larger alpha");
      for (cv::Mat* P : {&P1, &P2}) {
        P->at<double>(0, 0) *= kRectificationZoomStep;
        P->at<double>(1, 1) *= kRectificationZoomStep;
        P->at<double>(0, 3) *= kRectificationZoomStep;  // -f * baseline follows f
      }
    }
  } catch (const cv::Exception& e) {
    return Fail(error, where + "rectification failed in OpenCV: " + e.what());
  }
  r.camera.width = cam0.width;
  r.camera.height = cam0.height;
  r.camera.fx_px = P1.at<double>(0, 0);
  r.camera.fy_px = P1.at<double>(1, 1);
  r.camera.cx_px = P1.at<double>(0, 2);
  r.camera.cy_px = P1.at<double>(1, 2);
  r.camera.baseline_m = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
  r.R_cam0_rect0 = ToEigen3(R1).transpose();
  r.R_cam1_rect1 = ToEigen3(R2).transpose();
  // The result must be the ideal pair the VO assumes: rect1 at +baseline along rect0's x.
  const Eigen::Vector3d t_rect0_rect1 = r.R_cam0_rect0.transpose() * t;
  const double off_axis = std::max(std::abs(t_rect0_rect1.y()), std::abs(t_rect0_rect1.z()));
  if (!r.camera.IsValid(&why) || !IsRotation(r.R_cam0_rect0, 1e-9) ||
      !IsRotation(r.R_cam1_rect1, 1e-9) || std::abs(P2.at<double>(1, 3)) > 0.0 ||
      off_axis > kRectifiedBaselineOffAxisFraction * t.norm() ||
      std::abs(t_rect0_rect1.x() - r.camera.baseline_m) > 1e-9 * t.norm() + 1e-12)
    return Fail(error, where + "rectification gave a degenerate pair" +
                           (why.empty() ? std::string() : ": " + why));
  if (const std::string problem = RigProblem(r.camera); !problem.empty())
    return Fail(error, where + "the rectified pair: " + problem);
  *rectification = r;
  return true;
}

void RectifyFrame(const StereoRectification& rectification, DatasetFrame* frame) {
  if (rectification.IsIdentity()) return;
  const cv::Size raw = rectification.map0_x.size();
  if (frame->left.size() != raw || frame->right.size() != raw) {
    std::fprintf(stderr, "harness::RectifyFrame: images %dx%d / %dx%d, maps made for %dx%d\n",
                 frame->left.cols, frame->left.rows, frame->right.cols, frame->right.rows,
                 raw.width, raw.height);
    std::abort();
  }
  cv::Mat left, right;
  cv::remap(frame->left, left, rectification.map0_x, rectification.map0_y, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::remap(frame->right, right, rectification.map1_x, rectification.map1_y, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  frame->left = left;
  frame->right = right;
  frame->depth_m = cv::Mat();
  if (frame->has_gt) {
    Eigen::Isometry3d T_cam0_rect0 = Eigen::Isometry3d::Identity();
    T_cam0_rect0.linear() = rectification.R_cam0_rect0;
    frame->T_world_cam0 = frame->T_world_cam0 * T_cam0_rect0;
  }
}

// ---------------------------------------------------------------------------------------------
// EuRoC reader (continued)

bool EurocReader::Open(const std::string& dir, const Options& options, std::string* error) {
  *this = EurocReader();
  options_ = options;
  dir_ = NormalizeDir(dir);
  if (!std::isfinite(options_.gt_max_difference_s) || options_.gt_max_difference_s <= 0.0)
    return Fail(error, "EurocReader options: gt_max_difference_s must be finite and > 0");
  std::error_code ec;
  if (!fs::is_directory(dir_, ec)) return Fail(error, dir_ + ": dataset folder not found");
  const std::string mav0 = Join(dir_, "mav0");
  if (!fs::is_directory(mav0, ec)) return Fail(error, mav0 + ": folder not found (EuRoC layout)");

  std::map<int64_t, std::string> images[2];
  for (int cam = 0; cam < 2; ++cam) {
    const std::string base = Join(mav0, "cam" + std::to_string(cam));
    if (!ReadEurocSensorYaml(Join(base, "sensor.yaml"), &cam_[cam], error)) return false;
    if (!ReadEurocCameraCsv(Join(base, "data.csv"), Join(base, "data"), &images[cam], error))
      return false;
  }
  // Stereo frames: stamps present in both cameras.
  for (const auto& [t_ns, path0] : images[0]) {
    const auto it = images[1].find(t_ns);
    if (it == images[1].end()) continue;
    t_ns_.push_back(t_ns);
    files_[0].push_back(path0);
    files_[1].push_back(it->second);
  }
  unpaired_ = images[0].size() + images[1].size() - 2 * t_ns_.size();
  if (t_ns_.empty())
    return Fail(error, Join(mav0, "cam0/data.csv") + ": no time stamp shared with cam1/data.csv");
  for (size_t i = 0; i < t_ns_.size(); ++i)
    for (int cam = 0; cam < 2; ++cam)
      if (!fs::is_regular_file(files_[cam][i], ec))
        return Fail(error, files_[cam][i] + ": missing image file (listed in cam" +
                               std::to_string(cam) + "/data.csv)");

  // Ground truth (optional): the given file, else the first that exists.
  gt_index_.assign(t_ns_.size(), -1);
  gt_path_ = options_.gt_path;
  if (gt_path_.empty()) {
    for (const std::string& candidate :
         {Join(mav0, "state_groundtruth_estimate0/data.csv"), Join(dir_, "groundtruth_tum.txt"),
          Join(dir_, "groundtruth.txt")})
      if (fs::exists(candidate, ec)) {
        gt_path_ = candidate;
        break;
      }
  }
  if (gt_path_.empty()) return true;
  // EuRoC's own csv (by its .csv name) or a TUM trajectory.
  if (fs::path(gt_path_).extension() == ".csv") {
    std::vector<int64_t> gt_ns;
    if (!ReadEurocGroundTruth(gt_path_, &gt_ns, &gt_body_, error)) return false;
  } else if (!ReadTum(gt_path_, &gt_body_, error)) {
    return false;
  }
  std::vector<double> frame_s;
  for (int64_t t : t_ns_) frame_s.push_back(NsToSeconds(t));
  gt_index_ = AssociateGroundTruth(frame_s, gt_body_, options_.gt_max_difference_s);
  if (CountAssociated(gt_index_) == 0)
    return Fail(error,
                NoAssociationMessage(gt_path_, frame_s, gt_body_, options_.gt_max_difference_s));
  return true;
}

size_t EurocReader::ground_truth_frames() const { return CountAssociated(gt_index_); }

bool EurocReader::Rectification(const RectificationOptions& options,
                                StereoRectification* rectification, std::string* error) const {
  return ComputeStereoRectification(cam_[0], cam_[1], options, rectification, error);
}

bool EurocReader::ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const {
  if (index >= size())
    return Fail(error, dir_ + ": frame " + std::to_string(index) + " out of range (" +
                           std::to_string(size()) + " frames)");
  cv::Mat images[2];
  for (int cam = 0; cam < 2; ++cam) {
    if (!ReadGreyImage(files_[cam][index], cv::Size(cam_[cam].width, cam_[cam].height),
                       "resolution in sensor.yaml", &images[cam], error))
      return false;
  }
  frame->time_s = NsToSeconds(t_ns_[index]);
  frame->left = images[0];
  frame->right = images[1];
  frame->depth_m = cv::Mat();
  const long gt = gt_index_[index];
  frame->has_gt = gt >= 0;
  frame->T_world_cam0 =
      frame->has_gt ? gt_body_[gt].T_world_cam * cam_[0].T_body_cam : Eigen::Isometry3d::Identity();
  return true;
}

// ---------------------------------------------------------------------------------------------
// TUM-style stereo reader

namespace {

// Reads a TUM rgb.txt-style list: "timestamp filename" lines, '#' comments.
bool ReadTumImageList(const std::string& path, const std::string& dir, std::vector<double>* times_s,
                      std::vector<std::string>* files, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) {
    if (error) *error += " (expected the image list: 'timestamp filename' per line)";
    return false;
  }
  IncreasingStamps<double> order(path);
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsBlankOrComment(lines[i])) continue;
    const int line_no = static_cast<int>(i) + 1;
    std::istringstream in(lines[i]);
    std::string stamp, file, extra;
    double t = 0.0;
    if (!(in >> stamp >> file) || (in >> extra) || !ParseDouble(stamp, &t) || !std::isfinite(t))
      return Fail(error, Where(path, line_no) +
                             "expected 'timestamp filename' (seconds, a path relative to " + dir +
                             ")");
    if (!order.Next(t, stamp, line_no, error)) return false;
    times_s->push_back(t);
    files->push_back(Join(dir, file));
  }
  if (times_s->empty()) return Fail(error, path + ": no images listed");
  return true;
}

}  // namespace

bool TumReader::Open(const std::string& dir, const Options& options, std::string* error) {
  *this = TumReader();
  options_ = options;
  dir_ = NormalizeDir(dir);
  if (!(options_.gt_max_difference_s > 0.0) || !std::isfinite(options_.gt_max_difference_s) ||
      !(options_.stereo_max_difference_s > 0.0) || !std::isfinite(options_.stereo_max_difference_s))
    return Fail(error,
                "TumReader options: gt_max_difference_s and stereo_max_difference_s must "
                "be finite and > 0");
  std::error_code ec;
  if (!fs::is_directory(dir_, ec)) return Fail(error, dir_ + ": dataset folder not found");
  if (!ReadKittiCalib(Join(dir_, "calib.txt"), &camera_, error)) return false;
  std::vector<double> t[2];
  std::vector<std::string> files[2];
  const std::string lists[2] = {Join(dir_, "left.txt"), Join(dir_, "right.txt")};
  for (int cam = 0; cam < 2; ++cam)
    if (!ReadTumImageList(lists[cam], dir_, &t[cam], &files[cam], error)) return false;

  // Stereo frames: left and right associated by stamp; a frame's time is its left stamp.
  AssociateOptions stereo;
  stereo.max_difference_s = options_.stereo_max_difference_s;
  const double t0 = std::min(*std::min_element(t[0].begin(), t[0].end()),
                             *std::min_element(t[1].begin(), t[1].end()));
  std::vector<double> rel[2];
  for (int cam = 0; cam < 2; ++cam)
    for (double x : t[cam]) rel[cam].push_back(x - t0);
  for (const AssociatedPair& p : AssociateStamps(rel[0], rel[1], stereo)) {
    times_s_.push_back(t[0][p.first]);
    files_[0].push_back(files[0][p.first]);
    files_[1].push_back(files[1][p.second]);
  }
  unpaired_ = t[0].size() + t[1].size() - 2 * times_s_.size();
  if (times_s_.empty())
    return Fail(error, lists[0] + ": no left stamp within " +
                           FormatDouble(options_.stereo_max_difference_s) + " s of a stamp in " +
                           lists[1]);
  for (size_t i = 0; i < times_s_.size(); ++i)
    for (int cam = 0; cam < 2; ++cam)
      if (!fs::is_regular_file(files_[cam][i], ec))
        return Fail(error, files_[cam][i] + ": missing image file (listed in " + lists[cam] + ")");
  const cv::Mat left = cv::imread(files_[0][0], cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(files_[1][0], cv::IMREAD_GRAYSCALE);
  if (left.empty()) return Fail(error, files_[0][0] + ": cannot decode the image");
  if (right.empty()) return Fail(error, files_[1][0] + ": cannot decode the image");
  if (left.size() != right.size())
    return Fail(error, files_[1][0] + ": size " + SizeText(right) +
                           " differs from the left image's " + SizeText(left) + " (" +
                           files_[0][0] + ")");
  camera_.width = left.cols;
  camera_.height = left.rows;
  std::string why;
  if (!camera_.IsValid(&why)) return Fail(error, Join(dir_, "calib.txt") + ": " + why);
  if (const std::string problem = RigProblem(camera_); !problem.empty())
    return Fail(error, Join(dir_, "calib.txt") + ": " + problem);

  // Ground truth (optional).
  gt_index_.assign(times_s_.size(), -1);
  gt_path_ = options_.gt_path;
  if (gt_path_.empty() && fs::exists(Join(dir_, "groundtruth.txt"), ec))
    gt_path_ = Join(dir_, "groundtruth.txt");
  if (gt_path_.empty()) return true;
  if (!ReadTum(gt_path_, &gt_, error)) return false;
  gt_index_ = AssociateGroundTruth(times_s_, gt_, options_.gt_max_difference_s);
  if (CountAssociated(gt_index_) == 0)
    return Fail(error, NoAssociationMessage(gt_path_, times_s_, gt_, options_.gt_max_difference_s));
  return true;
}

size_t TumReader::ground_truth_frames() const { return CountAssociated(gt_index_); }

bool TumReader::ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const {
  if (index >= size())
    return Fail(error, dir_ + ": frame " + std::to_string(index) + " out of range (" +
                           std::to_string(size()) + " frames)");
  const cv::Size size(camera_.width, camera_.height);
  cv::Mat images[2];
  for (int cam = 0; cam < 2; ++cam) {
    if (!ReadGreyImage(files_[cam][index], size, "the size of the first pair", &images[cam], error))
      return false;
  }
  frame->time_s = times_s_[index];
  frame->left = images[0];
  frame->right = images[1];
  frame->depth_m = cv::Mat();
  const long gt = gt_index_[index];
  frame->has_gt = gt >= 0;
  frame->T_world_cam0 = frame->has_gt ? gt_[gt].T_world_cam : Eigen::Isometry3d::Identity();
  return true;
}

}  // namespace harness
