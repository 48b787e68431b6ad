// People, lights and auto-exposure (issue #34; sim/people.h, sim/lighting.h): people stand where
// their planned paths put them at the frame times, inside the free space; no people gives the
// renders of before; a lamp switched off darkens the frames from its switch on, and switched on
// again gives the very bytes back; the flicker's period shows in the frame means; the
// auto-exposure is a first-order step response; bad values are refused at their line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "sim/floor_plan.h"
#include "sim/lighting.h"
#include "sim/people.h"
#include "sim/scenario.h"
#include "sim/scene_walls.h"
#include "sim/simulator.h"
#include "sim_test_util.h"

namespace {

using vobench_test::TempDir;
using vobench_test::WriteText;

// A built-in scenario at a small resolution and without noise (means compare exactly).
sim::Scenario Small(const std::string& name) {
  sim::Scenario s;
  std::string error;
  EXPECT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath(name), &s, &error)) << error;
  s.camera.width = 80;
  s.camera.height = 60;
  s.noise = sim::NoiseOptions();
  return s;
}

struct SimRun {
  std::vector<sim::StereoFrame> frames;
  std::vector<std::vector<Eigen::Vector3d>> people;  // per frame
  std::vector<double> gains;                         // per frame
};

SimRun Simulate(const sim::Scenario& s, int count) {
  SimRun run;
  std::string error;
  auto simulator = sim::Simulator::Create(s, &error);
  EXPECT_NE(simulator, nullptr) << error;
  if (!simulator) return run;
  sim::StereoFrame f;
  while (static_cast<int>(run.frames.size()) < count && simulator->Next(&f, &error)) {
    run.frames.push_back(f);
    run.people.push_back(simulator->people_at_last_frame());
    run.gains.push_back(simulator->exposure_gain());
  }
  EXPECT_EQ(error, "");
  return run;
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

double Mean(const cv::Mat& m) { return cv::mean(m)[0]; }

double WallClearance(const std::vector<sim::SceneWall>& walls, const Eigen::Vector2d& p,
                     double below_m) {
  double d = 1e9;
  for (const sim::SceneWall& w : walls) {
    if (w.z_min_m >= below_m || !std::isfinite(w.half_length_m)) continue;
    d = std::min(d, sim::PointSegmentDistance(p, w.centre_xy - w.half_length_m * w.along_xy,
                                              w.centre_xy + w.half_length_m * w.along_xy));
  }
  return d;
}

TEST(PeopleTest, APersonWalksHerPathBackAndForth) {
  sim::PersonPath p;
  p.points = {{0, 0}, {3, 0}, {3, 1}};  // 4 m
  p.length_m = 4.0;
  p.phase_m = 1.0;
  const double speed = 0.5;
  const auto at = [&](double t) { return sim::PersonAt(p, speed, t); };
  EXPECT_NEAR((at(0).xy - Eigen::Vector2d(1, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR(at(0).yaw_rad, 0.0, 1e-12);
  EXPECT_NEAR((at(5).xy - Eigen::Vector2d(3, 0.5)).norm(), 0, 1e-12);  // 3.5 m along
  EXPECT_NEAR(at(5).yaw_rad, M_PI / 2, 1e-12);
  EXPECT_NEAR((at(7).xy - Eigen::Vector2d(3, 0.5)).norm(), 0, 1e-12);  // 4.5 m: back 0.5 m
  EXPECT_NEAR(at(7).yaw_rad, -M_PI / 2, 1e-12);
  EXPECT_NEAR((at(10).xy - Eigen::Vector2d(2, 0)).norm(), 0, 1e-12);  // 6 m: back on leg 1
  EXPECT_NEAR(std::abs(at(10).yaw_rad), M_PI, 1e-12);
  EXPECT_NEAR((at(16).xy - at(0).xy).norm(), 0, 1e-12);  // the round trip of 8 m
  EXPECT_NEAR((at(-2).xy - Eigen::Vector2d(0, 0)).norm(), 0, 1e-12);
}

// A floor plan: each person between two named places, planned; at every frame time the body is
// where PersonAt puts it, clear of the walls; the same seed gives the same paths, another seed
// others.
TEST(PeopleTest, PeopleInAFloorPlanWalkPlannedPathsBetweenPlaces) {
  sim::Scenario s = Small("office_floor");
  s.people.count = 3;
  s.people.seed = 4;
  std::vector<sim::SceneWall> walls;
  std::vector<sim::SceneFloor> floors;
  std::string error;
  ASSERT_TRUE(sim::WallsOfScene(s.scene_path, &walls, &error, &floors)) << error;
  std::vector<sim::PersonPath> paths, again, other;
  ASSERT_TRUE(sim::PlanPeople(s, walls, floors, &paths, &error)) << error;
  ASSERT_TRUE(sim::PlanPeople(s, walls, floors, &again, &error)) << error;
  ASSERT_EQ(paths.size(), 3u);
  sim::FloorPlan plan;
  ASSERT_TRUE(sim::LoadFloorPlan(s.scene_path, &plan, &error)) << error;
  const double clearance = sim::kPersonClearance * s.people.height_m;
  for (size_t i = 0; i < paths.size(); ++i) {
    EXPECT_EQ(paths[i].points, again[i].points);
    EXPECT_EQ(paths[i].phase_m, again[i].phase_m);
    // From one place to another.
    int ends = 0;
    for (const auto& [name, at] : plan.places)
      ends += (at - paths[i].points.front()).norm() < 1e-9 ||
              (at - paths[i].points.back()).norm() < 1e-9;
    EXPECT_EQ(ends, 2) << "person " << i;
  }
  s.people.seed = 5;
  ASSERT_TRUE(sim::PlanPeople(s, walls, floors, &other, &error)) << error;
  bool differ = false;
  for (size_t i = 0; i < paths.size(); ++i) differ |= paths[i].phase_m != other[i].phase_m;
  EXPECT_TRUE(differ);
  s.people.seed = 4;

  const SimRun run = Simulate(s, 12);
  ASSERT_EQ(run.frames.size(), 12u);
  for (size_t k = 0; k < run.frames.size(); ++k) {
    ASSERT_EQ(run.people[k].size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      const sim::PersonPose want =
          sim::PersonAt(paths[i], s.people.speed_mps, run.frames[k].time_s);
      const Eigen::Vector3d& got = run.people[k][i];
      EXPECT_NEAR((got.head<2>() - want.xy).norm(), 0.0, 1e-9) << "frame " << k << " person " << i;
      EXPECT_NEAR(got.z(), 0.0, 1e-12);
      EXPECT_GE(WallClearance(walls, got.head<2>(), 1.5), clearance - 1e-6)
          << "frame " << k << " person " << i;
    }
  }
}

// An MJCF scene: a line beside the robot's path, clear of the walls and of the robot.
TEST(PeopleTest, PeopleInAnMjcfSceneWalkBesideTheRobotsPath) {
  sim::Scenario s = Small("l_hallway");
  s.people.count = 5;
  std::vector<sim::SceneWall> walls;
  std::vector<sim::SceneFloor> floors;
  std::string error;
  ASSERT_TRUE(sim::WallsOfScene(s.scene_path, &walls, &error, &floors)) << error;
  std::vector<sim::PersonPath> paths;
  ASSERT_TRUE(sim::PlanPeople(s, walls, floors, &paths, &error)) << error;
  ASSERT_EQ(paths.size(), 5u);
  const double h = s.people.height_m;
  for (const sim::PersonPath& p : paths) {
    ASSERT_EQ(p.points.size(), 2u);
    EXPECT_GE(p.length_m, sim::kMinPersonLineM - 1e-9);
    EXPECT_LE(p.length_m, sim::kMaxPersonLineM + 1e-9);
    for (double u = 0; u <= 1.0; u += 0.01) {
      const Eigen::Vector2d q = p.points[0] + u * (p.points[1] - p.points[0]);
      EXPECT_GE(WallClearance(walls, q, h), sim::kPersonClearance * h - 1e-9);
      for (size_t j = 1; j < s.path.size(); ++j)
        EXPECT_GE(sim::PointSegmentDistance(q, s.path[j - 1], s.path[j]),
                  sim::kRobotClearanceM + sim::kPersonClearance * h - 1e-9);
    }
  }
  // Too tall to fit beside the robot in a 2 m corridor: refused, naming the key.
  sim::Scenario tall = s;
  tall.people.height_m = 2.3;
  EXPECT_FALSE(sim::PlanPeople(tall, walls, floors, &paths, &error));
  EXPECT_NE(error.find("beside the robot's path"), std::string::npos) << error;
}

// No people and no light changes: the renders of a scenario without the keys, byte for byte;
// people: the same bytes from the same seed, other bytes than without them once in view.
TEST(PeopleTest, NoPeopleGiveTheRendersOfBeforeAndPeopleAreDeterministic) {
  const sim::Scenario plain = Small("l_hallway");
  sim::Scenario zero = plain;
  zero.people.count = 0;
  zero.people.seed = 9;
  zero.lights.flicker_hz = 5.0;  // no depth: no flicker
  const SimRun a = Simulate(plain, 4), b = Simulate(zero, 4);
  ASSERT_EQ(a.frames.size(), 4u);
  ASSERT_EQ(b.frames.size(), 4u);
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_TRUE(SameBytes(a.frames[k].left, b.frames[k].left)) << k;
    EXPECT_TRUE(SameBytes(a.frames[k].right, b.frames[k].right)) << k;
    EXPECT_TRUE(SameBytes(a.frames[k].depth_m, b.frames[k].depth_m)) << k;
  }
  // The effective scenario of count 0 at the default seed reads as before the keys existed.
  sim::Scenario loaded;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &loaded, &error));
  EXPECT_EQ(sim::ScenarioToYaml(loaded).find("\npeople:"), std::string::npos);
  EXPECT_EQ(sim::ScenarioToYaml(loaded).find("\nlights:"), std::string::npos);
  EXPECT_EQ(sim::ScenarioToYaml(loaded).find("auto_exposure:"), std::string::npos);

  sim::Scenario crowd = plain;
  crowd.people.count = 5;
  const SimRun c = Simulate(crowd, 4), d = Simulate(crowd, 4);
  bool changed = false;
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_TRUE(SameBytes(c.frames[k].left, d.frames[k].left)) << k;
    EXPECT_TRUE(SameBytes(c.frames[k].depth_m, d.frames[k].depth_m)) << k;
    changed |= !SameBytes(c.frames[k].depth_m, a.frames[k].depth_m);
  }
  EXPECT_TRUE(changed) << "no person in view in 4 frames";
}

