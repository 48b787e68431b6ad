// Dense area-based disparity for a rectified stereo pair, and 3D for sparse features.
//
// The paper (Kwolek, docs/PAPER.md, "depth") takes 3D from a dense disparity map computed by the
// SRI Small Vision System (Konolige 1997, "Small Vision Systems: Hardware and
// Implementation"): correlation of small windows along the epipolar line, sub-pixel
// interpolation, then two post-filters: a confidence (texture) filter and a left-right
// consistency check. Features without a valid disparity are dropped.
//
// Here the correlation itself is OpenCV's StereoBM (SAD block matching on an x-Sobel
// prefiltered image, the closest relative of SVS), our own implementation of the same
// correlation that yields both views from one cost volume (sad_block_matcher.h; the pipeline's
// default, for speed), or StereoSGBM for comparison. The texture
// filter, the left-right check, the border handling and the speckle filter are ours, so they
// behave the same for both algorithms and need no opencv_contrib (ximgproc).
//
// Disparity convention: d = x_left - x_right (pixels) >= 0, stored per left-image pixel as
// CV_32F with 1/16 px resolution; invalid pixels hold kInvalidDisparity (-1).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/types.h"

namespace vo {

// Value of a disparity-map pixel without a valid estimate.
constexpr float kInvalidDisparity = -1.0f;

enum class DisparityAlgorithm {
  kBlockMatching,  // cv::StereoBM: SAD window correlation (SVS-like; the paper's choice)
  kSemiGlobal,     // cv::StereoSGBM: semi-global matching (Hirschmüller 2008), for comparison
  kBlockMatchingOneVolume,  // our SAD block matcher (vo/sad_block_matcher.h): the same
                            // correlation as kBlockMatching, but the left-right check's right
                            // view comes from the same cost volume instead of a second pass
                            // (about half the time with the check on); block_size <= 21
};

const char* ToString(DisparityAlgorithm algorithm);

struct DisparityOptions {
  DisparityAlgorithm algorithm = DisparityAlgorithm::kBlockMatching;  // correlation method
  int min_disparity_px = 0;   // smallest disparity searched (pixels), >= 0
  int num_disparities = 64;   // size of the search range (pixels), multiple of 16, >= 16;
                              // disparities searched: [min_disparity_px, min + num - 1]
  int block_size = 9;         // correlation window side (pixels), odd; BM: 5..255, SGBM: 1..255
  int prefilter_cap = 31;     // clip of the x-Sobel prefiltered intensities (grey levels), 1..63
  int uniqueness_ratio = 15;  // the best cost must beat the second best (away from +-1 px)
                              // by this margin (percent), 0..100; 0 disables
  double min_texture = 0.5;   // confidence (texture) filter, SVS style: the mean absolute
                              // horizontal gradient |I(x+1) - I(x-1)| / 2 of the left image
                              // over the correlation window (grey levels per pixel), >= 0;
                              // pixels below are invalid. 0 disables. 0.5 rejects windows
                              // flatter than sensor noise of sigma ~1 grey level; higher values
                              // cost density on Middlebury without lowering the error rate
  double left_right_max_diff_px = 1.0;  // left-right check: a pixel is kept only when the
                                        // right-view disparity at x - d agrees within this
                                        // (pixels), > 0; < 0 disables the check
  bool full_width = true;         // pad the images on the left by the search range so pixels in the
                                  // leftmost num_disparities columns also get estimates (only
                                  // matches inside the right image are kept); false = OpenCV's
                                  // behaviour, that band stays invalid
  int speckle_window_size = 100;  // connected regions of similar disparity smaller than this
                                  // (pixels) are invalidated; 0 disables
  double speckle_range_px = 1.0;  // neighbours belong to one region when their disparities
                                  // differ by at most this (pixels), > 0
  int sgbm_p1 = 0;  // SGBM smoothness penalty for +-1 px disparity changes; 0 = 8 * block^2
  int sgbm_p2 = 0;  // SGBM penalty for larger changes, > sgbm_p1; 0 = 32 * block^2
  bool sgbm_full_dp = false;  // SGBM: 8 paths (true) instead of 5 (slower, more memory)

  bool IsValid(std::string* error) const;
};

// Outcome of one ComputeDisparity call.
struct DisparityResult {
  bool ok = false;       // false: inputs or options rejected, `message` says why
  std::string message;   // empty when ok
  cv::Mat disparity_px;  // CV_32F, size of the left image; d = x_left - x_right (pixels,
                         // 1/16 px steps), kInvalidDisparity where no valid estimate
  int num_valid = 0;     // pixels with a valid disparity
  // Pixels removed by each post-filter (a pixel counts for the first filter that removed it).
  int num_rejected_texture = 0;
  int num_rejected_left_right = 0;
  int num_rejected_speckle = 0;
};

// Reusable disparity computer: holds the OpenCV matcher and scratch buffers, so repeated
// calls on same-size images do not reallocate. Not thread-safe; use one per thread.
class DisparityEstimator {
 public:
  explicit DisparityEstimator(const DisparityOptions& options = DisparityOptions());
  ~DisparityEstimator();
  DisparityEstimator(const DisparityEstimator&) = delete;
  DisparityEstimator& operator=(const DisparityEstimator&) = delete;

