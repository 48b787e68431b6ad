// Path-tracking controller for a differential-drive robot: pure pursuit along a polyline of
// waypoints, with either in-place turns at the corners or arcs that cut them; with in-place
// corners a stop of RobotOptions::stop_s before each turn, and at the end an in-place turn to
// RobotOptions::final_heading_deg when it is set.
//
// Each waypoint may carry its own goals (WaypointOptions, resolved by ResolveWaypoints; what it
// leaves out is the robot's, so a path without them drives exactly as before):
// - turn in_place: the robot brakes to the waypoint, stands its stop_s, turns in place to the next
//   leg. turn arc without radius_m: it does not stop; its target moves on to the next leg when
//   the look-ahead point passes the waypoint (pure pursuit cuts the corner). turn arc with
//   radius_m R: the path there is the circular arc of radius R tangent to both legs
//   (ArcAtCorner: from the corner R tan(|turn|/2) back along the leg in to as far along the leg
//   out), and the look-ahead point runs along the line, the arc and the next line in turn; on a
//   circle pure pursuit's curvature 2 sin(alpha) / chord is exactly 1 / R.
// - stop_s: stand still that long where the robot stops: an in-place corner (before its turn),
//   the first waypoint (before driving) or the last (after its final heading).
// - speed_mps: the cruise speed of the leg that starts at the waypoint (an arc at a corner is
//   driven at the speed of the leg after it). The speed is limited by the braking distance to
//   the next stop (sqrt(2 a d)) and, ahead of a slower leg reached without stopping, by
//   sqrt(v_next^2 + 2 a d), d the distance to where it starts.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "sim/scenario.h"

namespace sim {

// Body velocity command of a differential-drive base.
struct DriveCommand {
  double v_mps = 0.0;    // forward speed (m/s)
  double w_radps = 0.0;  // yaw rate, counter-clockwise seen from above (rad/s)
};

// Wheel angular speeds (rad/s, positive = forward) for a body command.
void WheelSpeeds(const DriveCommand& cmd, double wheel_radius_m, double track_m, double* left_radps,
                 double* right_radps);

// A waypoint's goals with the robot's values filled in.
struct WaypointGoal {
  bool arc = false;        // the corner is passed without stopping (turn arc); ends: false
  double radius_m = 0.0;   // arc: > 0 a circular arc of this radius; 0 the pure-pursuit cut
  double stop_s = 0.0;     // stand still here (s); 0 on arc corners
  double speed_mps = 0.4;  // cruise speed of the leg that starts here
};

// One goal per waypoint of `path`: each WaypointOptions field where given (`waypoints` empty or
// one per waypoint), else the robot's: turn from corner_mode, speed from speed_mps, stop_s from
// stop_s at in-place inner corners (none at the ends, none at arcs).
std::vector<WaypointGoal> ResolveWaypoints(const std::vector<Eigen::Vector2d>& path,
                                           const RobotOptions& robot,
                                           const std::vector<WaypointOptions>& waypoints);

// The circular arc of radius `radius_m` at the corner `corner` between the legs from `prev` and
// to `next`, tangent to both: it starts `tangent_m` = R tan(|turn| / 2) before the corner on the
// leg in, ends as far after it on the leg out, and turns by `sweep_rad` (counter-clockwise
// positive, the corner's turn) about `centre`, R from both tangent points.
struct CornerArc {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  Eigen::Vector2d end = Eigen::Vector2d::Zero();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  double tangent_m = 0.0;
  double sweep_rad = 0.0;
  double length_m() const { return radius_m * std::abs(sweep_rad); }
  // The point `s` metres along the arc from its start (0 <= s <= length_m()).
  Eigen::Vector2d PointAt(double s) const;
};
CornerArc ArcAtCorner(const Eigen::Vector2d& prev, const Eigen::Vector2d& corner,
                      const Eigen::Vector2d& next, double radius_m);

class PathFollower {
 public:
  enum class Mode { kTurn, kDrive, kArc, kStop, kDone };

  // `path`: waypoints (x, y) in the world (m), at least two; options as in the scenario;
  // `waypoints`: their own goals (empty: the robot's everywhere).
  PathFollower(std::vector<Eigen::Vector2d> path, const RobotOptions& options,
               const std::vector<WaypointOptions>& waypoints = {});

  // One control step: robot position (m) and yaw (rad) in the world, control period dt (s).
  DriveCommand Update(const Eigen::Vector2d& position, double yaw_rad, double dt_s);

  Mode mode() const { return mode_; }
  bool done() const { return mode_ == Mode::kDone; }
  // Index of the waypoint the robot is heading to (1..n-1).
  size_t target_index() const { return target_; }
  // Whether the robot stops at waypoint i (an in-place corner, or an end): it is then reached
  // when the target moves on from it.
  bool stops_at(size_t i) const { return !goals_[i].arc; }
  const std::vector<WaypointGoal>& goals() const { return goals_; }

 private:
  DriveCommand Drive(const Eigen::Vector2d& position, double yaw_rad, double dt_s);
  DriveCommand DriveArc(const Eigen::Vector2d& position, double yaw_rad, double dt_s);
  DriveCommand Turn(double yaw_rad, double dt_s);
  DriveCommand Pursue(const Eigen::Vector2d& position, double yaw_rad, const Eigen::Vector2d& goal,
                      double to_stop, size_t leg_start, double to_leg_end, double dt_s);
  double RampSpeed(double v_target, double dt_s);
  // The point `s` metres from path_[k - 1] along leg k, past a circular arc at path_[k] onto
  // the next leg (on the leg's line, or its extension, otherwise).
  Eigen::Vector2d PointAlong(size_t k, double s) const;
  // The path's length from the end of leg k (path_[k]) on to the next stop.
  double BeyondLeg(size_t k) const;

  std::vector<Eigen::Vector2d> path_;
  RobotOptions options_;
  std::vector<WaypointGoal> goals_;
  std::vector<CornerArc> arcs_;  // per waypoint: its circular arc (radius_m > 0 only)
  size_t arc_ = 0;               // kArc: the corner whose arc the robot drives
  bool final_stop_ = false;      // kStop at the last waypoint: done after it
  Mode mode_ = Mode::kTurn;
  size_t target_ = 1;         // heading to path_[target_]
  double v_ = 0.0;            // current commanded forward speed (m/s), ramped
  double w_ = 0.0;            // current commanded yaw rate when turning (rad/s), ramped
  double stop_left_s_ = 0.0;  // kStop: time still to stand (s)
  bool final_turn_ = false;   // kTurn toward final_heading_deg at the last waypoint
};

}  // namespace sim
