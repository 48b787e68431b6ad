#include "harness/sim_adapter.h"

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
