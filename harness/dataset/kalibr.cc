#include "harness/dataset/kalibr.h"

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "harness/dataset/internal.h"
#include "harness/trajectory_io.h"
#include "sim/yaml_input.h"

namespace harness {
namespace {

using dataset_internal::IsRotation;

// "  - [a, b, c, d]" lines of a 4x4 matrix, each row indented by `indent`.
std::string MatrixRows(const Eigen::Matrix4d& m, const std::string& indent) {
  std::string out;
  for (int r = 0; r < 4; ++r) {
    out += indent + "- [";
    for (int c = 0; c < 4; ++c) out += (c > 0 ? ", " : "") + FormatDouble(m(r, c));
    out += "]\n";
  }
  return out;
}

std::string CameraBlock(int cam, const vo::StereoCamera& c, const Eigen::Isometry3d& T_cam_imu,
                        const std::string& topic) {
  std::string out = "cam" + std::to_string(cam) + ":\n";
  out += "  T_cam_imu:\n" + MatrixRows(T_cam_imu.matrix(), "  ");
  if (cam == 1) {
    Eigen::Isometry3d T_cam1_cam0 = Eigen::Isometry3d::Identity();
    T_cam1_cam0.translation() = Eigen::Vector3d(-c.baseline_m, 0.0, 0.0);
    out += "  T_cn_cnm1:\n" + MatrixRows(T_cam1_cam0.matrix(), "  ");
  }
  out += "  camera_model: pinhole\n";
  out += "  intrinsics: [" + FormatDouble(c.fx_px) + ", " + FormatDouble(c.fy_px) + ", " +
         FormatDouble(c.cx_px) + ", " + FormatDouble(c.cy_px) + "]\n";
  out += "  distortion_model: radtan\n  distortion_coeffs: [0.0, 0.0, 0.0, 0.0]\n";
  out += "  resolution: [" + std::to_string(c.width) + ", " + std::to_string(c.height) + "]\n";
  out += "  rostopic: " + topic + "\n  timeshift_cam_imu: 0.0\n";
  return out;
}

}  // namespace

std::string KalibrCamchainYaml(const vo::StereoCamera& camera, const Eigen::Isometry3d& T_imu_cam0,
                               const std::string& left_topic, const std::string& right_topic) {
  Eigen::Isometry3d T_cam0_cam1 = Eigen::Isometry3d::Identity();
  T_cam0_cam1.translation() = Eigen::Vector3d(camera.baseline_m, 0.0, 0.0);
  const Eigen::Isometry3d T_cam0_imu = T_imu_cam0.inverse();
  const Eigen::Isometry3d T_cam1_imu = T_cam0_cam1.inverse() * T_cam0_imu;
  return "# Kalibr camchain-imucam.yaml written by vobench: the bag's rectified stereo pair\n"
         "# (camera_info's P) and each camera's pose relative to the IMU (T_cam_imu).\n" +
         CameraBlock(0, camera, T_cam0_imu, left_topic) +
         CameraBlock(1, camera, T_cam1_imu, right_topic);
}

bool ReadKalibrImuExtrinsics(const std::string& path, Eigen::Isometry3d* T_imu_cam0,
                             std::string* error) {
  sim::YamlReader r(path);
  if (!r.ParseFile(path, "Kalibr camchain-imucam file")) return r.Report(error);
  YAML::Node root = r.root();  // not const: a missing key reads as undefined, not invalid
  const std::string matrix = "4 rows of 4 numbers (cam0's T_cam_imu, Kalibr's camchain-imucam)";
  if (!r.ExpectMap(root, "", "a Kalibr camchain-imucam.yaml mapping (cam0: T_cam_imu: ...)") ||
      !r.Require(root, "", "cam0", "cam0: T_cam_imu: " + matrix) ||
      !r.ExpectMap(root["cam0"], "cam0") || !r.Require(root["cam0"], "cam0", "T_cam_imu", matrix))
    return r.Report(error);
  const YAML::Node rows = root["cam0"]["T_cam_imu"];
  if (!rows.IsSequence() || rows.size() != 4) {
    r.Fail(rows, "cam0.T_cam_imu", "expected " + matrix);
    return r.Report(error);
  }
  Eigen::Matrix4d T;
  for (size_t row = 0; row < 4; ++row) {
    std::vector<double> values;
    if (!r.ReadNumbers(rows[row], sim::YamlReader::Item("cam0.T_cam_imu", row), 4, &values))
      return r.Report(error);
    for (int col = 0; col < 4; ++col) T(static_cast<int>(row), col) = values[col];
  }
  if (!r.Check(T.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)) &&
                   IsRotation(T.topLeftCorner<3, 3>(), 1e-5),
               root["cam0"], "cam0", "T_cam_imu",
               "expected a rigid transform (a rotation, last row 0 0 0 1)"))
    return r.Report(error);
  if (sim::YamlReader::Has(root["cam0"], "timeshift_cam_imu")) {
    double shift = 0.0;
    if (!r.ReadDouble(root["cam0"]["timeshift_cam_imu"], "cam0.timeshift_cam_imu", &shift) ||
        !r.Check(shift == 0.0, root["cam0"], "cam0", "timeshift_cam_imu",
                 "a time shift between the cameras and the IMU is not applied by vobench; "
                 "expected 0, got " +
                     FormatDouble(shift)))
      return r.Report(error);
  }
  Eigen::Isometry3d T_cam0_imu = Eigen::Isometry3d::Identity();
  T_cam0_imu.matrix() = T;
  *T_imu_cam0 = T_cam0_imu.inverse();
  return true;
}

}  // namespace harness
