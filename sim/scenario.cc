#include "sim/scenario.h"

#include <mujoco/mujoco.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "sim/data_dir.h"
#include "sim/floor_plan.h"
#include "sim/lighting.h"
#include "sim/path_follower.h"
#include "sim/people.h"
#include "sim/scene_walls.h"
#include "sim/yaml_input.h"

namespace sim {
namespace {

namespace fs = std::filesystem;

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Frames are taken on physics steps: the frame period must be a whole number of steps, to this
// relative tolerance (10 Hz at 0.002 s is 50 steps up to rounding of the decimal values).
constexpr double kStepsPerFrameTolerance = 1e-6;

// The physics checks that involve several keys (rate vs step, exposure vs period): "" when
// fine, else the problem, and *key names the key to blame. Rates and steps out of their own
// ranges are left to the per-key checks.
std::string PhysicsProblem(const Scenario& s, std::string* key) {
  std::ostringstream e;
  if (!(s.rate_hz > 0) || !(s.physics_dt_s > 0)) return "";
  *key = "rate_hz";
  const double steps = 1.0 / (s.rate_hz * s.physics_dt_s);  // physics steps per frame period
  const double whole = std::round(steps);
  if (steps < 1.0 - kStepsPerFrameTolerance) {
    e << s.rate_hz << " Hz is above the physics rate 1/physics_dt_s = " << Num(1.0 / s.physics_dt_s)
      << " Hz (a frame per physics step at most)";
  } else if (std::abs(steps - whole) > kStepsPerFrameTolerance * whole) {
    e << "the frame period 1/" << s.rate_hz << " s is " << Num(steps) << " physics steps of "
      << s.physics_dt_s
      << " s; expected a whole number (frames are taken on physics steps), e.g. rate_hz "
      << Num(1.0 / (std::floor(steps) * s.physics_dt_s)) << " or "
      << Num(1.0 / (std::ceil(steps) * s.physics_dt_s));
  } else if (s.noise.motion_blur_exposure_s > 0.0) {
    // The exposures of consecutive frames must not share a physics step.
    const double max_exposure_s = (whole - 2.0) * s.physics_dt_s;
    *key = "noise.motion_blur_exposure_s";
    if (!(s.noise.motion_blur_exposure_s <= max_exposure_s + 1e-12))
      e << s.noise.motion_blur_exposure_s
        << " s does not fit in the frame period: expected at most the period minus 2 physics "
           "steps, "
        << Num(std::max(0.0, max_exposure_s)) << " s at rate_hz " << s.rate_hz
        << " and physics_dt_s " << s.physics_dt_s;
  }
  return e.str();
}

// The node of a key as IsValid names it ("rate_hz", "robot.speed_mps", "path[3]",
// "camera.width/height": the first of the pair); undefined when the file does not hold it.
YAML::Node NodeOfKey(const YAML::Node& root, const std::string& key) {
  YAML::Node node = root;
  std::string rest = key.substr(0, key.find('/'));
  while (!rest.empty() && node.IsDefined()) {
    const size_t dot = rest.find('.');
    std::string part = rest.substr(0, dot);
    rest = dot == std::string::npos ? "" : rest.substr(dot + 1);
    int index = -1;
    if (const size_t bracket = part.find('['); bracket != std::string::npos) {
      index = std::atoi(part.c_str() + bracket + 1);
      part = part.substr(0, bracket);
    }
    // reset(), not operator= (which would write into the tree), and const reads only.
    const YAML::Node& here = node;
    if (!here.IsMap() || !here[part].IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
    node.reset(here[part]);
    if (index >= 0) {
      const YAML::Node& list = node;
      if (!list.IsSequence() || index >= static_cast<int>(list.size()))
        return YAML::Node(YAML::NodeType::Undefined);
      node.reset(list[index]);
    }
  }
  return node;
}

double ShortestSegmentM(const std::vector<Eigen::Vector2d>& path) {
  double shortest = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < path.size(); ++i)
    shortest = std::min(shortest, (path[i] - path[i - 1]).norm());
  return shortest;
}

// imu: the keys' own ranges and the sample period a whole number of physics steps (samples are
// taken on steps): "" when fine, else the problem, and *key names the key to blame.
std::string ImuProblem(const Scenario& s, std::string* key) {
  const ImuOptions& o = s.imu;
  std::ostringstream e;
  const std::pair<const char*, double> densities[] = {
      {"gyro_noise_density", o.gyro_noise_density},
      {"gyro_random_walk", o.gyro_random_walk},
      {"accel_noise_density", o.accel_noise_density},
      {"accel_random_walk", o.accel_random_walk}};
  for (const auto& [name, v] : densities)
    if (!(v >= 0 && std::isfinite(v))) {
      *key = std::string("imu.") + name;
      return "expected a finite number >= 0, got " + Num(v);
    }
  const std::pair<const char*, double> pose[] = {{"x_m", o.x_m},
                                                 {"y_m", o.y_m},
                                                 {"z_m", o.z_m},
                                                 {"roll_deg", o.roll_deg},
                                                 {"pitch_deg", o.pitch_deg},
                                                 {"yaw_deg", o.yaw_deg}};
  for (const auto& [name, v] : pose)
    if (!std::isfinite(v)) {
      *key = std::string("imu.") + name;
      return "expected a finite number, got " + Num(v);
    }
  if (!(o.gyro_turn_on_bias_sigma_radps >= 0 && o.gyro_turn_on_bias_sigma_radps <= 1.0)) {
    *key = "imu.gyro_turn_on_bias_sigma_radps";
    return "expected a number in [0, 1] rad/s, got " + Num(o.gyro_turn_on_bias_sigma_radps);
  }
  // (A bad settle_s is settle_s's own error, told at its line.)
  if (!(o.pre_roll_s >= 0 && std::isfinite(o.pre_roll_s) &&
        (!(s.settle_s >= 0) || o.pre_roll_s <= s.settle_s))) {
    *key = "imu.pre_roll_s";
    return "expected seconds in [0, settle_s = " + Num(s.settle_s) +
           "] (the samples are taken while the robot stands before frame 0), got " +
           Num(o.pre_roll_s);
  }
  *key = "imu.rate_hz";
  if (!(o.rate_hz > 0) || !(s.physics_dt_s > 0)) return "expected > 0 Hz, got " + Num(o.rate_hz);
  const double steps = 1.0 / (o.rate_hz * s.physics_dt_s);
  const double whole = std::round(steps);
  if (steps < 1.0 - kStepsPerFrameTolerance)
    e << o.rate_hz << " Hz is above the physics rate 1/physics_dt_s = " << Num(1.0 / s.physics_dt_s)
      << " Hz (a sample per physics step at most)";
  else if (std::abs(steps - whole) > kStepsPerFrameTolerance * whole)
    e << "the sample period 1/" << o.rate_hz << " s is " << Num(steps) << " physics steps of "
      << s.physics_dt_s << " s; expected a whole number (samples are taken on physics steps), "
      << "e.g. " << Num(1.0 / (std::floor(steps) * s.physics_dt_s)) << " or "
      << Num(1.0 / (std::ceil(steps) * s.physics_dt_s)) << " Hz";
  return e.str();
}

// calibration_error and frames (issue #34): "" when fine, else the problem, and *key names the
// key to blame. Kept apart from the other checks (one block per scenario section).
std::string CalibrationAndFramesProblem(const Scenario& s, std::string* key) {
  const CalibrationErrorOptions& c = s.calibration_error;
  const std::pair<const char*, double> pct[] = {{"calibration_error.baseline_pct", c.baseline_pct},
                                                {"calibration_error.focal_pct", c.focal_pct}};
  for (const auto& [name, v] : pct)
    if (!(v > -100.0 && v < 1000.0)) {
      *key = name;
      return "expected a percentage in (-100, 1000), got " + Num(v);
    }
  *key = "calibration_error.rotation_deg";
  if (!(std::abs(c.rotation_deg) < 45.0))
    return "expected degrees in (-45, 45), got " + Num(c.rotation_deg);
  *key = "frames.drop_rate";
  if (!(s.frames.drop_rate >= 0.0 && s.frames.drop_rate < 1.0))
    return "expected a fraction in [0, 1), got " + Num(s.frames.drop_rate);
  *key = "frames.time_jitter_s";
  const double half_period = 0.5 / s.rate_hz;
  if (!(s.frames.time_jitter_s >= 0.0 && s.frames.time_jitter_s < half_period))
    return "expected seconds in [0, " + Num(half_period) +
           ") (below half the frame period at rate_hz " + Num(s.rate_hz) +
           ", so the stamps stay in order), got " + Num(s.frames.time_jitter_s);
  return "";
}

// Reads the calibration_error and frames sections (their ranges: CalibrationAndFramesProblem).
void ReadCalibrationAndFrames(const YAML::Node& root, YamlReader* r, Scenario* s) {
  if (const YAML::Node n = root["calibration_error"]; n.IsDefined() && r->ok()) {
    r->CheckKeys(n, "calibration_error", {"baseline_pct", "focal_pct", "rotation_deg"});
    r->Double(n, "calibration_error", "baseline_pct", &s->calibration_error.baseline_pct);
    r->Double(n, "calibration_error", "focal_pct", &s->calibration_error.focal_pct);
    r->Double(n, "calibration_error", "rotation_deg", &s->calibration_error.rotation_deg);
  }
  if (const YAML::Node n = root["camera"].IsMap() ? root["camera"]["distortion"]
                                                  : YAML::Node(YAML::NodeType::Undefined);
      n.IsDefined() && r->ok()) {
    // The lens: model radtan | equidistant (EuRoC's radial-tangential / equidistant) and its 4
    // coefficients; MakeDistortedView (sim/lens.h) checks the lens can be rendered.
    r->CheckKeys(n, "camera.distortion", {"model", "coeffs"});
    std::string model;
    r->Require(n, "camera.distortion", "model", "radtan or equidistant");
    r->Require(n, "camera.distortion", "coeffs", "4 numbers (k1 k2 p1 p2, or k1 .. k4)");
    r->String(n, "camera.distortion", "model", &model);
    r->Check(!r->ok() || model == "radtan" || model == "equidistant", n, "camera.distortion",
             "model", "expected radtan or equidistant, got '" + model + "'");
    LensDistortion& lens = s->camera.distortion;
    lens.model = model == "radtan" ? kRadTan : kEquidistant;
    if (r->ok() && n["coeffs"].IsSequence() && n["coeffs"].size() == 4) {
      lens.coeffs.assign(4, 0.0);
      for (size_t i = 0; i < 4 && r->ok(); ++i)
        r->ReadDouble(n["coeffs"][i], YamlReader::Item("camera.distortion.coeffs", i),
                      &lens.coeffs[i]);
    } else {
      r->Check(!r->ok(), n, "camera.distortion", "coeffs",
               "expected a list of 4 numbers (k1 k2 p1 p2 for radtan, k1 k2 k3 k4 for "
               "equidistant)");
    }
    if (DistortedView view;
        r->ok() && !MakeDistortedView(lens, 100, 100, 0, 0, 1, 1, &view, &model)) {
      r->Fail(n, "camera.distortion", model);
    }
  }
  if (const YAML::Node n = root["frames"]; n.IsDefined() && r->ok()) {
    r->CheckKeys(n, "frames", {"drop_rate", "time_jitter_s"});
    r->Double(n, "frames", "drop_rate", &s->frames.drop_rate);
    r->Double(n, "frames", "time_jitter_s", &s->frames.time_jitter_s);
  }
}

// camera.distortion in ScenarioToYaml's camera map, only with a lens.
void EmitLens(const Scenario& s, YAML::Emitter* out) {
  if (const LensDistortion& lens = s.camera.distortion; lens.any())
    *out << YAML::Key << "distortion" << YAML::Value << YAML::BeginMap << YAML::Key << "model"
         << YAML::Value << (lens.model == kRadTan ? "radtan" : "equidistant") << YAML::Key
         << "coeffs" << YAML::Value << YAML::Flow << lens.coeffs << YAML::EndMap;
}

// The two sections in ScenarioToYaml, only where they differ from the defaults (a scenario
// without them writes the same YAML as before they existed).
void EmitCalibrationAndFrames(const Scenario& s, YAML::Emitter* out) {
  if (s.calibration_error.any())
    *out << YAML::Key << "calibration_error" << YAML::Value << YAML::BeginMap << YAML::Key
         << "baseline_pct" << YAML::Value << s.calibration_error.baseline_pct << YAML::Key
         << "focal_pct" << YAML::Value << s.calibration_error.focal_pct << YAML::Key
         << "rotation_deg" << YAML::Value << s.calibration_error.rotation_deg << YAML::EndMap;
  if (s.frames.any())
    *out << YAML::Key << "frames" << YAML::Value << YAML::BeginMap << YAML::Key << "drop_rate"
         << YAML::Value << s.frames.drop_rate << YAML::Key << "time_jitter_s" << YAML::Value
         << s.frames.time_jitter_s << YAML::EndMap;
}

// people, lights and camera.auto_exposure (issue #34): "" when fine, else the problem, and *key
// names the key to blame.
std::string PeopleAndLightsProblem(const Scenario& s, std::string* key) {
  const PeopleOptions& p = s.people;
  *key = "people.count";
  if (!(p.count >= 0 && p.count <= kMaxPeople))
    return "expected 0 .. " + std::to_string(kMaxPeople) + " people, got " +
           std::to_string(p.count);
  *key = "people.speed_mps";
  if (!(p.speed_mps > 0 && p.speed_mps <= 3))
    return "expected in (0, 3] m/s, got " + Num(p.speed_mps);
  *key = "people.height_m";
  if (!(p.height_m >= 1.0 && p.height_m <= 2.3))
    return "expected in [1, 2.3] m, got " + Num(p.height_m);
  const LightsOptions& l = s.lights;
  *key = "lights.brightness_drift";
  if (!(l.brightness_drift >= -1.0 && l.brightness_drift <= 1.0))
    return "expected a fraction per minute in [-1, 1], got " + Num(l.brightness_drift);
  *key = "lights.flicker_hz";
  if (!(l.flicker_hz >= 0.0 && l.flicker_hz <= 1000.0))
    return "expected in [0, 1000] Hz, got " + Num(l.flicker_hz);
  *key = "lights.flicker_depth";
  if (!(l.flicker_depth >= 0.0 && l.flicker_depth <= 1.0))
    return "expected in [0, 1], got " + Num(l.flicker_depth);
  for (size_t i = 0; i < l.switches.size(); ++i) {
    const LightSwitch& w = l.switches[i];
    *key = YamlReader::Item("lights.switch", i) + ".at_s";
    if (!(w.at_s >= 0.0 && std::isfinite(w.at_s)))
      return "expected a time >= 0 s, got " + Num(w.at_s);
    if (i > 0 && w.at_s < l.switches[i - 1].at_s)
      return "expected the switches in time order: " + Num(w.at_s) + " s is before the previous " +
             Num(l.switches[i - 1].at_s) + " s";
    *key = YamlReader::Item("lights.switch", i) + ".light";
    if (w.light < 0) return "expected a light of the scene (its index or name)";
  }
  const AutoExposureOptions& a = s.camera.auto_exposure;
  *key = "camera.auto_exposure.target_mean";
  if (!(a.target_mean > 0.0 && a.target_mean < 255.0))
    return "expected a grey level in (0, 255), got " + Num(a.target_mean);
  *key = "camera.auto_exposure.time_constant_s";
  if (!(a.time_constant_s > 0.0 && a.time_constant_s <= 60.0))
    return "expected in (0, 60] s, got " + Num(a.time_constant_s);
  return "";
}

// Reads people, lights and camera.auto_exposure (their ranges as PeopleAndLightsProblem's,
// checked here at each key's line). A switch's light is kept by name; ResolveLights finds it.
void ReadPeopleAndLights(const YAML::Node& root, YamlReader* r, Scenario* s) {
  if (const YAML::Node n = root["people"]; n.IsDefined() && r->ok()) {
    r->CheckKeys(n, "people", {"count", "seed", "speed_mps", "height_m"});
    PeopleOptions& o = s->people;
    r->Int(n, "people", "count", 0, kMaxPeople, &o.count);
    r->Uint64(n, "people", "seed", &o.seed);
    r->Double(n, "people", "speed_mps", &o.speed_mps);
    r->Check(o.speed_mps > 0 && o.speed_mps <= 3, n, "people", "speed_mps",
             "expected in (0, 3] m/s, got " + Num(o.speed_mps));
    r->Double(n, "people", "height_m", &o.height_m);
    r->Check(o.height_m >= 1.0 && o.height_m <= 2.3, n, "people", "height_m",
             "expected in [1, 2.3] m, got " + Num(o.height_m));
  }
  if (const YAML::Node n = root["lights"]; n.IsDefined() && r->ok()) {
    r->CheckKeys(n, "lights", {"switch", "brightness_drift", "flicker_hz", "flicker_depth"});
    LightsOptions& o = s->lights;
    r->Double(n, "lights", "brightness_drift", &o.brightness_drift);
    r->Check(o.brightness_drift >= -1 && o.brightness_drift <= 1, n, "lights", "brightness_drift",
             "expected a fraction per minute in [-1, 1], got " + Num(o.brightness_drift));
    r->Double(n, "lights", "flicker_hz", &o.flicker_hz);
    r->Check(o.flicker_hz >= 0 && o.flicker_hz <= 1000, n, "lights", "flicker_hz",
             "expected in [0, 1000] Hz, got " + Num(o.flicker_hz));
    r->Double(n, "lights", "flicker_depth", &o.flicker_depth);
    r->Check(o.flicker_depth >= 0 && o.flicker_depth <= 1, n, "lights", "flicker_depth",
             "expected in [0, 1], got " + Num(o.flicker_depth));
    if (const YAML::Node list = n["switch"]; list.IsDefined() && r->ok()) {
      if (!list.IsSequence())
        r->Fail(list, "lights.switch", "expected a list of {at_s, light, on}");
      for (size_t i = 0; r->ok() && i < list.size(); ++i) {
        const std::string item = YamlReader::Item("lights.switch", i);
        const YAML::Node w = list[i];
        r->CheckKeys(w, item, {"at_s", "light", "on"});
        r->Require(w, item, "at_s", "the time of the switch (s from frame 0)");
        r->Require(w, item, "light", "the light's index in the scene (0, 1, ...) or its name");
        r->Require(w, item, "on", "true (switched on) or false (off)");
        LightSwitch sw;
        r->Double(w, item, "at_s", &sw.at_s);
        r->Check(sw.at_s >= 0, w, item, "at_s", "expected a time >= 0 s, got " + Num(sw.at_s));
        r->Check(o.switches.empty() || sw.at_s >= o.switches.back().at_s, w, item, "at_s",
                 "expected the switches in time order: " + Num(sw.at_s) +
                     " s is before the previous switch");
        r->String(w, item, "light", &sw.name, false);
        r->Bool(w, item, "on", &sw.on);
        o.switches.push_back(sw);
      }
    }
  }
  const YAML::Node camera = root["camera"];
  if (const YAML::Node n =
          camera.IsMap() ? camera["auto_exposure"] : YAML::Node(YAML::NodeType::Undefined);
      n.IsDefined() && r->ok()) {
    r->CheckKeys(n, "camera.auto_exposure", {"enabled", "target_mean", "time_constant_s"});
    AutoExposureOptions& o = s->camera.auto_exposure;
    r->Bool(n, "camera.auto_exposure", "enabled", &o.enabled);
    r->Double(n, "camera.auto_exposure", "target_mean", &o.target_mean);
    r->Check(o.target_mean > 0 && o.target_mean < 255, n, "camera.auto_exposure", "target_mean",
             "expected a grey level in (0, 255), got " + Num(o.target_mean));
    r->Double(n, "camera.auto_exposure", "time_constant_s", &o.time_constant_s);
    r->Check(o.time_constant_s > 0 && o.time_constant_s <= 60, n, "camera.auto_exposure",
             "time_constant_s", "expected in (0, 60] s, got " + Num(o.time_constant_s));
  }
}

// The switches' lights found in the scene (by name, or by index given as a number), at the line
// of a light that is not there.
bool ResolveLights(const YAML::Node& root, YamlReader* r, Scenario* s, std::string* error) {
  if (s->lights.switches.empty()) return true;
  mjModel* m = LoadSceneModel(s->scene_path, error);
  if (!m) return false;
  for (size_t i = 0; i < s->lights.switches.size(); ++i) {
    LightSwitch& sw = s->lights.switches[i];
    std::string known;
    sw.light = FindLight(m, sw.name, &known);
    if (sw.light < 0) {
      r->Fail(root["lights"]["switch"][i]["light"], YamlReader::Item("lights.switch", i) + ".light",
              "no light '" + sw.name + "' in " + s->scene_path +
                  " (lights: " + (known.empty() ? "none" : known) + ")");
      break;
    }
    // Kept by name when given by name, else by index.
    const char* name = mj_id2name(m, mjOBJ_LIGHT, sw.light);
    if (!name || sw.name != name) sw.name.clear();
  }
  mj_deleteModel(m);
  return r->Report(error);
}

// The people and lights sections in ScenarioToYaml, only where they differ from the defaults.
void EmitPeopleAndLights(const Scenario& s, YAML::Emitter* out) {
  const PeopleOptions p = s.people, d;
  if (p.count != d.count || p.seed != d.seed || p.speed_mps != d.speed_mps ||
      p.height_m != d.height_m)
    *out << YAML::Key << "people" << YAML::Value << YAML::BeginMap << YAML::Key << "count"
         << YAML::Value << p.count << YAML::Key << "seed" << YAML::Value << p.seed << YAML::Key
         << "speed_mps" << YAML::Value << p.speed_mps << YAML::Key << "height_m" << YAML::Value
         << p.height_m << YAML::EndMap;
  const LightsOptions& l = s.lights;
  if (!l.switches.empty() || l.brightness_drift != 0.0 || l.flicker_hz != 0.0 ||
      l.flicker_depth != 0.0) {
    *out << YAML::Key << "lights" << YAML::Value << YAML::BeginMap;
    if (!l.switches.empty()) {
      *out << YAML::Key << "switch" << YAML::Value << YAML::BeginSeq;
      for (const LightSwitch& w : l.switches) {
        *out << YAML::Flow << YAML::BeginMap << YAML::Key << "at_s" << YAML::Value << w.at_s
             << YAML::Key << "light" << YAML::Value;
        if (w.name.empty())
          *out << w.light;
        else
          *out << w.name;
        *out << YAML::Key << "on" << YAML::Value << w.on << YAML::EndMap;
      }
      *out << YAML::EndSeq;
    }
    *out << YAML::Key << "brightness_drift" << YAML::Value << l.brightness_drift << YAML::Key
         << "flicker_hz" << YAML::Value << l.flicker_hz << YAML::Key << "flicker_depth"
         << YAML::Value << l.flicker_depth << YAML::EndMap;
  }
}

// camera.auto_exposure in ScenarioToYaml's camera map, only where it differs from the defaults.
void EmitAutoExposure(const Scenario& s, YAML::Emitter* out) {
  const AutoExposureOptions a = s.camera.auto_exposure, d;
  if (a.enabled != d.enabled || a.target_mean != d.target_mean ||
      a.time_constant_s != d.time_constant_s)
    *out << YAML::Key << "auto_exposure" << YAML::Value << YAML::BeginMap << YAML::Key << "enabled"
         << YAML::Value << a.enabled << YAML::Key << "target_mean" << YAML::Value << a.target_mean
         << YAML::Key << "time_constant_s" << YAML::Value << a.time_constant_s << YAML::EndMap;
}

// path: a list of waypoints, each [x, y] or {at: [x, y], turn, radius_m, stop_s, speed_mps} (the
// waypoint's own goals, WaypointOptions; their ranges and how they fit: WaypointProblem).
bool ReadPath(const YAML::Node& list, YamlReader* r, Scenario* s) {
  bool maps = false;
  for (size_t i = 0; list.IsSequence() && i < list.size(); ++i) maps = maps || list[i].IsMap();
  if (!maps) {  // pairs only, as always
    std::vector<std::pair<double, double>> path;
    if (!r->ReadPairs(list, "path", &path, "a list of waypoints [x, y] (m)", "a pair [x, y] (m)"))
      return false;
    for (const auto& [x, y] : path) s->path.emplace_back(x, y);
    return true;
  }
  std::vector<WaypointOptions> own(list.size());
  for (size_t i = 0; i < list.size() && r->ok(); ++i) {
    const YAML::Node item = list[i];
    const std::string key = YamlReader::Item("path", i);
    std::vector<double> xy;
    if (!item.IsMap()) {
      r->ReadNumbers(item, key, 2, &xy, "a pair [x, y] (m) or a map {at: [x, y], ...}");
    } else {
      WaypointOptions& w = own[i];
      r->CheckKeys(item, key, {"at", "turn", "radius_m", "stop_s", "speed_mps"});
      r->Require(item, key, "at", "the waypoint [x, y] (m)");
      r->ReadNumbers(item["at"], key + ".at", 2, &xy, "a pair [x, y] (m)");
      r->String(item, key, "turn", &w.turn, false);
      r->Check(w.turn.empty() || w.turn == "in_place" || w.turn == "arc", item, key, "turn",
               "expected 'in_place' or 'arc', got '" + w.turn + "'");
      r->Double(item, key, "radius_m", &w.radius_m);
      r->Double(item, key, "stop_s", &w.stop_s);
      r->Double(item, key, "speed_mps", &w.speed_mps);
    }
    if (r->ok()) s->path.emplace_back(xy[0], xy[1]);
  }
  s->waypoints = own;
  return r->ok();
}

// The waypoints' own goals (WaypointOptions): "" when fine, else "path[i].KEY: problem".
std::string WaypointProblem(const Scenario& s) {
  if (s.waypoints.empty()) return "";
  std::ostringstream e;
  const size_t n = s.path.size();
  if (s.waypoints.size() != n) {
    e << "path: " << s.waypoints.size() << " waypoint goals for " << n << " waypoints";
    return e.str();
  }
  const std::vector<WaypointGoal> goals = ResolveWaypoints(s.path, s.robot, s.waypoints);
  auto tangent = [&](size_t i) {  // how much of each leg the circular arc at path[i] takes (m)
    return goals[i].radius_m > 0.0
               ? ArcAtCorner(s.path[i - 1], s.path[i], s.path[i + 1], goals[i].radius_m).tangent_m
               : 0.0;
  };
  for (size_t i = 0; i < n; ++i) {
    const WaypointOptions& w = s.waypoints[i];
    const std::string key = "path[" + std::to_string(i) + "].";
    const bool inner = i > 0 && i + 1 < n;
    if (!w.turn.empty() && w.turn != "in_place" && w.turn != "arc") {
      e << key << "turn: expected 'in_place' or 'arc', got '" << w.turn << "'";
    } else if (!w.turn.empty() && !inner) {
      e << key << "turn: the first and the last waypoint have no corner to turn";
    } else if (!std::isnan(w.radius_m) && !(w.radius_m > 0 && std::isfinite(w.radius_m))) {
      e << key << "radius_m: expected a finite radius > 0 m, got " << w.radius_m;
    } else if (!std::isnan(w.radius_m) && !goals[i].arc) {
      e << key << "radius_m: an arc's radius, at a corner turned in place"
        << (inner ? " (give turn: arc here, or robot.corner_mode: arc)"
                  : " (the first and the last waypoint have no corner)");
    } else if (!std::isnan(w.stop_s) && !(w.stop_s >= 0 && w.stop_s <= 600)) {
      e << key << "stop_s: expected in [0, 600] s, got " << w.stop_s;
    } else if (!std::isnan(w.stop_s) && w.stop_s > 0 && goals[i].arc) {
      e << key << "stop_s: the robot does not stop at an arc corner (give turn: in_place here)";
    } else if (!std::isnan(w.speed_mps) && !(w.speed_mps > 0 && w.speed_mps <= 3)) {
      e << key << "speed_mps: expected in (0, 3] m/s, got " << w.speed_mps;
    } else if (!std::isnan(w.speed_mps) && i + 1 == n) {
      e << key
        << "speed_mps: the speed of the leg that starts here; no leg starts at the last "
           "waypoint";
    } else if (inner && goals[i].radius_m > 0.0) {
      // The arc's tangent points on both legs, after the previous arc's and before the next's.
      const double t = tangent(i);
      const double in = (s.path[i] - s.path[i - 1]).norm(),
                   out = (s.path[i + 1] - s.path[i]).norm();
      const double t_prev = i > 1 ? tangent(i - 1) : 0.0;
      const double t_next = i + 2 < n ? tangent(i + 1) : 0.0;
      if (!(t + t_prev <= in && t + t_next <= out))
        e << key << "radius_m: an arc of " << w.radius_m << " m at this corner takes " << t
          << " m of each leg; the leg in is " << in << " m"
          << (t_prev > 0
                  ? " (less " + Num(t_prev) + " m for path[" + std::to_string(i - 1) + "]'s arc)"
                  : "")
          << ", the leg out " << out << " m"
          << (t_next > 0
                  ? " (less " + Num(t_next) + " m for path[" + std::to_string(i + 1) + "]'s arc)"
                  : "")
          << ": a smaller radius";
    }
    if (e.tellp() != 0) break;
  }
  return e.str();
}

}  // namespace

int EstimatedFrames(const Scenario& s) {
  // Driving at speed_mps, turning in place at turn_rate_dps at each corner (arc corners: no
  // extra time), at rate_hz; capped by max_duration_s.
  // The waypoints' own goals: each leg at its speed, stops where the robot stops.
  const std::vector<WaypointGoal> goals = ResolveWaypoints(s.path, s.robot, s.waypoints);
  double seconds = goals.empty() ? 0.0 : goals.front().stop_s + goals.back().stop_s;
  for (size_t i = 1; i < s.path.size(); ++i) {
    const Eigen::Vector2d d = s.path[i] - s.path[i - 1];
    seconds += d.norm() / goals[i - 1].speed_mps;
    if (i + 1 < s.path.size() && !goals[i].arc) {
      const Eigen::Vector2d next = s.path[i + 1] - s.path[i];
      const double turn = std::abs(std::atan2(d.x() * next.y() - d.y() * next.x(), d.dot(next)));
      seconds += turn * 180.0 / M_PI / s.robot.turn_rate_dps + goals[i].stop_s;
    }
  }
  if (std::isfinite(s.robot.final_heading_deg) && s.path.size() >= 2) {  // the final turn
    const Eigen::Vector2d d = s.path.back() - s.path[s.path.size() - 2];
    const double h = s.robot.final_heading_deg * M_PI / 180.0 - std::atan2(d.y(), d.x());
    seconds +=
        std::abs(std::atan2(std::sin(h), std::cos(h))) * 180.0 / M_PI / s.robot.turn_rate_dps;
  }
  seconds = std::min(seconds, s.max_duration_s);
  return static_cast<int>(std::floor(seconds * s.rate_hz)) + 1;
}

bool Scenario::IsValid(std::string* error) const {
  std::ostringstream e;
  if (path.size() < 2)
    e << "path: expected at least 2 waypoints, got " << path.size();
  else if (!(rate_hz > 0))
    e << "rate_hz: expected > 0, got " << rate_hz;
  else if (!(physics_dt_s > 0 && physics_dt_s <= 0.01))
    e << "physics_dt_s: expected in (0, 0.01], got " << physics_dt_s;
  else if (!(max_duration_s > 0))
    e << "max_duration_s: expected > 0";
  else if (!(settle_s >= 0))
    e << "settle_s: expected >= 0";
  else if (navigation != "ground_truth" && navigation != "vo")
    e << "navigation: expected 'ground_truth' or 'vo', got '" << navigation << "'";
  else if (!(robot.speed_mps > 0 && robot.speed_mps <= 3))
    e << "robot.speed_mps: expected in (0, 3], got " << robot.speed_mps;
  else if (!(robot.max_accel_mps2 > 0))
    e << "robot.max_accel_mps2: expected > 0";
  else if (!(robot.turn_rate_dps > 0 && robot.turn_rate_dps <= 360))
    e << "robot.turn_rate_dps: expected in (0, 360]";
  else if (!(robot.lookahead_m > 0))
    e << "robot.lookahead_m: expected > 0";
  else if (robot.corner_mode != "in_place" && robot.corner_mode != "arc")
    e << "robot.corner_mode: expected 'in_place' or 'arc', got '" << robot.corner_mode << "'";
  else if (!(robot.goal_tolerance_m > 0))
    e << "robot.goal_tolerance_m: expected > 0";
  else if (!(robot.stop_s >= 0 && robot.stop_s <= 600))
    e << "robot.stop_s: expected in [0, 600] s";
  else if (std::isinf(robot.final_heading_deg))
    e << "robot.final_heading_deg: expected a finite angle (or none)";
  else if (camera.width < 16 || camera.width > 4096 || camera.height < 16 || camera.height > 4096)
    e << "camera.width/height: expected 16..4096, got " << camera.width << "x" << camera.height;
  else if (!(camera.fovy_deg > kMinFovDeg && camera.fovy_deg < kMaxFovDeg))
    e << "camera.fovy_deg: expected in (1, 170), got " << camera.fovy_deg;
  else if (const double fovx_deg =
               2.0 *
               std::atan(std::tan(camera.fovy_deg * M_PI / 360.0) * camera.width / camera.height) *
               180.0 / M_PI;
           !(fovx_deg < kMaxFovDeg))
    e << "camera.fovy_deg: " << camera.fovy_deg << " deg at " << camera.width << "x"
      << camera.height << " gives a horizontal field of view of " << fovx_deg
      << " deg; expected below " << kMaxFovDeg << " deg";
  else if (!(camera.baseline_m >= kMinBaselineM && camera.baseline_m <= kMaxBaselineM))
    e << "camera.baseline_m: expected " << kMinBaselineM << " .. " << kMaxBaselineM
      << " m (1 mm to 5 m), got " << camera.baseline_m;
  else if (!(camera.height_m > 0))
    e << "camera.height_m: expected > 0, got " << camera.height_m;
  else if (!(camera.pitch_deg > -80 && camera.pitch_deg < 80))
    e << "camera.pitch_deg: expected in (-80, 80)";
  else if (!(noise.pixel_sigma >= 0))
    e << "noise.pixel_sigma: expected >= 0";
  else if (!(noise.gain_sigma >= 0 && noise.gain_sigma < 0.5))
    e << "noise.gain_sigma: expected in [0, 0.5)";
  else if (!(noise.bias_sigma >= 0))
    e << "noise.bias_sigma: expected >= 0";
  else if (!(noise.motion_blur_exposure_s >= 0 && noise.motion_blur_exposure_s < 1.0 / rate_hz))
    e << "noise.motion_blur_exposure_s: expected in [0, 1/rate_hz)";
  else if (noise.motion_blur_exposure_s > 0 && noise.motion_blur_samples < 2)
    e << "noise.motion_blur_samples: expected >= 2 when motion blur is on";
  else if (noise.motion_blur_samples < 1 || noise.motion_blur_samples > kMaxMotionBlurSamples)
    e << "noise.motion_blur_samples: expected 1 .. " << kMaxMotionBlurSamples << ", got "
      << noise.motion_blur_samples;
  else if (std::string key, physics = PhysicsProblem(*this, &key); !physics.empty())
    e << key << ": " << physics;
  else if (std::string imu_key, imu = ImuProblem(*this, &imu_key); !imu.empty())
    e << imu_key << ": " << imu;
  else if (std::string cf_key, cf = CalibrationAndFramesProblem(*this, &cf_key); !cf.empty())
    e << cf_key << ": " << cf;
  else if (std::string pl_key, pl = PeopleAndLightsProblem(*this, &pl_key); !pl.empty())
    e << pl_key << ": " << pl;
  else {
    for (size_t i = 0; i < path.size(); ++i) {
      if (!path[i].allFinite()) {
        e << "path[" << i << "]: expected finite coordinates";
        break;
      }
      if (i > 0 && (path[i] - path[i - 1]).norm() < 1e-3) {
        e << "path[" << i << "]: repeats the previous waypoint";
        break;
      }
    }
    if (e.tellp() == 0) e << WaypointProblem(*this);
    if (const double shortest = ShortestSegmentM(path);
        e.tellp() == 0 && !(robot.goal_tolerance_m < shortest))
      e << "robot.goal_tolerance_m: " << robot.goal_tolerance_m
        << " m is not below the shortest path segment (" << shortest
        << " m): the robot takes a waypoint within the tolerance as reached and would skip "
           "that segment";
  }
  if (e.tellp() == 0) return true;
  if (error) *error = e.str();
  return false;
}

bool ParseScenario(const std::string& yaml_text, const std::string& source_name,
                   const std::string& base_dir, Scenario* scenario, std::string* error) {
  YamlReader r(source_name);
  if (!r.Parse(yaml_text)) return r.Report(error);
  YAML::Node root = r.root();  // not const: a missing key reads as undefined, not invalid
  Scenario s;
  if (!root.IsMap()) {
    if (error) *error = source_name + ": expected a YAML mapping at the top level";
    return false;
  }
  constexpr int kIntMin = std::numeric_limits<int>::min();
  constexpr int kIntMax = std::numeric_limits<int>::max();
  r.CheckKeys(root, "",
              {"camera",
               "max_duration_s",
               "name",
               "noise",
               "path",
               "physics_dt_s",
               "rate_hz",
               "robot",
               "scene",
               "floor_plan",
               "route",
               "seed",
               "settle_s",
               "textures",
               "imu",
               "navigation",
               "calibration_error",
               "frames",
               "people",
               "lights"});
  r.String(root, "", "name", &s.name);
  // The scene: an MJCF file, or a floor plan it is generated from (sim/floor_plan.h).
  std::string scene, floor_plan;
  r.String(root, "", "scene", &scene);
  r.String(root, "", "floor_plan", &floor_plan);
  r.Check(scene.empty() || floor_plan.empty(), root, "", "floor_plan",
          "give scene (an MJCF file) or floor_plan (a floor-plan YAML), not both");
  r.Check(!scene.empty() || !floor_plan.empty(), root, "", "scene",
          "required: the MJCF scene file, or floor_plan: a floor-plan YAML (relative to the "
          "scenario file)");
  r.Check(scene.empty() || !IsFloorPlanPath(scene), root, "", "scene",
          "'" + scene + "' is a YAML file: a floor plan is given as floor_plan:");
  r.Check(floor_plan.empty() || IsFloorPlanPath(floor_plan), root, "", "floor_plan",
          "expected a .yaml or .yml floor plan, got '" + floor_plan + "'");
  const std::string scene_key = floor_plan.empty() ? "scene" : "floor_plan";
  if (!floor_plan.empty()) scene = floor_plan;
  r.Uint64(root, "", "seed", &s.seed);
  r.Double(root, "", "rate_hz", &s.rate_hz);
  r.Double(root, "", "physics_dt_s", &s.physics_dt_s);
  r.Double(root, "", "max_duration_s", &s.max_duration_s);
  r.Double(root, "", "settle_s", &s.settle_s);
  r.String(root, "", "navigation", &s.navigation);
  r.Check(s.navigation == "ground_truth" || s.navigation == "vo", root, "", "navigation",
          "expected 'ground_truth' or 'vo', got '" + s.navigation + "'");

  // route: {from: PLACE, to: PLACE}, the path planned through the floor plan (below).
  std::string route_from, route_to;
  const bool route = YamlReader::Has(root, "route");
  if (route) {
    const YAML::Node n = root["route"];
    r.Check(!YamlReader::Has(root, "path"), root, "", "path",
            "give path (waypoints) or route (planned between two places), not both");
    r.Check(!floor_plan.empty(), root, "", "route",
            "a route is planned through a floor plan: give floor_plan:");
    r.CheckKeys(n, "route", {"from", "to"});
    r.Require(n, "route", "from", "a place of the floor plan");
    r.Require(n, "route", "to", "a place of the floor plan");
    r.String(n, "route", "from", &route_from, false);
    r.String(n, "route", "to", &route_to, false);
  } else if (r.Require(root, "", "path", "a list of at least 2 waypoints [x, y] (m)") &&
             ReadPath(root["path"], &r, &s)) {
    r.Check(s.path.size() >= 2, root, "", "path",
            "expected at least 2 waypoints, got " + std::to_string(s.path.size()));
  }

  if (const YAML::Node n = root["robot"]; n.IsDefined() && r.ok()) {
    r.CheckKeys(n, "robot",
                {"corner_mode", "goal_tolerance_m", "lookahead_m", "max_accel_mps2", "speed_mps",
                 "turn_rate_dps", "stop_s", "final_heading_deg"});
    RobotOptions& o = s.robot;
    r.Double(n, "robot", "speed_mps", &o.speed_mps);
    r.Check(o.speed_mps > 0 && o.speed_mps <= 3, n, "robot", "speed_mps",
            "expected in (0, 3] m/s, got " + Num(o.speed_mps));
    r.Double(n, "robot", "max_accel_mps2", &o.max_accel_mps2);
    r.Check(o.max_accel_mps2 > 0, n, "robot", "max_accel_mps2", "expected > 0");
    r.Double(n, "robot", "turn_rate_dps", &o.turn_rate_dps);
    r.Check(o.turn_rate_dps > 0 && o.turn_rate_dps <= 360, n, "robot", "turn_rate_dps",
            "expected in (0, 360] deg/s");
    r.Double(n, "robot", "lookahead_m", &o.lookahead_m);
    r.Check(o.lookahead_m > 0, n, "robot", "lookahead_m", "expected > 0");
    r.String(n, "robot", "corner_mode", &o.corner_mode);
    r.Check(o.corner_mode == "in_place" || o.corner_mode == "arc", n, "robot", "corner_mode",
            "expected 'in_place' or 'arc', got '" + o.corner_mode + "'");
    r.Double(n, "robot", "goal_tolerance_m", &o.goal_tolerance_m);
    r.Check(o.goal_tolerance_m > 0, n, "robot", "goal_tolerance_m", "expected > 0");
    r.Double(n, "robot", "stop_s", &o.stop_s);
    r.Check(o.stop_s >= 0 && o.stop_s <= 600, n, "robot", "stop_s", "expected in [0, 600] s");
    r.Double(n, "robot", "final_heading_deg", &o.final_heading_deg);
  }
  if (const YAML::Node n = root["camera"]; n.IsDefined() && r.ok()) {
    r.CheckKeys(n, "camera",
                {"auto_exposure", "baseline_m", "distortion", "forward_m", "fovy_deg", "height",
                 "height_m", "pitch_deg", "width"});
    CameraOptions& o = s.camera;
    r.Int(n, "camera", "width", kIntMin, kIntMax, &o.width);
    r.Check(o.width >= 16 && o.width <= 4096, n, "camera", "width",
            "expected 16..4096 pixels, got " + std::to_string(o.width));
    r.Int(n, "camera", "height", kIntMin, kIntMax, &o.height);
    r.Check(o.height >= 16 && o.height <= 4096, n, "camera", "height",
            "expected 16..4096 pixels, got " + std::to_string(o.height));
    r.Double(n, "camera", "fovy_deg", &o.fovy_deg);
    r.Check(o.fovy_deg > kMinFovDeg && o.fovy_deg < kMaxFovDeg, n, "camera", "fovy_deg",
            "expected in (1, 170) degrees, got " + Num(o.fovy_deg));
    r.Double(n, "camera", "baseline_m", &o.baseline_m);
    r.Check(o.baseline_m >= kMinBaselineM && o.baseline_m <= kMaxBaselineM, n, "camera",
            "baseline_m",
            "expected a positive baseline of " + Num(kMinBaselineM) + " .. " + Num(kMaxBaselineM) +
                " m (1 mm to 5 m), got " + Num(o.baseline_m));
    r.Double(n, "camera", "height_m", &o.height_m);
    r.Check(o.height_m > 0, n, "camera", "height_m", "expected > 0 m, got " + Num(o.height_m));
    r.Double(n, "camera", "forward_m", &o.forward_m);
    r.Double(n, "camera", "pitch_deg", &o.pitch_deg);
    r.Check(o.pitch_deg > -80 && o.pitch_deg < 80, n, "camera", "pitch_deg",
            "expected in (-80, 80) degrees");
  }
  if (const YAML::Node n = root["noise"]; n.IsDefined() && r.ok()) {
    r.CheckKeys(n, "noise",
                {"bias_sigma", "gain_sigma", "motion_blur_exposure_s", "motion_blur_samples",
                 "pixel_sigma"});
    NoiseOptions& o = s.noise;
    r.Double(n, "noise", "pixel_sigma", &o.pixel_sigma);
    r.Check(o.pixel_sigma >= 0, n, "noise", "pixel_sigma", "expected >= 0 grey levels");
    r.Double(n, "noise", "gain_sigma", &o.gain_sigma);
    r.Check(o.gain_sigma >= 0 && o.gain_sigma < 0.5, n, "noise", "gain_sigma",
            "expected in [0, 0.5)");
    r.Double(n, "noise", "bias_sigma", &o.bias_sigma);
    r.Check(o.bias_sigma >= 0, n, "noise", "bias_sigma", "expected >= 0 grey levels");
    r.Double(n, "noise", "motion_blur_exposure_s", &o.motion_blur_exposure_s);
    r.Check(o.motion_blur_exposure_s >= 0, n, "noise", "motion_blur_exposure_s", "expected >= 0 s");
    r.Int(n, "noise", "motion_blur_samples", kIntMin, kIntMax, &o.motion_blur_samples);
    r.Check(o.motion_blur_samples >= 1 && o.motion_blur_samples <= kMaxMotionBlurSamples, n,
            "noise", "motion_blur_samples",
            "expected 1 .. " + std::to_string(kMaxMotionBlurSamples) + " renders per frame, got " +
                std::to_string(o.motion_blur_samples));
  }
  if (const YAML::Node n = root["textures"]; n.IsDefined() && r.ok()) {
    r.CheckKeys(n, "textures", {"seed"});
    r.Uint64(n, "textures", "seed", &s.textures.seed);
  }
  if (const YAML::Node n = root["imu"]; n.IsDefined() && r.ok()) {
    const char* keys[] = {"rate_hz",
                          "gyro_noise_density",
                          "gyro_random_walk",
                          "accel_noise_density",
                          "accel_random_walk",
                          "x_m",
                          "y_m",
                          "z_m",
                          "roll_deg",
                          "pitch_deg",
                          "yaw_deg",
                          "gyro_turn_on_bias_sigma_radps",
                          "pre_roll_s"};
    ImuOptions& o = s.imu;
    double* values[] = {&o.rate_hz,
                        &o.gyro_noise_density,
                        &o.gyro_random_walk,
                        &o.accel_noise_density,
                        &o.accel_random_walk,
                        &o.x_m,
                        &o.y_m,
                        &o.z_m,
                        &o.roll_deg,
                        &o.pitch_deg,
                        &o.yaw_deg,
                        &o.gyro_turn_on_bias_sigma_radps,
                        &o.pre_roll_s};
    r.CheckKeys(n, "imu", std::vector<std::string>(std::begin(keys), std::end(keys)));
    for (size_t i = 0; i < std::size(keys) && r.ok(); ++i) r.Double(n, "imu", keys[i], values[i]);
  }
  ReadCalibrationAndFrames(root, &r, &s);
  ReadPeopleAndLights(root, &r, &s);
  if (std::string key, imu = ImuProblem(s, &key);
      r.ok() && !imu.empty() && s.physics_dt_s > 0 && s.physics_dt_s <= 0.01) {
    // At the imu key's line, else at physics_dt_s (a step that the default rate does not fit).
    YAML::Node n = root["imu"];  // not const: a missing key reads as undefined
    const bool at_key = n.IsDefined() && n[key.substr(4)].IsDefined();
    const bool at_step = root["physics_dt_s"].IsDefined();
    r.Fail(at_key ? n[key.substr(4)] : at_step ? root["physics_dt_s"] : root, key, imu);
  }
  if (r.ok() && s.physics_dt_s > 0 && s.physics_dt_s <= 0.01) {
    // Rate vs step, exposure vs period: at the line of the key to change.
    std::string key;
    const std::string physics = PhysicsProblem(s, &key);
    if (!physics.empty()) {
      const YAML::Node noise = root["noise"];
      const YAML::Node at = key == "rate_hz"    ? root["rate_hz"]
                            : noise.IsDefined() ? noise["motion_blur_exposure_s"]
                                                : YAML::Node();
      r.Fail(at.IsDefined() ? at : root, key, physics);
    }
  }
  if (!r.Report(error)) return false;
  // Resolve the scene relative to the scenario's folder.
  fs::path scene_path(scene);
  if (scene_path.is_relative()) scene_path = fs::path(base_dir) / scene_path;
  s.scene_path = scene_path.lexically_normal().string();
  if (!fs::exists(s.scene_path)) {
    if (error) *error = source_name + ": key '" + scene_key + "': file not found: " + s.scene_path;
    return false;
  }
  if (route) {  // the planned path: waypoints from the plan's grid planner (sim/floor_plan.h)
    FloorPlan plan;
    if (!LoadFloorPlan(s.scene_path, &plan, error)) return false;
    Eigen::Vector2d ends[2];
    const std::string names[2] = {route_from, route_to};
    for (int k = 0; k < 2; ++k) {
      bool found = false;
      std::string known;
      for (const auto& [name, at] : plan.places) {
        known += (known.empty() ? "" : ", ") + name;
        if (name == names[k]) {
          ends[k] = at;
          found = true;
        }
      }
      if (!found) {
        r.Fail(root["route"][k == 0 ? "from" : "to"], k == 0 ? "route.from" : "route.to",
               "no place '" + names[k] + "' in " + s.scene_path +
                   " (places: " + (known.empty() ? "none" : known) + ")");
        return r.Report(error);
      }
    }
    std::string why;
    // The planner keeps 5 cm more than the path check needs: its grid steps may pass a little
    // closer than their ends.
    if (!PlanPath(plan, ends[0], ends[1], kRobotClearanceM + 0.05, &s.path, &why)) {
      r.Fail(root["route"], "route", why);
      return r.Report(error);
    }
  }
  if (s.name.empty()) s.name = fs::path(source_name).stem().string();
  s.source_path = source_name;
  std::string why;
  if (!ResolveLights(root, &r, &s, error)) return false;
  if (!s.IsValid(&why)) {
    // At the line of the key the problem names: "rate_hz: ...", "robot.speed_mps: ...",
    // "path[3]: ...", "camera.width/height: ..." (a key left at its default: no line).
    const size_t colon = why.find(": ");
    const std::string key = colon == std::string::npos ? "" : why.substr(0, colon);
    const YAML::Node at = NodeOfKey(root, key);
    r.Fail(at, key, colon == std::string::npos ? why : why.substr(colon + 2));
    return r.Report(error);
  }
  // The path in free space, inside the building (scene_walls.h): refused here, at the line of
  // the waypoint, before anything is simulated. Simulator::Create checks scenarios built in code.
  std::vector<SceneWall> walls;
  std::vector<SceneFloor> floors;
  if (!WallsOfScene(s.scene_path, &walls, error, &floors)) return false;
  int waypoint = -1;
  std::string field;
  if (const std::string problem = PathProblem(s, walls, floors, &waypoint, &field);
      !problem.empty()) {
    const std::string key =
        "path[" + std::to_string(waypoint) + "]" + (field.empty() ? "" : "." + field);
    r.Fail(NodeOfKey(root, key), key, problem);
    return r.Report(error);
  }
  // The people's paths (sim/people.h), refused here when there are none.
  if (std::vector<PersonPath> people; !PlanPeople(s, walls, floors, &people, &why)) {
    r.Fail(NodeOfKey(root, "people.count"), "people.count", why);
    return r.Report(error);
  }
  *scenario = std::move(s);
  return true;
}

bool LoadScenario(const std::string& path, Scenario* scenario, std::string* error) {
  std::string text, why;
  if (!ReadInputFile(path, "YAML scenario file", &text, &why)) {
    if (error) *error = why;
    return false;
  }
  const std::string base = fs::absolute(path).parent_path().string();
  return ParseScenario(text, path, base, scenario, error);
}

std::string ScenarioToYaml(const Scenario& s) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << s.name;
  out << YAML::Key << (IsFloorPlanPath(s.scene_path) ? "floor_plan" : "scene") << YAML::Value
      << s.scene_path;
  out << YAML::Key << "seed" << YAML::Value << s.seed;
  out << YAML::Key << "rate_hz" << YAML::Value << s.rate_hz;
  out << YAML::Key << "physics_dt_s" << YAML::Value << s.physics_dt_s;
  out << YAML::Key << "max_duration_s" << YAML::Value << s.max_duration_s;
  out << YAML::Key << "settle_s" << YAML::Value << s.settle_s;
  out << YAML::Key << "navigation" << YAML::Value << s.navigation;
  out << YAML::Key << "path" << YAML::Value << YAML::BeginSeq;
  for (size_t i = 0; i < s.path.size(); ++i) {
    const Eigen::Vector2d& p = s.path[i];
    const WaypointOptions* w = i < s.waypoints.size() ? &s.waypoints[i] : nullptr;
    if (!w || !w->any()) {  // a waypoint without goals of its own: a pair, as always
      out << YAML::Flow << YAML::BeginSeq << p.x() << p.y() << YAML::EndSeq;
      continue;
    }
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "at" << YAML::Value << YAML::Flow
        << YAML::BeginSeq << p.x() << p.y() << YAML::EndSeq;
    if (!w->turn.empty()) out << YAML::Key << "turn" << YAML::Value << w->turn;
    for (const auto& [k, v] : std::initializer_list<std::pair<const char*, double>>{
             {"radius_m", w->radius_m}, {"stop_s", w->stop_s}, {"speed_mps", w->speed_mps}})
      if (!std::isnan(v)) out << YAML::Key << k << YAML::Value << v;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "robot" << YAML::Value << YAML::BeginMap << YAML::Key << "speed_mps"
      << YAML::Value << s.robot.speed_mps << YAML::Key << "max_accel_mps2" << YAML::Value
      << s.robot.max_accel_mps2 << YAML::Key << "turn_rate_dps" << YAML::Value
      << s.robot.turn_rate_dps << YAML::Key << "lookahead_m" << YAML::Value << s.robot.lookahead_m
      << YAML::Key << "corner_mode" << YAML::Value << s.robot.corner_mode << YAML::Key
      << "goal_tolerance_m" << YAML::Value << s.robot.goal_tolerance_m;
  // The path's goals only where set: effective scenarios without them read as before.
  if (s.robot.stop_s != 0.0) out << YAML::Key << "stop_s" << YAML::Value << s.robot.stop_s;
  if (std::isfinite(s.robot.final_heading_deg))
    out << YAML::Key << "final_heading_deg" << YAML::Value << s.robot.final_heading_deg;
  out << YAML::EndMap;
  out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap << YAML::Key << "width"
      << YAML::Value << s.camera.width << YAML::Key << "height" << YAML::Value << s.camera.height
      << YAML::Key << "fovy_deg" << YAML::Value << s.camera.fovy_deg << YAML::Key << "baseline_m"
      << YAML::Value << s.camera.baseline_m << YAML::Key << "height_m" << YAML::Value
      << s.camera.height_m << YAML::Key << "forward_m" << YAML::Value << s.camera.forward_m
      << YAML::Key << "pitch_deg" << YAML::Value << s.camera.pitch_deg;
  EmitLens(s, &out);
  EmitAutoExposure(s, &out);
  out << YAML::EndMap;
  out << YAML::Key << "noise" << YAML::Value << YAML::BeginMap << YAML::Key << "pixel_sigma"
      << YAML::Value << s.noise.pixel_sigma << YAML::Key << "gain_sigma" << YAML::Value
      << s.noise.gain_sigma << YAML::Key << "bias_sigma" << YAML::Value << s.noise.bias_sigma
      << YAML::Key << "motion_blur_exposure_s" << YAML::Value << s.noise.motion_blur_exposure_s
      << YAML::Key << "motion_blur_samples" << YAML::Value << s.noise.motion_blur_samples
      << YAML::EndMap;
  out << YAML::Key << "textures" << YAML::Value << YAML::BeginMap << YAML::Key << "seed"
      << YAML::Value << s.textures.seed << YAML::EndMap;
  const ImuOptions& imu = s.imu;
  out << YAML::Key << "imu" << YAML::Value << YAML::BeginMap;
  for (const auto& [k, v] : std::initializer_list<std::pair<const char*, double>>{
           {"rate_hz", imu.rate_hz},
           {"gyro_noise_density", imu.gyro_noise_density},
           {"gyro_random_walk", imu.gyro_random_walk},
           {"accel_noise_density", imu.accel_noise_density},
           {"accel_random_walk", imu.accel_random_walk},
           {"x_m", imu.x_m},
           {"y_m", imu.y_m},
           {"z_m", imu.z_m},
           {"roll_deg", imu.roll_deg},
           {"pitch_deg", imu.pitch_deg},
           {"yaw_deg", imu.yaw_deg}})
    out << YAML::Key << k << YAML::Value << v;
  // Written only when set: a scenario without them emits the bytes it did before they existed.
  if (imu.gyro_turn_on_bias_sigma_radps != 0.0)
    out << YAML::Key << "gyro_turn_on_bias_sigma_radps" << YAML::Value
        << imu.gyro_turn_on_bias_sigma_radps;
  if (imu.pre_roll_s != 0.0) out << YAML::Key << "pre_roll_s" << YAML::Value << imu.pre_roll_s;
  out << YAML::EndMap;
  EmitCalibrationAndFrames(s, &out);
  EmitPeopleAndLights(s, &out);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

std::string ScenarioKeysYaml(const Scenario& scenario) {
  Scenario s = scenario;
  s.robot.stop_s = 1.0;
  s.robot.final_heading_deg = 0.0;
  s.camera.distortion.model = kRadTan;
  s.camera.distortion.coeffs.assign(4, 0.0);
  s.camera.auto_exposure.enabled = !AutoExposureOptions().enabled;
  s.calibration_error.baseline_pct = 1.0;
  s.frames.drop_rate = 0.1;
  s.people.count = 1;
  s.lights.switches.assign(1, LightSwitch{0.0, 0, "", false});
  s.lights.flicker_hz = 1.0;
  return ScenarioToYaml(s);
}

std::string BuiltinScenarioPath(const std::string& name) {
  return (fs::path(DataDir()) / "scenes" / (name + ".yaml")).string();
}

}  // namespace sim
