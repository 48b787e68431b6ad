#include "harness/dataset/rig.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

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
  out << "# The stereo camera's mounting on the vehicle (vobench render; metres, degrees).\n"
      << "camera_forward_m: " << rig.forward_m << "  # optical centre ahead of the wheel axle\n"
      << "camera_height_m: " << rig.height_m << "  # optical centre above the floor\n"
      << "camera_pitch_deg: " << rig.pitch_deg << "  # downward tilt of the optical axis\n";
  return out.str();
}

bool ReadRigYaml(const std::string& path, RigMounting* rig, std::string* error) {
  const auto fail = [&](const std::string& why) {
    if (error) *error = path + ": " + why;
    return false;
  };
  std::ifstream in(path);
  if (!in) return fail("cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    return fail(std::string("not valid YAML: ") + e.what());
  }
  if (!root.IsMap())
    return fail("must be a map of camera_forward_m, camera_height_m and camera_pitch_deg");
  RigMounting r;
  struct Key {
    const char* name;
    double* value;
  };
  const Key keys[] = {{"camera_forward_m", &r.forward_m},
                      {"camera_height_m", &r.height_m},
                      {"camera_pitch_deg", &r.pitch_deg}};
  for (const auto& entry : root) {
    const std::string name = entry.first.as<std::string>("");
    bool known = false;
    for (const Key& k : keys) known = known || name == k.name;
    if (!known) return fail("unknown key '" + name + "'");
  }
  for (const Key& k : keys) {
    const YAML::Node node = root[k.name];
    if (!node) return fail(std::string("missing ") + k.name);
    try {
      *k.value = node.as<double>();
    } catch (const YAML::Exception&) {
      return fail(std::string(k.name) + " must be a number");
    }
  }
  std::string why;
  if (!r.IsValid(&why)) return fail(why);
  *rig = r;
  return true;
}

}  // namespace harness
