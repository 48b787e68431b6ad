// Complex Gabor filter bank evaluated only at feature positions, and the phase similarity of
// Kwolek, "Visual Odometry Based on Gabor Filters and Sparse Bundle Adjustment", eqs. (3)–(5).
//
// Kernel, eq. (3), with R1 = x cosθ + y sinθ, R2 = −x sinθ + y cosθ:
//   f(x, y; θ, λ) = exp(−½ (R1²/σx² + R2²/σy²)) · exp(i 2π R1 / λ)
// orientations θ_k = π (k−1) / n, k = 1..n (n = 4: 0°, 45°, 90°, 135°), wavelengths λ.
// Envelope tied to λ: σx = sigma_per_wavelength · λ, σy = σx / aspect. The default 0.56 gives
// a half-magnitude bandwidth of one octave, since σ/λ = (1/π)·sqrt(ln2 / 2)·(2^b + 1)/(2^b − 1)
// for a bandwidth of b octaves. The real part is made zero-DC (the envelope times a constant
// is subtracted, Morlet-style), so responses ignore a brightness offset; the imaginary part is
// odd and zero-DC already. Kernels are scaled so that Σ envelope = 2: a sinusoid of amplitude
// A grey levels at the filter's own frequency and orientation gives |response| ≈ A.
//
// Response, eq. (4): g(x) = Σ_u I(x + u) f(u) (a correlation, evaluated directly at the
// feature only; kernels truncated at truncate_sigmas · σ and precomputed as float taps).
// Phase φ = atan2(Im g, Re g). With this convention a pattern translated by δ pixels along θ
// has its phase increased by 2πδ/λ, and moving the evaluation point by δ along θ decreases it
// by 2πδ/λ; the sub-pixel part of a feature position is applied as that linear correction.
//
// Speed: filters with λ >= half_res_min_wavelength_px are evaluated on the half-resolution
// image (cv::pyrDown: binomial 5-tap prefilter, decimation by 2) with λ/2 and σ/2: their
// one-octave passband ([2/3, 4/3]/λ <= 1/6 cycle/px) lies below the half-resolution Nyquist
// frequency (1/4), so the phase is kept while the kernel has 4× fewer taps. The prefilter
// attenuates their amplitude (by cos⁴(π/λ), ≈ 0.73 at λ = 8); phases are unaffected (the
// prefilter is symmetric).
//
// Phase similarity, eq. (5): G_ij = c · Π_{θ,λ} exp(−|Δφ_θλ|). Here |Δφ| is the wrapped
// difference in [0, π] (a plain difference is wrong near ±π), and the product is computed as a
// sum of logs and normalised as a weighted mean over the F usable filters:
//   S_ij = exp(−β · Σ_k w_k |Δφ_k| / Σ_k w_k) ∈ [e^{−βπ}, 1].
// β = phase_exponent: β = 1 is the geometric mean of the F factors of eq. (5) (c = the F-th
// root), β = F is eq. (5) literally with c = 1. The default β = 3 was chosen on the 640×480
// synthetic pairs of svd_matcher_test (~500 corners, two motions): the geometric mean is too
// flat to separate true pairs (S ≈ 0.78) from unrelated ones (S ≈ 0.2–0.3) inside the SVD
// (precision 0.49 at the harder motion with the matcher's cue thresholds off, 0.79 at β = 3),
// while β = F makes G so peaked that true pairs fall below the minimum-weight acceptance
// (recall 0.12–0.35, against 0.61–0.96 at β = 3). A filter is usable at a pair when both
// responses have amplitude >= min_amplitude (phase is meaningless where the response is ~0)
// and lie inside the image; w_k = 1 (PhaseWeighting::kUniform) or the geometric mean of the
// two amplitudes (kAmplitude: strong, reliable responses count more). With no usable filter
// S = exp(−β · unknown_phase_diff_rad), by default π/2: the mean |Δφ| of unrelated phases.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/types.h"

