// Motion estimation: a frame's motion from the reference from its matches (paper, section V:
// RANSAC over Horn's closed form, seeded by track ages; ransac.h, horn.h), and where RANSAC finds
// no usable consensus the few-point motion with the prior (few_point_motion, beyond the paper;
// prior_motion.h). Its options are MotionOptions (the `motion` group of vo_options.yaml, and the
// vehicle model of the `vehicle` group: ground_vehicle, few_point's axle and no-slip).
//
// Few points (off on the free platform, on for a ground vehicle: OdometryOptions::platform).
// While tracking normally (the previous frame's motion measured, no loss since), a frame with
// too few matches for RANSAC (fewer correspondences than min_inliers), with fewer than
// min_features features with depth (down to few_point_min_features; such a frame takes
// no RANSAC motion, only this one), or — a ground vehicle — whose weak RANSAC motion tilts or
// lifts the vehicle (vehicle_max_weak_tilt_deg, IsVehicleLike), takes the few-point
// motion on the same matches: the prior corrected by the few matches (inliers >=
// few_point.min_inliers and >= few_point.min_inlier_fraction of them), unless the frame's
// coarse-to-fine image shift contradicts it (few_point_max_shift_disagreement_px,
// AgreesWithImageShift). That frame is not bundle-adjusted (OdometryResult::few_point_motion).
// A plain end wall with two or three specks in front of a robot that stops and turns
// (l_hallway's texture seeds) is followed that way, not bridged. After a loss the prior is a
// bridge, not a measurement, and the solver is not used.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/odometry_result.h"
#include "vo/prior_motion.h"
#include "vo/ransac.h"
#include "vo/types.h"

