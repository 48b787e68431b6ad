// Normalised cross-correlation (NCC) of W×W patches, mapped to [0, 1] as in eq. (2) of
// Kwolek, "Visual Odometry Based on Gabor Filters and Sparse Bundle Adjustment":
//
//   C = Σ_{W×W} (I − Ī)(T − T̄) / (2 W² σ_I σ_T) + ½
//
// with Ī, T̄ the patch means and σ_I, σ_T the population standard deviations (divide by W²),
// i.e. C = (ρ + 1) / 2 for the Pearson correlation ρ ∈ [−1, 1]: 1 = identical up to gain and
// offset, ½ = uncorrelated, 0 = negated.
//
// Two forms:
//   - NccScore(): direct, double precision, for one pair (reference and tests);
//   - NccPatches: each feature's patch extracted once, zero-meaned and scaled to unit norm,
//     stored as a padded float vector, so C of a pair is ½·dot + ½ (the fast form used by
//     the matchers; patches are cached per frame, see matcher.h).
//
// Patches are centred on the pixel nearest to the feature position (no interpolation).
// Undefined cases come back explicitly (NccStatus) with score 0, which is "no evidence of a
// match" for every matcher: a patch crossing the image border, and a flat patch (σ below
// Options::min_stddev; ρ is 0/0 there).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/types.h"

namespace vo {

struct NccOptions {
  int window_px = 11;        // W: side of the square patch (pixels), odd, 3..63; paper: 11
  double min_stddev = 1e-3;  // patches with σ below this (grey levels, >= 0) count as flat
                             // (status kFlat, score 0); raise it (e.g. 2.0) to also reject
                             // nearly uniform, noise-only patches

  bool IsValid(std::string* error) const;
  bool operator==(const NccOptions& o) const {
    return window_px == o.window_px && min_stddev == o.min_stddev;
  }
  bool operator!=(const NccOptions& o) const { return !(*this == o); }
};

enum class NccStatus : uint8_t {
  kOk = 0,
  kOutOfBounds = 1,  // the W×W patch crosses the image border
  kFlat = 2,         // σ < min_stddev: correlation undefined
};

// Eq. (2) for the patches of `image_a` centred at `center_a` and of `image_b` at `center_b`
// (pixel coordinates, rounded to the nearest pixel). Images: CV_8UC1. Returns C ∈ [0, 1];
// returns 0 and sets *status (if non-null) to kOutOfBounds / kFlat when undefined.
double NccScore(const cv::Mat& image_a, const Eigen::Vector2d& center_a, const cv::Mat& image_b,
                const Eigen::Vector2d& center_b, const NccOptions& options,
                NccStatus* status = nullptr);

// Zero-mean, unit-norm patches of a set of features of one image: the fast form of eq. (2).
class NccPatches {
 public:
  NccPatches() = default;

  // Extracts the patch of every feature of `image` (CV_8UC1). Options must be valid.
  void Compute(const cv::Mat& image, const std::vector<Feature>& features,
               const NccOptions& options);

  int size() const { return static_cast<int>(status_.size()); }
  const NccOptions& options() const { return options_; }
  NccStatus status(int i) const { return status_[i]; }
  bool valid(int i) const { return status_[i] == NccStatus::kOk; }

  // C ∈ [0, 1] between patch i of this set and patch j of `other` (same window size);
  // 0 when either patch is not kOk. Cost: one dot product of W² floats.
  double Score(int i, const NccPatches& other, int j) const;

  // Pearson correlation ρ ∈ [−1, 1] (0 when either patch is not kOk).
  double Correlation(int i, const NccPatches& other, int j) const;

 private:
  NccOptions options_;
  int stride_ = 0;           // floats per patch: W² rounded up to a multiple of 8 (zero tail)
  std::vector<float> data_;  // size() × stride_, row-major patches, zero-mean, unit L2 norm
  std::vector<NccStatus> status_;
};

}  // namespace vo
