// The tracker: the stage that finds a frame's matches against the reference (or against the
// previous lost frame, for the lost-frame chain). It owns the inter-frame matcher (matcher.h:
// SVD · NCC · Gabor by default, the baselines) and runs it in up to four passes, each centred
// on a different guess of where the reference's features went: the motion prior's prediction,
// the coarse-to-fine image shift, the reference's own last motion, and — a guided pass — the
// motion just estimated; each pass is followed by RANSAC (motion_estimation.h), the pass with
// the most inliers is kept and OdometryResult::prediction says which. It receives the two
// frames, the prior's motion, the constant velocity and the reference's up (TrackingContext),
// nothing else of the pipeline; its options are TrackerOptions (the `tracker` group of
// vo_options.yaml: tracker.matcher, the gates, the confidence thresholds), and each pass's RANSAC
// and the few-point tie-break read the motion stage's MotionOptions. The passes in detail:
//
// Predicted matching (matcher.prediction = kMotionPrior, the default; kNone = the paper's
// unpredicted form, every position gate centred on the previous position). Beyond the paper,
// whose proximity term exp(−d²/2σ²) with σ = 10 px stops at ~28 px of image motion:
//   1. prior pass: each reference feature's 3D point is moved by the motion prior (the
//      constant-velocity motion from the last RELIABLE frame, or the caller's MotionPrior) and
//      projected (PredictFeaturePositions); every matcher centres its position gate there
//      (MatchPrediction), then RANSAC.
//   2. coarse-to-fine pass, when the prior is weak (no motion known yet, after a lost frame)
//      or contradicted (fewer inliers than confident_min_inliers or
//      confident_inlier_fraction of the features): the dominant image shift from the reference
//      to this frame on an image pyramid (image_motion.h, the paper's "multi-scale analysis"),
//      matching around uv + shift with gates widened by shift_radius_scale, then RANSAC; the
//      pass with more inliers is kept. When neither pass reaches a RANSAC consensus, the pass
//      whose matches support more of the few-point motion is kept (a prior that lags a turn
//      would otherwise win the tie).
//   2b. last-motion pass, when still not confident and the reference (the previous frame)
//      measured its own motion: matching around that motion as measured
//      (last_motion_pass). The prior takes a weak motion in only in part, so it lags
//      a turn that starts; the pass with more inliers is kept.
//   3. guided pass: every reference feature predicted with the motion just estimated, matched
//      in a tight window (guided_radius_scale), RANSAC; kept when it has at least as many
//      inliers, so more correct matches reach the bundle adjustment.
// The stateful Kalman tracker runs pass 1 only. OdometryResult::prediction says which pass
// the used matches came from; StageTimes::predict_ms / guided_ms time the new steps.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <string>

#include "vo/camera.h"
#include "vo/image_motion.h"
#include "vo/matcher.h"
#include "vo/motion_estimation.h"
#include "vo/motion_model.h"
#include "vo/odometry_result.h"