namespace vo {

// The motion stage's options (vo_options.yaml `motion`, and `vehicle`): RANSAC and the inliers a
// measured motion needs, how far it moves the constant-velocity prior, the few-point motion and
// the ground vehicle's model (its checks of a weak motion here; the recovery and the back end
// read ground_vehicle and few_point's axle from here too).
struct MotionOptions {
  RansacOptions ransac;                // robust frame-to-frame motion
  bool ransac_refine_with_ba = false;  // keep RANSAC's nonlinear refinement
                                       // (ransac.refine_nonlinear) when the BA runs after it;
                                       // false = skip it then (the BA refines anyway; saves
                                       // ~3 ms at 300 features). Without BA it always runs
                                       // as ransac.refine_nonlinear says
  int min_inliers = 12;           // fewer RANSAC inliers than this → lost, >= 3 (RANSAC's own
                                  // min_inliers is raised to this when lower)
  int reliable_min_inliers = 30;  // a motion with at least this many inliers replaces the
                                  // constant-velocity prior; one with fewer moves it only
                                  // part of the way (slerp), one whose bundle
                                  // adjustment was rejected not at all; >= 3. 30 =
                                  // TrackerOptions::confident_min_inliers: a motion the matcher
                                  // trusts is one the prior may repeat
  double prior_update_exponent = 2.0;  // ... namely (inliers / reliable_min_inliers) to
                                       // this power of the way, >= 1: a weak motion is
                                       // also more often grossly wrong (12 inliers at the edge
                                       // of a plain wall: 1-4 deg of yaw where the robot drove
                                       // straight), not only noisier, so half the support
                                       // moves the prior a quarter of the way. Measured on
                                       // l_hallway texture seeds 1-10 x strides 1/2/3/5 (40
                                       // runs, defaults): exponent 1 / 1.5 / 2 / 3 gave mean
                                       // end-pose error 0.442 / 0.419 / 0.398 / 0.393 m,
                                       // median 0.182 / 0.157 / 0.141 / 0.143 m; 3 took
                                       // camera.pitch_deg 10 to 1.40 % (2: 0.73 %)
  // Off unless platform ground_vehicle (measured below). The camera rides a wheeled ground vehicle:
  // where the images cannot measure the motion, it is a wheeled vehicle's. The few-point motion is
  // a yaw about the world's up and a forward distance of the axle, without sideways slip
  // (prior_motion.h, "Ground vehicle"; few_point.no_sideways_slip, few_point.axle_behind_camera_m);
  // its prior, the constant-velocity bridge of a lost frame, loses roll, pitch and lift; a lost
  // frame's rotation from the image shift is a yaw only (the shift's vertical part is zoom and
  // parallax; recovery.h). Needs the up direction from the first frame's orientation (the floor
  // found); without it, 6-DoF. Measured on l_hallway texture seeds 1-10 x strides 1/2/3/5 (40
  // runs, results/robustness/, with the lost-frame chain, prior_update_exponent 2 and the
  // recovery's vehicle_* options): with few_point_motion, mean end-pose error 0.375 -> 0.306 m,
  // median 0.136 -> 0.131 m, runs <= 0.29 m 26 -> 30, frames without motion 256 -> 171 against
  // the defaults, max 1.498 -> 2.723 m (texture seed 3, stride 5); with the rig's axle (0.15 m)
  // mean 0.294 m and at stride 1 max 1.129 -> 0.588 m; but camera.pitch_deg 10 goes 0.73 -> 1.13
  // % (drift on the straight approach that the 6-DoF window BA keeps; 0.33 % with
  // vehicle_planar_ba and the axle), so not the default yet. On its own (few_point_motion off)
  // the mean goes 0.375 -> 0.347 m, pitch 10 0.73 -> 0.47 %.
  bool ground_vehicle = false;
  // With ground_vehicle: a weak tracked motion (fewer than reliable_min_inliers RANSAC inliers)
  // that tilts the camera (rotation about an axis across up, the swing of its twist
  // decomposition) by more than vehicle_max_weak_tilt_deg, or lifts it along up by more than
  // vehicle_max_weak_lift_m, is no wheeled vehicle's motion and is rejected (the frame goes on
  // as one whose RANSAC failed: few-point motion, chain or bridge). On a plain wall a few
  // coplanar points let a pitch trade against a vertical step that shows the same image shift:
  // texture seed 3, stride 2, frame 100: 20 inliers, 9.0° of pitch and 0.19 m down while the
  // robot drove straight. Both > 0. Measured with few_point_motion and the rig's axle (0.15 m)
  // on l_hallway texture seeds 1-10 x strides 1/2/3/5 (40 runs): mean end-pose error 0.320 ->
  // 0.304 m; plain_corridor strides 2/3/5 0.168 / 0.415 / 0.379 -> 0.102 / 0.313 / 0.094 m.
  double vehicle_max_weak_tilt_deg = 2.0;
  double vehicle_max_weak_lift_m = 0.03;
  bool few_point_motion = false;  // off unless platform ground_vehicle (measured, l_hallway texture
                                  // seeds 1-10: stride 1 lost frames 113 -> 38, median end-pose
                                  // error 0.347 -> 0.152 m, but strides 2 and 3 worse on seeds 2,
                                  // 5, 10: median 0.256 -> 0.331 m at stride 2). On: when RANSAC
                                  // finds no consensus (too few features or
                                  // matches, or fewer than min_inliers of them agree: a plain
                                  // wall in front of the camera), the motion is
                                  // estimated from the few matches and the motion prior
                                  // (prior_motion.h: 1-point rotation hypotheses, then a
                                  // Gauss-Newton fit regularised by the prior) instead of losing
                                  // the frame; needs a prior (not on the first tracked frame)
  int few_point_min_features = 3;  // a frame with fewer than the front end's min_features
                                   // features with depth, but at least this many, is still
                                   // matched against the reference (few_point_motion), >= 1
  PriorMotionOptions few_point;    // that solver (fewer inliers than its min_inliers and
                                   // min_inlier_fraction: lost); its axle_behind_camera_m and
                                   // no_sideways_slip are the vehicle's
  double few_point_max_shift_disagreement_px =
      3.0;                              // a few-point motion is rejected when
                                        // the image shift it predicts (the image centre at the
                                        // reference's median depth) is farther from the
                                        // coarse-to-fine shift measured for the frame than the
                                        // prior's prediction is, by more than this (pixels), >= 0:
                                        // two wrong matches that agree must not turn the camera by
                                        // degrees that the image does not show, while the global
                                        // shift's own error (parallax and zoom of forward motion)
                                        // is what the prior shows too. No check without a shift.
                                        // A few-point frame is never bundle-adjusted: a BA over a
                                        // few points has no prior and is weaker than the solver
  double few_point_prior_update = 1.0;  // weight of a few-point motion in the constant-velocity
                                        // prior, in [0, 1] (the solver's estimate already
                                        // contains the prior)

