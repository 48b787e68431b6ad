#include "harness/dataset/writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "harness/dataset/euroc_imu.h"
#include "harness/dataset/internal.h"
#include "harness/dataset/kalibr.h"
#include "harness/trajectory_io.h"

namespace harness {
namespace fs = std::filesystem;
namespace {

using dataset_internal::Fail;
using dataset_internal::FrameName;
using dataset_internal::IsRotation;
using dataset_internal::Join;
using dataset_internal::NormalizeDir;
using dataset_internal::SizeText;

// Tolerance for "is this a rotation" on the options.
constexpr double kRotationTolerance = 1e-6;  // max |R^T R - I| entry
// Largest stamp offset: with |t| < 4e9 s (ExactNs) a stamp stays below 9.2e18 (int64).
constexpr int64_t kMaxStampOffsetNs = 5000000000000000000LL;

constexpr const char* kEurocGroundTruthHeader =
    "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
    "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
    "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
    "b_a_RS_S_z [m s^-2]";

bool WriteBytes(const std::string& path, const std::vector<uchar>& bytes, std::string* error) {
  return WriteFileBytes(path, bytes.data(), bytes.size(), error);
}

bool MakeDir(const std::string& path, std::string* error) {
  std::error_code ec;
  fs::create_directories(path, ec);
  if (ec) return Fail(error, path + ": cannot create folder: " + ec.message());
  return true;
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

// The first line of every YAML file written: OpenCV's cv::FileStorage refuses a file without
// it ("Input file is invalid"); EuRoC's files carry it; the yaml-cpp readers skip it.
constexpr const char* kOpenCvYamlHeader = "%YAML:1.0\n";

// "T_BS:" as EuRoC writes it: a 4x4 row-major map (OpenCV reads it as a map of cols, rows,
// data; yaml-cpp as well).
std::string EurocTransformYaml(const Eigen::Isometry3d& T_body_sensor) {
  const Eigen::Matrix4d& T = T_body_sensor.matrix();
  std::string s = "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    if (r > 0) s += "         ";
    for (int c = 0; c < 4; ++c) {
      s += FormatDouble(r == 3 ? (c == 3 ? 1.0 : 0.0) : T(r, c));
      s += (c < 3) ? ", " : (r < 3 ? ",\n" : "]\n");
    }
  }
  return s;
}

std::string EurocSensorYaml(const std::string& comment, const Eigen::Isometry3d& T_body_cam,
                            const vo::StereoCamera& camera, const sim::LensDistortion& lens,
                            double rate_hz) {
  std::string s = kOpenCvYamlHeader;
  s += "# General sensor definitions.\n";
  s += "sensor_type: camera\n";
  s += "comment: " + comment + "\n\n";
  s += "# Sensor extrinsics wrt. the body-frame.\n";
  s += EurocTransformYaml(T_body_cam);
  s += "\n# Camera specific definitions.\n";
  s += "rate_hz: " + FormatDouble(rate_hz) + "\n";
  s +=
      "resolution: [" + std::to_string(camera.width) + ", " + std::to_string(camera.height) + "]\n";
  s += "camera_model: pinhole\n";
  s += "intrinsics: [" + FormatDouble(camera.fx_px) + ", " + FormatDouble(camera.fy_px) + ", " +
       FormatDouble(camera.cx_px) + ", " + FormatDouble(camera.cy_px) + "] #fu, fv, cu, cv\n";
  if (!lens.any()) {
    s += "distortion_model: radial-tangential\n";
    s += "distortion_coefficients: [0, 0, 0, 0]\n";
  } else {
    s += "distortion_model: " + lens.model + "\n";
    s += "distortion_coefficients: [";
    for (size_t i = 0; i < lens.coeffs.size(); ++i)
      s += (i ? ", " : "") + FormatDouble(lens.coeffs[i]);
    s += "]\n";
  }
  return s;
}

// state_groundtruth_estimate0/sensor.yaml as EuRoC's: the estimate is of the body itself.
std::string EurocGroundTruthYaml() {
  std::string s = kOpenCvYamlHeader;
  s += "# General sensor definitions.\n";
  s += "sensor_type: visual-inertial\n";
  s += "comment: vobench simulator ground truth, exact: the body pose in the world at every camera "
       "stamp; velocity by central differences (one-sided at the ends); biases 0\n\n";
  s += "# Sensor extrinsics wrt. the body-frame.\n";
  s += EurocTransformYaml(Eigen::Isometry3d::Identity());
  return s;
}

// The frame time in whole nanoseconds from its correctly rounded decimal ("%.9f"), so an
// absolute time keeps its digits (llround(t * 1e9) is off by up to ~100 ns at 1.3e9 s). false
// when |t| >= 4e9 s (the stamp would not fit an int64 beside any offset).
bool ExactNs(double time_s, int64_t* t_ns) {
  if (!(std::abs(time_s) < 4e9)) return false;
  char text[64];
  std::snprintf(text, sizeof(text), "%.9f", std::abs(time_s));
  const char* dot = std::strchr(text, '.');
  const int64_t ns =
      std::strtoll(text, nullptr, 10) * 1000000000LL + std::strtoll(dot + 1, nullptr, 10);
  *t_ns = time_s < 0.0 ? -ns : ns;
  return true;
}

// A TUM stamp (seconds, 9 decimals) of a nanosecond stamp >= 0: the text of left.txt,
// right.txt, groundtruth.txt and the image names, e.g. "1767225600.033333333".
std::string TumStampText(int64_t stamp_ns) {
  char text[64];
  std::snprintf(text, sizeof(text), "%lld.%09lld", static_cast<long long>(stamp_ns / 1000000000LL),
                static_cast<long long>(stamp_ns % 1000000000LL));
  return text;
}

}  // namespace

bool DatasetWriter::Options::IsValid(std::string* error) const {
  if (format != DatasetFormat::kKitti && format != DatasetFormat::kEuroc &&
      format != DatasetFormat::kTum && format != DatasetFormat::kRosbag)
    return Fail(error, "format must be kitti, euroc, tum or rosbag");
  if (format == DatasetFormat::kRosbag && !RosbagSupported())
    return Fail(error, RosbagUnavailable());
  if (png_compression < 0 || png_compression > 9)
    return Fail(error, "png_compression must be in [0, 9], got " + std::to_string(png_compression));
  if (!T_body_cam0.matrix().allFinite() || !IsRotation(T_body_cam0.linear(), kRotationTolerance))
    return Fail(error, "T_body_cam0 must be finite with a rotation in its linear part");
  if (!T_body_imu.matrix().allFinite() || !IsRotation(T_body_imu.linear(), kRotationTolerance))
    return Fail(error, "T_body_imu must be finite with a rotation in its linear part");
  if (!std::isfinite(rate_hz) || rate_hz < 0.0)
    return Fail(error, "rate_hz must be finite and >= 0, got " + FormatDouble(rate_hz));
  if (stamp_offset_ns < 0 || stamp_offset_ns > kMaxStampOffsetNs)
    return Fail(error, "stamp_offset_ns must be in [0, " + std::to_string(kMaxStampOffsetNs) +
                           "], got " + std::to_string(stamp_offset_ns));
  std::string why;
  if (write_rig && !rig.IsValid(&why)) return Fail(error, "rig: " + why);
  return true;
}

DatasetWriter::~DatasetWriter() { RemovePartial(); }

void DatasetWriter::RemovePartial() {
  if (finished_ || partial_dir_.empty()) return;
  bag_.reset();  // closes the bag before its folder goes
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
  rectify_ = options_.rectification && !options_.rectification->IsIdentity();
  rectified_camera_ = rectify_ ? options_.rectification->camera : camera;
  if (rectify_ && (options_.rectification->map0_x.cols != camera.width ||
                   options_.rectification->map0_x.rows != camera.height))
    return Fail(error, "DatasetWriter: the rectification's maps are not of the camera's size");

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
  if (options_.format == DatasetFormat::kRosbag) {
    bag_ = std::make_unique<RosbagWriter>();
    const std::string name = fs::path(RosbagPathInDataset(dir_)).filename().string();
    if (!bag_->Open(Join(partial_dir_, name), rectified_camera_, options_.imu, error)) {
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
  int64_t t_ns = 0;
  if (!ExactNs(frame.time_s, &t_ns))
    return Fail(error,
                what + "time " + FormatDouble(frame.time_s) + " s is out of range (|t| < 4e9 s)");
  const int64_t stamp_ns = options_.stamp_offset_ns + t_ns;
  if (index > 0 && stamp_ns <= stamps_ns_.back())
    return Fail(error, what + "time " + FormatDouble(frame.time_s) +
                           " s is not after the previous frame's (need strictly increasing ns)");
  if (options_.format == DatasetFormat::kEuroc || options_.format == DatasetFormat::kTum ||
      options_.format == DatasetFormat::kRosbag) {
    // Names that sort in time order: one number of digits for the whole sequence.
    const std::string stamp = std::to_string(stamp_ns);
    if (stamp_ns < 0)
      return Fail(error, what + "stamp " + stamp +
                             " ns is negative (EuRoC/TUM stamps are >= 0; raise stamp_offset_ns)");
    if (index > 0 && stamp.size() != std::to_string(stamps_ns_.front()).size())
      return Fail(error, what + "stamp " + stamp +
                             " ns has another number of digits than frame 0's " +
                             std::to_string(stamps_ns_.front()) +
                             " (file names would not sort in time order)");
  }
  if (options_.format == DatasetFormat::kTum && index > 0) {
    double t = 0.0, previous = 0.0;  // the TUM lists hold seconds, read as doubles
    if (!ParseDouble(TumStampText(stamp_ns), &t) ||
        !ParseDouble(TumStampText(stamps_ns_.back()), &previous) || !(t > previous))
      return Fail(error, what + "stamp " + TumStampText(stamp_ns) +
                             " s reads as the same number of seconds as the previous frame's " +
                             TumStampText(stamps_ns_.back()) + " (closer than a double resolves)");
  }
  if (frame.left.type() != CV_8UC1 || frame.left.size() != size)
    return Fail(error, what + "left image must be CV_8UC1 " + std::to_string(size.width) + "x" +
                           std::to_string(size.height) + ", got type " +
                           std::to_string(frame.left.type()) + " " + SizeText(frame.left));
  if (frame.right.type() != CV_8UC1 || frame.right.size() != size)
    return Fail(error, what + "right image must be CV_8UC1 " + std::to_string(size.width) + "x" +
                           std::to_string(size.height) + ", got type " +
                           std::to_string(frame.right.type()) + " " + SizeText(frame.right));
  // The depth belongs to the raw view: with a rectification no side writes it.
  const bool frame_depth = options_.write_depth && !frame.depth_m.empty() && !rectify_;
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

  // Images: encode once, write the same bytes to every layout; with a rectification the EuRoC
  // side gets the raw images, the others the rectified ones.
  DatasetFrame rectified;
  if (rectify_) {
    rectified = frame;
    RectifyFrame(*options_.rectification, &rectified);
  }
  const DatasetFrame& out = rectify_ ? rectified : frame;
  const std::string png_ns = std::to_string(stamp_ns) + ".png";
  for (int cam = 0; cam < 2; ++cam) {
    std::vector<uchar> png, raw_png;
    if (!cv::imencode(".png", cam == 0 ? out.left : out.right, png, compression_params_) ||
        (rectify_ && options_.format == DatasetFormat::kEuroc &&
         !cv::imencode(".png", cam == 0 ? frame.left : frame.right, raw_png, compression_params_)))
      return Fail(error, what + "PNG encoding failed");
    const std::string cam_name = std::to_string(cam);
    if (!WriteBytes(Join(partial_dir_, "image_" + cam_name + "/" + FrameName(index, ".png")), png,
                    error))
      return false;
    if (options_.format == DatasetFormat::kEuroc &&
        !WriteBytes(Join(partial_dir_, "mav0/cam" + cam_name + "/data/" + png_ns),
                    rectify_ ? raw_png : png, error))
      return false;
    if (options_.format == DatasetFormat::kTum &&
        !WriteBytes(
            Join(partial_dir_, (cam == 0 ? "left/" : "right/") + TumStampText(stamp_ns) + ".png"),
            png, error))
      return false;
  }
  cv::Mat depth_mm;  // the depth PNG's image (and the bag's depth message)
  if (has_depth_) {
    depth_mm = DepthToMillimetres(frame.depth_m);
    std::vector<uchar> png;
    if (!cv::imencode(".png", depth_mm, png, compression_params_))
      return Fail(error, what + "depth PNG encoding failed");
    if (!WriteBytes(Join(partial_dir_, "depth/" + FrameName(index, ".png")), png, error))
      return false;
  }
  if (bag_ && !bag_->Add(out, depth_mm, stamp_ns, options_.stamp_offset_ns, error)) return false;
  times_s_.push_back(frame.time_s);
  stamps_ns_.push_back(stamp_ns);
  if (has_gt_) T_world_cam0_.push_back(frame.T_world_cam0);
  if (options_.format == DatasetFormat::kEuroc)
    imu_.insert(imu_.end(), frame.imu.begin(), frame.imu.end());
  bag_has_imu_ = bag_has_imu_ || (bag_ && !frame.imu.empty());
  return true;
}

bool DatasetWriter::WriteEurocSensorFolders(std::string* error) const {
  const size_t n = times_s_.size();
  double rate_hz = options_.rate_hz;
  if (rate_hz == 0.0 && n >= 2) {
    std::vector<double> dt;
    for (size_t i = 1; i < n; ++i) dt.push_back(times_s_[i] - times_s_[i - 1]);
    std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
    rate_hz = std::round(1e3 / dt[dt.size() / 2]) / 1e3;  // to 1 mHz: 30, not 29.99999999997
  }
  for (int cam = 0; cam < 2; ++cam)
    if (!WriteEurocCamera(cam, rate_hz, error)) return false;
  // With an IMU: imu0/, body.yaml and the ground truth at the IMU rate instead (euroc_imu.h).
  bool imu_ground_truth = false;
  if (!imu_.empty() && !WriteEurocImu(Join(partial_dir_, "mav0"), imu_, options_.imu,
                                      options_.stamp_offset_ns, &imu_ground_truth, error))
    return false;
  return !has_gt_ || imu_ground_truth || WriteEurocGroundTruth(error);
}

Eigen::Isometry3d DatasetWriter::EurocBodyCam0() const {
  // With IMU samples EuRoC's body frame is the IMU's (dataset/euroc_imu.h).
  return imu_.empty() ? options_.T_body_cam0
                      : CameraInImuFrame(options_.T_body_cam0, options_.T_body_imu);
}

bool DatasetWriter::WriteEurocCamera(int cam, double rate_hz, std::string* error) const {
  Eigen::Isometry3d T_cam0_cam1 = Eigen::Isometry3d::Identity();
  T_cam0_cam1.translation() = Eigen::Vector3d(camera_.baseline_m, 0.0, 0.0);
  T_cam0_cam1.linear() = options_.R_cam0_cam1;
  const Eigen::Isometry3d T_body_cam0 = EurocBodyCam0();
  const Eigen::Isometry3d T_body_cam = cam == 0 ? T_body_cam0 : T_body_cam0 * T_cam0_cam1;
  const std::string base = Join(partial_dir_, "mav0/cam" + std::to_string(cam));
  std::string csv = "#timestamp [ns],filename\n";
  for (int64_t t_ns : stamps_ns_)
    csv += std::to_string(t_ns) + "," + std::to_string(t_ns) + ".png\n";
  return WriteTextFile(Join(base, "data.csv"), csv, error) &&
         WriteTextFile(Join(base, "sensor.yaml"),
                       EurocSensorYaml(cam == 0 ? "vobench cam0 (left)" : "vobench cam1 (right)",
                                       T_body_cam, camera_, options_.lens, rate_hz),
                       error);
}

bool DatasetWriter::WriteEurocGroundTruth(std::string* error) const {
  // Ground truth: body pose in the world, velocity by finite differences, zero biases.
  const size_t n = times_s_.size();
  const std::string gt_dir = Join(partial_dir_, "mav0/state_groundtruth_estimate0");
  if (!MakeDir(gt_dir, error)) return false;
  const Eigen::Isometry3d T_cam0_body = EurocBodyCam0().inverse();
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
    csv += std::to_string(stamps_ns_[i]);
    for (double x : {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), v.x(), v.y(), v.z()})
      csv += "," + FormatDouble(x);
    csv += ",0,0,0,0,0,0\n";
  }
  return WriteTextFile(Join(gt_dir, "data.csv"), csv, error) &&
         WriteTextFile(Join(gt_dir, "sensor.yaml"), EurocGroundTruthYaml(), error);
}

Eigen::Isometry3d DatasetWriter::LeftCameraPose(size_t i) const {
  if (!rectify_) return T_world_cam0_[i];
  return RectifiedLeftIn(T_world_cam0_[i], options_.rectification->R_cam0_rect0);
}

bool DatasetWriter::WriteTumText(std::string* error) const {
  const char* names[2] = {"left", "right"};
  for (int cam = 0; cam < 2; ++cam) {
    std::string list = std::string("# ") + names[cam] +
                       " images (vobench TUM-style stereo layout)\n# timestamp filename\n";
    for (int64_t stamp_ns : stamps_ns_) {
      const std::string stamp = TumStampText(stamp_ns);
      list += stamp + " " + names[cam] + "/" + stamp + ".png\n";
    }
    if (!WriteTextFile(Join(partial_dir_, std::string(names[cam]) + ".txt"), list, error))
      return false;
  }
  if (!has_gt_) return true;
  // "t tx ty tz qx qy qz qw" (WriteTum's numbers) with the stamps' own text.
  std::string gt = "# ground truth: left camera in the world (vobench TUM-style stereo layout)\n";
  gt += "# timestamp tx ty tz qx qy qz qw\n";
  for (size_t i = 0; i < stamps_ns_.size(); ++i) {
    const Eigen::Isometry3d T = LeftCameraPose(i);
    const Eigen::Vector3d t = T.translation();
    const Eigen::Quaterniond q = CanonicalQuaternion(T.linear());
    gt += TumStampText(stamps_ns_[i]);
    for (double x : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) gt += ' ' + FormatDouble(x);
    gt += '\n';
  }
  return WriteTextFile(Join(partial_dir_, "groundtruth.txt"), gt, error);
}

bool DatasetWriter::Finish(std::string* error) {
  if (!is_open()) return Fail(error, "DatasetWriter::Finish: writer is not open");
  if (times_s_.empty()) return Fail(error, dir_ + ": no frames were added");

  // calib.txt as KITTI odometry's: rectified projection matrices, P1 = K [I | (-fx baseline_m, 0,
  // 0)]; P2/P3 (KITTI's colour pair) repeat P0/P1, Tr (velodyne to cam0) is the identity: the
  // tools read all five (pykitti: P_rect_20, T_cam0_velo; cv::datasets::SLAM_kitti).
  // With a rectification: the rectified camera (the KITTI side holds the rectified images).
  const vo::StereoCamera& c = rectified_camera_;
  const double P0[12] = {c.fx_px, 0, c.cx_px, 0, 0, c.fy_px, c.cy_px, 0, 0, 0, 1, 0};
  double P1[12];
  std::copy(P0, P0 + 12, P1);
  P1[3] = -(c.fx_px * c.baseline_m);
  const double Tr[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  if (!WriteTextFile(Join(partial_dir_, "calib.txt"),
                     CalibRow("P0:", P0) + CalibRow("P1:", P1) + CalibRow("P2:", P0) +
                         CalibRow("P3:", P1) + CalibRow("Tr:", Tr),
                     error) ||
      !WriteKittiTimes(Join(partial_dir_, "times.txt"), times_s_, error))
    return false;
  if (options_.write_rig &&
      !WriteTextFile(Join(partial_dir_, kRigFileName), RigYaml(options_.rig), error))
    return false;

  if (has_gt_) {
    // Ground truth relative to the first left camera, as KITTI's poses.txt (with a
    // rectification: of the rectified left camera, whose images the KITTI side holds).
    std::vector<Eigen::Isometry3d> T_world_left;
    for (size_t i = 0; i < T_world_cam0_.size(); ++i) T_world_left.push_back(LeftCameraPose(i));
    const Eigen::Isometry3d T_cam0first_world = T_world_left.front().inverse();
    std::vector<Eigen::Isometry3d> poses;
    std::vector<StampedPose> tum;
    for (size_t i = 0; i < times_s_.size(); ++i) {
      poses.push_back(i == 0 ? Eigen::Isometry3d::Identity() : T_cam0first_world * T_world_left[i]);
      tum.push_back({times_s_[i], poses.back()});
    }
    if (!WriteKittiPoses(Join(partial_dir_, "poses.txt"), poses, error) ||
        !WriteTum(Join(partial_dir_, "groundtruth_tum.txt"), tum, error) ||
        !WriteKittiPoses(Join(partial_dir_, "T_world_cam0first.txt"), {T_world_left.front()},
                         error))
      return false;
  }
  if (options_.format == DatasetFormat::kEuroc && !WriteEurocSensorFolders(error)) return false;
  if (options_.format == DatasetFormat::kTum && !WriteTumText(error)) return false;
  if (bag_ && !bag_->Close(error)) return false;
  if (bag_has_imu_) {
    // The bag's camera_info holds no mounting on the IMU: Kalibr's camchain-imucam.yaml beside
    // it does (the rectified left camera's, whose images the bag holds).
    Eigen::Isometry3d T_imu_left = CameraInImuFrame(options_.T_body_cam0, options_.T_body_imu);
    if (rectify_) T_imu_left = RectifiedLeftIn(T_imu_left, options_.rectification->R_cam0_rect0);
    const RosbagTopics topics;
    if (!WriteTextFile(Join(partial_dir_, kKalibrCamchainFileName),
                       KalibrCamchainYaml(rectified_camera_, T_imu_left, topics.left, topics.right),
                       error))
      return false;
  }

  // Publish: rename the partial folder to DIR (replacing an old vobench dataset when allowed).
  if (!folder_.Publish(error)) return false;
  finished_ = true;
  partial_dir_.clear();
  return true;
}

}  // namespace harness