// Light 0 off at 0.25 s (frames 3, 4 at 10 Hz) and on again at 0.45 s: frames 0-2 and 5- are
// the steady scene's bytes, frames 3-4 darker.
TEST(LightsTest, ASwitchedOffLampDarkensTheFramesFromItsSwitch) {
  const sim::Scenario steady = Small("l_hallway");
  sim::Scenario switched = steady;
  sim::LightSwitch off, on;
  off.at_s = 0.25;
  off.light = 0;
  on.at_s = 0.45;
  on.light = 0;
  on.on = true;
  switched.lights.switches = {off, on};
  EXPECT_TRUE(sim::LightOnAt(switched.lights, 0, 0.2));
  EXPECT_FALSE(sim::LightOnAt(switched.lights, 0, 0.25));
  EXPECT_TRUE(sim::LightOnAt(switched.lights, 0, 0.45));
  EXPECT_TRUE(sim::LightOnAt(switched.lights, 1, 0.3));
  const SimRun a = Simulate(steady, 7), b = Simulate(switched, 7);
  ASSERT_EQ(b.frames.size(), 7u);
  for (size_t k = 0; k < 7; ++k) {
    const bool dark = k == 3 || k == 4;
    EXPECT_EQ(SameBytes(a.frames[k].left, b.frames[k].left), !dark) << k;
    if (dark) {
      EXPECT_LT(Mean(b.frames[k].left), Mean(a.frames[k].left) - 2.0) << k;
    }
    // The geometry does not change with the light.
    EXPECT_TRUE(SameBytes(a.frames[k].depth_m, b.frames[k].depth_m)) << k;
  }
}

