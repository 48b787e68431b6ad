// The front end: one rectified stereo pair to the frame the tracker matches (paper, section
// IV). The disparity is prepared (disparity_mode at_features: the block matcher's cost volume,
// evaluated later at the pixels the features read; dense, or the first frame's orientation:
// the whole map) with the search range the scene asked for (SceneNumDisparities: the previous
// frame's largest feature disparity with a margin), features are detected in the left image
// (Harris | SIFT, bucketed; a weakly textured view detected again with a lower threshold,
// adaptive_min_features), each reads its depth from the disparity (AttachDepth: texture
// filter, uniqueness, left-right check) and those without depth are dropped with their
// descriptors. The seam (ProcessFeatures) takes given features instead: KeepFeaturesWithDepth
// and ReindexMatches. disparity.h, features.h. Its options are FrontEndOptions (the `front_end`
// group of vo_options.yaml).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/disparity.h"
#include "vo/features.h"
#include "vo/matcher.h"
#include "vo/odometry_result.h"
#include "vo/types.h"

namespace vo {

// Detector defaults for the pipeline: Harris, at most 300 features, bucketed on an 8 × 6 grid
// (at most 10 per cell) so they spread over the image, Harris quality_level 0.001.
DetectorOptions DefaultOdometryDetectorOptions();
// Disparity defaults for the pipeline: block matching with the left-right check, both views
// from one cost volume (kBlockMatchingOneVolume; the same disparities as cv::StereoBM run
// twice, in about half the time).
DisparityOptions DefaultOdometryDisparityOptions();

// Where the pipeline evaluates the disparity.
enum class DisparityMode {
  kDense,       // the whole map of every frame (any disparity.algorithm; the speckle filter)
  kAtFeatures,  // only the pixels the features' depth sampling reads, and the right-view
                // pixels of their left-right check (DisparityEstimator::PrepareAtPixels):
                // the same values as the dense map there without its speckle filter, bit for
                // bit; needs disparity.algorithm block_matching_one_volume. The first frame's
                // plane-based orientation still reads a dense map (that one frame)
};
// "dense", "at_features" (defined with ToString(Platform), odometry_options.cc).
const char* ToString(DisparityMode mode);

// The front end's options (vo_options.yaml `front_end`): the disparity, its search range, the
// detector and the features' depth, and the fewest features with depth a frame is tracked with.
struct FrontEndOptions {
  DetectorOptions detector = DefaultOdometryDetectorOptions();  // feature detection (left)
  DisparityOptions disparity =
      DefaultOdometryDisparityOptions();  // the block matcher and its post-filters;
                                          // num_disparities is replaced by the value
                                          // derived from the camera when derive_num_disparities
  DisparityMode disparity_mode = DisparityMode::kAtFeatures;  // see DisparityMode
  bool disparity_range_from_scene = true;  // search range per frame from the depths seen:
                                           // the previous frame's largest feature disparity
                                           // · (1 + disparity_range_margin) +
                                           // disparity_range_margin_px, rounded up to 16 and
                                           // at most the camera-derived range; the full range
                                           // on the first frame and after a lost frame
  double disparity_range_margin = 0.25;    // relative margin of that range, >= 0
  double disparity_range_margin_px = 8.0;  // absolute margin (pixels), >= 0
  bool derive_num_disparities = true;      // search range from the camera: the smallest multiple
                                       // of 16 >= fx · baseline / disparity_min_depth_m, clamped
                                       // to [16, max_num_disparities] (and < image width)
  double disparity_min_depth_m = 0.7;  // nearest depth the derived search range covers (metres),
                                       // > 0. Hallway rig (fx 230 px, 0.09 m): 29.6 px → 32
                                       // disparities, depth >= 0.67 m (the L-path's nearest
                                       // surface, at the corner turn, is 0.735 m from the camera
                                       // in the simulator's depth); KITTI (718 px, 0.54 m):
                                       // clamped to 256 (≈ 1.5 m)
  int max_num_disparities = 256;       // upper clamp of the derived range (pixels), multiple
                                       // of 16, >= 16
  DepthSamplingOptions depth;          // how features read the disparity map
  int adaptive_min_features = 0;       // a Harris detection with fewer features than this is
                                       // repeated with quality_level adaptive_quality_level and the
                                       // larger set kept (weakly textured views: one bright light
  // otherwise sets the bar for the whole image), >= 0; 0 = off.
  // Off by default: 100 took the L-hallway's texture seeds 1-10
  // from a 0.44 to a 0.28 m median end-pose error (114 to 73
  // frames without motion), but seed 7 from 0.44 to 0.61 % and
  // the plain corridor from 0.26 to 0.69 m (noise-level corners)
  double adaptive_quality_level = 1e-4;  // that second, lower relative threshold, in [0, 1)
  int min_features = 15;  // fewer features with depth than this → lost (black, textureless or
                          // overexposed frame), >= 3; the few-point motion may still take a
                          // frame with fewer (MotionOptions::few_point_min_features)

  bool IsValid(std::string* error) const;
};

// The search range the camera asks for (derive_num_disparities): the smallest multiple of 16
// >= fx · b / disparity_min_depth_m, clamped to [16, max_num_disparities] and below the width.
int DerivedNumDisparities(const StereoCamera& camera, const FrontEndOptions& options);

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
                                          const FrontEndOptions& options, std::string* error);
  FrontEnd(const FrontEnd&) = delete;
  FrontEnd& operator=(const FrontEnd&) = delete;

  // left/right: CV_8UC1 of the camera's size (the caller checks). num_disparities: this
  // frame's search range; dense: the whole map (else prepared at the features' pixels).
  // Fills result's num_disparities, num_features, disparity_pixels, num_features_with_depth
  // and times (disparity_ms, detect_ms, depth_ms).
  FrontEndFrame Process(const cv::Mat& left, const cv::Mat& right, int num_disparities, bool dense,
                        OdometryResult* result);

 private:
  FrontEnd(const StereoCamera& camera, const FrontEndOptions& options);

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
int SceneNumDisparities(const std::vector<Feature>& features, const FrontEndOptions& options);

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
