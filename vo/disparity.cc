#include "vo/disparity.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <utility>
#include <vector>

#include "vo/sad_block_matcher.h"

namespace vo {
namespace {

// OpenCV's stereo matchers return fixed-point disparities with 4 fractional bits.
constexpr int kDisparityScale = 16;
// Fixed-point value we use for "invalid" while post-filtering (= kInvalidDisparity * 16).
constexpr int16_t kInvalidFixed = -kDisparityScale;

bool Fail(std::ostringstream& msg, std::string* error) {
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

std::string DescribeMat(const cv::Mat& m) {
  std::ostringstream s;
  if (m.empty()) return "an empty image";
  s << m.cols << "x" << m.rows << " " << cv::typeToString(m.type());
  return s.str();
}

// The samplers read the map through `at(x, y)` (a disparity, or < 0 when invalid) on a
// rows x cols grid, so the dense map and the disparity evaluated on demand share them.

// Nearest valid disparity around (u, v) within `radius` (Chebyshev) of the nearest pixel;
// ties resolved by scan order (row, then column). Returns kInvalidDisparity when none.
template <class At>
float SampleNearest(const At& at, int rows, int cols, double u, double v, int radius) {
  const int xi = static_cast<int>(std::lround(u));
  const int yi = static_cast<int>(std::lround(v));
  float best = kInvalidDisparity;
  double best_dist2 = std::numeric_limits<double>::infinity();
  for (int y = std::max(0, yi - radius); y <= std::min(rows - 1, yi + radius); ++y) {
    for (int x = std::max(0, xi - radius); x <= std::min(cols - 1, xi + radius); ++x) {
      const float d = at(x, y);
      if (!(d >= 0.0f)) continue;
      const double dist2 = (x - u) * (x - u) + (y - v) * (y - v);
      if (dist2 < best_dist2) {
        best_dist2 = dist2;
        best = d;
      }
    }
  }
  return best;
}

// Bilinear interpolation over the valid pixels of the 2x2 neighbourhood of (u, v), weights
// renormalised; falls back to SampleNearest at depth edges or without valid weight.
template <class At>
float SampleBilinear(const At& at, int rows, int cols, double u, double v,
                     const DepthSamplingOptions& options) {
  const int x0 = static_cast<int>(std::floor(u));
  const int y0 = static_cast<int>(std::floor(v));
  const double ax = u - x0;
  const double ay = v - y0;
  double sum_w = 0.0, sum_wd = 0.0;
  float lo = std::numeric_limits<float>::infinity();
  float hi = -std::numeric_limits<float>::infinity();
  for (int dy = 0; dy <= 1; ++dy) {
    const int y = y0 + dy;
    if (y < 0 || y >= rows) continue;
    for (int dx = 0; dx <= 1; ++dx) {
      const int x = x0 + dx;
      if (x < 0 || x >= cols) continue;
      const double w = (dx ? ax : 1.0 - ax) * (dy ? ay : 1.0 - ay);
      if (w <= 0.0) continue;
      const float d = at(x, y);
      if (!(d >= 0.0f)) continue;
      sum_w += w;
      sum_wd += w * d;
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  if (sum_w <= 0.0 || hi - lo > options.max_spread_px) {
    return SampleNearest(at, rows, cols, u, v, options.search_radius_px);
  }
  return static_cast<float>(sum_wd / sum_w);
}

// Texture-filter threshold on the window SUM of |I(x+1) - I(x-1)| (an integer): the window
// mean is below 2 · min_texture exactly when the sum is below this.
int MinTextureSum(const DisparityOptions& o) {
  return static_cast<int>(std::ceil(2.0 * o.min_texture * o.block_size * o.block_size));
}

// That sum at one pixel, borders replicated (as cv::Sobel + cv::boxFilter with
// BORDER_REPLICATE in the dense path).
int TextureSum(const cv::Mat& image, int x, int y, int half) {
  const int w = image.cols, h = image.rows;
  int sum = 0;
  for (int dy = -half; dy <= half; ++dy) {
    const uint8_t* row = image.ptr<uint8_t>(std::min(std::max(y + dy, 0), h - 1));
    for (int dx = -half; dx <= half; ++dx) {
      const int xc = std::min(std::max(x + dx, 0), w - 1);
      sum += std::abs(row[std::min(xc + 1, w - 1)] - row[std::max(xc - 1, 0)]);
    }
  }
  return sum;
}

}  // namespace

const char* ToString(DisparitySampling sampling) {
  switch (sampling) {
    case DisparitySampling::kNearest:
      return "nearest";
    case DisparitySampling::kBilinear:
      return "bilinear";
  }
  return "unknown";
}

const char* ToString(DisparityAlgorithm algorithm) {
  switch (algorithm) {
    case DisparityAlgorithm::kBlockMatching:
      return "block_matching";
    case DisparityAlgorithm::kSemiGlobal:
      return "semi_global";
    case DisparityAlgorithm::kBlockMatchingOneVolume:
      return "block_matching_one_volume";
  }
  return "unknown";
}

static SadBlockMatcherOptions ToSadOptions(const DisparityOptions& o) {
  SadBlockMatcherOptions s;
  s.min_disparity_px = o.min_disparity_px;
  s.num_disparities = o.num_disparities;
  s.block_size = o.block_size;
  s.prefilter_cap = o.prefilter_cap;
  s.uniqueness_ratio = o.uniqueness_ratio;
  return s;
}

bool DisparityOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  const bool bm = algorithm == DisparityAlgorithm::kBlockMatching;
  std::string sad_error;
  if (algorithm != DisparityAlgorithm::kBlockMatching &&
      algorithm != DisparityAlgorithm::kSemiGlobal &&
      algorithm != DisparityAlgorithm::kBlockMatchingOneVolume) {
    msg << "algorithm: unknown value " << static_cast<int>(algorithm);
  } else if (algorithm == DisparityAlgorithm::kBlockMatchingOneVolume &&
             !ToSadOptions(*this).IsValid(&sad_error)) {
    msg << sad_error;
  } else if (min_disparity_px < 0) {
    msg << "min_disparity_px must be >= 0, got " << min_disparity_px;
  } else if (num_disparities < 16 || num_disparities % 16 != 0) {
    msg << "num_disparities must be a positive multiple of 16, got " << num_disparities;
  } else if (block_size % 2 == 0 || block_size > 255 || block_size < (bm ? 5 : 1)) {
    msg << "block_size must be odd and in [" << (bm ? 5 : 1) << ", 255] for " << ToString(algorithm)
        << ", got " << block_size;
  } else if (prefilter_cap < 1 || prefilter_cap > 63) {
    msg << "prefilter_cap must be in [1, 63], got " << prefilter_cap;
  } else if (uniqueness_ratio < 0 || uniqueness_ratio > 100) {
    msg << "uniqueness_ratio must be in [0, 100] percent, got " << uniqueness_ratio;
  } else if (!std::isfinite(min_texture) || min_texture < 0.0) {
    msg << "min_texture must be finite and >= 0, got " << min_texture;
  } else if (!std::isfinite(left_right_max_diff_px) || left_right_max_diff_px == 0.0) {
    msg << "left_right_max_diff_px must be finite and > 0 (or < 0 to disable), got "
        << left_right_max_diff_px;
  } else if (speckle_window_size < 0) {
    msg << "speckle_window_size must be >= 0, got " << speckle_window_size;
  } else if (!std::isfinite(speckle_range_px) || speckle_range_px <= 0.0) {
    msg << "speckle_range_px must be finite and > 0, got " << speckle_range_px;
  } else if (sgbm_p1 < 0 || sgbm_p2 < 0) {
    msg << "sgbm_p1 and sgbm_p2 must be >= 0, got " << sgbm_p1 << ", " << sgbm_p2;
  } else if (sgbm_p1 > 0 && sgbm_p2 > 0 && sgbm_p2 <= sgbm_p1) {
    msg << "sgbm_p2 must be > sgbm_p1, got p1 = " << sgbm_p1 << ", p2 = " << sgbm_p2;
  }
  return Fail(msg, error);
}

bool DepthSamplingOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (sampling != DisparitySampling::kNearest && sampling != DisparitySampling::kBilinear) {
    msg << "sampling: unknown value " << static_cast<int>(sampling);
  } else if (search_radius_px < 0) {
    msg << "search_radius_px must be >= 0, got " << search_radius_px;
  } else if (!std::isfinite(max_spread_px) || max_spread_px < 0.0) {
    msg << "max_spread_px must be finite and >= 0, got " << max_spread_px;
  } else if (!std::isfinite(min_depth_m) || min_depth_m <= 0.0) {
    msg << "min_depth_m must be finite and > 0, got " << min_depth_m;
  } else if (!(max_depth_m > min_depth_m)) {
    msg << "max_depth_m must be > min_depth_m (" << min_depth_m << "), got " << max_depth_m;
  }
  return Fail(msg, error);
}

// ------------------------------------------------------------------------------------------
// DisparityEstimator

struct DisparityEstimator::Impl {
  cv::Ptr<cv::StereoMatcher> matcher;    // both views (the right one on the mirrored pair)
  std::unique_ptr<SadBlockMatcher> sad;  // kBlockMatchingOneVolume: both views at once
  // Scratch buffers, reused between calls.
  cv::Mat padded_a, padded_b, flipped_a, flipped_b, raw_fixed;
  cv::Mat left_fixed, right_fixed;  // CV_16S, 1/16 px, cropped to the image
  cv::Mat gradient, texture, low_texture;
  // PrepareAtPixels: the pair's left image (texture filter), per-pixel caches of the left
  // (post-filtered) and right views in 1/16 px (kUnevaluated until computed), counts.
  bool prepared = false;
  cv::Mat sparse_image, sparse_left, sparse_right;
  // The pixels of sparse_left / sparse_right evaluated since Prepare (offsets): the next Prepare
  // resets those rather than the whole maps.
  std::vector<int> touched_left, touched_right;
  PixelCounts counts;
};

namespace {

cv::Ptr<cv::StereoMatcher> CreateMatcher(const DisparityOptions& o) {
  if (o.algorithm == DisparityAlgorithm::kBlockMatching) {
    cv::Ptr<cv::StereoBM> bm = cv::StereoBM::create(o.num_disparities, o.block_size);
    bm->setMinDisparity(o.min_disparity_px);
    bm->setPreFilterType(cv::StereoBM::PREFILTER_XSOBEL);
    bm->setPreFilterCap(o.prefilter_cap);
    bm->setUniquenessRatio(o.uniqueness_ratio);
    // The texture filter, LR check and speckle filter are applied by Compute() itself.
    bm->setTextureThreshold(0);
    bm->setSpeckleWindowSize(0);
    bm->setDisp12MaxDiff(-1);
    return bm;
  }
  const int area = o.block_size * o.block_size;
  const int p1 = o.sgbm_p1 > 0 ? o.sgbm_p1 : 8 * area;
  const int p2 = o.sgbm_p2 > 0 ? o.sgbm_p2 : std::max(32 * area, p1 + 1);
  return cv::StereoSGBM::create(
      o.min_disparity_px, o.num_disparities, o.block_size, p1, p2, /*disp12MaxDiff=*/-1,
      o.prefilter_cap, o.uniqueness_ratio, /*speckleWindowSize=*/0, /*speckleRange=*/0,
      o.sgbm_full_dp ? cv::StereoSGBM::MODE_HH : cv::StereoSGBM::MODE_SGBM);
}

}  // namespace

DisparityEstimator::DisparityEstimator(const DisparityOptions& options)
    : options_(options), impl_(std::make_unique<Impl>()) {
  if (!options_.IsValid(nullptr)) return;  // reported by Compute()
  // The same matcher (same uniqueness filter) serves the right view: a right pixel without a
  // unique match vetoes the left estimate that lands on it. Measured on Middlebury, matching
  // the right view without the uniqueness filter gains ~2 points of density for ~0.3 points
  // more bad pixels (and ~1.5 ms at 320x240); we keep the stricter check.
  if (options_.algorithm == DisparityAlgorithm::kBlockMatchingOneVolume) {
    impl_->sad = std::make_unique<SadBlockMatcher>(ToSadOptions(options_));
  } else {
    impl_->matcher = CreateMatcher(options_);
  }
}

DisparityEstimator::~DisparityEstimator() = default;

namespace {

// Value of a sparse cache entry not computed yet.
constexpr int16_t kUnevaluated = INT16_MIN;

// The checks Compute and PrepareAtPixels share; false with result->message set.
bool CheckPair(const DisparityOptions& o, const cv::Mat& left, const cv::Mat& right,
               int num_disparities, DisparityResult* result) {
  std::string error;
  if (!o.IsValid(&error)) {
    result->message = "invalid DisparityOptions: " + error;
    return false;
  }
  if (num_disparities != 0 && (num_disparities < 16 || num_disparities % 16 != 0)) {
    result->message =
        "num_disparities must be 0 (the options') or a positive multiple of 16, got " +
        std::to_string(num_disparities);
    return false;
  }
  // Inputs: rectified 8-bit grey pair of one size.
  if (left.empty() || right.empty()) {
    result->message = "left and right images must be non-empty (left is " + DescribeMat(left) +
                      ", right is " + DescribeMat(right) + ")";
    return false;
  }
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1) {
    result->message = "left and right images must be CV_8UC1 (left is " + DescribeMat(left) +
                      ", right is " + DescribeMat(right) + ")";
    return false;
  }
  if (left.size() != right.size()) {
    result->message = "left and right images must have the same size (left is " +
                      DescribeMat(left) + ", right is " + DescribeMat(right) + ")";
    return false;
  }
  const int nd = num_disparities > 0 ? num_disparities : o.num_disparities;
  const int max_disparity = o.min_disparity_px + nd - 1;
  if (left.rows < o.block_size || left.cols < o.block_size ||
      (!o.full_width && left.cols <= max_disparity + o.block_size)) {
    std::ostringstream msg;
    msg << "image " << DescribeMat(left) << " is too small for block_size " << o.block_size
        << (o.full_width ? "" : " and the disparity search range (full_width = false)");
    result->message = msg.str();
    return false;
  }
  return true;
}

}  // namespace

DisparityResult DisparityEstimator::Compute(const cv::Mat& left, const cv::Mat& right,
                                            int num_disparities) {
  DisparityResult result;
  const DisparityOptions& o = options_;
  if (!CheckPair(o, left, right, num_disparities, &result)) return result;
  const int nd = num_disparities > 0 ? num_disparities : o.num_disparities;
  const int max_disparity = o.min_disparity_px + nd - 1;
  if (impl_->matcher && impl_->matcher->getNumDisparities() != nd) {
    impl_->matcher->setNumDisparities(nd);
  }

  Impl& s = *impl_;
  const int half = o.block_size / 2;
  // Border padding (full_width): the matchers only estimate x >= max_disparity (+ half a
  // window); replicate-padding by that much on the left, and half a window elsewhere, lets
  // every real pixel be estimated. Matches landing in the padding are removed below.
  const int pad_left = o.full_width ? max_disparity + half + 1 : 0;
  const int pad_other = o.full_width ? half : 0;
  const cv::Rect roi(pad_left, pad_other, left.cols, left.rows);

  auto match = [&](cv::StereoMatcher& matcher, const cv::Mat& a, const cv::Mat& b, cv::Mat* fixed) {
    if (o.full_width) {
      cv::copyMakeBorder(a, s.padded_a, pad_other, pad_other, pad_left, pad_other,
                         cv::BORDER_REPLICATE);
      cv::copyMakeBorder(b, s.padded_b, pad_other, pad_other, pad_left, pad_other,
                         cv::BORDER_REPLICATE);
      matcher.compute(s.padded_a, s.padded_b, s.raw_fixed);
      s.raw_fixed(roi).copyTo(*fixed);
    } else {
      matcher.compute(a, b, *fixed);
    }
  };

  // Confidence (texture) filter input, SVS style: mean |I(x+1) - I(x-1)| over the window.
  // Compared as a window sum (integer, so the pixel-wise evaluation gets the same answer).
  const bool texture_filter = o.min_texture > 0.0;
  const int min_texture_sum = MinTextureSum(o);
  if (texture_filter) {
    cv::Sobel(left, s.gradient, CV_16S, 1, 0, /*ksize=*/1, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::convertScaleAbs(s.gradient, s.gradient);  // |I(x+1) - I(x-1)|, CV_8U
    cv::boxFilter(s.gradient, s.texture, CV_32S, cv::Size(o.block_size, o.block_size),
                  cv::Point(-1, -1), /*normalize=*/false, cv::BORDER_REPLICATE);
  }

  const bool lr_check = o.left_right_max_diff_px > 0.0;
  if (s.sad) {
    // Both views from one cost volume; the padding is the matcher's own (same rule). Pixels
    // the texture filter removes below skip the matcher's uniqueness test (same result).
    const cv::Mat* discard = nullptr;
    if (texture_filter) {
      cv::compare(s.texture, min_texture_sum, s.low_texture, cv::CMP_LT);
      discard = &s.low_texture;
    }
    s.sad->Compute(left, right, &s.left_fixed, lr_check ? &s.right_fixed : nullptr, discard, nd);
  } else {
    // Correlation along the epipolar lines, sub-pixel (1/16 px), left view.
    match(*s.matcher, left, right, &s.left_fixed);
    // Right view for the left-right check: matching the mirrored pair (flip(right) as the
    // reference image, flip(left) as the target) gives, per right-image pixel, the disparity
    // to its left-image match with the same sign convention; flipping back indexes it by x_r.
    if (lr_check) {
      cv::flip(right, s.flipped_a, 1);
      cv::flip(left, s.flipped_b, 1);
      match(*s.matcher, s.flipped_a, s.flipped_b, &s.right_fixed);
      cv::flip(s.right_fixed, s.right_fixed, 1);
    }
  }

  const int min_fixed = o.min_disparity_px * kDisparityScale;
  const double lr_max_diff_fixed = o.left_right_max_diff_px * kDisparityScale;

  // Post-filters, in order: no estimate, texture, match outside the right image, LR check.
  for (int y = 0; y < left.rows; ++y) {
    int16_t* d_row = s.left_fixed.ptr<int16_t>(y);
    const int16_t* r_row = lr_check ? s.right_fixed.ptr<int16_t>(y) : nullptr;
    const int* t_row = texture_filter ? s.texture.ptr<int>(y) : nullptr;
    for (int x = 0; x < left.cols; ++x) {
      const int16_t d = d_row[x];
      if (d < min_fixed) {
        d_row[x] = kInvalidFixed;
        continue;
      }
      if (texture_filter && t_row[x] < min_texture_sum) {
        d_row[x] = kInvalidFixed;
        ++result.num_rejected_texture;
        continue;
      }
      // Position of the match in the right image, rounded to the nearest pixel (fixed point).
      const int x_r_fixed = x * kDisparityScale - d + kDisparityScale / 2;
      if (x_r_fixed < 0) {  // lands in the padding, left of the right image: no real match
        d_row[x] = kInvalidFixed;
        continue;
      }
      const int x_r = x_r_fixed / kDisparityScale;
      if (lr_check) {
        const int16_t d_r = r_row[x_r];
        if (d_r < min_fixed || std::abs(static_cast<int>(d) - d_r) > lr_max_diff_fixed) {
          d_row[x] = kInvalidFixed;
          ++result.num_rejected_left_right;
          continue;
        }
      }
    }
  }

  // Speckle filter: small islands of similar disparity are usually mismatches.
  if (o.speckle_window_size > 0) {
    const int before = cv::countNonZero(s.left_fixed >= 0);
    cv::filterSpeckles(s.left_fixed, kInvalidFixed, o.speckle_window_size,
                       std::max(1.0, std::round(o.speckle_range_px * kDisparityScale)));
    result.num_rejected_speckle = before - cv::countNonZero(s.left_fixed >= 0);
  }

  s.left_fixed.convertTo(result.disparity_px, CV_32F, 1.0 / kDisparityScale);
  result.num_valid = cv::countNonZero(s.left_fixed >= 0);
  result.ok = true;
  return result;
}

DisparityResult DisparityEstimator::PrepareAtPixels(const cv::Mat& left, const cv::Mat& right,
                                                    int num_disparities) {
  DisparityResult result;
  Impl& s = *impl_;
  s.prepared = false;
  s.counts = PixelCounts();
  if (!CheckPair(options_, left, right, num_disparities, &result)) return result;
  if (!s.sad) {
    result.message = std::string("disparity at single pixels needs algorithm ") +
                     ToString(DisparityAlgorithm::kBlockMatchingOneVolume) + ", not " +
                     ToString(options_.algorithm);
    return result;
  }
  // The dense path's buffers (a first frame's map) are not needed by the sparse one.
  if (!s.left_fixed.empty()) {
    for (cv::Mat* m : {&s.padded_a, &s.padded_b, &s.flipped_a, &s.flipped_b, &s.raw_fixed,
                       &s.left_fixed, &s.right_fixed, &s.gradient, &s.texture, &s.low_texture}) {
      m->release();
    }
    s.sad->ReleaseDenseScratch();
  }
  s.sad->Prepare(left, right, num_disparities);
  left.copyTo(s.sparse_image);
  for (auto [map, touched] : {std::make_pair(&s.sparse_left, &s.touched_left),
                              std::make_pair(&s.sparse_right, &s.touched_right)}) {
    if (map->size() == left.size() && map->type() == CV_16S && map->isContinuous()) {
      int16_t* cache = map->ptr<int16_t>();
      for (int i : *touched) cache[i] = kUnevaluated;
    } else {
      map->create(left.size(), CV_16S);
      map->setTo(kUnevaluated);
    }
    touched->clear();
  }
  s.prepared = true;
  result.ok = true;
  return result;
}

float DisparityEstimator::DisparityAt(int x, int y) {
  Impl& s = *impl_;
  if (!s.prepared || x < 0 || y < 0 || x >= s.sparse_left.cols || y >= s.sparse_left.rows) {
    return kInvalidDisparity;
  }
  int16_t& cached = s.sparse_left.at<int16_t>(y, x);
  if (cached != kUnevaluated) return cached < 0 ? kInvalidDisparity : cached / 16.0f;
  s.touched_left.push_back(y * s.sparse_left.cols + x);
  const DisparityOptions& o = options_;
  ++s.counts.left;
  // The post-filters of Compute, in its order of effect (texture first: it needs no costs).
  cached = kInvalidFixed;
  if (o.min_texture > 0.0 &&
      TextureSum(s.sparse_image, x, y, o.block_size / 2) < MinTextureSum(o)) {
    ++s.counts.rejected_texture;
    return kInvalidDisparity;
  }
  const int16_t d = s.sad->LeftAt(x, y);
  const int min_fixed = o.min_disparity_px * kDisparityScale;
  if (d < min_fixed) return kInvalidDisparity;
  const int x_r_fixed = x * kDisparityScale - d + kDisparityScale / 2;
  if (x_r_fixed < 0) return kInvalidDisparity;  // lands left of the right image
  if (o.left_right_max_diff_px > 0.0) {
    const int x_r = x_r_fixed / kDisparityScale;
    int16_t& d_r = s.sparse_right.at<int16_t>(y, x_r);
    if (d_r == kUnevaluated) {
      s.touched_right.push_back(y * s.sparse_right.cols + x_r);
      d_r = s.sad->RightAt(x_r, y);
      ++s.counts.right;
    }
    if (d_r < min_fixed ||
        std::abs(static_cast<int>(d) - d_r) > o.left_right_max_diff_px * kDisparityScale) {
      ++s.counts.rejected_left_right;
      return kInvalidDisparity;
    }
  }
  cached = d;
  return d / 16.0f;
}

DisparityEstimator::PixelCounts DisparityEstimator::pixel_counts() const { return impl_->counts; }

cv::Size DisparityEstimator::prepared_size() const {
  return impl_->prepared ? impl_->sparse_left.size() : cv::Size();
}

DisparityResult ComputeDisparity(const cv::Mat& left, const cv::Mat& right,
                                 const DisparityOptions& options) {
  DisparityEstimator estimator(options);
  return estimator.Compute(left, right);
}

// ------------------------------------------------------------------------------------------
// Features <- disparity

namespace {

// AttachDepth over a disparity read through at(x, y) on a rows x cols grid.
template <class At>
AttachDepthResult AttachDepthWith(const At& at, int rows, int cols, const StereoCamera& cam,
                                  std::vector<Feature>* features,
                                  const DepthSamplingOptions& options) {
  AttachDepthResult result;
  std::string error;
  if (features == nullptr) {
    result.message = "features must not be null";
    return result;
  }
  if (!options.IsValid(&error)) {
    result.message = "invalid DepthSamplingOptions: " + error;
    return result;
  }
  if (!cam.IsValid(&error)) {
    result.message = "invalid StereoCamera: " + error;
    return result;
  }
  if (cols != cam.width || rows != cam.height) {
    std::ostringstream msg;
    msg << "disparity is " << cols << "x" << rows << " but the camera is " << cam.width << "x"
        << cam.height;
    result.message = msg.str();
    return result;
  }
  // Disparity range that maps into [min_depth_m, max_depth_m].
  const double min_d = cam.DisparityFromDepth(options.max_depth_m);
  const double max_d = cam.DisparityFromDepth(options.min_depth_m);
  for (Feature& f : *features) {
    const double u = f.uv_px.x();
    const double v = f.uv_px.y();
    float d = kInvalidDisparity;
    if (std::isfinite(u) && std::isfinite(v) && u > -0.5 && v > -0.5 && u < cols - 0.5 &&
        v < rows - 0.5) {
      d = options.sampling == DisparitySampling::kNearest
              ? SampleNearest(at, rows, cols, u, v, options.search_radius_px)
              : SampleBilinear(at, rows, cols, u, v, options);
    }
    if (d > 0.0f && d >= min_d && d <= max_d) {
      f.disparity_px = d;
      f.p_cam0 = cam.Backproject(u, v, d);
      ++result.num_with_depth;
    } else {
      f.disparity_px = -1.0;
      f.p_cam0 = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
      ++result.num_without_depth;
    }
  }
  result.ok = true;
  return result;
}

}  // namespace

AttachDepthResult AttachDepth(const cv::Mat& disparity, const StereoCamera& cam,
                              std::vector<Feature>* features, const DepthSamplingOptions& options) {
  if (disparity.empty() || disparity.type() != CV_32FC1) {
    AttachDepthResult result;
    result.message = "disparity must be a non-empty CV_32FC1 map, got " + DescribeMat(disparity);
    return result;
  }
  const auto at = [&disparity](int x, int y) { return disparity.at<float>(y, x); };
  return AttachDepthWith(at, disparity.rows, disparity.cols, cam, features, options);
}

AttachDepthResult AttachDepth(DisparityEstimator* estimator, const StereoCamera& cam,
                              std::vector<Feature>* features, const DepthSamplingOptions& options) {
  if (estimator == nullptr) {
    AttachDepthResult result;
    result.message = "estimator must not be null";
    return result;
  }
  const cv::Size size = estimator->prepared_size();
  if (size.width == 0) {
    AttachDepthResult result;
    result.message = "the estimator holds no prepared pair (PrepareAtPixels)";
    return result;
  }
  const auto at = [estimator](int x, int y) { return estimator->DisparityAt(x, y); };
  return AttachDepthWith(at, size.height, size.width, cam, features, options);
}

int DropFeaturesWithoutDepth(std::vector<Feature>* features) {
  if (features == nullptr) return 0;
  const auto first_removed = std::remove_if(features->begin(), features->end(),
                                            [](const Feature& f) { return !f.has_depth(); });
  const int removed = static_cast<int>(features->end() - first_removed);
  features->erase(first_removed, features->end());
  return removed;
}

}  // namespace vo
