// Scenario files: the shipped ones load; every malformed input is refused with a message that
// names the file, the key (and line) and what was expected.
#include "sim/scenario.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "sim/simulator.h"
#include "sim_test_util.h"

namespace {

using vobench_test::TempDir;
using vobench_test::WriteText;

const char* kGood = R"(name: t
scene: scene.xml
seed: 3
rate_hz: 10
path:
  - [0, 0]
  - [2, 0]
camera:
  baseline_m: 0.12
noise:
  pixel_sigma: 1.0
)";

class ScenarioFileTest : public ::testing::Test {
 protected:
  ScenarioFileTest() : dir_("scenario") { WriteText(dir_ / "scene.xml", "<mujoco/>"); }
  // Loads `yaml` from a file; returns the error ("" on success).
  std::string Load(const std::string& yaml, sim::Scenario* s = nullptr) {
    const std::string path = dir_ / "s.yaml";
    WriteText(path, yaml);
    sim::Scenario local;
    std::string error;
    if (sim::LoadScenario(path, s ? s : &local, &error)) return "";
    EXPECT_NE(error.find(path), std::string::npos) << "message must name the file: " << error;
    return error.empty() ? "(empty message)" : error;
  }
  std::string Replace(const std::string& from, const std::string& to) {
    std::string y = kGood;
    const size_t at = y.find(from);
    EXPECT_NE(at, std::string::npos);
    return y.replace(at, from.size(), to);
  }
  TempDir dir_;
};

TEST_F(ScenarioFileTest, GoodFileLoadsWithDefaults) {
  sim::Scenario s;
  ASSERT_EQ(Load(kGood, &s), "");
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.seed, 3u);
  EXPECT_DOUBLE_EQ(s.camera.baseline_m, 0.12);
  EXPECT_EQ(s.camera.width, 320);  // default
  ASSERT_EQ(s.path.size(), 2u);
  EXPECT_EQ(s.path[1], Eigen::Vector2d(2, 0));
  EXPECT_EQ(s.scene_path, dir_ / "scene.xml");
}

TEST_F(ScenarioFileTest, ShippedScenariosLoad) {
  for (const char* name : {"l_hallway", "plain_corridor"}) {
    sim::Scenario s;
    std::string error;
    EXPECT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath(name), &s, &error)) << error;
    EXPECT_EQ(s.name, name);
  }
}

TEST_F(ScenarioFileTest, EffectiveScenarioRoundTrips) {
  sim::Scenario s, again;
  ASSERT_EQ(Load(kGood, &s), "");
  const std::string path = dir_ / "effective.yaml";
  WriteText(path, sim::ScenarioToYaml(s));
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(path, &again, &error)) << error;
  EXPECT_EQ(sim::ScenarioToYaml(again), sim::ScenarioToYaml(s));
}

TEST_F(ScenarioFileTest, MissingFile) {
  sim::Scenario s;
  std::string error;
  EXPECT_FALSE(sim::LoadScenario(dir_ / "nope.yaml", &s, &error));
  EXPECT_NE(error.find("nope.yaml"), std::string::npos);
  EXPECT_NE(error.find("no such file"), std::string::npos) << error;
}

TEST_F(ScenarioFileTest, MalformedYamlGivesLine) {
  const std::string e = Load("name: t\npath: [[0, 0], [1, 0]\nscene: scene.xml\n");
  EXPECT_NE(e.find("malformed YAML"), std::string::npos) << e;
}

