#include "vo/gabor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace vo {

const char* ToString(PhaseWeighting weighting) {
  switch (weighting) {
    case PhaseWeighting::kUniform:
      return "uniform";
    case PhaseWeighting::kAmplitude:
      return "amplitude";
  }
  return "unknown";
}
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxOrientations = 16;
constexpr int kMaxWavelengths = 8;
constexpr double kMinWavelengthPx = 2.5;  // below this the wave is at the Nyquist limit
constexpr int kLaneBlock = 8;             // tap lanes are padded to a multiple of this

// Programmer errors abort with a message (no exceptions across the vo API).
void CheckOrDie(bool ok, const char* message) {
  if (ok) return;
  std::fprintf(stderr, "vo/gabor: %s\n", message);
  std::abort();
}

// Wraps an angle to (−π, π].
inline double WrapPi(double a) {
  while (a > kPi) a -= 2.0 * kPi;
  while (a <= -kPi) a += 2.0 * kPi;
  return a;
}

// atan2(y, x) in [−π, π] with an absolute error below 3e-7 rad (libm's atan2 dominated the
// cost of the bank). atan(t) on [0, 1] as t·p(t²), p of degree 6 fitted to atan by weighted
// least squares (iteratively reweighted towards the maximum error), then the octant symmetries.
inline double FastAtan2(double y, double x) {
  constexpr double kC[7] = {0.99999611155398827,  -0.33317368059502717, 0.19807815572268669,
                            -0.13233342053706629, 0.079623670876101296, -0.033604218892024841,
                            0.0068117926587647343};
  const double ax = std::abs(x), ay = std::abs(y);
  const double mx = std::max(ax, ay), mn = std::min(ax, ay);
  if (mx == 0.0) return 0.0;
  const double t = mn / mx, t2 = t * t;
  double a = kC[6];
  for (int k = 5; k >= 0; --k) a = a * t2 + kC[k];
  a *= t;
  if (ay > ax) a = 0.5 * kPi - a;
  if (x < 0.0) a = kPi - a;
  return y < 0.0 ? -a : a;
}

// eq. (4) at one point for one wavelength, for 8 lanes (orientations × re/im) starting at
// the lane `taps` points to: acc[l] += I(centre + offset[t]) · tap[t][l] over the T taps of
// the disc, taps `stride` floats apart. The 8 lanes are updated together as two 4-float
// vectors where the compiler has vector extensions (GCC/Clang: SSE2 on x86-64, NEON on ARM),
// a plain loop otherwise; four interleaved partial sums (taps t mod 4) hide the add latency.
// Both paths sum in the same order, so the result does not depend on the path.
#if defined(__GNUC__) || defined(__clang__)
typedef float Float4 __attribute__((vector_size(16), aligned(4)));  // unaligned loads allowed

inline Float4 Load4(const float* p) { return *reinterpret_cast<const Float4*>(p); }

void Accumulate8(const float* center, const int* offsets, int num_taps, const float* taps,
                 int stride, float* out) {
  const Float4 zero = {0.f, 0.f, 0.f, 0.f};
  Float4 a0 = zero, a1 = zero, b0 = zero, b1 = zero, c0 = zero, c1 = zero, d0 = zero, d1 = zero;
  int t = 0;
  for (; t + 4 <= num_taps; t += 4) {
    const float* k = taps + static_cast<size_t>(t) * stride;
    const float v0 = center[offsets[t]], v1 = center[offsets[t + 1]];
    const float v2 = center[offsets[t + 2]], v3 = center[offsets[t + 3]];
    a0 += v0 * Load4(k);
    a1 += v0 * Load4(k + 4);
    b0 += v1 * Load4(k + stride);
    b1 += v1 * Load4(k + stride + 4);
    c0 += v2 * Load4(k + 2 * stride);
    c1 += v2 * Load4(k + 2 * stride + 4);
    d0 += v3 * Load4(k + 3 * stride);
    d1 += v3 * Load4(k + 3 * stride + 4);
  }
  for (; t < num_taps; ++t) {
    const float* k = taps + static_cast<size_t>(t) * stride;
    const float v = center[offsets[t]];
    a0 += v * Load4(k);
    a1 += v * Load4(k + 4);
  }
  const Float4 s0 = (a0 + b0) + (c0 + d0), s1 = (a1 + b1) + (c1 + d1);
  for (int l = 0; l < 4; ++l) {
    out[l] = s0[l];
    out[4 + l] = s1[l];
  }
}
#else
void Accumulate8(const float* center, const int* offsets, int num_taps, const float* taps,
                 int stride, float* out) {
  float acc[4][8] = {};
  for (int t = 0; t < num_taps; ++t) {
    // Tap t goes to partial sum t mod 4 while a full group of 4 remains, else to sum 0.
    const int part = t < num_taps / 4 * 4 ? t % 4 : 0;
    const float* k = taps + static_cast<size_t>(t) * stride;
    const float v = center[offsets[t]];
    for (int l = 0; l < 8; ++l) acc[part][l] += v * k[l];
  }
  for (int l = 0; l < 8; ++l) out[l] = (acc[0][l] + acc[1][l]) + (acc[2][l] + acc[3][l]);
}
#endif

}  // namespace

