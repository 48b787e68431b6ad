#include "vo/gabor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include <opencv2/imgproc.hpp>

namespace vo {
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
  a = std::remainder(a, 2.0 * kPi);  // [−π, π]
  return a <= -kPi ? a + 2.0 * kPi : a;
}

// eq. (4) at one point for one wavelength: acc[l] += I(x+dx, y+dy) · tap[l] over the disc.
// LANES is a compile-time constant so the lane update is a fixed-width vector operation.
template <int LANES>
void AccumulateTaps(const cv::Mat& image, int x, int y, const std::vector<int>& row_dy,
                    const std::vector<int>& row_dx0, const float* taps, float* acc_out) {
  float acc[LANES];
  for (int l = 0; l < LANES; ++l) acc[l] = 0.f;
  const float* t = taps;
  for (size_t r = 0; r < row_dy.size(); ++r) {
    const int dx0 = row_dx0[r];
    const int len = 1 - 2 * dx0;
    const float* p = image.ptr<float>(y + row_dy[r]) + (x + dx0);
    for (int u = 0; u < len; ++u, t += LANES) {
      const float v = p[u];
      for (int l = 0; l < LANES; ++l) acc[l] += v * t[l];
    }
  }
  for (int l = 0; l < LANES; ++l) acc_out[l] = acc[l];
}

}  // namespace

bool GaborOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (num_orientations < 1 || num_orientations > kMaxOrientations) {
    msg << "GaborOptions::num_orientations must be in [1, 16], got " << num_orientations;
  } else if (wavelengths_px.empty() || wavelengths_px.size() > kMaxWavelengths) {
    msg << "GaborOptions::wavelengths_px must hold 1..8 values, got " << wavelengths_px.size();
  } else if (!(sigma_per_wavelength >= 0.2 && sigma_per_wavelength <= 2.0)) {
    msg << "GaborOptions::sigma_per_wavelength must be in [0.2, 2], got "
        << sigma_per_wavelength;
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
         subpixel_phase_correction == o.subpixel_phase_correction &&
         weighting == o.weighting && min_amplitude == o.min_amplitude &&
         phase_exponent == o.phase_exponent && unknown_phase_diff_rad == o.unknown_phase_diff_rad;
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
    int num_taps = 0;
    for (int dy = -s.radius; dy <= s.radius; ++dy) {
      const int half = static_cast<int>(std::floor(std::sqrt(double(s.radius) * s.radius - dy * dy)));
      s.row_dy.push_back(dy);
      s.row_dx0.push_back(-half);
      num_taps += 2 * half + 1;
    }
    // eq. (3) for every orientation; real part made zero-DC, then scaled so Σ envelope = 2.
    std::vector<double> env(num_taps), re(num_taps), im(num_taps);
    s.taps.assign(static_cast<size_t>(num_taps) * lanes_, 0.f);
    for (int o = 0; o < n; ++o) {
      double sum_env = 0.0, sum_re = 0.0, sum_im = 0.0;
      int t = 0;
      for (size_t r = 0; r < s.row_dy.size(); ++r) {
        const double y = s.row_dy[r];
        for (int x = s.row_dx0[r]; x <= -s.row_dx0[r]; ++x, ++t) {
          const double r1 = x * cos_theta_[o] + y * sin_theta_[o];   // R1: along the wave
          const double r2 = -x * sin_theta_[o] + y * cos_theta_[o];  // R2: along the front
          env[t] = std::exp(-0.5 * (r1 * r1 / (sigma_x * sigma_x) + r2 * r2 / (sigma_y * sigma_y)));
          re[t] = env[t] * std::cos(2.0 * kPi * r1 / lambda);
          im[t] = env[t] * std::sin(2.0 * kPi * r1 / lambda);
          sum_env += env[t];
          sum_re += re[t];
          sum_im += im[t];
        }
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

void GaborBank::Evaluate(const cv::Mat& level_image, const Scale& scale, int x, int y, float* re,
                         float* im) const {
  float acc[4 * kLaneBlock];
  switch (lanes_) {
    case 8:
      AccumulateTaps<8>(level_image, x, y, scale.row_dy, scale.row_dx0, scale.taps.data(), acc);
      break;
    case 16:
      AccumulateTaps<16>(level_image, x, y, scale.row_dy, scale.row_dx0, scale.taps.data(), acc);
      break;
    default:
      AccumulateTaps<32>(level_image, x, y, scale.row_dy, scale.row_dx0, scale.taps.data(), acc);
      break;
  }
  const int n = options_.num_orientations;
  for (int o = 0; o < n; ++o) {
    re[o] = acc[o];
    im[o] = acc[n + o];
  }
}

GaborResponses GaborBank::Compute(const cv::Mat& image, const std::vector<Feature>& features) const {
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
  const bool need_half = std::any_of(scales_.begin(), scales_.end(),
                                     [](const Scale& s) { return s.level == 1; });
  if (need_half) cv::pyrDown(levels[0], levels[1]);

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
      Evaluate(img, s, x, y, re, im);
      const double dx = uv.x() - x * step, dy = uv.y() - y * step;  // full-res offset
      for (int o = 0; o < n; ++o) {
        const int k = o + n * static_cast<int>(w);
        double phi = std::atan2(static_cast<double>(im[o]), static_cast<double>(re[o]));
        if (options_.subpixel_phase_correction) {
          // Moving the evaluation point by δ along θ lowers the phase by 2πδ/λ.
          phi -= 2.0 * kPi * (dx * cos_theta_[o] + dy * sin_theta_[o]) / s.wavelength_px;
          phi = WrapPi(phi);
        }
        phase[k] = static_cast<float>(phi);
        amplitude[k] = std::hypot(re[o], im[o]);
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
  const float min_amplitude = static_cast<float>(opt.min_amplitude);
  // eq. (5) as a sum of logs: log S = −β Σ w_k |Δφ_k| / Σ w_k, |Δφ| wrapped to [0, π].
  double sum_w = 0.0, sum_wd = 0.0;
  for (int k = 0; k < num_filters; ++k) {
    if (aa[k] < min_amplitude || ab[k] < min_amplitude || aa[k] < 0.f || ab[k] < 0.f) continue;
    const double w = opt.weighting == PhaseWeighting::kAmplitude
                         ? std::sqrt(static_cast<double>(aa[k]) * ab[k])
                         : 1.0;
    sum_w += w;
    sum_wd += w * WrappedPhaseDiff(pa[k], pb[k]);
  }
  const double mean_diff = sum_w > 0.0 ? sum_wd / sum_w : opt.unknown_phase_diff_rad;
  return std::exp(-opt.phase_exponent * mean_diff);
}

}  // namespace vo
