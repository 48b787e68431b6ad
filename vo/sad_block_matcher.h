// SAD block matching that gives the disparities of BOTH views from one cost volume.
//
// The left-right consistency check of the paper's SVS-style correlation (disparity.h) needs the
// right view's disparity map too. Running a block matcher a second time on the mirrored pair
// (what cv::StereoBM allows) recomputes every window cost: the cost of left pixel x at
// disparity d is the cost of right pixel x - d at the same d. This matcher computes each
// window cost once and takes both minima from it:
//   left view:  d_L(x)  = argmin_d C(x, d)
//   right view: d_R(xr) = argmin_d C(xr + d, d)
// with the same prefilter, window, uniqueness test and sub-pixel interpolation for both, so the
// left view equals cv::StereoBM's up to ties and the image border (tests/vo/disparity_test.cc).
//
// The correlation, as cv::StereoBM's: images prefiltered with a 3x3 x-Sobel clipped to
// [-prefilter_cap, prefilter_cap] (offset by prefilter_cap), SAD over block_size² windows;
// uniqueness: a pixel is invalid when a disparity more than 1 px from the best has a cost
// <= best + best · uniqueness_ratio / 100; sub-pixel: equiangular (V-shaped) interpolation of
// the costs at d - 1, d, d + 1. The image is padded (replicate) by the search range on the left
// and by half a window elsewhere, so every pixel gets an estimate; a left estimate whose match
// falls left of the right image is kept here and removed by the caller (it knows the padding
// rule). Right-view candidates beyond the left image's right border are not searched (those
// right pixels see a truncated range, which only makes the left-right check stricter there).
//
// Costs are int16 with the disparity innermost, so the inner loops vectorise for both views
// (SSE2 intrinsics, AVX2 ones chosen at run time on CPUs that have it, scalar elsewhere); the
// window cost is updated incrementally (column sums down the image, a sliding sum along the
// row).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace vo {

struct SadBlockMatcherOptions {
  int min_disparity_px = 0;   // smallest disparity searched (pixels), >= 0
  int num_disparities = 64;   // search range (pixels), multiple of 16, >= 16
  int block_size = 9;         // window side (pixels), odd, >= 3
  int prefilter_cap = 31;     // x-Sobel clip (grey levels), 1..63
  int uniqueness_ratio = 15;  // percent, 0..100; 0 disables
  bool allow_avx2 = true;     // use the AVX2 kernels when the CPU has them (x86-64; same
                              // results, ~1/3 faster); false = the SSE2/scalar baseline

  // Also checks that a window's SAD fits in a signed 16-bit cost:
  // block_size² · 2 · prefilter_cap <= 32767 (block_size <= 21 at the default cap).
  bool IsValid(std::string* error) const;
};

// Value of a fixed-point (1/16 px) disparity without an estimate.
constexpr int16_t kSadInvalidFixed = -16;

class SadBlockMatcher {
 public:
  explicit SadBlockMatcher(const SadBlockMatcherOptions& options) : options_(options) {}

  // left/right: CV_8UC1 of one size, at least block_size in each dimension (checked by the
  // caller; options must be valid). Writes CV_16S disparities in 1/16 px, kSadInvalidFixed
  // where none: *left_fixed per left pixel, *right_fixed (when not null) per right pixel.
  // `discard` (optional, CV_8UC1 of the image size): nonzero marks left pixels the caller
  // throws away anyway (e.g. its texture filter); their uniqueness test is skipped, so their
  // output may hold a non-unique estimate. num_disparities: this pair's search range (a
  // multiple of 16, >= 16; 0 = the options').
  void Compute(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_fixed, cv::Mat* right_fixed,
               const cv::Mat* discard = nullptr, int num_disparities = 0);

  // Sparse evaluation: Prepare() prefilters and pads the pair once (same inputs as Compute,
  // and num_disparities: the search range of this pair, a multiple of 16 >= 16, 0 = the
  // options'); then LeftAt / RightAt give, at one pixel, exactly what Compute would write
  // there (*left_fixed / *right_fixed, 1/16 px or kSadInvalidFixed), computing only that
  // pixel's window costs (each window summed directly, the disparities in the SIMD lanes).
  // Ties between equal right-view costs are broken in Compute's visiting order, so the right
  // view matches bit for bit as well.
  void Prepare(const cv::Mat& left, const cv::Mat& right, int num_disparities = 0);
  int16_t LeftAt(int x, int y);    // 0 <= x < width, 0 <= y < height of the prepared pair
  int16_t RightAt(int xr, int y);  // right-image pixel, same bounds
  int prepared_num_disparities() const { return geometry_.nd; }
  // Frees the buffers only Compute uses (its cost volume rows, column sums, right-view
  // minima), e.g. when a caller switches to the sparse evaluation for good.
  void ReleaseDenseScratch();

  const SadBlockMatcherOptions& options() const { return options_; }

  // Geometry of the prepared pair (Prepare / Compute).
  struct Geometry {
    int w = 0, h = 0, nd = 0, dmin = 0, half = 0, win = 0, pad_left = 0, padded_w = 0, uniq256 = 0;
    bool avx2 = false;  // the AVX2 kernels are used (also sets the right view's tie order)
  };

 private:
  SadBlockMatcherOptions options_;
  Geometry geometry_;
  // Scratch, reused between calls.
  cv::Mat left_pf_, right_pf_, right_pf_reversed_;
  std::vector<int16_t> column_sums_, costs_, right_min_, right_best_, right_thresh_,
      right_ambiguous_;
  std::vector<int16_t> pixel_costs_;  // sparse: one pixel's costs
  std::vector<uint8_t> segment_;      // sparse right view: one window row of the left image
};

}  // namespace vo