bool GaborOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (num_orientations < 1 || num_orientations > kMaxOrientations) {
    msg << "GaborOptions::num_orientations must be in [1, 16], got " << num_orientations;
  } else if (wavelengths_px.empty() || wavelengths_px.size() > kMaxWavelengths) {
    msg << "GaborOptions::wavelengths_px must hold 1..8 values, got " << wavelengths_px.size();
  } else if (!(sigma_per_wavelength >= 0.2 && sigma_per_wavelength <= 2.0)) {
    msg << "GaborOptions::sigma_per_wavelength must be in [0.2, 2], got " << sigma_per_wavelength;
  } else if (!(aspect >= 0.25 && aspect <= 4.0)) {
    msg << "GaborOptions::aspect must be in [0.25, 4], got " << aspect;
  } else if (!(truncate_sigmas >= 1.0 && truncate_sigmas <= 4.0)) {
    msg << "GaborOptions::truncate_sigmas must be in [1, 4], got " << truncate_sigmas;
  } else if (!(half_res_min_wavelength_px >= 2.0 * kMinWavelengthPx)) {
    msg << "GaborOptions::half_res_min_wavelength_px must be >= 5, got "
        << half_res_min_wavelength_px;
  } else if (!(min_amplitude >= 0.0) || !std::isfinite(min_amplitude)) {
    msg << "GaborOptions::min_amplitude must be finite and >= 0, got " << min_amplitude;
  } else if (!(phase_exponent > 0.0 && phase_exponent <= 64.0)) {
    msg << "GaborOptions::phase_exponent must be in (0, 64], got " << phase_exponent;
  } else if (!(unknown_phase_diff_rad >= 0.0 && unknown_phase_diff_rad <= kPi)) {
    msg << "GaborOptions::unknown_phase_diff_rad must be in [0, pi], got "
        << unknown_phase_diff_rad;
  } else {
    for (double lambda : wavelengths_px) {
      if (!(lambda >= kMinWavelengthPx && lambda <= 1e3)) {
        msg << "GaborOptions::wavelengths_px values must be in [2.5, 1000], got " << lambda;
        break;
      }
    }
  }
  if (msg.tellp() == 0) return true;
  if (error != nullptr) *error = msg.str();
  return false;
}

bool GaborOptions::operator==(const GaborOptions& o) const {
  return num_orientations == o.num_orientations && wavelengths_px == o.wavelengths_px &&
         sigma_per_wavelength == o.sigma_per_wavelength && aspect == o.aspect &&
         truncate_sigmas == o.truncate_sigmas &&
         half_res_min_wavelength_px == o.half_res_min_wavelength_px &&
         subpixel_phase_correction == o.subpixel_phase_correction && weighting == o.weighting &&
         min_amplitude == o.min_amplitude && phase_exponent == o.phase_exponent &&
         unknown_phase_diff_rad == o.unknown_phase_diff_rad;
}