TEST_F(ScenarioFileTest, UnknownKeyNamedWithLine) {
  const std::string e = Load(Replace("  baseline_m: 0.12", "  baseline_m: 0.12\n  focal: 3"));
  EXPECT_NE(e.find("'camera.focal'"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("s.yaml:10"), std::string::npos) << e;  // the line of the key
}

TEST_F(ScenarioFileTest, WrongType) {
  const std::string e = Load(Replace("rate_hz: 10", "rate_hz: fast"));
  EXPECT_NE(e.find("'rate_hz'"), std::string::npos) << e;
  EXPECT_NE(e.find("expected a number"), std::string::npos) << e;
  const std::string e2 = Load(Replace("seed: 3", "seed: [1, 2]"));
  EXPECT_NE(e2.find("'seed'"), std::string::npos) << e2;
}

// Found by fuzz_scenario: a section that is a scalar or a list instead of a mapping
// ("robot:\n  speed_mps:lookahead 0.4" is the scalar "speed_mps:lookahead 0.4") threw
// YAML::BadSubscript out of ParseScenario (std::terminate in vobench).
TEST_F(ScenarioFileTest, SectionThatIsNotAMappingIsRefused) {
  for (const char* section : {"robot", "camera", "noise", "textures"}) {
    for (const char* value : {"\n  speed_mps:lookahead 0.4", " [1, 2]", " 3"}) {
      SCOPED_TRACE(std::string(section) + ":" + value);
      std::string e;
      const std::string yaml =
          std::string("scene: scene.xml\npath: [[0, 0], [2, 0]]\n") + section + ":" + value + "\n";
      EXPECT_NO_THROW(e = Load(yaml));
      EXPECT_NE(e.find(std::string("'") + section + "'"), std::string::npos) << e;
      EXPECT_NE(e.find("expected a mapping"), std::string::npos) << e;
    }
  }
}

TEST_F(ScenarioFileTest, NegativeBaseline) {
  const std::string e = Load(Replace("baseline_m: 0.12", "baseline_m: -0.09"));
  EXPECT_NE(e.find("'camera.baseline_m'"), std::string::npos) << e;
  EXPECT_NE(e.find("positive"), std::string::npos) << e;
}

TEST_F(ScenarioFileTest, NaNRefused) {
  const std::string e = Load(Replace("pixel_sigma: 1.0", "pixel_sigma: .nan"));
  EXPECT_NE(e.find("'noise.pixel_sigma'"), std::string::npos) << e;
  EXPECT_NE(e.find("finite"), std::string::npos) << e;
  const std::string e2 = Load(Replace("[2, 0]", "[.nan, 0]"));
  EXPECT_NE(e2.find("path[1]"), std::string::npos) << e2;
}

TEST_F(ScenarioFileTest, PathNeedsTwoWaypoints) {
  const std::string e = Load(Replace("  - [0, 0]\n  - [2, 0]\n", "  - [0, 0]\n"));
  EXPECT_NE(e.find("'path'"), std::string::npos) << e;
  EXPECT_NE(e.find("at least 2 waypoints"), std::string::npos) << e;
  const std::string e2 = Load(Replace("  - [2, 0]\n", "  - [2, 0, 1]\n"));
  EXPECT_NE(e2.find("path[1]"), std::string::npos) << e2;
}

TEST_F(ScenarioFileTest, MissingSceneFile) {
  const std::string e = Load(Replace("scene: scene.xml", "scene: nowhere.xml"));
  EXPECT_NE(e.find("nowhere.xml"), std::string::npos) << e;
  EXPECT_NE(e.find("not found"), std::string::npos) << e;
  const std::string e2 = Load(Replace("scene: scene.xml\n", ""));
  EXPECT_NE(e2.find("'scene'"), std::string::npos) << e2;
}

// Issue #11: a key given twice was read from its first occurrence, silently.
TEST_F(ScenarioFileTest, DuplicateKeysAreRefusedWithBothLines) {
  EXPECT_NE(Load(Replace("rate_hz: 10", "rate_hz: 10\nrate_hz: 20"))
                .find("s.yaml:5: key 'rate_hz': duplicate (first at line 4)"),
            std::string::npos);
  const std::string e =
      Load(Replace("  baseline_m: 0.12", "  baseline_m: 0.12\n  baseline_m: 0.5"));
  EXPECT_NE(e.find("s.yaml:10: key 'camera.baseline_m': duplicate (first at line 9)"),
            std::string::npos)
      << e;
}

// Issue #11: the frame rate is checked against the physics step (1000 Hz at 0.002 s wrote 2
// frames; 30 Hz is 16.67 steps per frame).
TEST_F(ScenarioFileTest, FrameRateMustFitThePhysicsStep) {
  const std::string above = Load(Replace("rate_hz: 10", "rate_hz: 1000"));
  EXPECT_NE(above.find("s.yaml:4: key 'rate_hz': 1000 Hz is above the physics rate"),
            std::string::npos)
      << above;
  const std::string fraction = Load(Replace("rate_hz: 10", "rate_hz: 30"));
  EXPECT_NE(fraction.find("key 'rate_hz'"), std::string::npos) << fraction;
  EXPECT_NE(fraction.find("16.6667 physics steps"), std::string::npos) << fraction;
  EXPECT_NE(fraction.find("whole number"), std::string::npos) << fraction;
  EXPECT_EQ(Load(Replace("rate_hz: 10", "rate_hz: 500")), "");  // one step per frame
  EXPECT_EQ(Load(Replace("rate_hz: 10", "rate_hz: 25\nphysics_dt_s: 0.001")), "");
}

// Issue #11: an exposure of 0.0999 s at 10 Hz passed, then failed after 300 simulated seconds
// ("stuck against a wall"); 1e8 blur samples hung the render.
TEST_F(ScenarioFileTest, MotionBlurMustFitTheFramePeriodWithBoundedSamples) {
  const std::string e = Load(Replace("  pixel_sigma: 1.0", "  motion_blur_exposure_s: 0.0999"));
  EXPECT_NE(e.find("key 'noise.motion_blur_exposure_s': 0.0999 s does not fit in the frame period"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("0.096 s"), std::string::npos) << e;  // 100 ms - 2 steps of 2 ms
  EXPECT_EQ(Load(Replace("  pixel_sigma: 1.0", "  motion_blur_exposure_s: 0.096")), "");
  const std::string samples = Load(Replace(
      "  pixel_sigma: 1.0", "  motion_blur_exposure_s: 0.03\n  motion_blur_samples: 100000000"));
  EXPECT_NE(samples.find("key 'noise.motion_blur_samples': expected 1 .. 1000"), std::string::npos)
      << samples;
}

// Issue #11: `baseline_m: 1e300` ran and gave inf/NaN metrics. Bounds: 1 mm .. 5 m.
TEST_F(ScenarioFileTest, BaselineAndFieldOfViewInPlausibleRanges) {
  for (const char* bad : {"1e300", "0.0005", "5.5"}) {
    const std::string e = Load(Replace("baseline_m: 0.12", std::string("baseline_m: ") + bad));
    EXPECT_NE(e.find("key 'camera.baseline_m': expected a positive baseline of 0.001 .. 5 m"),
              std::string::npos)
        << e;
  }
  EXPECT_EQ(Load(Replace("baseline_m: 0.12", "baseline_m: 0.001")), "");
  EXPECT_EQ(Load(Replace("baseline_m: 0.12", "baseline_m: 5")), "");
  // 55 deg vertically over 4096x16 pixels is a horizontal field of view of ~180 deg.
  const std::string wide =
      Load(Replace("  baseline_m: 0.12", "  baseline_m: 0.12\n  width: 4096\n  height: 16"));
  EXPECT_NE(wide.find("horizontal field of view"), std::string::npos) << wide;
}

// Issue #11: a path through a wall was accepted (walls are visual only), so the camera
// rendered from outside the hallway. Issue #31: refused when the file is read, at the line of the
// waypoint (the simulator still checks scenarios built in code).
TEST_F(ScenarioFileTest, PathThroughAWallIsRefusedNamingTheWaypoint) {
  const std::string scene = std::string(VOBENCH_SOURCE_DIR) + "/scenes/hallway_l.xml";
  const std::string through = Load("scene: " + scene + "\npath:\n  - [0, 0]\n  - [0, 3]\n");
  EXPECT_NE(through.find("s.yaml:4: key 'path[1]': the segment from path[0] (0, 0) to path[1] "
                         "(0, 3) crosses wall 'wall_north' of hallway_l.xml at (0, 1)"),
            std::string::npos)
      << through;
  // The paper's L path stays inside.
  sim::Scenario s;
  EXPECT_EQ(Load("scene: " + scene + "\npath: [[0, 0], [8, 0], [8, 8]]\n", &s), "");
  // Past the end of the east wall's leg: the third segment leaves through wall_end (y = 12).
  const std::string end = Load("scene: " + scene + "\npath: [[0, 0], [8, 0], [8, 13]]\n");
  EXPECT_NE(end.find("s.yaml:2: key 'path[2]'"), std::string::npos) << end;
  EXPECT_NE(end.find("wall 'wall_end'"), std::string::npos) << end;
  // Built in code: Simulator::Create refuses it before simulating.
  s.path.back() = Eigen::Vector2d(8, 13);
  std::string error;
  EXPECT_EQ(sim::Simulator::Create(s, &error), nullptr);
  EXPECT_NE(error.find("key 'path[2]'"), std::string::npos) << error;
  EXPECT_NE(error.find("wall 'wall_end'"), std::string::npos) << error;
}

TEST_F(ScenarioFileTest, OutOfRangeValues) {
  EXPECT_NE(Load(Replace("rate_hz: 10", "rate_hz: 0")), "");
  EXPECT_NE(Load(Replace("  baseline_m: 0.12", "  width: 8")).find("'camera.width'"),
            std::string::npos);
  EXPECT_NE(Load(Replace("name: t", "name: t\nrobot:\n  corner_mode: drift")).find("corner_mode"),
            std::string::npos);
}

// navigation (sim/navigation.h): ground_truth by default, vo for the closed loop, nothing else.
TEST_F(ScenarioFileTest, NavigationIsGroundTruthOrVoAndAnythingElseIsRefusedAtItsLine) {
  sim::Scenario s;
  ASSERT_EQ(Load(kGood, &s), "");
  EXPECT_EQ(s.navigation, "ground_truth");
  ASSERT_EQ(Load(std::string(kGood) + "navigation: vo\n", &s), "");
  EXPECT_EQ(s.navigation, "vo");
  EXPECT_NE(sim::ScenarioToYaml(s).find("navigation: vo\n"), std::string::npos);
  const std::string e = Load(std::string(kGood) + "navigation: slam\n");
  EXPECT_NE(e.find("s.yaml:12: key 'navigation': expected 'ground_truth' or 'vo', got 'slam'"),
            std::string::npos)
      << e;
  // Built in code: Simulator::Create refuses it through Scenario::IsValid.
  s.navigation = "odometry";
  std::string why;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("navigation: expected 'ground_truth' or 'vo', got 'odometry'"),
            std::string::npos)
      << why;
}

}  // namespace

