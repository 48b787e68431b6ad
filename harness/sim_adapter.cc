#include "harness/sim_adapter.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>

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

std::string CalibrationErrorProblem(const sim::Scenario& scenario, bool euroc,
                                    const std::string& where) {
  if (!euroc && scenario.camera.distortion.any())
    return scenario.source_path + ": camera.distortion: raw images of a lens cannot be " +
           "exported to " + where + " (rectified images only); render it with --format euroc, " +
           "whose sensor.yaml holds the lens for `eval --format euroc` to rectify";
  if (euroc || scenario.calibration_error.rotation_deg == 0.0) return "";
  return scenario.source_path + ": calibration_error.rotation_deg: a rotation between the " +
         "cameras cannot be exported to " + where +
         " (a rectified calibration: same orientation for both cameras); render it with " +
         "--format euroc, whose cam1 sensor.yaml T_BS holds it";
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
