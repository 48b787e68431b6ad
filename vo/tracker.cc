#include "vo/tracker.h"

#include <algorithm>
#include <chrono>
#include <sstream>
#include <utility>

#include "vo/image_motion.h"
#include "vo/options_check.h"

namespace vo {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

ImageShiftOptions DefaultTrackingImageShiftOptions() {
  ImageShiftOptions options;
  options.min_score = 0.1;
  return options;
}

bool TrackerOptions::IsValid(std::string* error) const {
  if (!PartIsValid(matcher, "matcher", error) ||
      (coarse_to_fine && !PartIsValid(image_shift, "image_shift", error))) {
    return false;
  }
  std::ostringstream msg;
  if (!(prior_radius_scale >= 0.05 && prior_radius_scale <= 20.0)) {
    msg << "prior_radius_scale must be in [0.05, 20], got " << prior_radius_scale;
  } else if (!(shift_radius_scale >= 0.05 && shift_radius_scale <= 20.0)) {
    msg << "shift_radius_scale must be in [0.05, 20], got " << shift_radius_scale;
  } else if (confident_min_inliers < 0) {
    msg << "confident_min_inliers must be >= 0, got " << confident_min_inliers;
  } else if (!(confident_inlier_fraction >= 0.0 && confident_inlier_fraction <= 1.0)) {
    msg << "confident_inlier_fraction must be in [0, 1], got " << confident_inlier_fraction;
  } else if (!(guided_radius_scale >= 0.05 && guided_radius_scale <= 20.0)) {
    msg << "guided_radius_scale must be in [0.05, 20], got " << guided_radius_scale;
  }
  return NoBrokenRule(msg, error);
}

std::unique_ptr<Tracker> Tracker::Create(const StereoCamera& camera, const TrackerOptions& options,
                                         const MotionOptions& motion, std::string* error) {
  std::string why;
  std::unique_ptr<FrameMatcher> matcher = CreateFrameMatcher(options.matcher, &why);
  if (!matcher) {
    if (error) *error = why;
    return nullptr;
  }
  return std::unique_ptr<Tracker>(new Tracker(camera, options, motion, std::move(matcher)));
}

Tracker::Tracker(const StereoCamera& camera, const TrackerOptions& options,
                 const MotionOptions& motion, std::unique_ptr<FrameMatcher> matcher)
    : camera_(camera), options_(options), motion_(motion), matcher_(std::move(matcher)) {}

MotionAttempt Tracker::Estimate(const std::vector<Feature>& ref_features,
                                const std::vector<Feature>& curr_features,
                                std::vector<Match> matches, PredictionSource source) const {
  return EstimateMotion(camera_, motion_.ransac, ref_features, curr_features, std::move(matches),
                        source);
}

MotionAttempt Tracker::MatchAndEstimate(const MatchFrame& ref, const MatchFrame& frame,
                                        const TrackingContext& context, OdometryResult* result,
                                        std::string* matcher_error) {
  const Eigen::Isometry3d* T_ref_curr_prior = context.T_ref_curr_prior;
  const TrackerOptions& o = options_;
  // One pass: match around `prediction`, then RANSAC. Times go to `match_ms` / `motion_ms`.
  auto pass = [&](const MatchPrediction& prediction, PredictionSource source, double* match_ms,
                  double* motion_ms, MotionAttempt* attempt) {
    Clock::time_point t = Clock::now();
    MatcherSummary summary;
    std::vector<Match> matches = matcher_->MatchFrames(ref, frame, prediction, &summary);
    *match_ms += ElapsedMs(t);
    if (!summary.ok) {
      *matcher_error = summary.message;
      return false;
    }
    t = Clock::now();
    *attempt = Estimate(ref.features, frame.features, std::move(matches), source);
    *motion_ms += ElapsedMs(t);
    return true;
  };
  MotionAttempt best;
  StageTimes& times = result->times;
  if (options_.matcher.prediction == PredictionMode::kNone) {  // the paper's form
    pass(MatchPrediction(), PredictionSource::kNone, &times.match_ms, &times.motion_ms, &best);
    result->num_first_pass_inliers = best.inliers();
    return best;
  }

  // 1. Centred on the motion prior's prediction (previous positions without a prior).
  Clock::time_point t = Clock::now();
  MatchPrediction prediction;
  PredictionSource source = PredictionSource::kNone;
  if (T_ref_curr_prior != nullptr) {
    prediction.uv_px = PredictFeaturePositions(camera_, ref.features, *T_ref_curr_prior,
                                               RansacOptions::kMinDepthM);
    prediction.radius_scale = o.prior_radius_scale;
    source = PredictionSource::kMotionPrior;
  }
  times.predict_ms += ElapsedMs(t);
  if (!pass(prediction, source, &times.match_ms, &times.motion_ms, &best)) return best;
  result->num_first_pass_inliers = best.inliers();
  // The stateful Kalman tracker sees each frame pair once.
  if (matcher_->type() == MatcherType::kKalman) return best;

  // 2. Weak (no reliable motion yet, or after a loss) or contradicted prior: the dominant image
  //    shift, coarse-to-fine, and a wider search around it; the pass with more inliers wins.
  const double smaller = static_cast<double>(std::min(ref.features.size(), frame.features.size()));
  const bool weak = T_ref_curr_prior == nullptr || context.after_loss;
  auto confident = [&](const MotionAttempt& a) {
    return a.inliers() >= std::max(motion_.min_inliers, o.confident_min_inliers) &&
           a.inliers() >= o.confident_inlier_fraction * smaller;
  };
  if (o.coarse_to_fine && (weak || !confident(best))) {
    t = Clock::now();
    const ImageShiftResult shift = EstimateImageShift(ref.image, frame.image, o.image_shift);
    result->image_shift_ok = shift.ok;
    if (shift.ok) result->image_shift_px = shift.shift_px;
    times.predict_ms += ElapsedMs(t);
    if (shift.ok) {
      MatchPrediction shifted;
      shifted.radius_scale = o.shift_radius_scale;
      shifted.uv_px.reserve(ref.features.size());
      for (const Feature& f : ref.features) shifted.uv_px.push_back(f.uv_px + shift.shift_px);
      MotionAttempt attempt;
      if (!pass(shifted, PredictionSource::kImageShift, &times.match_ms, &times.motion_ms,
                &attempt)) {
        return best;
      }
      if (attempt.inliers() > best.inliers()) {
        best = std::move(attempt);
      } else if (best.inliers() == 0 && attempt.inliers() == 0 && motion_.few_point_motion &&
                 context.few_point_tie && T_ref_curr_prior != nullptr) {
        // Neither pass has a RANSAC consensus (too few features: the few-point solver will
        // decide). The prior's pass must not win by default: a prior that lags a turn centres
        // its gates where the features are not and picks up neighbours that agree with it.
        // The pass whose matches support more of the few-point motion is kept.
        Eigen::Isometry3d unused;
        const PriorMotionResult few_best =
            FewPointMotion(camera_, motion_.few_point, best.correspondences, *T_ref_curr_prior,
                           context.up_ref, &unused);
        const PriorMotionResult few_shift =
            FewPointMotion(camera_, motion_.few_point, attempt.correspondences, *T_ref_curr_prior,
                           context.up_ref, &unused);
        if (few_shift.ok && (!few_best.ok || few_shift.num_inliers > few_best.num_inliers)) {
          best = std::move(attempt);
        }
      }
    }
  }

  // 2b. Still not confident, and the previous frame (the reference) measured its own motion: a
  //     pass around that motion as measured. The prior took a weak motion in only in part, so
  //     where a turn starts it lags (l_hallway, camera pitched 20°, stride 2: 12 px behind at the
  //     radiator whose fins repeat every 12 px, where the image shift, 65 px, was ambiguous too).
  //     Skipped when both predict the same (within a pixel at the image centre).
  if (o.last_motion_pass && !confident(best) && T_ref_curr_prior != nullptr &&
      context.velocity != nullptr && context.velocity->last_measured_frame() >= 0 &&
      ref.frame_id == context.velocity->last_measured_frame() &&
      frame.frame_id == ref.frame_id + 1 &&
      (PredictedCentreShift(camera_, context.velocity->last_measured(), -1.0) -
       PredictedCentreShift(camera_, *T_ref_curr_prior, -1.0))
              .norm() > 1.0) {
    t = Clock::now();
    MatchPrediction measured;
    measured.uv_px = PredictFeaturePositions(
        camera_, ref.features, context.velocity->last_measured(), RansacOptions::kMinDepthM);
    measured.radius_scale = o.prior_radius_scale;
    times.predict_ms += ElapsedMs(t);
    MotionAttempt attempt;
    if (!pass(measured, PredictionSource::kLastMotion, &times.match_ms, &times.motion_ms,
              &attempt)) {
      return best;
    }
    if (attempt.inliers() > best.inliers()) best = std::move(attempt);
  }

  // 3. Guided second pass: every reference feature predicted with the estimated motion, matched
  //    in a tight window, so more correct matches reach the bundle adjustment.
  if (o.guided_rematch && best.ransac.ok() && IsFinitePose(best.ransac.T_prev_curr)) {
    t = Clock::now();
    MatchPrediction guided;
    guided.uv_px = PredictFeaturePositions(camera_, ref.features, best.ransac.T_prev_curr,
                                           RansacOptions::kMinDepthM);
    guided.radius_scale = o.guided_radius_scale;
    guided.coherence_test = false;
    double match_ms = 0.0, motion_ms = 0.0;
    MotionAttempt attempt;
    const bool ok = pass(guided, PredictionSource::kGuided, &match_ms, &motion_ms, &attempt);
    times.guided_ms += ElapsedMs(t);
    if (!ok) return best;
    if (attempt.inliers() >= best.inliers()) best = std::move(attempt);
  }
  return best;
}

}  // namespace vo