namespace {

// The IMU (sim/imu.h): its samples are taken on physics steps, its noise numbers are >= 0.
TEST_F(ScenarioFileTest, ImuRateMustBeAWholeNumberOfPhysicsSteps) {
  sim::Scenario s;
  ASSERT_EQ(Load(kGood, &s), "");
  EXPECT_EQ(s.imu.rate_hz, 250.0);  // the ICM-20602 default: every 2nd step of 0.002 s
  const std::string imu = std::string(kGood) + "imu:\n  rate_hz: 200\n";
  const std::string e = Load(imu);
  EXPECT_NE(e.find("s.yaml:13: key 'imu.rate_hz': the sample period 1/200 s is 2.5 physics steps"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("e.g. 250 or 166.667 Hz"), std::string::npos) << e;
  EXPECT_EQ(Load(std::string(kGood) + "physics_dt_s: 0.001\nimu:\n  rate_hz: 200\n", &s), "");
  EXPECT_EQ(s.imu.rate_hz, 200.0);
  // A physics step the default rate does not fit is blamed on physics_dt_s's line.
  const std::string step = Load(std::string(kGood) + "physics_dt_s: 0.0025\n");
  EXPECT_NE(step.find("s.yaml:12: key 'imu.rate_hz'"), std::string::npos) << step;
  const std::string above = Load(std::string(kGood) + "imu:\n  rate_hz: 1000\n");
  EXPECT_NE(above.find("key 'imu.rate_hz': 1000 Hz is above the physics rate"), std::string::npos)
      << above;
}

TEST_F(ScenarioFileTest, CalibrationErrorAndFrameKeysAreCheckedAndRoundTrip) {
  const std::string good = std::string(kGood) +
                           "calibration_error:\n  baseline_pct: 1.5\n  rotation_deg: -0.25\n"
                           "frames:\n  drop_rate: 0.05\n  time_jitter_s: 0.004\n";
  sim::Scenario s, again, plain;
  ASSERT_EQ(Load(good, &s), "");
  EXPECT_EQ(s.calibration_error.baseline_pct, 1.5);
  EXPECT_EQ(s.calibration_error.focal_pct, 0.0);
  EXPECT_EQ(s.calibration_error.rotation_deg, -0.25);
  EXPECT_EQ(s.frames.drop_rate, 0.05);
  EXPECT_EQ(s.frames.time_jitter_s, 0.004);
  const std::string path = dir_ / "effective.yaml";
  WriteText(path, sim::ScenarioToYaml(s));
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(path, &again, &error)) << error;
  EXPECT_EQ(sim::ScenarioToYaml(again), sim::ScenarioToYaml(s));
  // Without them the effective YAML does not mention them (as before they existed).
  ASSERT_EQ(Load(kGood, &plain), "");
  EXPECT_EQ(sim::ScenarioToYaml(plain).find("calibration_error"), std::string::npos);
  EXPECT_EQ(sim::ScenarioToYaml(plain).find("frames"), std::string::npos);

  const std::pair<std::string, std::string> bad[] = {
      {"calibration_error:\n  baseline_pct: -100\n",
       "s.yaml:13: key 'calibration_error.baseline_pct': expected a percentage in (-100, 1000)"},
      {"calibration_error:\n  focal_pct: .nan\n", "s.yaml:13: key 'calibration_error.focal_pct'"},
      {"calibration_error:\n  rotation_deg: 45\n",
       "s.yaml:13: key 'calibration_error.rotation_deg': expected degrees in (-45, 45)"},
      {"calibration_error:\n  roll_deg: 1\n", "s.yaml:13: key 'calibration_error.roll_deg'"},
      {"frames:\n  drop_rate: 1\n",
       "s.yaml:13: key 'frames.drop_rate': expected a fraction in [0, 1)"},
      {"frames:\n  time_jitter_s: 0.05\n",
       "s.yaml:13: key 'frames.time_jitter_s': expected seconds in [0, 0.05) (below half the "
       "frame period at rate_hz 10"},
      {"frames:\n  time_jitter_s: -0.001\n", "s.yaml:13: key 'frames.time_jitter_s'"},
      {"frames: 3\n", "s.yaml:12: key 'frames'"}};
  for (const auto& [yaml, expected] : bad) {
    const std::string e = Load(std::string(kGood) + yaml);
    EXPECT_NE(e.find(expected), std::string::npos) << yaml << " -> " << e;
  }
}

TEST_F(ScenarioFileTest, LensKeysAreCheckedAndRoundTrip) {
  sim::Scenario s, again;
  ASSERT_EQ(Load(Replace("  baseline_m: 0.12\n",
                         "  baseline_m: 0.12\n  distortion:\n    model: equidistant\n"
                         "    coeffs: [0.05, -0.01, 0.002, -0.0005]\n"),
                 &s),
            "");
  EXPECT_EQ(s.camera.distortion.model, sim::kEquidistant);
  EXPECT_EQ(s.camera.distortion.coeffs, (std::vector<double>{0.05, -0.01, 0.002, -0.0005}));
  const std::string path = dir_ / "effective.yaml";
  WriteText(path, sim::ScenarioToYaml(s));
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(path, &again, &error)) << error;
  EXPECT_EQ(sim::ScenarioToYaml(again), sim::ScenarioToYaml(s));
  const std::string model = Load(
      Replace("  baseline_m: 0.12\n",
              "  baseline_m: 0.12\n  distortion:\n    model: fisheye\n    coeffs: [0, 0, 0, 0]\n"));
  EXPECT_NE(model.find("s.yaml:11: key 'camera.distortion.model': expected radtan or equidistant"),
            std::string::npos)
      << model;
  const std::string three = Load(
      Replace("  baseline_m: 0.12\n",
              "  baseline_m: 0.12\n  distortion:\n    model: radtan\n    coeffs: [0, 0, 0]\n"));
  EXPECT_NE(three.find("key 'camera.distortion.coeffs': expected a list of 4 numbers"),
            std::string::npos)
      << three;
}