GaborBank::GaborBank(const GaborOptions& options) : options_(options) {
  std::string error;
  if (!options_.IsValid(&error)) CheckOrDie(false, error.c_str());
  const int n = options_.num_orientations;
  lanes_ = (2 * n + kLaneBlock - 1) / kLaneBlock * kLaneBlock;
  for (int o = 0; o < n; ++o) {
    const double theta = kPi * o / n;  // θ_k = π (k−1) / n
    cos_theta_.push_back(std::cos(theta));
    sin_theta_.push_back(std::sin(theta));
  }
  for (double lambda_full : options_.wavelengths_px) {
    Scale s;
    s.wavelength_px = lambda_full;
    s.level = lambda_full >= options_.half_res_min_wavelength_px ? 1 : 0;
    const double lambda = lambda_full / (1 << s.level);  // λ at the evaluated level
    const double sigma_x = options_.sigma_per_wavelength * lambda;
    const double sigma_y = sigma_x / options_.aspect;
    s.radius = static_cast<int>(std::ceil(options_.truncate_sigmas * std::max(sigma_x, sigma_y)));
    // Disc of taps, row by row.
    for (int dy = -s.radius; dy <= s.radius; ++dy) {
      const int half =
          static_cast<int>(std::floor(std::sqrt(double(s.radius * s.radius - dy * dy))));
      for (int dx = -half; dx <= half; ++dx) {
        s.tap_dx.push_back(dx);
        s.tap_dy.push_back(dy);
      }
    }
    const int num_taps = static_cast<int>(s.tap_dx.size());
    // eq. (3) for every orientation; real part made zero-DC, then scaled so Σ envelope = 2.
    std::vector<double> env(num_taps), re(num_taps), im(num_taps);
    s.taps.assign(static_cast<size_t>(num_taps) * lanes_, 0.f);
    for (int o = 0; o < n; ++o) {
      double sum_env = 0.0, sum_re = 0.0, sum_im = 0.0;
      for (int t = 0; t < num_taps; ++t) {
        const double x = s.tap_dx[t], y = s.tap_dy[t];
        const double r1 = x * cos_theta_[o] + y * sin_theta_[o];   // R1: along the wave
        const double r2 = -x * sin_theta_[o] + y * cos_theta_[o];  // R2: along the front
        env[t] = std::exp(-0.5 * (r1 * r1 / (sigma_x * sigma_x) + r2 * r2 / (sigma_y * sigma_y)));
        re[t] = env[t] * std::cos(2.0 * kPi * r1 / lambda);
        im[t] = env[t] * std::sin(2.0 * kPi * r1 / lambda);
        sum_env += env[t];
        sum_re += re[t];
        sum_im += im[t];
      }
      const double dc_re = sum_re / sum_env, dc_im = sum_im / sum_env;
      const double scale = 2.0 / sum_env;
      for (int k = 0; k < num_taps; ++k) {
        s.taps[static_cast<size_t>(k) * lanes_ + o] =
            static_cast<float>(scale * (re[k] - dc_re * env[k]));
        s.taps[static_cast<size_t>(k) * lanes_ + n + o] =
            static_cast<float>(scale * (im[k] - dc_im * env[k]));
      }
    }
    scales_.push_back(std::move(s));
  }
}

void GaborBank::Evaluate(const float* center, const int* offsets, const Scale& scale, float* re,
                         float* im) const {
  float acc[2 * kMaxOrientations + kLaneBlock];
  const int num_taps = static_cast<int>(scale.tap_dx.size());
  for (int first = 0; first < lanes_; first += kLaneBlock) {
    Accumulate8(center, offsets, num_taps, scale.taps.data() + first, lanes_, acc + first);
  }
  const int n = options_.num_orientations;
  for (int o = 0; o < n; ++o) {
    re[o] = acc[o];
    im[o] = acc[n + o];
  }
}

