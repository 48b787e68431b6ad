// The path follower's goals on an ideal unicycle (no physics): the final heading and the stops
// at in-place corners; without them it drives as before.
#include "sim/path_follower.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

struct Trace {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;
  double time_s = 0.0;
  double standing_s = 0.0;  // time with v = w = 0 commanded before the end
};

// Drives `path` with the follower at 500 Hz until done (at most 200 s).
Trace Drive(const std::vector<Eigen::Vector2d>& path, const sim::RobotOptions& options) {
  sim::PathFollower follower(path, options);
  Trace t;
  const double dt = 0.002;
  while (!follower.done() && t.time_s < 200.0) {
    const sim::DriveCommand c = follower.Update(t.position, t.yaw_rad, dt);
    if (c.v_mps == 0.0 && c.w_radps == 0.0 && !follower.done()) t.standing_s += dt;
    t.position += c.v_mps * dt * Eigen::Vector2d(std::cos(t.yaw_rad), std::sin(t.yaw_rad));
    t.yaw_rad += c.w_radps * dt;
    t.time_s += dt;
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

}  // namespace
