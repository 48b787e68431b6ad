// The path follower's goals on an ideal unicycle (no physics): the final heading and the stops
// at in-place corners; without them it drives as before. Each waypoint's own goals (turn, arc
// radius, stop, leg speed): the same as the robot's when they say the robot's values, a circular
// arc's geometry exact, and on the simulated robot (ground truth, MuJoCo physics) a stop that
// holds it still, the legs' speeds reached and an arc driven on its circle.
#include "sim/path_follower.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim/simulator.h"
#include "sim_test_util.h"

namespace {

struct Trace {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;
  double time_s = 0.0;
  double standing_s = 0.0;  // time with v = w = 0 commanded before the end
};

// Drives `path` with the follower at 500 Hz until done (at most 200 s); `track` gets the
// position after every step.
Trace Drive(const std::vector<Eigen::Vector2d>& path, const sim::RobotOptions& options,
            const std::vector<sim::WaypointOptions>& waypoints = {},
            std::vector<Eigen::Vector2d>* track = nullptr) {
  sim::PathFollower follower(path, options, waypoints);
  Trace t;
  const double dt = 0.002;
  while (!follower.done() && t.time_s < 200.0) {
    const sim::DriveCommand c = follower.Update(t.position, t.yaw_rad, dt);
    if (c.v_mps == 0.0 && c.w_radps == 0.0 && !follower.done()) t.standing_s += dt;
    t.position += c.v_mps * dt * Eigen::Vector2d(std::cos(t.yaw_rad), std::sin(t.yaw_rad));
    t.yaw_rad += c.w_radps * dt;
    t.time_s += dt;
    if (track) track->push_back(t.position);
  }
  return t;
}

TEST(PathFollowerTest, TurnsToTheFinalHeadingAtTheGoal) {
  sim::RobotOptions o;
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {2, 0}};
  const Trace plain = Drive(path, o);
  EXPECT_NEAR(plain.yaw_rad, 0.0, 0.005);
  o.final_heading_deg = 135.0;
  const Trace goal = Drive(path, o);
  EXPECT_LT(goal.time_s, 200.0);
  EXPECT_NEAR(std::atan2(std::sin(goal.yaw_rad), std::cos(goal.yaw_rad)), 0.75 * M_PI, 0.005);
  EXPECT_NEAR((goal.position - Eigen::Vector2d(2, 0)).norm(), 0.0, 0.03);
  // 135 deg at up to 30 deg/s: at least 4.5 s more than without the goal's heading.
  EXPECT_GT(goal.time_s, plain.time_s + 4.5);
}

TEST(PathFollowerTest, StopsAtEachInPlaceCornerForStopS) {
  sim::RobotOptions o;
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const Trace plain = Drive(path, o);
  o.stop_s = 1.5;
  const Trace stops = Drive(path, o);
  EXPECT_NEAR((stops.position - Eigen::Vector2d(0, 1)).norm(), 0.0, 0.03);
  // Two corners, 1.5 s each: 3 s longer; standing still (v = w = 0 commanded) all of it but
  // the braking from the approach speed at the corner (up to 0.14 m/s at 0.5 m/s^2: 0.28 s).
  EXPECT_NEAR(stops.time_s - plain.time_s, 3.0, 0.05);
  EXPECT_GT(stops.standing_s - plain.standing_s, 3.0 - 2 * 0.29);
  EXPECT_LE(stops.standing_s - plain.standing_s, 3.0 + 1e-9);
}

