// Motion estimation: a frame's motion from the reference from its matches (paper, section V:
// RANSAC over Horn's closed form, seeded by track ages; ransac.h, horn.h), and where RANSAC finds
// no usable consensus the few-point motion with the prior (tracking.few_point_motion, beyond the
// paper; prior_motion.h).
//
// Few points (off on the free platform, on for a ground vehicle: OdometryOptions::platform).
// While tracking normally (the previous frame's motion measured, no loss since), a frame with
// too few matches for RANSAC (fewer correspondences than min_inliers), with fewer than
// min_features features with depth (down to tracking.few_point_min_features; such a frame takes
// no RANSAC motion, only this one), or — a ground vehicle — whose weak RANSAC motion tilts or
// lifts the vehicle (tracking.vehicle_max_weak_tilt_deg, IsVehicleLike), takes the few-point
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
#include "vo/odometry_options.h"
#include "vo/odometry_result.h"
#include "vo/prior_motion.h"
#include "vo/ransac.h"
#include "vo/types.h"

namespace vo {

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
double PriorUpdateWeight(int num_inliers, const RobustTrackingOptions& tracking);

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
// that is used; see the header comment). num_features: the frame's features with depth;
// up_ref: the world's up in the reference camera frame for a ground vehicle whose up is known
// (null otherwise); T_ref_curr_prior: the prior's motion (null = none); prior_measured: the
// previous frame's motion was measured and no frame was lost since; shift_ok / shift_px: the
// frame's coarse-to-fine image shift.
FrameMotion ResolveFrameMotion(const StereoCamera& camera, const OdometryOptions& options,
                               int num_features, const std::vector<Feature>& ref_features,
                               const Eigen::Vector3d* up_ref,
                               const Eigen::Isometry3d* T_ref_curr_prior, bool prior_measured,
                               bool shift_ok, const Eigen::Vector2d& shift_px,
                               MotionAttempt* attempt);

// Why a frame's motion failed ("motion failed: ...", with the counts), for its message.
std::string MotionFailureMessage(const FrameMotion& motion, const MotionAttempt& attempt,
                                 int min_inliers);

}  // namespace vo
