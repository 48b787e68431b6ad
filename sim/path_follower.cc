#include "sim/path_follower.h"

#include <algorithm>
#include <cmath>

namespace sim {
namespace {

constexpr double kTurnDoneRad = 0.004;      // heading error that ends an in-place turn (rad)
constexpr double kMinTurnRateRadps = 0.08;  // slowest commanded turn: overcomes wheel friction
constexpr double kTurnGain = 3.0;           // yaw-rate command per rad of heading error (1/s)
constexpr double kAngularAccel = 1.5;       // yaw acceleration limit (rad/s²)
constexpr double kCreepSpeed = 0.02;        // minimum speed while approaching a stop (m/s)

double WrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

double Heading(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const Eigen::Vector2d d = to - from;
  return std::atan2(d.y(), d.x());
}

}  // namespace

void WheelSpeeds(const DriveCommand& cmd, double wheel_radius_m, double track_m, double* left_radps,
                 double* right_radps) {
  *left_radps = (cmd.v_mps - cmd.w_radps * track_m / 2.0) / wheel_radius_m;
  *right_radps = (cmd.v_mps + cmd.w_radps * track_m / 2.0) / wheel_radius_m;
}

PathFollower::PathFollower(std::vector<Eigen::Vector2d> path, const RobotOptions& options)
    : path_(std::move(path)), options_(options) {
  mode_ = path_.size() < 2 ? Mode::kDone : Mode::kTurn;
}

double PathFollower::RampSpeed(double v_target, double dt_s) {
  const double dv = options_.max_accel_mps2 * dt_s;
  v_ = std::clamp(v_target, v_ - dv, v_ + dv);
  return v_;
}

DriveCommand PathFollower::Turn(double yaw_rad, double dt_s) {
  const double goal = final_turn_ ? options_.final_heading_deg * M_PI / 180.0
                                  : Heading(path_[target_ - 1], path_[target_]);
  const double err = WrapAngle(goal - yaw_rad);
  const double max_rate = options_.turn_rate_dps * M_PI / 180.0;
  // Rate that still lets us stop in time: w² = 2 α |err|.
  const double w_stop = std::sqrt(2.0 * kAngularAccel * std::abs(err));
  const double w_mag =
      std::max(kMinTurnRateRadps, std::min({max_rate, kTurnGain * std::abs(err), w_stop}));
  const double w_target = std::copysign(w_mag, err);
  const double dw = kAngularAccel * dt_s;
  w_ = std::clamp(w_target, w_ - dw, w_ + dw);
  if (std::abs(err) < kTurnDoneRad) {
    w_ = 0.0;
    mode_ = final_turn_ ? Mode::kDone : Mode::kDrive;
  }
  return {RampSpeed(0.0, dt_s), w_};
}

DriveCommand PathFollower::Drive(const Eigen::Vector2d& position, double yaw_rad, double dt_s) {
  const bool arc = options_.corner_mode == "arc";
  const Eigen::Vector2d a = path_[target_ - 1];
  const Eigen::Vector2d b = path_[target_];
  const Eigen::Vector2d dir = (b - a).normalized();
  const double seg_len = (b - a).norm();
  const double along = (position - a).dot(dir);
  const bool last = target_ + 1 == path_.size();

  // Distance left before the robot must stand still: to this waypoint when turning in place,
  // to the final waypoint otherwise.
  double to_stop = seg_len - along;
  if (arc) {
    for (size_t k = target_ + 1; k < path_.size(); ++k) to_stop += (path_[k] - path_[k - 1]).norm();
  }

  // Segment switch: in-place mode stops and turns at each waypoint; arc mode moves its
  // target on as soon as the look-ahead point passes the waypoint.
  if (to_stop <= options_.goal_tolerance_m) {
    if (last && std::isfinite(options_.final_heading_deg)) {  // the goal's heading
      final_turn_ = true;
      mode_ = Mode::kTurn;
      return Turn(yaw_rad, dt_s);
    }
    if (last) {
      mode_ = Mode::kDone;
      v_ = 0.0;
      return {};
    }
    ++target_;
    if (options_.stop_s > 0.0) {  // stand still, then turn
      stop_left_s_ = options_.stop_s;
      mode_ = Mode::kStop;
      return {RampSpeed(0.0, dt_s), 0.0};
    }
    mode_ = Mode::kTurn;
    return Turn(yaw_rad, dt_s);
  }
  if (arc && !last && seg_len - along < options_.lookahead_m) {
    ++target_;
    return Drive(position, yaw_rad, dt_s);
  }

  // Pure pursuit: a look-ahead point on the segment (or its extension, so that the
  // steering stays calm near the waypoint), curvature κ = 2 sin(α) / L.
  const Eigen::Vector2d goal = a + dir * (std::max(along, 0.0) + options_.lookahead_m);
  const Eigen::Vector2d to_goal = goal - position;
  const double dist = to_goal.norm();
  const double alpha = WrapAngle(std::atan2(to_goal.y(), to_goal.x()) - yaw_rad);
  const double kappa = 2.0 * std::sin(alpha) / std::max(dist, 1e-6);

  // Speed: cruise, limited by the braking distance to the next stop.
  double v_target =
      std::min(options_.speed_mps, std::sqrt(2.0 * options_.max_accel_mps2 * to_stop));
  v_target = std::max(v_target, std::min(kCreepSpeed, options_.speed_mps));
  const double v = RampSpeed(v_target, dt_s);
  return {v, v * kappa};
}

DriveCommand PathFollower::Update(const Eigen::Vector2d& position, double yaw_rad, double dt_s) {
  switch (mode_) {
    case Mode::kTurn:
      return Turn(yaw_rad, dt_s);
    case Mode::kDrive:
      return Drive(position, yaw_rad, dt_s);
    case Mode::kStop:
      stop_left_s_ -= dt_s;
      if (stop_left_s_ <= 0.0) mode_ = Mode::kTurn;
      return {RampSpeed(0.0, dt_s), 0.0};
    case Mode::kDone:
      break;
  }
  v_ = 0.0;
  w_ = 0.0;
  return {};
}

}  // namespace sim