// A lamp is a spotlight over the floor of a plain corridor (a floor plan with a dim directional
// light 0 and lamp 1 at (3, 0, 2.4) pointing down, a 20 degree cone: a disc of radius
// 2.4 tan 20 = 0.87 m on the floor, well inside the 2.4 m wide corridor). Switched off from the
// start, it darkens exactly its region: every pixel whose surface point lies outside the cone by
// more than one quad of the floor's rendering grid keeps its byte, every pixel well inside
// (within 12 degrees) is darker, and most of the view is outside. MuJoCo's fixed-function
// lighting is computed at the vertices of a plane's grid and interpolated across each quad; the
// quads are 0.2 m for a plan's 0.1 m grid spacing (the changed pixels reach 0.19 m past the
// cone, more than the 0.14 m diagonal of 0.1 m quads), so the margin is a 0.2 m quad's diagonal.
TEST(LightsTest, ALampSwitchedOffDarkensExactlyItsRegion) {
  TempDir dir("lamp_region");
  WriteText(dir / "plan.yaml",
            "ceiling_height_m: 2.5\nfloor: plain\nceiling: plain\n"
            "corridors:\n  - {name: hall, centre: [[-1.5, 0], [9, 0]], width_m: 2.4, walls: "
            "plain}\n"
            "lights:\n  - {type: directional, dir: [0.3, 0.2, -1], diffuse: 0.05}\n"
            "  - {type: point, pos: [3, 0, 2.4], dir: [0, 0, -1], diffuse: 0.2, cutoff_deg: "
            "20}\n");
  WriteText(dir / "s.yaml",
            "floor_plan: plan.yaml\npath:\n  - [0, 0]\n  - [1, 0]\ncamera:\n  width: 160\n"
            "  height: 120\n");
  sim::Scenario lit;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(dir / "s.yaml", &lit, &error)) << error;
  lit.noise = sim::NoiseOptions();
  sim::Scenario dark = lit;
  sim::LightSwitch off;
  off.at_s = 0.0;
  off.light = 1;
  dark.lights.switches = {off};
  const SimRun a = Simulate(lit, 1), b = Simulate(dark, 1);
  ASSERT_EQ(a.frames.size(), 1u);
  ASSERT_EQ(b.frames.size(), 1u);
  const sim::StereoFrame& fa = a.frames[0];
  const sim::StereoFrame& fb = b.frames[0];
  EXPECT_TRUE(SameBytes(fa.depth_m, fb.depth_m));

  double fx = 0, fy = 0, cx = 0, cy = 0;
  sim::IntrinsicsFromFovy(lit.camera.fovy_deg, lit.camera.width, lit.camera.height, &fx, &fy, &cx,
                          &cy);
  const Eigen::Vector3d lamp(3, 0, 2.4), down(0, 0, -1);
  const double cutoff = 20.0 * M_PI / 180.0, cell_m = 0.2 * std::sqrt(2.0);
  int outside = 0, inside = 0, outside_changed = 0, inside_not_darker = 0;
  double inside_darkening = 0.0;
  for (int v = 0; v < fa.left.rows; ++v) {
    for (int u = 0; u < fa.left.cols; ++u) {
      const double z = fa.depth_m.at<float>(v, u);
      const Eigen::Vector3d p =
          fa.T_world_cam0 * Eigen::Vector3d((u - cx) / fx * z, (v - cy) / fy * z, z);
      const Eigen::Vector3d ray = p - lamp;
      const double angle = std::acos(std::clamp(ray.normalized().dot(down), -1.0, 1.0));
      // How far the point lies outside the cone's surface (m).
      const double beyond_m = ray.norm() * std::sin(std::min(angle - cutoff, M_PI / 2));
      const int lit_grey = fa.left.at<uchar>(v, u), dark_grey = fb.left.at<uchar>(v, u);
      if (angle > cutoff && beyond_m > cell_m) {
        ++outside;
        outside_changed += lit_grey != dark_grey;
      } else if (angle < 12.0 * M_PI / 180.0) {
        ++inside;
        inside_not_darker += dark_grey >= lit_grey;
        inside_darkening += lit_grey - dark_grey;
      }
    }
  }
  std::printf(
      "lamp off: %d pixels outside the cone (%d changed), %d inside (%d not darker), "
      "darker by %.1f grey levels on average\n",
      outside, outside_changed, inside, inside_not_darker, inside_darkening / std::max(inside, 1));
  EXPECT_GT(outside, fa.left.rows * fa.left.cols / 2);
  EXPECT_GT(inside, 200);
  EXPECT_EQ(outside_changed, 0) << "of " << outside << " pixels outside the lamp's cone";
  EXPECT_EQ(inside_not_darker, 0) << "of " << inside << " pixels inside the lamp's cone";
  EXPECT_GT(inside_darkening / std::max(inside, 1), 10.0);  // grey levels, on average
}