namespace vo {

// Image-shift defaults for the pipeline's coarse-to-fine pass: min_score 0.1 instead of 0.3. A
// wrong shift only costs one matching pass that loses to the other on inliers, while a turn
// past nearby walls (perspective, parallax) scores ZNCC ~0.3 at the right shift; the pose
// bridge of a lost frame asks for more (RecoveryOptions::rotation_min_shift_score).
ImageShiftOptions DefaultTrackingImageShiftOptions();

// The tracker's options (vo_options.yaml `tracker`): the matcher and its passes (beyond the
// paper's unpredicted matcher when matcher.prediction is kMotionPrior; see the header comment).
struct TrackerOptions {
  MatcherOptions matcher;      // inter-frame matcher (default: SVD · NCC · Gabor)
  bool coarse_to_fine = true;  // when the prior is weak (no reliable motion yet, after a lost
                               // frame) or contradicted (the first pass is not confident),
                               // estimate the dominant image shift coarse-to-fine
                               // (image_motion.h) and match again around it
  ImageShiftOptions image_shift = DefaultTrackingImageShiftOptions();  // the coarse-to-fine
                                                                       // estimate (also the
                                                                       // recovery's shift)
  bool last_motion_pass = true;     // still not confident after that: when the reference (the
                                    // previous frame) measured its own motion and it predicts
                                    // otherwise than the prior (which blends a weak motion in only
                                    // in part), match again around that motion; the pass with more
                                    // inliers wins
  double prior_radius_scale = 0.5;  // the matcher's position gates around the motion prior's
                                    // prediction are scaled by this, in [0.05, 20]: the
                                    // prediction leaves a few pixels (SVD σ 10 → 5 px), and
                                    // a contradicted prior falls to the coarse-to-fine pass
  double shift_radius_scale = 2.0;  // the matcher's position gates are widened by this around
                                    // a shift estimate (a global shift ignores parallax),
                                    // in [0.05, 20]
  int confident_min_inliers = 30;   // a first pass with fewer RANSAC inliers than this (or than
                                    // MotionOptions::min_inliers) ...
  double confident_inlier_fraction = 0.2;  // ... or than this fraction of the smaller feature
                                           // count of the two frames, in [0, 1], is not
                                           // confident: the coarse-to-fine pass is tried too
                                           // and the one with more inliers is kept
  bool guided_rematch = true;              // after RANSAC, predict every reference feature with the
                               // estimated motion and match again in a tight window; the
                               // second pass is kept when it has at least as many inliers
  double guided_radius_scale = 0.3;  // gate scale of that pass (σ 10 px → 3 px), [0.05, 20]

  bool IsValid(std::string* error) const;
};

// What one matching of a frame knows besides the two frames.
struct TrackingContext {
  const Eigen::Isometry3d* T_ref_curr_prior = nullptr;  // the prior's motion from the
                                                        // reference to the frame (null: none)
  bool after_loss = false;  // frames were lost since the last tracked one (the prior is weak)
  const ConstantVelocity* velocity = nullptr;  // its last measured motion (pass 2b; may be null)
  // With few_point_motion, a 0-0 tie of the prior's and the shift's pass goes to the one the
  // few-point motion supports more (only against the reference, whose pose is in the window).
  bool few_point_tie = true;
  const Eigen::Vector3d* up_ref = nullptr;  // the world's up in the reference camera frame for
                                            // a ground vehicle (FewPointMotion; null: 6-DoF)
};

class Tracker {
 public:
  // nullptr (and *error filled) when options.matcher cannot build a matcher. motion: each
  // pass's RANSAC (ransac, min_inliers) and the few-point tie-break (few_point_motion,
  // few_point).
  static std::unique_ptr<Tracker> Create(const StereoCamera& camera, const TrackerOptions& options,
                                         const MotionOptions& motion, std::string* error);
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;

  // Matches `frame` against `ref` with the prediction passes; fills the prediction fields
  // (num_first_pass_inliers, image_shift_ok/_px) and times of `result`. A matcher failure
  // leaves *matcher_error set and returns the best pass so far.
  MotionAttempt MatchAndEstimate(const MatchFrame& ref, const MatchFrame& frame,
                                 const TrackingContext& context, OdometryResult* result,
                                 std::string* matcher_error);

  // RANSAC on given matches (the seam), as each pass does after matching.
  MotionAttempt Estimate(const std::vector<Feature>& ref_features,
                         const std::vector<Feature>& curr_features, std::vector<Match> matches,
                         PredictionSource source) const;

  // Frames are skipped from the matcher's point of view (the Kalman tracker keeps state).
  void Reset() { matcher_->Reset(); }
  MatcherType matcher_type() const { return matcher_->type(); }

 private:
  Tracker(const StereoCamera& camera, const TrackerOptions& options, const MotionOptions& motion,
          std::unique_ptr<FrameMatcher> matcher);

  StereoCamera camera_;
  TrackerOptions options_;
  MotionOptions motion_;
  std::unique_ptr<FrameMatcher> matcher_;
};

}  // namespace vo
