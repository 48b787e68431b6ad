// Feature detection in the left image: Harris corners (the paper's choice) or SIFT (its
// alternative). Kwolek, docs/PAPER.md, "features": Harris corners, 0.04 s per 320x240 frame on a
// Pentium IV; SIFT 0.94 s.
//
// Plug-in point: FeatureDetector is a small interface; a new detector = a .h/.cc pair, a
// test, a DetectorType value and a `case` in CreateFeatureDetector().
//
// Output contract (every detector): features lie at least border_margin_px inside the image
// (so 11x11 NCC patches and the Gabor kernels fit), at most max_features of them, sorted by
// response (descending), ties by row then column (ascending): the same image gives the same
// vector, run after run. Only uv_px and response are set; depth and track fields keep their
// defaults (see AttachDepth in disparity.h).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/types.h"

namespace vo {

enum class DetectorType {
  kHarris,  // Harris & Stephens corners + non-maximum suppression (the paper's detector)
  kSift,    // Lowe's SIFT keypoints (cv::SIFT), with 128-float descriptors
};

const char* ToString(DetectorType type);

// Harris & Stephens (1988). With aperture 3 and block_size <= 31 the response is computed by a
// fused integer implementation (same values as cv::cornerHarris, about twice as fast);
// otherwise by cv::cornerHarris. See HarrisResponse().
struct HarrisOptions {
  int block_size = 3;           // side of the window summing the structure tensor (pixels), >= 2
  int aperture_size = 3;        // Sobel aperture of the image derivatives: 3, 5 or 7
  double k = 0.04;              // Harris constant in R = det(M) - k trace(M)^2, in (0, 0.25)
  double quality_level = 0.01;  // relative threshold: keep R >= quality_level * R of the
                                // strongest corner inside the margin, in [0, 1)
  double min_response = 1e-7;   // absolute threshold on R (OpenCV cornerHarris scaling, i.e.
                                // derivatives normalised to grey/255), >= 0; a uniform image
                                // has R = 0 everywhere and gives no corners
  double nms_radius_px = 5.0;   // non-maximum suppression: no two corners closer than this
                                // (pixels, Euclidean, integer positions), >= 1; greedy,
                                // strongest kept first
  bool subpixel = false;        // refine positions with cv::cornerSubPix (gradient-orthogonality);
                                // a corner moves by at most subpixel_half_window_px
  int subpixel_half_window_px = 2;    // cornerSubPix search window half side (pixels), >= 1
  int subpixel_max_iterations = 20;   // cornerSubPix iteration limit, >= 1
  double subpixel_epsilon_px = 0.01;  // cornerSubPix stop when a step is below this (pixels)

  bool IsValid(std::string* error) const;
};

struct SiftOptions {
  int octave_layers = 3;             // layers per octave (Lowe: 3), >= 1
  double contrast_threshold = 0.04;  // DoG contrast threshold (OpenCV units), > 0
  double edge_threshold = 10.0;      // principal-curvature ratio limit against edges, > 1
  double sigma = 1.6;                // Gaussian sigma of the first octave (pixels), > 0
  bool unique_positions = true;      // keep one keypoint per position (SIFT emits one per
                                     // dominant orientation; the one with the smallest angle
                                     // is kept, its descriptor goes with it)

  bool IsValid(std::string* error) const;
};

struct DetectorOptions {
  DetectorType type = DetectorType::kHarris;  // which detector CreateFeatureDetector builds
  int max_features = 300;     // at most this many features, strongest first; 0 = no limit
  int border_margin_px = 12;  // features keep this distance from every image border (pixels):
                              // x in [margin, width - 1 - margin]; >= 0
  int bucket_cols = 0;        // bucketing grid over the image inside the margin: columns;
                              // 0 (with bucket_rows = 0) disables bucketing
  int bucket_rows = 0;        // bucketing grid: rows; both > 0 or both 0
  int max_per_bucket = 4;     // with bucketing: at most this many features per cell, >= 1
  HarrisOptions harris;       // used when type == kHarris
  SiftOptions sift;           // used when type == kSift

  bool IsValid(std::string* error) const;
};

// Features plus what a descriptor-based matcher needs. Row i of `descriptors` and
// keypoints[i] belong to features[i].
struct FeatureSet {
  std::vector<Feature> features;
  std::vector<cv::KeyPoint> keypoints;  // OpenCV keypoints (SIFT: size and angle set)
  cv::Mat descriptors;  // SIFT: CV_32F, one 128-float row per feature; empty for Harris
};

class FeatureDetector {
 public:
  virtual ~FeatureDetector() = default;

  // Features of `image` (CV_8UC1; anything else, or an empty image, gives no features).
  virtual std::vector<Feature> Detect(const cv::Mat& image) = 0;

  // Features with keypoints and descriptors (descriptors empty for detectors without them).
  // The default wraps Detect().
  virtual FeatureSet DetectWithDescriptors(const cv::Mat& image);

  virtual DetectorType type() const = 0;
};

// Factory on options.type. Returns nullptr (and fills *error when given) for invalid options.
std::unique_ptr<FeatureDetector> CreateFeatureDetector(const DetectorOptions& options,
                                                       std::string* error = nullptr);

// Harris response R = det(M) - k trace(M)^2 per pixel (CV_32F, size of `image`), with
// cv::cornerHarris's scaling (derivatives scaled by 1 / (2^(aperture-1) * block * 255), block
// sums unnormalised). Equal to cv::cornerHarris(image, R, block_size, aperture_size, k) up to
// float rounding, except within block_size/2 px of the edge of `image`, which are 0 on the fast
// path (aperture 3, block <= 31). False for an empty or non-CV_8UC1 image or invalid options.
// The fast path uses AVX2 where the CPU has it unless allow_avx2 is false: the same values
// (integer sums, element-wise float arithmetic); the switch is for the test that says so.
bool HarrisResponse(const cv::Mat& image, const HarrisOptions& options, cv::Mat* response,
                    bool allow_avx2 = true);

// Keeps features in the order given (strongest first), taking at most max_per_bucket per cell
// of a bucket_cols x bucket_rows grid over [margin, size - margin) and at most max_features
// overall; the detectors call this, exposed for other sources of features. Returns the kept
// indices. `image_size` is the image's size in pixels.
std::vector<int> SelectFeatures(const std::vector<Feature>& sorted_features,
                                const cv::Size& image_size, const DetectorOptions& options);

}  // namespace vo