// 2.5 Hz flicker of depth 0.5 at 10 Hz: brightness 1, 0.75, 0.5, 0.75, 1, ... (period 4 frames).
// The frame means over the steady scene's follow it; where surfaces saturate a dimmed pixel
// keeps more than the factor, so a ratio is at least the factor.
TEST(LightsTest, FlickerShowsItsPeriodInTheFrameMeans) {
  const sim::Scenario steady = Small("l_hallway");
  sim::Scenario flicker = steady;
  flicker.lights.flicker_hz = 2.5;
  flicker.lights.flicker_depth = 0.5;
  const SimRun a = Simulate(steady, 9), b = Simulate(flicker, 9);
  ASSERT_EQ(b.frames.size(), 9u);
  std::vector<double> ratio;
  for (size_t k = 0; k < 9; ++k) {
    ratio.push_back(Mean(b.frames[k].left) / Mean(a.frames[k].left));
    const double factor = sim::GlobalBrightness(flicker.lights, b.frames[k].time_s);
    EXPECT_NEAR(factor, 1.0 - 0.25 * (1.0 - std::cos(M_PI * k / 2.0)), 1e-12);
    EXPECT_GE(ratio[k], factor - 0.01) << k;
    EXPECT_LE(ratio[k], factor + 0.2) << k;
  }
  for (size_t k : {0, 4, 8}) EXPECT_NEAR(ratio[k], 1.0, 1e-3) << k;
  for (size_t k : {2, 6}) EXPECT_LT(ratio[k], ratio[k - 1] - 0.05) << k;
  for (size_t k : {1, 5}) EXPECT_NEAR(ratio[k], ratio[k + 2], 0.02) << k;
}

