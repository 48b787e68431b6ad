#include "harness/dataset/euroc.h"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string_view>
#include <system_error>

#include "harness/dataset/euroc_imu.h"
#include "harness/dataset/internal.h"
#include "sim/scenario.h"
#include "sim/yaml_input.h"

namespace harness {
namespace fs = std::filesystem;
namespace {

using dataset_internal::AssociateWithFrames;
using dataset_internal::CheckFrameIndex;
using dataset_internal::CountAssociated;
using dataset_internal::Fail;
using dataset_internal::FirstPairBits;
using dataset_internal::IntrinsicsProblem;
using dataset_internal::IsRotation;
using dataset_internal::Join;
using dataset_internal::NormalizeDir;
using dataset_internal::NsToSeconds;
using dataset_internal::ReadGreyImage;
using dataset_internal::Where;

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
  if (r.ok()) {
    const std::string problem = IntrinsicsProblem(c.width, c.height, c.fu_px, c.fv_px, c.cu_px,
                                                  c.cv_px, c.distortion_model == "equidistant");
    r.Check(problem.empty(), root, "", "intrinsics", problem);
  }
  c.t_bs_line = root["T_BS"].Mark().line + 1;
  if (r.Require(root, "", "distortion_coefficients", "a list of numbers"))
    r.ReadNumbers(root["distortion_coefficients"], "distortion_coefficients", 0,
                  &c.distortion_coefficients);
  r.Double(root, "", "rate_hz", &c.rate_hz);
  if (!r.Report(error)) return false;
  c.path = path;
  *calibration = c;
  return true;
}

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
  // The stereo baseline from the two T_BS, in the range every layout keeps (RigProblem).
  const double baseline_m =
      (cam_[0].T_body_cam.inverse() * cam_[1].T_body_cam).translation().norm();
  if (!(baseline_m >= sim::kMinBaselineM && baseline_m <= sim::kMaxBaselineM))
    return Fail(error, Where(cam_[1].path, cam_[1].t_bs_line) + "key 'T_BS': the baseline " +
                           "between cam0 and cam1 is " + FormatDouble(baseline_m) +
                           " m, outside the plausible range " + FormatDouble(sim::kMinBaselineM) +
                           " .. " + FormatDouble(sim::kMaxBaselineM) + " m (1 mm to 5 m)");
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
  if (!FirstPairBits(files_[0][0], files_[1][0], &bits_, error)) return false;

  // The IMU (optional): mav0/imu0/data.csv.
  if (const std::string imu = Join(mav0, "imu0/data.csv");
      fs::exists(imu, ec) && !ReadEurocImu(imu, &imu_ns_, &imu_, error))
    return false;
  if (const std::string yaml = Join(mav0, "imu0/sensor.yaml");
      has_imu() && fs::exists(yaml, ec) && !ReadEurocImuSensorYaml(yaml, &imu_options_, error))
    return false;

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
  return AssociateWithFrames(gt_path_, frame_s, gt_body_, options_.gt_max_difference_s, &gt_index_,
                             error);
}

size_t EurocReader::ground_truth_frames() const { return CountAssociated(gt_index_); }

bool EurocReader::Rectification(const RectificationOptions& options,
                                StereoRectification* rectification, std::string* error) const {
  return ComputeStereoRectification(cam_[0], cam_[1], options, rectification, error);
}

bool EurocReader::ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const {
  if (!CheckFrameIndex(dir_, index, size(), error)) return false;
  cv::Mat images[2];
  for (int cam = 0; cam < 2; ++cam) {
    if (!ReadGreyImage(files_[cam][index], cv::Size(cam_[cam].width, cam_[cam].height),
                       "resolution in sensor.yaml", bits_, &images[cam], error))
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
  frame->imu.clear();
  ImuSamplesBetween(imu_ns_, imu_, index > 0 ? t_ns_[index - 1] : INT64_MIN, t_ns_[index],
                    &frame->imu);
  return true;
}

}  // namespace harness
