// The front end: one rectified stereo pair to the frame the tracker matches (paper, section
// IV). The disparity is prepared (disparity_mode at_features: the block matcher's cost volume,
// evaluated later at the pixels the features read; dense, or the first frame's orientation:
// the whole map) with the search range the scene asked for (SceneNumDisparities: the previous
// frame's largest feature disparity with a margin), features are detected in the left image
// (Harris | SIFT, bucketed; a weakly textured view detected again with a lower threshold,
// adaptive_min_features), each reads its depth from the disparity (AttachDepth: texture
// filter, uniqueness, left-right check) and those without depth are dropped with their
// descriptors. The seam (ProcessFeatures) takes given features instead: KeepFeaturesWithDepth
// and ReindexMatches. disparity.h, features.h.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/disparity.h"
#include "vo/features.h"
#include "vo/matcher.h"
#include "vo/odometry_options.h"
#include "vo/odometry_result.h"
#include "vo/types.h"

namespace vo {

// One stereo pair through the front end.
struct FrontEndFrame {
  bool ok = false;       // false: the disparity failed (message says why; nothing detected)
  std::string message;   // "disparity: ..." when not ok
  cv::Mat disparity_px;  // the dense map (CV_32F) when it was asked for, else empty
  MatchFrame frame;      // features with depth (and their descriptors); frame_id and image
                         // are the caller's to set
};

class FrontEnd {
 public:
  // nullptr (and *error filled) when a detector cannot be built from options.detector.
  static std::unique_ptr<FrontEnd> Create(const StereoCamera& camera,
                                          const OdometryOptions& options, std::string* error);
  FrontEnd(const FrontEnd&) = delete;
  FrontEnd& operator=(const FrontEnd&) = delete;

  // left/right: CV_8UC1 of the camera's size (the caller checks). num_disparities: this
  // frame's search range; dense: the whole map (else prepared at the features' pixels).
  // Fills result's num_disparities, num_features, disparity_pixels, num_features_with_depth
  // and times (disparity_ms, detect_ms, depth_ms).
  FrontEndFrame Process(const cv::Mat& left, const cv::Mat& right, int num_disparities, bool dense,
                        OdometryResult* result);

 private:
  FrontEnd(const StereoCamera& camera, const OdometryOptions& options);

  StereoCamera camera_;
  DepthSamplingOptions depth_;
  int adaptive_min_features_ = 0;
  std::unique_ptr<DisparityEstimator> disparity_;
  std::unique_ptr<FeatureDetector> detector_;
  std::unique_ptr<FeatureDetector> weak_detector_;  // adaptive_min_features fallback (or null)
};

// The next frame's disparity search range from the depths of this frame's features
// (disparity_range_from_scene): the largest feature disparity · (1 + disparity_range_margin) +
// disparity_range_margin_px, rounded up to a multiple of 16 (at least 16); 0 (the full range)
// when the option is off, no feature has depth, or the range would not be below
// disparity.num_disparities.
int SceneNumDisparities(const std::vector<Feature>& features, const OdometryOptions& options);

// The seam's features: those with a finite position and disparity > 0, p_cam0 recomputed from
// them with the camera, track fields reset. *index_map (given index → kept index, -1 for
// dropped) has one entry per given feature.
std::vector<Feature> KeepFeaturesWithDepth(const StereoCamera& camera,
                                           const std::vector<Feature>& features,
                                           std::vector<int>* index_map);

// Matches given in the indices of the previous and the current call re-indexed to the kept
// features (prev_index_map, curr_index_map: KeepFeaturesWithDepth's maps; num_prev_kept,
// num_curr_kept: the kept counts), skipping dropped or out-of-range features and repeated
// indices (the first match of an index wins), sorted by prev.
std::vector<Match> ReindexMatches(const std::vector<Match>& matches,
                                  const std::vector<int>& prev_index_map,
                                  const std::vector<int>& curr_index_map, size_t num_prev_kept,
                                  size_t num_curr_kept);

}  // namespace vo
