// `vobench match-eval`: matcher precision / recall / F1 against the simulator's ground truth.
//
// Ground truth of a match: a feature of frame k at pixel u with ground-truth depth z is
// back-projected, moved into frame k+s with the ground-truth poses and projected; it is
// visible there when it lands inside the image and the ground-truth depth of frame k+s at
// that pixel agrees with its depth (no occluder). A match (i, j) is correct when feature j of
// frame k+s lies within `correct_px` of that projection.
//   precision = correct / evaluated matches   (a match of a feature that is not visible in
//               frame k+s counts as wrong)
//   recall    = correct / possible, possible = evaluated features of frame k with a
//               detected feature of frame k+s within correct_px of their projection
// Features whose ground-truth depth is ambiguous (a depth edge inside their 3x3 neighbourhood)
// are left out of both counts. Features are those the VO uses: detector output with a valid
// stereo disparity (features without depth are dropped, as in the paper).
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/disparity.h"
#include "vo/features.h"
#include "vo/matcher.h"
#include "vo/odometry.h"

namespace harness {

// One frame with what the evaluation needs.
struct GroundTruthFrame {
  cv::Mat left, right;  // CV_8UC1
  cv::Mat depth_m;      // CV_32FC1 z-depth of the left view (m), 0 = none
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
};

struct MatchEvalOptions {
  std::vector<int> strides = {1, 2, 3, 5, 8};  // frame strides k -> k+s, each >= 1
  std::vector<vo::MatcherType> matchers = {    // matchers to evaluate
      vo::MatcherType::kSvdProximity, vo::MatcherType::kSvdNcc,      vo::MatcherType::kSvdNccGabor,
      vo::MatcherType::kNccMutual,    vo::MatcherType::kLucasKanade, vo::MatcherType::kKalman,
      vo::MatcherType::kSiftRatio};
  vo::DetectorOptions detector;    // Harris by default; kSiftRatio always uses SIFT
  vo::DisparityOptions disparity;  // for dropping features without depth
  vo::DepthSamplingOptions depth;
  vo::MatcherOptions matcher;  // per-matcher options (type is overridden)
  vo::PredictionMode prediction =
      vo::PredictionMode::kMotionPrior;  // kMotionPrior: every
                                         // matcher searches around the same predicted positions,
                                         // the features' stereo 3D points moved by a
                                         // constant-velocity prior (the ground-truth motion of the
                                         // previous pair of the same stride; none for the first
                                         // pair), as the VO predicts; kNone: previous positions
  double prediction_radius_scale =
      vo::TrackerOptions().prior_radius_scale;  // gate scale around that prediction,
                                                // as the VO's prior pass uses it
  double correct_px = 2.0;            // a match is correct within this of the GT position (px)
  double depth_agree_rel = 0.03;      // visibility: |z_gt - z_proj| <= this * z_proj + 0.01 m
  double ambiguous_depth_rel = 0.05;  // GT depth spread in 3x3 above this * z: feature left out

  bool IsValid(std::string* error) const;
};

struct MatchEvalRow {
  std::string matcher;
  int stride = 0;
  int pairs = 0;     // frame pairs evaluated
  long matches = 0;  // evaluated matches (prev feature with unambiguous ground truth)
  long correct = 0;
  long possible = 0;
  double precision = 0.0, recall = 0.0, f1 = 0.0;
  double ms_per_pair = 0.0;  // matcher time per frame pair (ms)
};

// Evaluates every matcher at every stride over the sequence (pairs (0,s), (s,2s), ...).
// `progress` (may be null) is called with (done, total) work units.
bool EvaluateMatchers(const std::vector<GroundTruthFrame>& frames, const vo::StereoCamera& camera,
                      const MatchEvalOptions& options, std::vector<MatchEvalRow>* rows,
                      std::string* error, const std::function<void(int, int)>& progress = nullptr);

// Ground-truth position in frame b of a point seen at uv_px with depth z in frame a; false when
// it is not visible in b (outside, behind, occluded). Exposed for tests.
bool ProjectGroundTruth(const vo::StereoCamera& camera, const GroundTruthFrame& a,
                        const GroundTruthFrame& b, const Eigen::Vector2d& uv_px, double depth_m,
                        double depth_agree_rel, Eigen::Vector2d* uv_b_px);

// The VO's own matches of one frame (reference frame -> current) checked against the ground
// truth, as EvaluateMatchers checks a matcher's: a match counts when its reference feature has
// an unambiguous ground-truth depth; it is correct when the current feature lies within
// correct_px of the reference feature's ground-truth projection. Sums over a run.
struct VoMatchStats {
  long matches = 0;          // evaluated matches
  long correct = 0;          // of which correct
  long inliers = 0;          // evaluated matches that were RANSAC inliers
  long inliers_correct = 0;  // of which correct
  int frames = 0;            // frames that contributed
  double precision() const { return matches > 0 ? static_cast<double>(correct) / matches : 0.0; }
  double inlier_precision() const {
    return inliers > 0 ? static_cast<double>(inliers_correct) / inliers : 0.0;
  }
};
void AccumulateVoMatchStats(const vo::StereoCamera& camera, const GroundTruthFrame& reference,
                            const GroundTruthFrame& current,
                            const std::vector<vo::Feature>& reference_features,
                            const std::vector<vo::Feature>& features,
                            const std::vector<vo::Match>& matches,
                            const std::vector<bool>& inlier_mask, const MatchEvalOptions& options,
                            VoMatchStats* stats);

// Writes rows as CSV (header:
// matcher,stride,pairs,matches,correct,possible,precision,recall,f1,ms_per_pair).
bool WriteMatchEvalCsv(const std::string& path, const std::vector<MatchEvalRow>& rows,
                       std::string* error);

}  // namespace harness