  // Disparity of the left image. left/right: rectified CV_8UC1 of the same non-empty size
  // (wider than the search range when full_width is false). num_disparities: this pair's
  // search range (a multiple of 16, >= 16), 0 = the options'. Never throws; rejected inputs
  // or options give ok = false and a message.
  DisparityResult Compute(const cv::Mat& left, const cv::Mat& right, int num_disparities = 0);

  // Disparity only where it is read (algorithm kBlockMatchingOneVolume only):
  // PrepareAtPixels() takes the pair (same checks as Compute; result.disparity_px stays
  // empty), then DisparityAt(x, y) evaluates one left pixel on first use (later calls read it
  // back). Each pixel gets exactly the value of Compute's map with speckle_window_size = 0 —
  // the same prefilter, window costs, uniqueness test, sub-pixel step, texture filter and
  // left-right check (its right-view pixel evaluated alone as well) — bit for bit; the
  // speckle filter, a whole-map operation, is not applied. Costs about
  // 2 · block_size² · num_disparities / 16 vector operations per pixel, against the dense
  // map's ~4 · num_disparities / 16 per pixel of the whole image.
  DisparityResult PrepareAtPixels(const cv::Mat& left, const cv::Mat& right,
                                  int num_disparities = 0);
  // Disparity (pixels, 1/16 px steps) of the left pixel (x, y) of the prepared pair, or
  // kInvalidDisparity (also outside the image or before a successful PrepareAtPixels).
  float DisparityAt(int x, int y);
  // Counts since the last PrepareAtPixels: left pixels evaluated, right-view pixels evaluated
  // for their left-right check, and pixels removed by each post-filter.
  struct PixelCounts {
    int left = 0, right = 0, rejected_texture = 0, rejected_left_right = 0;
  };
  PixelCounts pixel_counts() const;
  // Size of the pair of the last successful PrepareAtPixels (0 x 0 when none).
  cv::Size prepared_size() const;

  const DisparityOptions& options() const { return options_; }

 private:
  struct Impl;
  DisparityOptions options_;
  std::unique_ptr<Impl> impl_;
};

// One-shot convenience wrapper around DisparityEstimator.
DisparityResult ComputeDisparity(const cv::Mat& left, const cv::Mat& right,
                                 const DisparityOptions& options = DisparityOptions());

// How a feature at a sub-pixel position reads the disparity map.
enum class DisparitySampling {
  kNearest,   // the nearest pixel; if it is invalid, the nearest valid pixel within
              // search_radius_px (ties: smallest row, then smallest column)
  kBilinear,  // bilinear weights over the 2x2 neighbours, renormalised over the valid ones;
              // when the valid ones straddle a depth edge (spread > max_spread_px) or none is
              // valid, falls back to kNearest
};
// "nearest", "bilinear".
const char* ToString(DisparitySampling sampling);

struct DepthSamplingOptions {
  DisparitySampling sampling = DisparitySampling::kBilinear;  // see DisparitySampling
  int search_radius_px = 1;    // kNearest fallback: radius (pixels, Chebyshev) searched for a
                               // valid pixel, >= 0; 0 = the nearest pixel only
  double max_spread_px = 1.0;  // kBilinear: largest max - min disparity among the valid
                               // neighbours that is still interpolated (pixels), >= 0
  double min_depth_m = 0.1;    // points closer than this get no depth (metres), > 0
  double max_depth_m = 50.0;   // points farther than this get no depth (metres), > min_depth_m

  bool IsValid(std::string* error) const;
};

// Outcome of AttachDepth.
struct AttachDepthResult {
  bool ok = false;            // false: bad disparity map, camera or options; features untouched
  std::string message;        // empty when ok
  int num_with_depth = 0;     // features that now have depth
  int num_without_depth = 0;  // features left with disparity_px = -1 and p_cam0 = NaN
};

// Fills disparity_px and p_cam0 (= cam.Backproject(u, v, d), metres, cam0 frame) of every
// feature from `disparity` (CV_32F, as produced by ComputeDisparity, same size as cam's
// images). Features outside the map, on invalid disparity, with d <= 0, or with depth outside
// [min_depth_m, max_depth_m] get disparity_px = -1 and p_cam0 = NaN.
AttachDepthResult AttachDepth(const cv::Mat& disparity, const StereoCamera& cam,
                              std::vector<Feature>* features,
                              const DepthSamplingOptions& options = DepthSamplingOptions());

// The same, reading the disparity from a DisparityEstimator prepared with PrepareAtPixels on
// images of cam's size: only the pixels the sampling reads are evaluated, and the result
// equals AttachDepth on Compute's map (speckle filter off) bit for bit.
AttachDepthResult AttachDepth(DisparityEstimator* estimator, const StereoCamera& cam,
                              std::vector<Feature>* features,
                              const DepthSamplingOptions& options = DepthSamplingOptions());

// Removes the features without depth, keeping the order of the others (the paper drops them).
// Returns the number removed.
int DropFeaturesWithoutDepth(std::vector<Feature>* features);

}  // namespace vo
