// Closed-loop navigation (scenario key `navigation`): what the path follower steers on, and
// what the robot physically did.
//
// `navigation: ground_truth` (the default) steers on the true pose of the robot at every
// physics step, as the bench always did. `navigation: vo` steers on a belief, as a robot would:
// the belief is a planar body pose (x, y, yaw of the wheel axle in the world) that an estimator
// corrects from outside (Simulator::FixAtLastFrame: the VO's estimate of a frame, mapped into
// the world by NavigationFixes below), and that the simulator dead-reckons between corrections
// with the follower's own commanded body velocity (DeadReckon: a unicycle integrated over each
// physics step). Dead reckoning rather than holding the last estimate: the follower runs at the
// physics rate (500 Hz) and a fix comes at the frame rate (10 Hz), so a held pose is up to
// 0.1 s stale (4 cm at 0.4 m/s, 3 deg into a 30 deg/s turn) and the in-place turns would
// overshoot by that much; a robot does the same with its odometry. The commanded velocity is
// the only odometry here (no wheel encoders, the IMU is not used), so a wheel slipping or the
// robot pushing against a wall is seen only at the next fix. A frame the VO loses gives no fix:
// the belief goes on dead-reckoned.
//
// A fix is of the frame's time; the commands issued since that time are replayed on it, so the
// belief stays exact in time. A perfect estimator (the true pose as a fix at every step,
// Simulator::SetStepEstimator) drives exactly like ground-truth navigation, bit for bit.
//
// What the robot did (NavigationReport, metrics.json's `navigation` group), for both modes:
//   end_error_m           the wheel axle where the run ended vs the path's last waypoint (m)
//   max_waypoint_error_m  at each moment the follower believed it reached a waypoint (the target
//                         moves on, or the path is done), the true distance of the axle from it;
//                         the largest (m). At an arc corner (corner_mode arc, or the waypoint's
//                         turn: arc) the follower does not go to the waypoint: only the waypoints
//                         it stops at count (in-place corners, the last). NaN when none was reached
//   wall_contacts         contact events between the robot's geoms and the building's collision
//                         geoms (geoms fixed to the world other than upward-facing planes, the
//                         floor): a step with at least one such MuJoCo contact after a step with
//                         none starts one event. -1 when the scene has no such geoms (walls that
//                         are drawn only: nothing to touch)
//   wall_contact_s        simulated time with at least one such contact (s)
//   reached_goal          the follower was done (it believed it reached the last waypoint and
//                         the robot stood still) within max_duration_s; with navigation: vo a run
//                         that is not ends there (the sequence ends, reached_goal false); with
//                         ground_truth it is an error, as it always was
#pragma once

#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <vector>

#include "sim/path_follower.h"

namespace sim {

// A pose in the ground plane: the robot's wheel axle (x, y in the world, m) and its yaw (rad,
// counter-clockwise from +x).
struct PlanarPose {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;
};

// `pose` moved by the body command `cmd` over `dt_s` (a unicycle, the heading of the step's
// midpoint).
PlanarPose DeadReckon(const PlanarPose& pose, const DriveCommand& cmd, double dt_s);

// The planar pose of a body pose (x forward, z up): its position's x, y and its x axis' yaw.
PlanarPose PlanarPoseOf(const Eigen::Isometry3d& T_world_body);

// The body pose of a planar one with the axle at height `z_m` (level).
Eigen::Isometry3d BodyPoseOf(const PlanarPose& pose, double z_m);

// One frame of a run: what the follower believed (after the frame's fix, if any) and where the
// robot was, at the frame's time.
struct NavigationFrame {
  double time_s = 0.0;
  PlanarPose believed;
  PlanarPose truth;
  bool fixed = false;  // the estimator corrected the belief at this frame
};

struct NavigationReport {
  std::string mode = "ground_truth";  // the scenario's navigation key
  bool reached_goal = false;
  double end_error_m = std::numeric_limits<double>::quiet_NaN();
  double max_waypoint_error_m = std::numeric_limits<double>::quiet_NaN();
  int wall_contacts = -1;  // -1: the scene has no building geoms to touch
  double wall_contact_s = 0.0;
  std::vector<NavigationFrame> frames;
};

// Maps a stereo VO's estimates of cam0 (in the VO's own world) into the simulator's world as
// body poses: the first estimate is anchored at what the robot believed at that frame (the known
// start pose at frame 0; dead reckoning if the VO initialised later), through the rig's
// camera-on-body transform: T_world_body = T_world_vo * T_vo_cam0 * T_body_cam0^-1, with
// T_world_vo = BodyPoseOf(belief, axle_height) * T_body_cam0 * T_vo_cam0(first)^-1.
class NavigationFixes {
 public:
  NavigationFixes(const Eigen::Isometry3d& T_body_cam0, double axle_height_m)
      : T_body_cam0_(T_body_cam0), axle_height_m_(axle_height_m) {}
  // The body pose of the estimate T_vo_cam0; `belief` is the believed pose at the same time
  // (used for the anchor on the first call).
  PlanarPose Fix(const Eigen::Isometry3d& T_vo_cam0, const PlanarPose& belief);

 private:
  Eigen::Isometry3d T_body_cam0_;
  double axle_height_m_;
  bool anchored_ = false;
  Eigen::Isometry3d T_world_vo_ = Eigen::Isometry3d::Identity();
};

}  // namespace sim
