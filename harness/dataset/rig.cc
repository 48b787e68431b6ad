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
  if (!r.ExpectMap(root, "", "a mapping of camera_forward_m, camera_height_m, camera_pitch_deg") ||
      !r.CheckKeys(root, "", keys))
    return r.Report(error);
  RigMounting m;
  double* values[] = {&m.forward_m, &m.height_m, &m.pitch_deg};
  for (size_t i = 0; i < keys.size(); ++i) {
    if (!r.Require(root, "", keys[i], "a number") ||
        !r.ReadDouble(root[keys[i]], keys[i], values[i]))
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
