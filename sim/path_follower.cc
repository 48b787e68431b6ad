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

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// A corner whose legs turn by less than this is straight: no arc to drive (rad).
constexpr double kStraightRad = 1e-9;

}  // namespace

std::vector<WaypointGoal> ResolveWaypoints(const std::vector<Eigen::Vector2d>& path,
                                           const RobotOptions& robot,
                                           const std::vector<WaypointOptions>& waypoints) {
  const size_t n = path.size();
  std::vector<WaypointGoal> goals(n);
  for (size_t i = 0; i < n; ++i) {
    const WaypointOptions* w = waypoints.size() == n ? &waypoints[i] : nullptr;
    const bool inner = i > 0 && i + 1 < n;
    WaypointGoal& g = goals[i];
    g.arc = inner && (w && !w->turn.empty() ? w->turn == "arc" : robot.corner_mode == "arc");
    g.radius_m = g.arc && w && std::isfinite(w->radius_m) ? w->radius_m : 0.0;
    g.stop_s = w && !std::isnan(w->stop_s) ? w->stop_s : inner && !g.arc ? robot.stop_s : 0.0;
    if (g.arc) g.stop_s = 0.0;
    g.speed_mps = w && !std::isnan(w->speed_mps) ? w->speed_mps : robot.speed_mps;
  }
  return goals;
}

Eigen::Vector2d CornerArc::PointAt(double s) const {
  const double angle = (sweep_rad >= 0 ? 1.0 : -1.0) * s / radius_m;
  const Eigen::Vector2d r = start - centre;
  return centre + Eigen::Vector2d(std::cos(angle) * r.x() - std::sin(angle) * r.y(),
                                  std::sin(angle) * r.x() + std::cos(angle) * r.y());
}

CornerArc ArcAtCorner(const Eigen::Vector2d& prev, const Eigen::Vector2d& corner,
                      const Eigen::Vector2d& next, double radius_m) {
  const Eigen::Vector2d d0 = (corner - prev).normalized(), d1 = (next - corner).normalized();
  CornerArc c;
  c.radius_m = radius_m;
  c.sweep_rad = std::atan2(Cross(d0, d1), d0.dot(d1));
  c.tangent_m = radius_m * std::tan(0.5 * std::abs(c.sweep_rad));
  c.start = corner - c.tangent_m * d0;
  c.end = corner + c.tangent_m * d1;
  const Eigen::Vector2d left(-d0.y(), d0.x());  // the centre: on the side the corner turns to
  c.centre = c.start + (c.sweep_rad >= 0 ? radius_m : -radius_m) * left;
  return c;
}

void WheelSpeeds(const DriveCommand& cmd, double wheel_radius_m, double track_m, double* left_radps,
                 double* right_radps) {
  *left_radps = (cmd.v_mps - cmd.w_radps * track_m / 2.0) / wheel_radius_m;
  *right_radps = (cmd.v_mps + cmd.w_radps * track_m / 2.0) / wheel_radius_m;
}

PathFollower::PathFollower(std::vector<Eigen::Vector2d> path, const RobotOptions& options,
                           const std::vector<WaypointOptions>& waypoints)
    : path_(std::move(path)), options_(options) {
  goals_ = ResolveWaypoints(path_, options_, waypoints);
  arcs_.resize(path_.size());
  for (size_t i = 1; i + 1 < path_.size(); ++i) {
    if (goals_[i].radius_m <= 0.0) continue;
    arcs_[i] = ArcAtCorner(path_[i - 1], path_[i], path_[i + 1], goals_[i].radius_m);
    if (std::abs(arcs_[i].sweep_rad) < kStraightRad) goals_[i].radius_m = 0.0;  // straight on
  }
  mode_ = path_.size() < 2 ? Mode::kDone : Mode::kTurn;
  if (mode_ == Mode::kTurn && goals_[0].stop_s > 0.0) {  // stand at the start first
    stop_left_s_ = goals_[0].stop_s;
    mode_ = Mode::kStop;
  }
}

