// Path-tracking controller for a differential-drive robot: pure pursuit along a polyline of
// waypoints, with either in-place turns at the corners or arcs that cut them; with in-place
// corners a stop of RobotOptions::stop_s before each turn, and at the end an in-place turn to
// RobotOptions::final_heading_deg when it is set.
#pragma once

#include <Eigen/Core>
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

class PathFollower {
 public:
  enum class Mode { kTurn, kDrive, kStop, kDone };

  // `path`: waypoints (x, y) in the world (m), at least two; options as in the scenario.
  PathFollower(std::vector<Eigen::Vector2d> path, const RobotOptions& options);

  // One control step: robot position (m) and yaw (rad) in the world, control period dt (s).
  DriveCommand Update(const Eigen::Vector2d& position, double yaw_rad, double dt_s);

  Mode mode() const { return mode_; }
  bool done() const { return mode_ == Mode::kDone; }
  // Index of the waypoint the robot is heading to (1..n-1).
  size_t target_index() const { return target_; }

 private:
  DriveCommand Drive(const Eigen::Vector2d& position, double yaw_rad, double dt_s);
  DriveCommand Turn(double yaw_rad, double dt_s);
  double RampSpeed(double v_target, double dt_s);

  std::vector<Eigen::Vector2d> path_;
  RobotOptions options_;
  Mode mode_ = Mode::kTurn;
  size_t target_ = 1;         // heading to path_[target_]
  double v_ = 0.0;            // current commanded forward speed (m/s), ramped
  double w_ = 0.0;            // current commanded yaw rate when turning (rad/s), ramped
  double stop_left_s_ = 0.0;  // kStop: time still to stand (s)
  bool final_turn_ = false;   // kTurn toward final_heading_deg at the last waypoint
};

}  // namespace sim