// Waypoint goals that say the robot's own values drive exactly as without them, in both corner
// modes (the bit-identical default: an existing scenario's runs do not change).
TEST(PathFollowerTest, WaypointGoalsWithTheRobotsValuesDriveBitForBitAsWithout) {
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {2, 0}, {2, 2}, {0, 2.5}};
  for (const char* mode : {"in_place", "arc"}) {
    sim::RobotOptions o;
    o.corner_mode = mode;
    o.stop_s = std::string(mode) == "in_place" ? 0.7 : 0.0;
    std::vector<sim::WaypointOptions> same(path.size());
    for (size_t i = 0; i < path.size(); ++i) {
      if (i + 1 < path.size()) same[i].speed_mps = o.speed_mps;
      if (i > 0 && i + 1 < path.size()) {
        same[i].turn = mode;
        if (o.stop_s > 0) same[i].stop_s = o.stop_s;
      }
    }
    std::vector<Eigen::Vector2d> a, b;
    const Trace ta = Drive(path, o, {}, &a);
    const Trace tb = Drive(path, o, same, &b);
    ASSERT_EQ(a.size(), b.size()) << mode;
    for (size_t k = 0; k < a.size(); ++k) ASSERT_EQ(a[k], b[k]) << mode << " step " << k;
    EXPECT_EQ(ta.yaw_rad, tb.yaw_rad);
  }
}

