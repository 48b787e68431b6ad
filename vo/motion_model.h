// The motion model the stages share: the constant-velocity prior (ConstantVelocity: the last
// measured per-frame motion, blended in by its support, and the last motion as it was
// measured), what a motion predicts in the image (PredictFeaturePositions, where the matcher
// centres its search; PredictedCentreShift, the image shift at the centre), a prior corrected
// by a measured image shift (CorrectPriorWithImageShift; a ground vehicle's,
// VehicleMotionFromImageShift), the ground vehicle's plausibility test (IsVehicleLike), and the
// pose algebra of the pipeline (Blend, Root, WorldUpInCamera).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "vo/camera.h"
#include "vo/odometry_result.h"
#include "vo/types.h"

namespace vo {

// Where each reference feature's 3D point (p_cam0, from its disparity) appears in the current
// left image when the camera moved by T_ref_curr (p_ref = T_ref_curr * p_curr): the predicted
// centre of the matcher's search. NaN for features without depth or behind the camera
// (z <= min_depth_m).
std::vector<Eigen::Vector2d> PredictFeaturePositions(const StereoCamera& camera,
                                                     const std::vector<Feature>& features,
                                                     const Eigen::Isometry3d& T_ref_curr,
                                                     double min_depth_m);

// A ground vehicle's frame-to-frame motion (VehicleMotion: a yaw about up_prev, the world's up
// in the previous camera frame, and the forward distance of the axle point axle_behind_camera_m
// behind the camera) from a measured image shift: the forward distance is the prior's
// (VehicleMotionParameters of T_prev_curr_prior), the yaw is the one whose motion, including
// the camera's swing about the axle, predicts the measured shift for the image centre at
// depth_m (metres; <= 0 or non-finite = far, the swing then shows no parallax). A camera ahead
// of the axle swings sideways as the vehicle turns, so a near wall's image moves by (1 + d / z)
// times the rotation's shift: read as a rotation alone (CorrectPriorWithImageShift), a turn in
// front of a wall 0.85 m away is over-read by 18 % with d = 0.15 m. Fixed-point iteration
// (contraction ~ d / z); exact for the centre point up to 1e-12 rad. A non-finite result or
// input gives T_prev_curr_prior back.
Eigen::Isometry3d VehicleMotionFromImageShift(const StereoCamera& camera,
                                              const Eigen::Vector3d& up_prev,
                                              double axle_behind_camera_m,
                                              const Eigen::Isometry3d& T_prev_curr_prior,
                                              const Eigen::Vector2d& shift_px, double depth_m);

// Whether the motion T_a_b (p_a = T_a_b · p_b) of a ground vehicle whose up direction in frame a
// is up_a (any length > 0) tilts by at most max_tilt_deg (the angle of its rotation left after
// the twist about up, PlanarPart) and moves along up by at most max_lift_m. A non-finite input
// is not vehicle-like. Used by MotionOptions::vehicle_max_weak_tilt_deg / _lift_m.
bool IsVehicleLike(const Eigen::Isometry3d& T_a_b, const Eigen::Vector3d& up_a, double max_tilt_deg,
                   double max_lift_m);

// The image shift (pixels, image_motion.h convention) that the motion T_ref_curr predicts for
// the reference image's centre at depth_m (metres; <= 0 or non-finite = infinitely far, the
// rotation alone): where that point appears in the current image minus the centre. +inf when
// it falls behind the camera.
Eigen::Vector2d PredictedCentreShift(const StereoCamera& camera,
                                     const Eigen::Isometry3d& T_ref_curr, double depth_m);

// The prior's frame-to-frame motion T_prev_curr_prior corrected by a measured image shift
// (image_motion.h: curr(x + shift) ≈ prev(x)): the shift the prior predicts for the image
// centre at depth_m (metres; <= 0 or non-finite = infinitely far, rotation only) is subtracted,
// and the rest is explained by a rotation of the current camera about its centre (pan/tilt, no
// roll). Exact for the image centre; used to bridge frames whose features are too few for a
// motion (a plain wall in front of a turning robot).
Eigen::Isometry3d CorrectPriorWithImageShift(const StereoCamera& camera,
                                             const Eigen::Isometry3d& T_prev_curr_prior,
                                             const Eigen::Vector2d& shift_px, double depth_m);

// Whether every entry of T is finite.
inline bool IsFinitePose(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

// The world's up (+z of the hallway frame) in the camera frame of T_world_cam.
Eigen::Vector3d WorldUpInCamera(const Eigen::Isometry3d& T_world_cam);

// Rotation and translation blend: slerp(q_a, q_b, w), (1 − w) t_a + w t_b; T_a itself for
// w <= 0.
Eigen::Isometry3d Blend(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b, double w);

// The per-frame motion of a motion spanning n >= 1 frames: the rotation's n-th root (slerp from
// identity), the translation divided by n (exact for pure translations and pure rotations).
Eigen::Isometry3d Root(const Eigen::Isometry3d& T, int64_t n);

// The constant-velocity model: the per-frame motion T_prev_curr the next frame is predicted
// with (unknown until a first motion is measured), and the last motion as it was measured,
// per frame, with its frame (the prior blends a weak motion in only in part; where the motion
// changes fast, a turn that starts, that one is nearer the next frame's).
class ConstantVelocity {
 public:
  bool known() const { return known_; }
  // The per-frame motion (identity while unknown).
  const Eigen::Isometry3d& per_frame() const { return velocity_; }
  // The prior's motion since the previous output: the caller's prior (when finite), else the
  // constant velocity (its rotation the measured one when set), else none (identity; the
  // measured rotation when set).
  Eigen::Isometry3d Prior(const MotionPrior* prior) const;
  // Moved `weight` of the way (slerp) to a measured per-frame motion (the first one is taken as
  // it is; a non-finite one is ignored, and so is a weight of 0 once known).
  void Move(const Eigen::Isometry3d& per_frame, double weight);
  // Replaced by a motion measured on a lost frame (bridge or direct alignment), when known.
  void ReplaceIfKnown(const Eigen::Isometry3d& per_frame) {
    if (known_) velocity_ = per_frame;
  }
  // Its rotation replaced by one measured from the image shift, when known.
  void ReplaceRotationIfKnown(const Eigen::Matrix3d& R) {
    if (known_) velocity_.linear() = R;
  }
  // The coming frame's rotation as another sensor measured it (the gyro's, gyro_prior.h):
  // Prior(nullptr) takes it in place of the constant velocity's rotation (the translation stays
  // the constant velocity's; none while unknown), until ClearMeasuredRotation.
  void SetMeasuredRotation(const Eigen::Matrix3d& R_prev_curr) {
    measured_rotation_ = R_prev_curr;
    has_measured_rotation_ = true;
  }
  void ClearMeasuredRotation() { has_measured_rotation_ = false; }
  bool has_measured_rotation() const { return has_measured_rotation_; }

  // The last measured motion (per frame) and its frame index; -1: none.
  void SetLastMeasured(const Eigen::Isometry3d& per_frame, int64_t frame_index) {
    last_motion_ = per_frame;
    last_motion_frame_ = frame_index;
  }
  const Eigen::Isometry3d& last_measured() const { return last_motion_; }
  int64_t last_measured_frame() const { return last_motion_frame_; }

  void Reset() {
    velocity_ = Eigen::Isometry3d::Identity();
    known_ = false;
    last_motion_frame_ = -1;
    has_measured_rotation_ = false;
  }

 private:
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();
  bool known_ = false;
  Eigen::Isometry3d last_motion_ = Eigen::Isometry3d::Identity();
  int64_t last_motion_frame_ = -1;
  Eigen::Matrix3d measured_rotation_ = Eigen::Matrix3d::Identity();
  bool has_measured_rotation_ = false;
};

}  // namespace vo
