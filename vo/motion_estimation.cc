#include "vo/motion_estimation.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "vo/motion_model.h"
#include "vo/options_check.h"

namespace vo {

bool MotionOptions::IsValid(std::string* error) const {
  if (!PartIsValid(ransac, "ransac", error) ||
      (few_point_motion && !PartIsValid(few_point, "few_point", error))) {
    return false;
  }
  std::ostringstream msg;
  if (min_inliers < 3) {
    msg << "min_inliers must be >= 3, got " << min_inliers;
  } else if (reliable_min_inliers < 3) {
    msg << "reliable_min_inliers must be >= 3, got " << reliable_min_inliers;
  } else if (!(prior_update_exponent >= 1.0) || !std::isfinite(prior_update_exponent)) {
    msg << "prior_update_exponent must be finite and >= 1, got " << prior_update_exponent;
  } else if (!(few_point_max_shift_disagreement_px >= 0.0) ||
             !std::isfinite(few_point_max_shift_disagreement_px)) {
    msg << "few_point_max_shift_disagreement_px must be finite and >= 0, got "
        << few_point_max_shift_disagreement_px;
  } else if (!(vehicle_max_weak_tilt_deg > 0.0) || !std::isfinite(vehicle_max_weak_tilt_deg) ||
             !(vehicle_max_weak_lift_m > 0.0) || !std::isfinite(vehicle_max_weak_lift_m)) {
    msg << "vehicle_max_weak_tilt_deg and vehicle_max_weak_lift_m must be finite and > 0, got "
        << vehicle_max_weak_tilt_deg << " and " << vehicle_max_weak_lift_m;
  } else if (few_point_min_features < 1) {
    msg << "few_point_min_features must be >= 1, got " << few_point_min_features;
  } else if (!(few_point_prior_update >= 0.0 && few_point_prior_update <= 1.0)) {
    msg << "few_point_prior_update must be in [0, 1], got " << few_point_prior_update;
  }
  return NoBrokenRule(msg, error);
}

MotionAttempt EstimateMotion(const StereoCamera& camera, const RansacOptions& ransac,
                             const std::vector<Feature>& ref_features,
                             const std::vector<Feature>& curr_features, std::vector<Match> matches,
                             PredictionSource source) {
  MotionAttempt a;
  a.matches = std::move(matches);
  a.source = source;
  a.correspondences =
      MakeStereoCorrespondences(ref_features, curr_features, a.matches, &a.match_index);
  a.ransac = EstimateMotionRansac(camera, a.correspondences, ransac);
  return a;
}

PriorMotionResult FewPointMotion(const StereoCamera& camera, const PriorMotionOptions& few_point,
                                 const std::vector<StereoCorrespondence>& correspondences,
                                 const Eigen::Isometry3d& T_ref_curr_prior,
                                 const Eigen::Vector3d* up_ref, Eigen::Isometry3d* few_prior) {
  // A ground vehicle's motion is planar: the prior without roll, pitch and lift, and the
  // correction about the world's up (known when the first frame's orientation found the
  // floor), as the reference's pose puts it.
  const bool planar = up_ref != nullptr;
  const Eigen::Vector3d up = planar ? *up_ref : Eigen::Vector3d::UnitZ();
  *few_prior = planar ? PlanarPart(T_ref_curr_prior, up) : T_ref_curr_prior;
  const Eigen::Vector3d up_curr = few_prior->linear().transpose() * up;
  return EstimateMotionWithPrior(camera, correspondences, *few_prior, few_point,
                                 planar ? &up_curr : nullptr);
}

bool AgreesWithImageShift(const StereoCamera& camera, const std::vector<Feature>& ref_features,
                          const Eigen::Isometry3d& T_ref_curr,
                          const Eigen::Isometry3d& T_ref_curr_prior, bool shift_ok,
                          const Eigen::Vector2d& shift_px, double max_disagreement_px) {
  if (!shift_ok) return true;
  // The image shift the motions predict at the image centre (the reference's median depth)
  // against the measured one.
  std::vector<double> z;
  for (const Feature& f : ref_features) {
    if (f.has_depth() && f.p_cam0.allFinite()) z.push_back(f.p_cam0.z());
  }
  double depth_m = -1.0;
  if (!z.empty()) {
    std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
    depth_m = z[z.size() / 2];
  }
  const double motion_px = (PredictedCentreShift(camera, T_ref_curr, depth_m) - shift_px).norm();
  const double prior_px =
      (PredictedCentreShift(camera, T_ref_curr_prior, depth_m) - shift_px).norm();
  return motion_px <= prior_px + max_disagreement_px;
}

double PriorUpdateWeight(int num_inliers, const MotionOptions& options) {
  return std::pow(std::min(1.0, static_cast<double>(num_inliers) / options.reliable_min_inliers),
                  options.prior_update_exponent);
}

FrameMotion ResolveFrameMotion(const StereoCamera& camera, const MotionOptions& options,
                               bool few_features, const std::vector<Feature>& ref_features,
                               const Eigen::Vector3d* up_ref,
                               const Eigen::Isometry3d* T_ref_curr_prior, bool prior_measured,
                               bool shift_ok, const Eigen::Vector2d& shift_px,
                               MotionAttempt* attempt) {
  // No consensus (too few matches, or fewer than min_inliers of them agree), or a frame with
  // fewer than min_features features (matched only for this): the few-point solver with the
  // prior. Such a frame takes no RANSAC motion. (Until 2026-12-03 a frame with min_inliers
  // matches or more but fewer inliers was left lost: texture seed 10, stride 1, frame 204, 11
  // of 13.) So does a ground vehicle's frame whose weak RANSAC motion tilts or lifts it: until
  // 2026-12-04 it was left lost when that motion had min_inliers inliers or more (9 of the 31
  // lost frames of texture seeds 1-10 at stride 1, 12-27 inliers each).
  RansacResult& ransac = attempt->ransac;
  const std::vector<StereoCorrespondence>& correspondences = attempt->correspondences;
  FrameMotion m;
  m.few_features = few_features;
  m.ransac_failed = m.few_features || !ransac.ok() || ransac.num_inliers < options.min_inliers ||
                    !IsFinitePose(ransac.T_prev_curr);
  // A ground vehicle neither tilts nor lifts: a weak motion that does is a wrong consensus.
  m.not_vehicle_like =
      !m.ransac_failed && up_ref != nullptr && ransac.num_inliers < options.reliable_min_inliers &&
      !IsVehicleLike(ransac.T_prev_curr, *up_ref, options.vehicle_max_weak_tilt_deg,
                     options.vehicle_max_weak_lift_m);
  if (m.not_vehicle_like) m.ransac_failed = true;
  if (m.ransac_failed && options.few_point_motion && T_ref_curr_prior != nullptr &&
      prior_measured && !correspondences.empty() &&
      (m.few_features || m.not_vehicle_like || ransac.num_inliers < options.min_inliers)) {
    Eigen::Isometry3d few_prior;
    const PriorMotionResult few = FewPointMotion(camera, options.few_point, correspondences,
                                                 *T_ref_curr_prior, up_ref, &few_prior);
    const bool agrees =
        few.ok && AgreesWithImageShift(camera, ref_features, few.T_prev_curr, few_prior, shift_ok,
                                       shift_px, options.few_point_max_shift_disagreement_px);
    if (agrees) {
      ransac.status = RansacResult::Status::kOk;
      ransac.message.clear();
      ransac.T_prev_curr = few.T_prev_curr;
      ransac.inlier_mask = few.inlier_mask;
      ransac.num_inliers = few.num_inliers;
      ransac.rms_reprojection_px = few.rms_reprojection_px;
      m.few_point = true;
      std::ostringstream msg;
      msg << "few-point motion with the prior (" << few.num_inliers << " inliers of "
          << correspondences.size() << " correspondences)";
      m.message = msg.str();
    }
  }
  return m;
}

std::string MotionFailureMessage(const FrameMotion& motion, const MotionAttempt& attempt,
                                 int min_inliers) {
  const RansacResult& ransac = attempt.ransac;
  std::ostringstream why;
  why << "motion failed: "
      << (motion.few_features       ? "too few features for RANSAC, no few-point motion"
          : motion.not_vehicle_like ? "a weak motion tilts or lifts the ground vehicle (more than "
                                      "tracking.vehicle_max_weak_tilt_deg / _lift_m)"
          : ransac.ok()             ? "too few inliers"
                                    : ToString(ransac.status))
      << " (" << ransac.num_inliers << " inliers of " << attempt.correspondences.size()
      << " correspondences, " << attempt.matches.size() << " matches; need " << min_inliers
      << (motion.not_vehicle_like ? ", and tracking.reliable_min_inliers to pass without the check"
                                  : "")
      << ")";
  if (!ransac.message.empty()) why << ": " << ransac.message;
  return why.str();
}

}  // namespace vo