// The circular arc at a corner: tangent points R tan(turn / 2) from the corner, the centre R from
// both on the inner side, the arc's end where it should be (closed form: exact to rounding).
TEST(PathFollowerTest, ACornersCircularArcIsTangentToBothLegs) {
  const sim::CornerArc left = sim::ArcAtCorner({0, 0}, {4, 0}, {4, 4}, 1.5);
  EXPECT_NEAR(left.sweep_rad, M_PI / 2, 1e-12);
  EXPECT_NEAR(left.tangent_m, 1.5, 1e-12);
  EXPECT_NEAR((left.start - Eigen::Vector2d(2.5, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((left.end - Eigen::Vector2d(4, 1.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((left.centre - Eigen::Vector2d(2.5, 1.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((left.PointAt(left.length_m()) - left.end).norm(), 0.0, 1e-12);
  EXPECT_NEAR(left.length_m(), 1.5 * M_PI / 2, 1e-12);
  // A right turn of 135 deg: tangent R tan(67.5 deg), the centre to the right.
  const Eigen::Vector2d next(4 - 3 * std::cos(M_PI / 4), -3 * std::sin(M_PI / 4));
  const sim::CornerArc right = sim::ArcAtCorner({0, 0}, {4, 0}, next, 0.5);
  EXPECT_NEAR(right.sweep_rad, -0.75 * M_PI, 1e-12);
  EXPECT_NEAR(right.tangent_m, 0.5 * std::tan(0.375 * M_PI), 1e-12);
  EXPECT_NEAR((right.centre - Eigen::Vector2d(4 - right.tangent_m, -0.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((right.end - right.centre).norm(), 0.5, 1e-12);
  EXPECT_NEAR((right.PointAt(right.length_m()) - right.end).norm(), 0.0, 1e-12);
  for (int k = 0; k <= 10; ++k)
    EXPECT_NEAR((right.PointAt(right.length_m() * k / 10) - right.centre).norm(), 0.5, 1e-12);
}

// On an ideal unicycle the robot drives the arc on its circle: every step with its angle about
// the centre inside the arc's sweep is within 2 cm of the radius (pure pursuit is exact on the
// circle; the 2 cm are the entry, where the look-ahead point reaches onto the arc 0.5 m early).
TEST(PathFollowerTest, AnArcWithARadiusIsDrivenOnItsCircle) {
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {4, 0}, {4, 4}};
  std::vector<sim::WaypointOptions> w(3);
  w[1].turn = "arc";
  w[1].radius_m = 1.5;
  sim::RobotOptions o;
  std::vector<Eigen::Vector2d> track;
  const Trace t = Drive(path, o, w, &track);
  EXPECT_LT(t.time_s, 200.0);
  EXPECT_NEAR((t.position - path.back()).norm(), 0.0, 0.03);
  const sim::CornerArc c = sim::ArcAtCorner(path[0], path[1], path[2], 1.5);
  double worst = 0.0;
  int on_arc = 0;
  for (const Eigen::Vector2d& p : track) {
    const Eigen::Vector2d r = p - c.centre;
    if (!(r.x() > 0 && r.y() < 0)) continue;  // the quarter circle's sweep about (2.5, 1.5)
    worst = std::max(worst, std::abs(r.norm() - 1.5));
    ++on_arc;
  }
  EXPECT_GT(on_arc, 1000);  // 2.36 m at 0.4 m/s: about 5.9 s, 2950 steps
  EXPECT_LT(worst, 0.02);
  // Without stopping: no step stands still but the first (the start's zero turn).
  EXPECT_LE(t.standing_s, 0.002 + 1e-12);
}

// The simulated robot (MuJoCo physics, ground truth): a stop of 2 s at a straight waypoint holds
// it still, each leg's speed is reached, and an arc of 1.5 m is driven on its circle.
TEST(PathFollowerTest, TheSimulatedRobotStopsReachesItsLegSpeedsAndDrivesTheArc) {
  vobench_test::TempDir dir("path_follower");
  sim::Scenario s = vobench_test::MakeScenario(vobench_test::WriteScene(dir, ""), 3.0);
  s.camera.width = 32;
  s.camera.height = 24;
  s.path = {{0, 0}, {3, 0}, {7, 0}, {7, 4}};
  s.waypoints.resize(4);
  s.waypoints[1].stop_s = 2.0;     // in place (the robot's corner mode): stop, no turn
  s.waypoints[1].speed_mps = 0.6;  // then 0.6 m/s
  s.waypoints[2].turn = "arc";     // a circular arc of 1.5 m,
  s.waypoints[2].radius_m = 1.5;   // driven at the next leg's 0.3 m/s
  s.waypoints[2].speed_mps = 0.3;
  std::string error;
  ASSERT_TRUE(s.IsValid(&error)) << error;
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  sim::StereoFrame frame;
  while (simulator->Next(&frame, &error)) {
  }
  ASSERT_TRUE(error.empty()) << error;
  EXPECT_TRUE(simulator->navigation().reached_goal);
  const std::vector<Eigen::Vector3d>& track = simulator->body_track();
  const double dt = s.physics_dt_s;
  // Standing still: the steps that move the robot less than 2 um (1 mm/s), near (3, 0).
  int still = 0, longest = 0;
  double leg0 = 0, leg1 = 0, leg2 = 0, arc_worst = 0;
  for (size_t k = 1; k < track.size(); ++k) {
    const Eigen::Vector2d p = track[k].head<2>();
    const double v = (track[k] - track[k - 1]).head<2>().norm() / dt;
    still = (v < 1e-3 && (p - Eigen::Vector2d(3, 0)).norm() < 0.05) ? still + 1 : 0;
    longest = std::max(longest, still);
    if (p.x() > 1 && p.x() < 2.5 && p.y() < 0.5) leg0 = std::max(leg0, v);
    if (p.x() > 3.5 && p.x() < 5.0 && p.y() < 0.5) leg1 = std::max(leg1, v);
    if (p.y() > 2.0 && p.y() < 3.8) leg2 = std::max(leg2, v);
    const Eigen::Vector2d r = p - Eigen::Vector2d(5.5, 1.5);  // the arc's centre
    if (r.x() > 0.15 && r.y() < -0.15) arc_worst = std::max(arc_worst, std::abs(r.norm() - 1.5));
  }
  // Still for the stop less the braking from the creep into the waypoint (at most 0.3 s).
  EXPECT_GT(longest * dt, 2.0 - 0.3);
  EXPECT_LE(longest * dt, 2.0 + 0.05);
  EXPECT_NEAR(leg0, 0.4, 0.01);  // the robot's speed
  EXPECT_NEAR(leg1, 0.6, 0.01);  // path[1]'s
  EXPECT_NEAR(leg2, 0.3, 0.01);  // path[2]'s
  // On the circle, away from its ends (where the curvature steps), within 3 cm.
  EXPECT_LT(arc_worst, 0.03);
}

}  // namespace