  bool IsValid(std::string* error) const;
};

// One matching pass and its RANSAC motion.
struct MotionAttempt {
  std::vector<Match> matches;
  std::vector<int> match_index;  // correspondence → index into matches
  std::vector<StereoCorrespondence> correspondences;
  RansacResult ransac;
  PredictionSource source = PredictionSource::kNone;
  int inliers() const { return ransac.ok() ? ransac.num_inliers : 0; }
};

// RANSAC on the matches (both features with depth), seeded by track ages.
MotionAttempt EstimateMotion(const StereoCamera& camera, const RansacOptions& ransac,
                             const std::vector<Feature>& ref_features,
                             const std::vector<Feature>& curr_features, std::vector<Match> matches,
                             PredictionSource source);

// The few-point motion (prior_motion.h) of `correspondences` from the prior T_ref_curr_prior;
// with up_ref (the world's up in the reference camera frame: a ground vehicle whose up is
// known; null otherwise) made planar: the prior without roll, pitch and lift, the correction
// about that up. *few_prior: the prior the solver used.
PriorMotionResult FewPointMotion(const StereoCamera& camera, const PriorMotionOptions& few_point,
                                 const std::vector<StereoCorrespondence>& correspondences,
                                 const Eigen::Isometry3d& T_ref_curr_prior,
                                 const Eigen::Vector3d* up_ref, Eigen::Isometry3d* few_prior);

// Whether a motion T_ref_curr measured from few matches agrees with the frame's coarse-to-fine
// image shift (when found: shift_ok): the shift it predicts at the image centre (ref_features'
// median depth) is no farther from the measured one than the prior's prediction, by more than
// max_disagreement_px.
bool AgreesWithImageShift(const StereoCamera& camera, const std::vector<Feature>& ref_features,
                          const Eigen::Isometry3d& T_ref_curr,
                          const Eigen::Isometry3d& T_ref_curr_prior, bool shift_ok,
                          const Eigen::Vector2d& shift_px, double max_disagreement_px);

// How far a measured motion with num_inliers RANSAC inliers moves the constant velocity:
// (num_inliers / reliable_min_inliers)^prior_update_exponent, at most 1.
double PriorUpdateWeight(int num_inliers, const MotionOptions& options);

// What a frame's matching pass gave as its motion.
struct FrameMotion {
  bool few_features = false;      // fewer than min_features features with depth: no RANSAC
  bool not_vehicle_like = false;  // a weak RANSAC motion that tilts or lifts the ground vehicle
  bool ransac_failed = false;     // no usable RANSAC motion (any of the above, no consensus,
                                  // fewer than min_inliers inliers, not finite)
  bool few_point = false;         // the few-point motion replaced it (in attempt->ransac)
  std::string message;            // the few-point motion's, when used
  bool ok() const { return few_point || !ransac_failed; }
};

// The frame's motion from `attempt` (its RANSAC result replaced by the few-point motion when
// that is used; see the header comment). few_features: the frame has fewer than the front end's
// min_features features with depth (no RANSAC motion); up_ref: the world's up in the reference
// camera frame for a ground vehicle whose up is known (null otherwise); T_ref_curr_prior: the
// prior's motion (null = none); prior_measured: the previous frame's motion was measured, no
// frame was lost since and the matches are predicted (matcher.prediction is not kNone): a prior
// the few-point motion may correct; shift_ok / shift_px: the frame's coarse-to-fine image shift.
FrameMotion ResolveFrameMotion(const StereoCamera& camera, const MotionOptions& options,
                               bool few_features, const std::vector<Feature>& ref_features,
                               const Eigen::Vector3d* up_ref,
                               const Eigen::Isometry3d* T_ref_curr_prior, bool prior_measured,
                               bool shift_ok, const Eigen::Vector2d& shift_px,
                               MotionAttempt* attempt);

// Why a frame's motion failed ("motion failed: ...", with the counts), for its message.
std::string MotionFailureMessage(const FrameMotion& motion, const MotionAttempt& attempt,
                                 int min_inliers);

}  // namespace vo