namespace vo {

enum class PhaseWeighting {
  kUniform,    // every usable filter counts the same (the paper's product)
  kAmplitude,  // weight w_k = sqrt(amplitude_i · amplitude_j)
};
// "uniform", "amplitude".
const char* ToString(PhaseWeighting weighting);

struct GaborOptions {
  int num_orientations = 4;  // n: θ_k = π (k−1) / n; paper: 4; in [1, 16]
  std::vector<double> wavelengths_px = {4.0, 6.0, 8.0, 12.0};
  // λ of the plane wave (pixels, full resolution), each >= 2.5 (above Nyquist), at most 8
  // of them. Default: a half-octave ladder from 4 px (finest phase that survives the
  // ~0.5 px corner jitter: 1 px error = π/2 rad) to 12 px (about the 11-px NCC window), so
  // the phases describe the neighbourhood the NCC compares and a bit beyond
  double sigma_per_wavelength = 0.56;  // σx / λ (envelope spread along the wave); 0.56 = one
                                       // octave bandwidth; in [0.2, 2]
  double aspect = 1.0;  // γ = σx / σy; 1 = isotropic (all orientations share one compact disc
                        // of taps); < 1 elongates along the wave front; in [0.25, 4]
  double truncate_sigmas = 2.0;  // kernel radius = ceil(truncate_sigmas · max(σx, σy)) pixels
                                 // (of the level evaluated); 2 keeps 86 % of the envelope mass;
                                 // in [1, 4]
  double half_res_min_wavelength_px = 8.0;  // filters with λ >= this are evaluated on the
                                            // half-resolution image (4× fewer taps); a
                                            // value > every λ disables it; >= 5 (λ/2 must stay
                                            // >= 2.5)
  bool subpixel_phase_correction = true;    // apply the sub-pixel offset of the feature (and of
                                            // the half-resolution sampling point) to the phase,
                                            // linearly: φ −= 2π (δ·n_θ) / λ
  PhaseWeighting weighting = PhaseWeighting::kUniform;  // see header comment
  double min_amplitude = 1.0;   // a filter's phase is used only where |g| >= this (grey levels
                                // of an equivalent sinusoid); >= 0
  double phase_exponent = 3.0;  // β in S = exp(−β · mean |Δφ|); 1 = geometric mean of the
                                // factors of eq. (5), F = eq. (5) with c = 1; in (0, 64]
  double unknown_phase_diff_rad = 1.5707963267948966;  // mean |Δφ| assumed when no filter is
                                                       // usable at a pair (rad, [0, π]); π/2 =
                                                       // that of unrelated phases

  int num_filters() const { return num_orientations * static_cast<int>(wavelengths_px.size()); }
  bool IsValid(std::string* error) const;
  bool operator==(const GaborOptions& o) const;
  bool operator!=(const GaborOptions& o) const { return !(*this == o); }
};

// Phases and amplitudes of every filter at every feature of one image. Filter index
// k = orientation + num_orientations · wavelength_index.
struct GaborResponses {
  GaborOptions options;          // the bank that produced them
  int num_filters = 0;           // F
  std::vector<float> phase;      // size() × F, radians in (−π, π]
  std::vector<float> amplitude;  // size() × F, |g| (grey levels); < 0 where the kernel window
                                 // crosses the image border (filter unusable there)

  int size() const { return num_filters == 0 ? 0 : static_cast<int>(phase.size()) / num_filters; }
  const float* phase_of(int i) const { return phase.data() + static_cast<size_t>(i) * num_filters; }
  const float* amplitude_of(int i) const {
    return amplitude.data() + static_cast<size_t>(i) * num_filters;
  }
};

class GaborBank {
 public:
  // Precomputes the kernels. Options must be valid (aborts otherwise: a programmer error).
  explicit GaborBank(const GaborOptions& options = GaborOptions());

  const GaborOptions& options() const { return options_; }
  int num_filters() const { return options_.num_filters(); }

  // Responses of every filter at every feature of `image` (CV_8UC1, any size; empty features
  // give empty responses). Builds the float image (and its half-resolution copy) once.
  GaborResponses Compute(const cv::Mat& image, const std::vector<Feature>& features) const;

  // Kernel radius (pixels of its own level) and level (0 = full, 1 = half resolution) of the
  // filters of wavelength index w.
  int radius(int w) const { return scales_[w].radius; }
  int level(int w) const { return scales_[w].level; }

 private:
  // Taps of the n orientations of one wavelength, on a disc of radius `radius`, interleaved
  // as [tap][lane]: lanes 0..n−1 = real parts, n..2n−1 = imaginary parts, zero-padded to
  // `lanes` (a multiple of 8) so the inner loop is a fixed-width vector update.
  struct Scale {
    double wavelength_px = 0.0;  // full-resolution λ
    int level = 0;               // 0 = full, 1 = half resolution
    int radius = 0;              // disc radius (pixels at `level`)
    std::vector<int> tap_dx;     // per tap: column offset (pixels at `level`)
    std::vector<int> tap_dy;     // per tap: row offset
    std::vector<float> taps;     // num_taps × lanes
  };

  // eq. (4) at the pixel `center` points to; offsets[t] = tap t's offset in floats.
  void Evaluate(const float* center, const int* offsets, const Scale& scale, float* re,
                float* im) const;

  GaborOptions options_;
  int lanes_ = 8;
  std::vector<Scale> scales_;
  std::vector<double> cos_theta_, sin_theta_;
};

// eq. (5): phase similarity S ∈ [e^{−βπ}, 1] between feature i of `a` and feature j of `b`
// (same bank), as described in the header comment.
double GaborPhaseSimilarity(const GaborResponses& a, int i, const GaborResponses& b, int j);

// |φa − φb| wrapped to [0, π] (radians; inputs in any range of width 2π, e.g. (−π, π]).
inline double WrappedPhaseDiff(double phi_a, double phi_b) {
  constexpr double kPi = 3.14159265358979323846;
  double d = phi_a - phi_b;
  d = d < 0.0 ? -d : d;
  d = d - 2.0 * kPi * static_cast<int>(d / (2.0 * kPi));  // [0, 2π)
  return d > kPi ? 2.0 * kPi - d : d;
}

}  // namespace vo