TEST_F(ScenarioFileTest, ImuKeysAreCheckedAndRoundTrip) {
  const std::string good = std::string(kGood) +
                           "imu:\n  gyro_noise_density: 1e-4\n  accel_random_walk: 0\n"
                           "  x_m: -0.1\n  yaw_deg: 90\n";
  sim::Scenario s, again;
  ASSERT_EQ(Load(good, &s), "");
  EXPECT_EQ(s.imu.gyro_noise_density, 1e-4);
  EXPECT_EQ(s.imu.accel_random_walk, 0.0);
  EXPECT_EQ(s.imu.x_m, -0.1);
  EXPECT_EQ(s.imu.yaw_deg, 90.0);
  const std::string path = dir_ / "effective.yaml";
  WriteText(path, sim::ScenarioToYaml(s));
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(path, &again, &error)) << error;
  EXPECT_EQ(sim::ScenarioToYaml(again), sim::ScenarioToYaml(s));
  EXPECT_EQ(again.imu.yaw_deg, 90.0);

  const std::string negative = Load(std::string(kGood) + "imu:\n  gyro_random_walk: -1\n");
  EXPECT_NE(negative.find("s.yaml:13: key 'imu.gyro_random_walk': expected a finite number >= 0"),
            std::string::npos)
      << negative;
  const std::string unknown = Load(std::string(kGood) + "imu:\n  gyro_noise: 1\n");
  EXPECT_NE(unknown.find("s.yaml:13"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("gyro_noise_density"), std::string::npos) << unknown;
  const std::string nan = Load(std::string(kGood) + "imu:\n  z_m: .nan\n");
  EXPECT_NE(nan.find("imu.z_m"), std::string::npos) << nan;
  // Scenarios built in code are checked the same way (Simulator::Create calls IsValid).
  std::string why;
  s.imu.yaw_deg = std::nan("");
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("imu.yaw_deg: expected a finite number"), std::string::npos) << why;
  s.imu.yaw_deg = 0.0;
  s.imu.rate_hz = 300.0;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("imu.rate_hz: the sample period"), std::string::npos) << why;
}