TEST(LightsTest, BrightnessDriftIsLinearPerMinuteAndStopsAtDark) {
  sim::LightsOptions o;
  o.brightness_drift = -0.3;
  EXPECT_DOUBLE_EQ(sim::GlobalBrightness(o, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(sim::GlobalBrightness(o, 60.0), 0.7);
  EXPECT_DOUBLE_EQ(sim::GlobalBrightness(o, 30.0), 0.85);
  EXPECT_DOUBLE_EQ(sim::GlobalBrightness(o, 1000.0), 0.0);
}

// The first-order loop: a step in the scene's mean from 50 to 25 at gain 1 (target 100): the gain
// goes from 2 to 4 as 4 - 2 exp(-t / tau) at the frame times, exactly.
TEST(AutoExposureTest, FollowsAStepWithItsTimeConstant) {
  sim::AutoExposureOptions o;
  o.enabled = true;
  o.target_mean = 100.0;
  o.time_constant_s = 0.5;
  sim::AutoExposure ae(o, 0.1);
  EXPECT_DOUBLE_EQ(ae.UpdateOnMean(50.0), 2.0);  // starts converged
  EXPECT_DOUBLE_EQ(ae.UpdateOnMean(50.0), 2.0);
  for (int k = 1; k <= 30; ++k) {
    const double g = ae.UpdateOnMean(25.0);
    EXPECT_NEAR(g, 4.0 - 2.0 * std::exp(-0.1 * k / 0.5), 1e-12) << k;
  }
  // At one time constant the gain has gone 1 - 1/e of the way.
  sim::AutoExposure ae2(o, 0.5);
  ae2.UpdateOnMean(50.0);
  EXPECT_NEAR((ae2.UpdateOnMean(25.0) - 2.0) / 2.0, 1.0 - std::exp(-1.0), 1e-12);
  // The gain's range.
  sim::AutoExposure ae3(o, 0.1);
  EXPECT_DOUBLE_EQ(ae3.UpdateOnMean(0.0), sim::kMaxExposureGain);
}

// In the simulator: both lamps off at 0.45 s; with auto-exposure (target 100, 0.3 s) the gains
// are the loop's on the frames' means at gain 1 (the same scenario without it), the frame mean
// starts at the target and comes back to it.
TEST(AutoExposureTest, TheCameraBringsTheMeanBackToTheTarget) {
  sim::Scenario raw = Small("l_hallway");
  for (int light = 0; light < 2; ++light) {
    sim::LightSwitch off;
    off.at_s = 0.45;
    off.light = light;
    raw.lights.switches.push_back(off);
  }
  sim::Scenario ae = raw;
  ae.camera.auto_exposure.enabled = true;
  ae.camera.auto_exposure.target_mean = 100.0;
  ae.camera.auto_exposure.time_constant_s = 0.3;
  const SimRun a = Simulate(raw, 22), b = Simulate(ae, 22);
  ASSERT_EQ(b.frames.size(), 22u);
  sim::AutoExposure replay(ae.camera.auto_exposure, 0.1);
  for (size_t k = 0; k < b.frames.size(); ++k) {
    EXPECT_EQ(a.gains[k], 1.0);
    const double g = replay.UpdateOnMean(Mean(a.frames[k].left));
    EXPECT_NEAR(b.gains[k], g, 0.01 * g) << k;  // the raw means are rounded to 8 bits here
    EXPECT_NEAR(Mean(b.frames[k].left), b.gains[k] * Mean(a.frames[k].left), 1.0) << k;
  }
  EXPECT_NEAR(Mean(b.frames[0].left), 100.0, 1.0);
  EXPECT_LT(Mean(b.frames[5].left), 100.0 - 5.0);  // the step: darker at first
  EXPECT_GT(b.gains[6], b.gains[5]);
  EXPECT_NEAR(Mean(b.frames[21].left), 100.0, 3.0);  // 5.3 time constants later
}

// A suite's overrides are checked against every key a scenario may have, the optional sections
// included (harness/suite/spec.cc): those of this issue are there.
TEST(PeopleLightsKeysTest, EveryOverridableKeyIsListed) {
  const std::string keys = sim::ScenarioKeysYaml(sim::Scenario());
  for (const char* key : {"\npeople:", "  count:", "  speed_mps:", "  height_m:", "\nlights:",
                          "  switch:", "  brightness_drift:", "  flicker_hz:", "  flicker_depth:",
                          "  auto_exposure:", "    target_mean:", "    time_constant_s:",
                          "\ncalibration_error:", "\nframes:", "  distortion:"})
    EXPECT_NE(keys.find(key), std::string::npos) << key << " in\n" << keys;
}

class PeopleLightsFileTest : public ::testing::Test {
 protected:
  PeopleLightsFileTest() : dir_("people_lights") {}
  std::string Load(const std::string& extra, sim::Scenario* s = nullptr) {
    const std::string path = dir_ / "s.yaml";
    WriteText(path, "scene: " + std::string(VOBENCH_SOURCE_DIR) +
                        "/scenes/hallway_l.xml\npath:\n  - [0, 0]\n  - [8, 0]\n  - [8, 8]\n" +
                        extra);
    sim::Scenario local;
    std::string error;
    return sim::LoadScenario(path, s ? s : &local, &error) ? "" : error;
  }
  TempDir dir_;
};

TEST_F(PeopleLightsFileTest, KeysAreReadCheckedAndRoundTrip) {
  sim::Scenario s, again;
  ASSERT_EQ(Load("people:\n  count: 2\n  seed: 3\n  speed_mps: 1.0\n  height_m: 1.6\n"
                 "lights:\n  switch:\n    - {at_s: 2, light: 1, on: false}\n"
                 "    - {at_s: 4.5, light: 1, on: true}\n  brightness_drift: -0.2\n"
                 "  flicker_hz: 0.5\n  flicker_depth: 0.3\n"
                 "camera:\n  auto_exposure: {enabled: true, target_mean: 90, time_constant_s: 1}\n",
                 &s),
            "");
  EXPECT_EQ(s.people.count, 2);
  EXPECT_EQ(s.people.seed, 3u);
  EXPECT_EQ(s.people.height_m, 1.6);
  ASSERT_EQ(s.lights.switches.size(), 2u);
  EXPECT_EQ(s.lights.switches[1].light, 1);
  EXPECT_TRUE(s.lights.switches[1].on);
  EXPECT_EQ(s.lights.brightness_drift, -0.2);
  EXPECT_TRUE(s.camera.auto_exposure.enabled);
  EXPECT_EQ(s.camera.auto_exposure.time_constant_s, 1.0);
  WriteText(dir_ / "effective.yaml", sim::ScenarioToYaml(s));
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(dir_ / "effective.yaml", &again, &error)) << error;
  EXPECT_EQ(sim::ScenarioToYaml(again), sim::ScenarioToYaml(s));

  const std::pair<std::string, std::string> bad[] = {
      {"people:\n  count: 21\n",
       "s.yaml:7: key 'people.count': expected an integer in [0, 20], got 21"},
      {"people:\n  count: -1\n", "s.yaml:7: key 'people.count'"},
      {"people:\n  count: 2.5\n", "s.yaml:7: key 'people.count'"},
      {"people:\n  speed_mps: 0\n", "s.yaml:7: key 'people.speed_mps': expected in (0, 3] m/s"},
      {"people:\n  height_m: 3\n", "s.yaml:7: key 'people.height_m': expected in [1, 2.3] m"},
      {"people:\n  seed: -2\n", "s.yaml:7: key 'people.seed'"},
      {"people:\n  count: 1\n  height_m: 2.3\n",
       "s.yaml:7: key 'people.count': no line of 1.5 m beside the robot's path"},
      {"people:\n  name: bob\n", "s.yaml:7: key 'people.name': unknown key"},
      {"lights:\n  flicker_hz: -1\n", "s.yaml:7: key 'lights.flicker_hz': expected in [0, 1000]"},
      {"lights:\n  flicker_depth: 1.5\n",
       "s.yaml:7: key 'lights.flicker_depth': expected in [0, 1]"},
      {"lights:\n  brightness_drift: 2\n",
       "s.yaml:7: key 'lights.brightness_drift': expected a fraction per minute in [-1, 1]"},
      {"lights:\n  switch: 3\n", "s.yaml:7: key 'lights.switch': expected a list"},
      {"lights:\n  switch:\n    - {at_s: 1, light: 2, on: false}\n",
       "s.yaml:8: key 'lights.switch[0].light': no light '2' in"},
      {"lights:\n  switch:\n    - {at_s: 1, light: lamp, on: false}\n",
       "key 'lights.switch[0].light': no light 'lamp'"},
      {"lights:\n  switch:\n    - {at_s: -1, light: 0, on: false}\n",
       "s.yaml:8: key 'lights.switch[0].at_s': expected a time >= 0 s"},
      {"lights:\n  switch:\n    - {at_s: 2, light: 0, on: false}\n    - {at_s: 1, light: 0, on: "
       "true}\n",
       "s.yaml:9: key 'lights.switch[1].at_s': expected the switches in time order"},
      {"lights:\n  switch:\n    - {at_s: 2, light: 0}\n", "key 'lights.switch[0].on': required"},
      {"lights:\n  switch:\n    - {at_s: 2, light: 0, on: maybe}\n",
       "s.yaml:8: key 'lights.switch[0].on': expected true or false"},
      {"camera:\n  auto_exposure:\n    target_mean: 255\n",
       "s.yaml:8: key 'camera.auto_exposure.target_mean': expected a grey level in (0, 255)"},
      {"camera:\n  auto_exposure:\n    time_constant_s: 0\n",
       "s.yaml:8: key 'camera.auto_exposure.time_constant_s': expected in (0, 60] s"},
      {"camera:\n  auto_exposure:\n    enabled: 2\n",
       "s.yaml:8: key 'camera.auto_exposure.enabled': expected true or false"}};
  for (const auto& [yaml, expected] : bad) {
    const std::string e = Load(yaml);
    EXPECT_NE(e.find(expected), std::string::npos) << yaml << " -> " << e;
  }
}

}  // namespace