Eigen::Vector2d PathFollower::PointAlong(size_t k, double s) const {
  const Eigen::Vector2d a = path_[k - 1];
  const Eigen::Vector2d b = path_[k];
  const Eigen::Vector2d dir = (b - a).normalized();
  if (k + 1 < path_.size() && goals_[k].arc && goals_[k].radius_m > 0.0) {
    const CornerArc& c = arcs_[k];
    const double into = s - ((b - a).norm() - c.tangent_m);  // past the arc's start
    if (into > 0.0) {
      if (into <= c.length_m()) return c.PointAt(into);
      return c.end + (path_[k + 1] - b).normalized() * (into - c.length_m());
    }
  }
  return a + dir * s;
}

double PathFollower::BeyondLeg(size_t k) const {
  // Summed leg by leg (as the follower always did), each circular arc replacing its two
  // tangents.
  double d = 0.0;
  for (size_t j = k + 1; j < path_.size() && goals_[j - 1].arc; ++j) {
    d += (path_[j] - path_[j - 1]).norm();
    if (goals_[j - 1].radius_m > 0.0) d += arcs_[j - 1].length_m() - 2.0 * arcs_[j - 1].tangent_m;
  }
  return d;
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
    if (final_turn_ && goals_.back().stop_s > 0.0) {  // then stand at the goal
      stop_left_s_ = goals_.back().stop_s;
      final_stop_ = true;
      mode_ = Mode::kStop;
    }
  }
  return {RampSpeed(0.0, dt_s), w_};
}

DriveCommand PathFollower::Drive(const Eigen::Vector2d& position, double yaw_rad, double dt_s) {
  const Eigen::Vector2d a = path_[target_ - 1];
  const Eigen::Vector2d b = path_[target_];
  const Eigen::Vector2d dir = (b - a).normalized();
  const double seg_len = (b - a).norm();
  const double along = (position - a).dot(dir);
  const bool last = target_ + 1 == path_.size();
  const WaypointGoal& at_b = goals_[target_];
  const bool through = !last && at_b.arc;  // passed without stopping

  // Distance left before the robot must stand still: to this waypoint when it stops there, to
  // the next waypoint it stops at otherwise.
  double to_stop = seg_len - along;
  if (through) {
    for (size_t k = target_ + 1; k < path_.size() && goals_[k - 1].arc; ++k) {
      to_stop += (path_[k] - path_[k - 1]).norm();
      if (goals_[k - 1].radius_m > 0.0)
        to_stop += arcs_[k - 1].length_m() - 2.0 * arcs_[k - 1].tangent_m;
    }
  }

  // Segment switch: an in-place corner stops and turns at the waypoint; a cut corner moves the
  // target on as soon as the look-ahead point passes the waypoint; a circular one at its arc.
  if (to_stop <= options_.goal_tolerance_m) {
    if (last && std::isfinite(options_.final_heading_deg)) {  // the goal's heading
      final_turn_ = true;
      mode_ = Mode::kTurn;
      return Turn(yaw_rad, dt_s);
    }
    if (last && goals_.back().stop_s > 0.0) {  // stand at the goal, then done
      stop_left_s_ = goals_.back().stop_s;
      final_stop_ = true;
      mode_ = Mode::kStop;
      return {RampSpeed(0.0, dt_s), 0.0};
    }
    if (last) {
      mode_ = Mode::kDone;
      v_ = 0.0;
      return {};
    }
    ++target_;
    if (const double stop_s = goals_[target_ - 1].stop_s; stop_s > 0.0) {  // stand, then turn
      stop_left_s_ = stop_s;
      mode_ = Mode::kStop;
      return {RampSpeed(0.0, dt_s), 0.0};
    }
    mode_ = Mode::kTurn;
    return Turn(yaw_rad, dt_s);
  }
  if (through && at_b.radius_m == 0.0 && seg_len - along < options_.lookahead_m) {
    ++target_;
    return Drive(position, yaw_rad, dt_s);
  }
  if (through && at_b.radius_m > 0.0 && along >= seg_len - arcs_[target_].tangent_m) {
    arc_ = target_++;
    mode_ = Mode::kArc;
    return DriveArc(position, yaw_rad, dt_s);
  }

  // Pure pursuit: a look-ahead point on the segment (or its extension, so that the
  // steering stays calm near the waypoint; or on the arc that follows), curvature
  // κ = 2 sin(α) / L.
  const Eigen::Vector2d goal = PointAlong(target_, std::max(along, 0.0) + options_.lookahead_m);
  return Pursue(position, yaw_rad, goal, to_stop, target_ - 1, seg_len - along, dt_s);
}

