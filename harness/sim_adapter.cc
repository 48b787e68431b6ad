#include "harness/sim_adapter.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>

#include "harness/dataset/euroc_imu.h"

namespace harness {

namespace fs = std::filesystem;

bool ResolveScenario(const std::string& arg, sim::Scenario* scenario, std::string* error) {
  std::string path = arg;
  if (!fs::exists(path)) {
    const std::string builtin = sim::BuiltinScenarioPath(arg);
    if (arg.find('/') == std::string::npos && fs::exists(builtin)) {
      path = builtin;
    } else {
      *error = arg + ": no such scenario file (and no built-in scenario of that name in " +
               fs::path(builtin).parent_path().string() + ")";
      return false;
    }
  }
  return sim::LoadScenario(path, scenario, error);
}

vo::StereoCamera ToStereoCamera(const sim::StereoCalibration& c) {
  vo::StereoCamera cam;
  cam.width = c.width;
  cam.height = c.height;
  cam.fx_px = c.fx_px;
  cam.fy_px = c.fy_px;
  cam.cx_px = c.cx_px;
  cam.cy_px = c.cy_px;
  cam.baseline_m = c.baseline_m;
  return cam;
}

vo::StereoCamera ExportedStereoCamera(const sim::Scenario& scenario,
                                      const sim::StereoCalibration& calibration) {
  vo::StereoCamera cam = ToStereoCamera(calibration);
  const sim::CalibrationErrorOptions& e = scenario.calibration_error;
  if (e.baseline_pct != 0.0) cam.baseline_m *= 1.0 + e.baseline_pct / 100.0;
  if (e.focal_pct != 0.0) {
    cam.fx_px *= 1.0 + e.focal_pct / 100.0;
    cam.fy_px *= 1.0 + e.focal_pct / 100.0;
  }
  return cam;
}

Eigen::Matrix3d ExportedRotationCam0Cam1(const sim::Scenario& scenario) {
  const double angle = scenario.calibration_error.rotation_deg * M_PI / 180.0;
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

bool ExportsRawFrames(const sim::Scenario& scenario) {
  return scenario.camera.distortion.any() || scenario.calibration_error.rotation_deg != 0.0;
}

bool ExportedRectification(const sim::Scenario& scenario, const sim::StereoCalibration& calibration,
                           StereoRectification* rectification, std::string* error) {
  const vo::StereoCamera camera = ExportedStereoCamera(scenario, calibration);
  const sim::LensDistortion& lens = scenario.camera.distortion;
  const Eigen::Matrix3d R_cam0_cam1 = ExportedRotationCam0Cam1(scenario);
  if (!ExportsRawFrames(scenario)) {
    *rectification = StereoRectification();
    rectification->camera = camera;
    return true;
  }
  Eigen::Isometry3d T_cam0_cam1 = Eigen::Isometry3d::Identity();
  T_cam0_cam1.linear() = R_cam0_cam1;
  T_cam0_cam1.translation() = Eigen::Vector3d(camera.baseline_m, 0.0, 0.0);
  // cam0 in EuRoC's body, the IMU's (DatasetWriter::EurocBodyCam0), and cam1 beside it: the
  // numbers render --format euroc writes (exactly, FormatDouble), so `eval` makes the same maps.
  const Eigen::Isometry3d T_body_cam0 =
      CameraInImuFrame(calibration.T_body_cam0, calibration.T_body_imu);
  EurocCameraCalibration cam[2];
  for (int i = 0; i < 2; ++i) {
    EurocCameraCalibration& c = cam[i];
    c.T_body_cam = i == 0 ? T_body_cam0 : T_body_cam0 * T_cam0_cam1;
    c.fu_px = camera.fx_px;
    c.fv_px = camera.fy_px;
    c.cu_px = camera.cx_px;
    c.cv_px = camera.cy_px;
    c.camera_model = "pinhole";
    c.distortion_model = lens.any() ? lens.model : sim::kRadTan;
    c.distortion_coefficients = lens.any() ? lens.coeffs : std::vector<double>{0, 0, 0, 0};
    c.width = camera.width;
    c.height = camera.height;
    c.rate_hz = scenario.rate_hz;
    c.path = scenario.source_path + " (cam" + std::to_string(i) + " as exported)";
  }
  return ComputeStereoRectification(cam[0], cam[1], RectificationOptions(), rectification, error);
}

DatasetFrame ToDatasetFrame(const sim::StereoFrame& f) {
  DatasetFrame d;
  d.time_s = f.time_s;
  d.left = f.left;
  d.right = f.right;
  d.depth_m = f.depth_m;
  d.has_gt = true;
  d.T_world_cam0 = f.T_world_cam0;
  d.imu = f.imu;
  return d;
}

}  // namespace harness