GaborResponses GaborBank::Compute(const cv::Mat& image,
                                  const std::vector<Feature>& features) const {
  GaborResponses out;
  out.options = options_;
  out.num_filters = num_filters();
  const size_t num_features = features.size();
  out.phase.assign(num_features * out.num_filters, 0.f);
  out.amplitude.assign(num_features * out.num_filters, -1.f);
  if (num_features == 0) return out;
  CheckOrDie(image.type() == CV_8UC1, "GaborBank::Compute needs a CV_8UC1 image");

  // Float images of the levels used: full and (if any filter needs it) half resolution.
  cv::Mat levels[2];
  image.convertTo(levels[0], CV_32F);
  const bool need_half =
      std::any_of(scales_.begin(), scales_.end(), [](const Scale& s) { return s.level == 1; });
  if (need_half) cv::pyrDown(levels[0], levels[1]);

  // Tap offsets (floats from the centre pixel) of every scale in its level's image.
  std::vector<std::vector<int>> offsets(scales_.size());
  for (size_t w = 0; w < scales_.size(); ++w) {
    const int step = static_cast<int>(levels[scales_[w].level].step1());
    for (size_t t = 0; t < scales_[w].tap_dx.size(); ++t) {
      offsets[w].push_back(scales_[w].tap_dy[t] * step + scales_[w].tap_dx[t]);
    }
  }

  const int n = options_.num_orientations;
  float re[kMaxOrientations], im[kMaxOrientations];
  for (size_t i = 0; i < num_features; ++i) {
    const Eigen::Vector2d& uv = features[i].uv_px;
    float* phase = out.phase.data() + i * out.num_filters;
    float* amplitude = out.amplitude.data() + i * out.num_filters;
    for (size_t w = 0; w < scales_.size(); ++w) {
      const Scale& s = scales_[w];
      const cv::Mat& img = levels[s.level];
      const double step = 1 << s.level;  // full-resolution pixels per level pixel
      // Nearest sampling point of the level; pyrDown puts level pixel x at full-res 2x.
      const int x = static_cast<int>(std::lround(uv.x() / step));
      const int y = static_cast<int>(std::lround(uv.y() / step));
      if (x - s.radius < 0 || y - s.radius < 0 || x + s.radius >= img.cols ||
          y + s.radius >= img.rows) {
        continue;  // window crosses the border: amplitude stays < 0 (unusable)
      }
      Evaluate(img.ptr<float>(y) + x, offsets[w].data(), s, re, im);
      const double dx = uv.x() - x * step, dy = uv.y() - y * step;  // full-res offset
      for (int o = 0; o < n; ++o) {
        const int k = o + n * static_cast<int>(w);
        double phi = FastAtan2(im[o], re[o]);
        if (options_.subpixel_phase_correction) {
          // Moving the evaluation point by δ along θ lowers the phase by 2πδ/λ.
          phi -= 2.0 * kPi * (dx * cos_theta_[o] + dy * sin_theta_[o]) / s.wavelength_px;
          phi = WrapPi(phi);
        }
        phase[k] = static_cast<float>(phi);
        amplitude[k] = std::sqrt(re[o] * re[o] + im[o] * im[o]);
      }
    }
  }
  return out;
}

double GaborPhaseSimilarity(const GaborResponses& a, int i, const GaborResponses& b, int j) {
  const GaborOptions& opt = a.options;
  const int num_filters = a.num_filters;
  const float* pa = a.phase_of(i);
  const float* pb = b.phase_of(j);
  const float* aa = a.amplitude_of(i);
  const float* ab = b.amplitude_of(j);
  // A filter is usable where both amplitudes reach min_amplitude (and are >= 0: inside the
  // image). The phases lie in (−π, π], so |Δφ| < 2π and one reflection wraps it to [0, π].
  const float min_amplitude = std::max(0.f, static_cast<float>(opt.min_amplitude));
  constexpr float kTwoPi = static_cast<float>(2.0 * kPi);
  // eq. (5) as a sum of logs: log S = −β Σ w_k |Δφ_k| / Σ w_k.
  float sum_w = 0.f, sum_wd = 0.f;
  if (opt.weighting == PhaseWeighting::kAmplitude) {
    for (int k = 0; k < num_filters; ++k) {
      const bool usable = aa[k] >= min_amplitude && ab[k] >= min_amplitude;
      const float d = std::abs(pa[k] - pb[k]);
      const float w = usable ? std::sqrt(aa[k] * ab[k]) : 0.f;
      sum_w += w;
      sum_wd += w * std::min(d, kTwoPi - d);
    }
  } else {
    for (int k = 0; k < num_filters; ++k) {
      const bool usable = aa[k] >= min_amplitude && ab[k] >= min_amplitude;
      const float d = std::abs(pa[k] - pb[k]);
      sum_w += usable ? 1.f : 0.f;
      sum_wd += usable ? std::min(d, kTwoPi - d) : 0.f;
    }
  }
  const double mean_diff =
      sum_w > 0.f ? static_cast<double>(sum_wd) / sum_w : opt.unknown_phase_diff_rad;
  return std::exp(-opt.phase_exponent * mean_diff);
}

}  // namespace vo