// Waypoints as pairs and as maps with their own goals, mixed in one path; the goals round-trip
// through the effective YAML (a path of pairs writes pairs, as before); a bad goal is refused at
// its line with its key path[i].KEY.
TEST_F(ScenarioFileTest, WaypointGoalsParseInBothFormsAndAreCheckedAtTheirLines) {
  const std::string head = "name: t\nscene: scene.xml\npath:\n  - [0, 0]\n";
  const std::string good = head +
                           "  - {at: [3, 0], turn: arc, radius_m: 1.0, speed_mps: 0.6}\n"
                           "  - at: [3, 4]\n    stop_s: 2\n    turn: in_place\n"
                           "  - [6, 4]\n";
  sim::Scenario s, again, plain;
  ASSERT_EQ(Load(good, &s), "");
  ASSERT_EQ(s.path.size(), 4u);
  EXPECT_EQ(s.path[1], Eigen::Vector2d(3, 0));
  EXPECT_EQ(s.path[2], Eigen::Vector2d(3, 4));
  EXPECT_EQ(s.path[3], Eigen::Vector2d(6, 4));
  ASSERT_EQ(s.waypoints.size(), 4u);
  EXPECT_FALSE(s.waypoints[0].any());
  EXPECT_EQ(s.waypoints[1].turn, "arc");
  EXPECT_EQ(s.waypoints[1].radius_m, 1.0);
  EXPECT_EQ(s.waypoints[1].speed_mps, 0.6);
  EXPECT_TRUE(std::isnan(s.waypoints[1].stop_s));
  EXPECT_EQ(s.waypoints[2].stop_s, 2.0);
  EXPECT_EQ(s.waypoints[2].turn, "in_place");
  EXPECT_FALSE(s.waypoints[3].any());
  const std::string path = dir_ / "effective.yaml";
  WriteText(path, sim::ScenarioToYaml(s));
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(path, &again, &error)) << error;
  EXPECT_EQ(sim::ScenarioToYaml(again), sim::ScenarioToYaml(s));
  ASSERT_EQ(again.waypoints.size(), 4u);
  EXPECT_EQ(again.waypoints[1].radius_m, 1.0);
  ASSERT_EQ(Load(kGood, &plain), "");
  EXPECT_TRUE(plain.waypoints.empty());
  EXPECT_EQ(sim::ScenarioToYaml(plain).find("at:"), std::string::npos);
  // Its frames estimate: the legs at their speeds, the stop and the in-place turn at path[2].
  const double seconds = 3 / 0.4 + 4 / 0.6 + 3 / 0.4 + 2.0 + 90.0 / 30.0;
  EXPECT_EQ(sim::EstimatedFrames(s), static_cast<int>(std::floor(seconds * 10)) + 1);

  const std::pair<std::string, std::string> bad[] = {
      {"  - {at: [3, 0], radius_m: 1.0}\n  - [3, 4]\n",
       "s.yaml:5: key 'path[1].radius_m': an arc's radius, at a corner turned in place"},
      {"  - {at: [3, 0], turn: arc, radius_m: 5}\n  - [3, 4]\n",
       "s.yaml:5: key 'path[1].radius_m': an arc of 5 m at this corner takes 5 m of each leg; the "
       "leg in is 3 m"},
      {"  - {at: [3, 0], turn: arc, radius_m: -1}\n  - [3, 4]\n",
       "s.yaml:5: key 'path[1].radius_m': expected a finite radius > 0 m"},
      {"  - {at: [3, 0], turn: arc, stop_s: 1}\n  - [3, 4]\n",
       "s.yaml:5: key 'path[1].stop_s': the robot does not stop at an arc corner"},
      {"  - {at: [3, 0], stop_s: 700}\n  - [3, 4]\n",
       "s.yaml:5: key 'path[1].stop_s': expected in [0, 600] s"},
      {"  - {at: [3, 0], turn: spin}\n  - [3, 4]\n",
       "s.yaml:5: key 'path[1].turn': expected 'in_place' or 'arc', got 'spin'"},
      {"  - {at: [3, 0], speed_mps: 0}\n  - [3, 4]\n",
       "s.yaml:5: key 'path[1].speed_mps': expected in (0, 3] m/s"},
      {"  - [3, 0]\n  - {at: [3, 4], speed_mps: 1}\n",
       "s.yaml:6: key 'path[2].speed_mps': the speed of the leg that starts here; no leg starts"},
      {"  - [3, 0]\n  - {at: [3, 4], turn: arc}\n",
       "s.yaml:6: key 'path[2].turn': the first and the last waypoint have no corner"},
      {"  - {at: [3, 0], wait: 1}\n  - [3, 4]\n", "s.yaml:5: key 'path[1].wait': unknown key"},
      {"  - {turn: arc}\n  - [3, 4]\n", "s.yaml:5: key 'path[1].at': required"},
      {"  - {at: [3, 0, 1]}\n  - [3, 4]\n", "s.yaml:5: key 'path[1].at'"},
      {"  - {at: [3, 0]}\n  - [3, 4, 5]\n", "s.yaml:6: key 'path[2]'"}};
  for (const auto& [yaml, expected] : bad) {
    const std::string e = Load(head + yaml);
    EXPECT_NE(e.find(expected), std::string::npos) << yaml << " -> " << e;
  }
}

}  // namespace