DriveCommand PathFollower::DriveArc(const Eigen::Vector2d& position, double yaw_rad, double dt_s) {
  const CornerArc& c = arcs_[arc_];
  const double sign = c.sweep_rad >= 0 ? 1.0 : -1.0;
  const Eigen::Vector2d r0 = c.start - c.centre, rp = position - c.centre;
  const double swept = sign * std::atan2(Cross(r0, rp), r0.dot(rp));  // about the centre (rad)
  if (swept >= std::abs(c.sweep_rad)) {  // past the arc: on the leg after it
    mode_ = Mode::kDrive;
    return Drive(position, yaw_rad, dt_s);
  }
  const double s = std::max(swept, 0.0) * c.radius_m;  // along the arc (m)
  const double rest = c.length_m() - s;
  const Eigen::Vector2d next_dir = (path_[target_] - path_[arc_]).normalized();
  const double ahead = s + options_.lookahead_m;
  const Eigen::Vector2d goal = ahead <= c.length_m()
                                   ? c.PointAt(ahead)
                                   : Eigen::Vector2d(c.end + next_dir * (ahead - c.length_m()));
  const double to_leg_end = rest + (path_[target_] - path_[arc_]).norm() - c.tangent_m;
  double to_stop = to_leg_end;
  if (target_ + 1 < path_.size() && goals_[target_].arc) to_stop += BeyondLeg(target_);
  return Pursue(position, yaw_rad, goal, to_stop, arc_, to_leg_end, dt_s);
}

DriveCommand PathFollower::Pursue(const Eigen::Vector2d& position, double yaw_rad,
                                  const Eigen::Vector2d& goal, double to_stop, size_t leg_start,
                                  double to_leg_end, double dt_s) {
  const Eigen::Vector2d to_goal = goal - position;
  const double dist = to_goal.norm();
  const double alpha = WrapAngle(std::atan2(to_goal.y(), to_goal.x()) - yaw_rad);
  const double kappa = 2.0 * std::sin(alpha) / std::max(dist, 1e-6);

  // Speed: the leg's cruise, limited by the braking distance to the next stop, and ahead of a
  // slower leg reached without stopping by the braking to its speed where it starts.
  const double cruise = goals_[leg_start].speed_mps;
  double v_target = std::min(cruise, std::sqrt(2.0 * options_.max_accel_mps2 * to_stop));
  double d = to_leg_end;  // to the end of the leg (the corner) being driven
  for (size_t k = leg_start + 1; k + 1 < path_.size() && goals_[k].arc; ++k) {
    const double slower = goals_[k].speed_mps;
    const double to_start =
        std::max(0.0, d - (goals_[k].radius_m > 0.0 ? arcs_[k].tangent_m : 0.0));
    if (slower < cruise)
      v_target =
          std::min(v_target, std::sqrt(slower * slower + 2.0 * options_.max_accel_mps2 * to_start));
    d += (path_[k + 1] - path_[k]).norm();
    if (goals_[k].radius_m > 0.0) d += arcs_[k].length_m() - 2.0 * arcs_[k].tangent_m;
  }
  v_target = std::max(v_target, std::min(kCreepSpeed, cruise));
  const double v = RampSpeed(v_target, dt_s);
  return {v, v * kappa};
}

DriveCommand PathFollower::Update(const Eigen::Vector2d& position, double yaw_rad, double dt_s) {
  switch (mode_) {
    case Mode::kTurn:
      return Turn(yaw_rad, dt_s);
    case Mode::kDrive:
      return Drive(position, yaw_rad, dt_s);
    case Mode::kArc:
      return DriveArc(position, yaw_rad, dt_s);
    case Mode::kStop:
      stop_left_s_ -= dt_s;
      if (stop_left_s_ <= 0.0) mode_ = final_stop_ ? Mode::kDone : Mode::kTurn;
      return {RampSpeed(0.0, dt_s), 0.0};
    case Mode::kDone:
      break;
  }
  v_ = 0.0;
  w_ = 0.0;
  return {};
}

}  // namespace sim
