// Closed-loop navigation (sim/navigation.h): the follower steering on an estimate instead of the
// true pose, and what the robot physically did.
#include "sim/navigation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>

#include "sim/floor_plan.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"

namespace {

using vobench_test::MakeScenario;
using vobench_test::TempDir;
using vobench_test::WriteScene;
using vobench_test::WriteText;

// A building of collision-only boxes (group 3: never drawn), as the hallway's solid walls.
std::string Box(const std::string& name, double x, double y, double hx, double hy) {
  return "    <geom name='" + name + "' type='box' size='" + std::to_string(hx) + " " +
         std::to_string(hy) + " 0.5' pos='" + std::to_string(x) + " " + std::to_string(y) +
         " 0.5' group='3' rgba='0 0 0 0'/>\n";
}

// A small rig: the tests are about the robot, not the images.
sim::Scenario SmallScenario(const std::string& scene, double x_end) {
  sim::Scenario s = MakeScenario(scene, x_end);
  s.camera.width = 32;
  s.camera.height = 24;
  return s;
}

// Runs the simulator to its end; false (with the message) on an error.
bool RunToEnd(sim::Simulator& simulator, std::vector<sim::StereoFrame>* frames,
              std::string* error) {
  sim::StereoFrame frame;
  while (simulator.Next(&frame, error)) frames->push_back(frame);
  return error->empty();
}

TEST(NavigationTest, DeadReckoningFollowsAnArcAndAPlanarPoseRoundTrips) {
  // v = 1 m/s, w = 0.5 rad/s for 1 s in 1 ms steps: an arc of radius 2 m through 0.5 rad.
  sim::PlanarPose p;
  for (int i = 0; i < 1000; ++i) p = sim::DeadReckon(p, {1.0, 0.5}, 0.001);
  EXPECT_NEAR(p.yaw_rad, 0.5, 1e-12);
  EXPECT_NEAR(p.position.x(), 2.0 * std::sin(0.5), 1e-7);
  EXPECT_NEAR(p.position.y(), 2.0 * (1.0 - std::cos(0.5)), 1e-7);
  sim::PlanarPose q;
  q.position = Eigen::Vector2d(1.5, -2.0);
  q.yaw_rad = 2.5;
  const sim::PlanarPose back = sim::PlanarPoseOf(sim::BodyPoseOf(q, 0.095));
  EXPECT_NEAR((back.position - q.position).norm(), 0.0, 1e-15);
  EXPECT_NEAR(back.yaw_rad, q.yaw_rad, 1e-15);
}

// A VO's estimates in a world of its own (any rigid transform G of the simulator's) map back to
// the body poses: the first anchored at the belief, the rest through the rig.
TEST(NavigationTest, FixesMapAVoWorldBackToTheBodyThroughTheStartAndTheRig) {
  Eigen::Isometry3d T_body_cam0 = Eigen::Isometry3d::Identity();
  T_body_cam0.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // camera looks along x_body
  T_body_cam0.linear() =
      T_body_cam0.linear() * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T_body_cam0.translation() = Eigen::Vector3d(0.15, 0.045, 0.905);
  Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
  G.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  G.translation() = Eigen::Vector3d(-3, 4, 0.5);
  const double z = 0.095;
  std::vector<sim::PlanarPose> truth(3);
  truth[0].position = Eigen::Vector2d(1, 2);
  truth[0].yaw_rad = 0.3;
  truth[1].position = Eigen::Vector2d(2.5, 2.2);
  truth[1].yaw_rad = 0.45;
  truth[2].position = Eigen::Vector2d(2.6, 4.0);
  truth[2].yaw_rad = 1.9;
  sim::NavigationFixes fixes(T_body_cam0, z);
  sim::PlanarPose wrong;  // the belief matters for the anchor only
  wrong.position = Eigen::Vector2d(50, 50);
  for (size_t k = 0; k < truth.size(); ++k) {
    const Eigen::Isometry3d T_vo_cam0 = G * sim::BodyPoseOf(truth[k], z) * T_body_cam0;
    const sim::PlanarPose p = fixes.Fix(T_vo_cam0, k == 0 ? truth[0] : wrong);
    EXPECT_NEAR((p.position - truth[k].position).norm(), 0.0, 1e-12) << k;
    EXPECT_NEAR(p.yaw_rad, truth[k].yaw_rad, 1e-12) << k;
  }
}

// The perfect estimator: the true pose as the estimate at every control step, through the
// closed loop's belief, gives the open-loop run bit for bit (an L with an in-place turn, between
// solid walls).
TEST(NavigationTest, APerfectEstimatorDrivesTheOpenLoopRunExactly) {
  TempDir dir("navigation");
  const std::string scene =
      WriteScene(dir, Box("south", 1.0, -1.05, 2.5, 0.05) + Box("north", 1.0, 2.55, 2.5, 0.05));
  sim::Scenario open = SmallScenario(scene, 2.0);
  open.path.push_back(Eigen::Vector2d(2.0, 1.5));
  sim::Scenario closed = open;
  closed.navigation = "vo";
  std::string error;
  auto a = sim::Simulator::Create(open, &error);
  ASSERT_TRUE(a) << error;
  auto b = sim::Simulator::Create(closed, &error);
  ASSERT_TRUE(b) << error;
  int estimates = 0;
  b->SetStepEstimator([&estimates](const sim::PlanarPose& truth) {
    ++estimates;
    return truth;
  });
  std::vector<sim::StereoFrame> fa, fb;
  ASSERT_TRUE(RunToEnd(*a, &fa, &error)) << error;
  ASSERT_TRUE(RunToEnd(*b, &fb, &error)) << error;
  EXPECT_GT(estimates, 1000);
  ASSERT_GT(fa.size(), 40u);
  ASSERT_EQ(fa.size(), fb.size());
  for (size_t k = 0; k < fa.size(); ++k)
    ASSERT_TRUE(fa[k].T_world_body.matrix() == fb[k].T_world_body.matrix()) << "frame " << k;
  ASSERT_EQ(a->body_track(), b->body_track());
  const sim::NavigationReport& na = a->navigation();
  const sim::NavigationReport& nb = b->navigation();
  EXPECT_EQ(na.mode, "ground_truth");
  EXPECT_EQ(nb.mode, "vo");
  EXPECT_TRUE(na.reached_goal);
  EXPECT_TRUE(nb.reached_goal);
  EXPECT_EQ(na.end_error_m, nb.end_error_m);
  EXPECT_EQ(na.max_waypoint_error_m, nb.max_waypoint_error_m);
  // The follower's own precision: within its tolerance (2 cm) and a little stopping.
  EXPECT_LT(na.end_error_m, 0.03);
  EXPECT_LT(na.max_waypoint_error_m, 0.03);
  EXPECT_EQ(na.wall_contacts, 0);
  EXPECT_EQ(nb.wall_contacts, 0);
  ASSERT_EQ(nb.frames.size(), fb.size());
  EXPECT_EQ(nb.frames.back().truth.position, fb.back().T_world_body.translation().head<2>());
}

// The frame-rate loop the VO takes: a fix per frame (here the true pose), dead reckoning between.
// Close to the open loop, not equal (the commanded velocity is not the robot's).
TEST(NavigationTest, FixesAtTheFrameRateWithDeadReckoningBetweenReachTheGoal) {
  TempDir dir("navigation");
  const std::string scene = WriteScene(dir, "");
  sim::Scenario s = SmallScenario(scene, 2.0);
  s.path.push_back(Eigen::Vector2d(2.0, 1.5));
  s.navigation = "vo";
  std::string error;
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  sim::StereoFrame frame;
  int frames = 0;
  double belief_error_m = 0.0;  // the dead-reckoned belief at a frame vs the truth
  while (simulator->Next(&frame, &error)) {
    const sim::PlanarPose truth = sim::PlanarPoseOf(frame.T_world_body);
    belief_error_m =
        std::max(belief_error_m, (simulator->BeliefAtLastFrame().position - truth.position).norm());
    if (frames++ % 2 == 0) simulator->FixAtLastFrame(truth);  // every other frame "lost"
  }
  ASSERT_TRUE(error.empty()) << error;
  const sim::NavigationReport& n = simulator->navigation();
  EXPECT_TRUE(n.reached_goal);
  EXPECT_LT(n.end_error_m, 0.05);
  EXPECT_LT(n.max_waypoint_error_m, 0.05);
  EXPECT_LT(belief_error_m, 0.05);
  EXPECT_EQ(n.wall_contacts, -1);  // no building geoms in this scene
  ASSERT_EQ(static_cast<int>(n.frames.size()), frames);
  EXPECT_TRUE(n.frames[0].fixed);
  EXPECT_FALSE(n.frames[1].fixed);
}

// A constant heading bias δ: pure pursuit on a true position and a heading δ off settles where
// the look-ahead point is seen δ off its true bearing, the lateral offset L·tan(δ) to the right
// of the path; the stop is on the true distance along it. So the robot misses the goal by that.
TEST(NavigationTest, AHeadingBiasMissesTheGoalByTheLookaheadTimesItsTangent) {
  TempDir dir("navigation");
  const std::string scene = WriteScene(dir, "");
  sim::Scenario s = SmallScenario(scene, 6.0);
  s.navigation = "vo";
  const double bias = 10.0 * M_PI / 180.0;
  std::string error;
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  simulator->SetStepEstimator([bias](const sim::PlanarPose& truth) {
    sim::PlanarPose p = truth;
    p.yaw_rad += bias;
    return p;
  });
  std::vector<sim::StereoFrame> frames;
  ASSERT_TRUE(RunToEnd(*simulator, &frames, &error)) << error;
  const sim::NavigationReport& n = simulator->navigation();
  const double expected_offset = s.robot.lookahead_m * std::tan(bias);  // 0.088 m
  const Eigen::Vector2d end = frames.back().T_world_body.translation().head<2>();
  RecordProperty("lateral_offset_m", std::to_string(end.y()));
  EXPECT_NEAR(end.y(), -expected_offset, 0.005);
  EXPECT_TRUE(n.reached_goal);
  EXPECT_NEAR(n.end_error_m, (end - s.path.back()).norm(), 0.005);
  EXPECT_GT(n.end_error_m, expected_offset - 0.005);
}

// A wall across the path: the robot steering on a perfect estimate pushes against it and never
// gets there. The closed loop ends at max_duration_s with the goal not reached and the contact
// counted; the open loop refuses it as it always did (an error).
TEST(NavigationTest, AWallAcrossThePathIsTouchedAndTheRunEndsAtTheTimeLimit) {
  TempDir dir("navigation");
  const std::string scene = WriteScene(dir, Box("across", 2.1, 0.0, 0.05, 1.0));
  sim::Scenario s = SmallScenario(scene, 4.0);
  s.max_duration_s = 12.0;
  s.navigation = "vo";
  std::string error;
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  simulator->SetStepEstimator([](const sim::PlanarPose& truth) { return truth; });
  std::vector<sim::StereoFrame> frames;
  ASSERT_TRUE(RunToEnd(*simulator, &frames, &error)) << error;
  const sim::NavigationReport& n = simulator->navigation();
  EXPECT_FALSE(n.reached_goal);
  EXPECT_GE(n.wall_contacts, 1);
  EXPECT_GT(n.wall_contact_s, 1.0);
  // Stopped at the wall: its face at x = 2.05, the chassis' front 0.18 m ahead of the axle.
  EXPECT_NEAR(n.end_error_m, 4.0 - (2.05 - 0.18), 0.05);
  EXPECT_TRUE(std::isnan(n.max_waypoint_error_m));  // no waypoint reached

  s.navigation = "ground_truth";
  auto open = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(open) << error;
  frames.clear();
  EXPECT_FALSE(RunToEnd(*open, &frames, &error));
  EXPECT_NE(error.find("did not finish its path within max_duration_s"), std::string::npos)
      << error;
  EXPECT_GE(open->navigation().wall_contacts, 1);
}

// A floor plan's building is solid (sim/floor_plan.h PlanSolids): collision-only boxes behind the
// drawn walls and in the furniture, in geom group 3. The renders are those of the same plan
// without them, byte for byte; open loop nothing is touched (wall_contacts 0, not -1: there is
// something to touch); an estimate 0.9 m off sideways steers the robot into the corridor's
// south wall (at y = -1; the chassis is 0.19 m wide each side of the axle), and the contact is
// counted.
TEST(NavigationTest, AFloorPlansWallsAreSolidAndItsRendersUnchanged) {
  TempDir dir("navigation");
  WriteText(dir / "plan.yaml",
            "corridors:\n  - {name: c, centre: [[0, 0], [6, 0]], width_m: 2}\nrooms:\n"
            "  - {name: r, rect: [2, 1.1, 5, 4]}\ndoors:\n"
            "  - {between: [c, r], at: [3.5, 1.05], width_m: 1.2, height_m: 2.1}\n"
            "boxes:\n  - {name: desk, at: [3.5, 3], size_m: [1, 0.5], height_m: 0.7}\n");
  sim::FloorPlan plan;
  std::string error;
  ASSERT_TRUE(sim::LoadFloorPlan(dir / "plan.yaml", &plan, &error)) << error;
  // The solids: one per wall piece and jamb, and one per box; the corridor's and the room's walls
  // are 0.1 m apart, so each solid behind them is 0.05 m thick (half the gap), the others too.
  const std::vector<sim::PlanSolid> solids = sim::PlanSolids(plan);
  size_t vertical = 0;
  for (const sim::PlanSurface& surface : sim::PlanSurfaces(plan))
    vertical +=
        std::abs(surface.y_axis.z()) > 0.5 && surface.name.find("_box_") == std::string::npos;
  EXPECT_EQ(solids.size(), vertical + 1);
  for (const sim::PlanSolid& solid : solids)
    if (solid.name.rfind("solid_box_", 0) != 0) {
      EXPECT_NEAR(solid.half_size.z(), 0.025, 1e-12) << solid.name;
    }
  std::filesystem::copy_file(plan.robot_path, dir / "robot.xml");  // included beside the scene
  WriteText(dir / "drawn_only.xml", sim::FloorPlanToMjcf(plan, "robot.xml", false));

  sim::Scenario with = SmallScenario(dir / "plan.yaml", 3.5);
  with.path[0] = Eigen::Vector2d(0.6, 0.0);        // the corridor's end wall is at x = 0
  with.path.push_back(Eigen::Vector2d(3.5, 2.4));  // through the door into the room
  sim::Scenario without = with;
  without.scene_path = dir / "drawn_only.xml";
  auto a = sim::Simulator::Create(with, &error);
  ASSERT_TRUE(a) << error;
  auto b = sim::Simulator::Create(without, &error);
  ASSERT_TRUE(b) << error;
  std::vector<sim::StereoFrame> fa, fb;
  ASSERT_TRUE(RunToEnd(*a, &fa, &error)) << error;
  ASSERT_TRUE(RunToEnd(*b, &fb, &error)) << error;
  ASSERT_GT(fa.size(), 50u);
  ASSERT_EQ(fa.size(), fb.size());
  for (size_t k = 0; k < fa.size(); ++k) {
    ASSERT_EQ(cv::norm(fa[k].left, fb[k].left, cv::NORM_INF), 0.0) << "frame " << k;
    ASSERT_EQ(cv::norm(fa[k].right, fb[k].right, cv::NORM_INF), 0.0) << "frame " << k;
    ASSERT_TRUE(fa[k].T_world_body.matrix() == fb[k].T_world_body.matrix()) << "frame " << k;
  }
  EXPECT_EQ(a->navigation().wall_contacts, 0);
  EXPECT_EQ(b->navigation().wall_contacts, -1);  // drawn planes only: nothing to touch
  EXPECT_TRUE(a->navigation().reached_goal);

  sim::Scenario off = SmallScenario(dir / "plan.yaml", 5.0);
  off.path[0] = Eigen::Vector2d(0.6, 0.0);
  off.navigation = "vo";
  off.max_duration_s = 20.0;
  auto c = sim::Simulator::Create(off, &error);
  ASSERT_TRUE(c) << error;
  c->SetStepEstimator([](const sim::PlanarPose& truth) {
    sim::PlanarPose p = truth;
    p.position.y() += 0.9;
    return p;
  });
  std::vector<sim::StereoFrame> fc;
  ASSERT_TRUE(RunToEnd(*c, &fc, &error)) << error;
  EXPECT_GE(c->navigation().wall_contacts, 1);
  EXPECT_GT(c->navigation().wall_contact_s, 0.0);
  // Held off the wall by it: the axle the chassis' half width from y = -1, less the soft
  // contact's give while the robot pushes against it (measured 1.0 cm; 2 cm allowed).
  EXPECT_GT(fc.back().T_world_body.translation().y(), -1.0 + 0.19 - 0.02);
}

}  // namespace
