#include "harness/dataset/rig.h"

#include <cmath>
#include <sstream>
#include <vector>

#include "sim/yaml_input.h"

namespace harness {

bool RigMounting::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!std::isfinite(forward_m))
    msg << "camera_forward_m must be finite, got " << forward_m;
  else if (!(height_m > 0.0) || !std::isfinite(height_m))
    msg << "camera_height_m must be finite and > 0, got " << height_m;
  else if (!(pitch_deg > -90.0 && pitch_deg < 90.0))
    msg << "camera_pitch_deg must be in (-90, 90), got " << pitch_deg;
  else if (has_imu && !(std::isfinite(imu_x_m) && std::isfinite(imu_y_m) &&
                        std::isfinite(imu_z_m) && std::isfinite(imu_roll_deg) &&
                        std::isfinite(imu_pitch_deg) && std::isfinite(imu_yaw_deg)))
    msg << "the IMU's pose (imu_x_m .. imu_yaw_deg) must be finite";
  else
    return true;
  if (error) *error = msg.str();
  return false;
}

std::string RigYaml(const RigMounting& rig) {
  std::ostringstream out;
  out.precision(17);
  out << "%YAML:1.0\n"  // OpenCV's cv::FileStorage needs it first; ReadRigYaml skips it
      << "# The stereo camera's mounting on the vehicle (vobench render; metres, degrees).\n"
      << "camera_forward_m: " << rig.forward_m << "  # optical centre ahead of the wheel axle\n"
      << "camera_height_m: " << rig.height_m << "  # optical centre above the floor\n"
      << "camera_pitch_deg: " << rig.pitch_deg << "  # downward tilt of the optical axis\n";
  if (rig.has_imu)
    out << "# The IMU on the body (x forward, y left, z up from the wheel axle; its axes\n"
        << "# Rz(yaw) Ry(pitch) Rx(roll) of the body's).\n"
        << "imu_x_m: " << rig.imu_x_m << "\nimu_y_m: " << rig.imu_y_m
        << "\nimu_z_m: " << rig.imu_z_m << "\nimu_roll_deg: " << rig.imu_roll_deg
        << "\nimu_pitch_deg: " << rig.imu_pitch_deg << "\nimu_yaw_deg: " << rig.imu_yaw_deg << "\n";
  return out.str();
}

bool ReadRigYaml(const std::string& path, RigMounting* rig, std::string* error) {
  sim::YamlReader r(path);
  std::string text, why;
  if (!sim::ReadInputFile(path, "rig file", &text, &why)) {
    if (error != nullptr) *error = why;
    return false;
  }
  // OpenCV-style files start with "%YAML:1.0", which yaml-cpp rejects: blank that line (so
  // the line numbers of messages stay the file's).
  if (text.rfind("%YAML:", 0) == 0) text.erase(0, text.find('\n'));
  if (!r.Parse(text)) return r.Report(error);
  YAML::Node root = r.root();  // not const: a missing key reads as undefined, not invalid
  const std::vector<std::string> keys = {"camera_forward_m", "camera_height_m", "camera_pitch_deg"};
  const std::vector<std::string> imu_keys = {"imu_x_m",      "imu_y_m",       "imu_z_m",
                                             "imu_roll_deg", "imu_pitch_deg", "imu_yaw_deg"};
  std::vector<std::string> all = keys;
  all.insert(all.end(), imu_keys.begin(), imu_keys.end());
  if (!r.ExpectMap(root, "", "a mapping of camera_forward_m, camera_height_m, camera_pitch_deg") ||
      !r.CheckKeys(root, "", all))
    return r.Report(error);
  RigMounting m;
  double* values[] = {&m.forward_m, &m.height_m, &m.pitch_deg};
  for (size_t i = 0; i < keys.size(); ++i) {
    if (!r.Require(root, "", keys[i], "a number") ||
        !r.ReadDouble(root[keys[i]], keys[i], values[i]))
      return r.Report(error);
  }
  // The IMU: all six keys or none.
  m.has_imu = false;
  for (const std::string& k : imu_keys) m.has_imu = m.has_imu || sim::YamlReader::Has(root, k);
  double* imu_values[] = {&m.imu_x_m,      &m.imu_y_m,       &m.imu_z_m,
                          &m.imu_roll_deg, &m.imu_pitch_deg, &m.imu_yaw_deg};
  for (size_t i = 0; m.has_imu && i < imu_keys.size(); ++i) {
    if (!r.Require(root, "", imu_keys[i], "a number (the IMU's pose: all six imu_ keys or none)") ||
        !r.ReadDouble(root[imu_keys[i]], imu_keys[i], imu_values[i]))
      return r.Report(error);
  }
  if (!r.Check(m.height_m > 0.0, root, "", "camera_height_m",
               "must be > 0, got " + std::to_string(m.height_m)) ||
      !r.Check(m.pitch_deg > -90.0 && m.pitch_deg < 90.0, root, "", "camera_pitch_deg",
               "must be in (-90, 90), got " + std::to_string(m.pitch_deg)))
    return r.Report(error);
  *rig = m;
  return true;
}

}  // namespace harness
