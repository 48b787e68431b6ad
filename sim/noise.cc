#include "sim/noise.h"

#include <cmath>
#include <cstring>

#include "sim/random.h"

namespace sim {

namespace {

// The pixel noise's normal values, fast and without changing one output byte.
//
// A pixel's value is clamp(lround(base + sigma * N), 0, 255) with N = SplitMix64::BoxMuller(u1,
// u2): only the integer it rounds to matters. FastNormal computes N with polynomials instead of
// libm's log and cos (~40 % of the simulator's noise time went to cos and log), to within
// ~1e-13 (the polynomials' truncation ~5e-13 relative, a few ulps of rounding); where base +
// sigma * N_fast lies within kMargin * (1 + sigma) of a rounding boundary (k + 0.5) the exact N
// is computed as before, so every output byte is the one the exact formula gives: the margin
// (1e-9, over 1000 times the error) is met about twice in a billion pixels. Tested against the
// exact formula on millions of draws and on whole images (tests/sim/noise_test.cc).
constexpr double kMargin = 1e-9;

// log(x) for x in (0, 1] (normal doubles): x = m 2^e with m in [sqrt(1/2), sqrt(2)), log(m) =
// 2 atanh(t), t = (m - 1) / (m + 1), |t| <= 0.1716, by its series to t^13 (truncation < 5e-13
// relative). Without branches (the fold of m is integer arithmetic): a random m would mispredict.
inline double FastLog(double x) {
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof(bits));
  const uint64_t mantissa = bits & 0x000fffffffffffffull;
  const uint64_t above = mantissa > 0x6a09e667f3bcdull ? 1 : 0;  // m > sqrt(2): halve it
  const int e = static_cast<int>(bits >> 52) - 1023 + static_cast<int>(above);
  bits = mantissa | ((0x3ffull - above) << 52);
  double m;
  std::memcpy(&m, &bits, sizeof(m));
  const double t = (m - 1.0) / (m + 1.0), t2 = t * t;
  constexpr double a3 = 1.0 / 3, a5 = 1.0 / 5, a7 = 1.0 / 7, a9 = 1.0 / 9, a11 = 1.0 / 11,
                   a13 = 1.0 / 13;
  const double series = 1.0 + t2 * (a3 + t2 * (a5 + t2 * (a7 + t2 * (a9 + t2 * (a11 + t2 * a13)))));
  return e * M_LN2 + 2.0 * t * series;
}

// cos(2 pi u) for u in [0, 1): 2 pi u = k pi/2 + x with k the nearest quadrant and x in
// [-pi/4, pi/4], then cos or sin of x (Taylor to x^14 / x^15: within 1e-15) with the quadrant's
// sign, picked without branches.
inline double FastCos2Pi(double u) {
  const double u4 = 4.0 * u;
  const int k = static_cast<int>(u4 + 0.5);
  const double x = M_PI_2 * (u4 - k), x2 = x * x;  // u4 - k is exact
  constexpr double c1 = -1.0 / 2, c2 = 1.0 / 24, c3 = -1.0 / 720, c4 = 1.0 / 40320,
                   c5 = -1.0 / 3628800, c6 = 1.0 / 479001600, c7 = -1.0 / 87178291200;
  constexpr double s1 = -1.0 / 6, s2 = 1.0 / 120, s3 = -1.0 / 5040, s4 = 1.0 / 362880,
                   s5 = -1.0 / 39916800, s6 = 1.0 / 6227020800, s7 = -1.0 / 1307674368000;
  const double pick[2] = {
      1.0 + x2 * (c1 + x2 * (c2 + x2 * (c3 + x2 * (c4 + x2 * (c5 + x2 * (c6 + x2 * c7)))))),
      x * (1.0 + x2 * (s1 + x2 * (s2 + x2 * (s3 + x2 * (s4 + x2 * (s5 + x2 * (s6 + x2 * s7))))))),
  };
  // cos(k pi/2 + x) = cos x, -sin x, -cos x, sin x for k = 0, 1, 2, 3 (mod 4).
  static constexpr double kSign[4] = {1.0, -1.0, -1.0, 1.0};
  return kSign[k & 3] * pick[k & 1];
}

inline double InlineFastBoxMuller(double u1, double u2) {
  return std::sqrt(-2.0 * FastLog(u1)) * FastCos2Pi(u2);
}

}  // namespace

double FastBoxMuller(double u1, double u2) { return InlineFastBoxMuller(u1, u2); }

cv::Mat ApplyCameraNoise(const cv::Mat& grey, const NoiseOptions& options, uint64_t seed) {
  CV_Assert(grey.type() == CV_32FC1);
  SplitMix64 rng(seed);
  // Per-image exposure: I' = gain * I + bias.
  const double gain = 1.0 + options.gain_sigma * rng.Normal();
  const double bias = options.bias_sigma * rng.Normal();
  const double sigma = options.pixel_sigma;
  const bool pixel_noise = sigma > 0.0;
  const double margin = kMargin * (1.0 + sigma);
  cv::Mat out(grey.size(), CV_8UC1);
  for (int r = 0; r < grey.rows; ++r) {
    const float* src = grey.ptr<float>(r);
    unsigned char* dst = out.ptr<unsigned char>(r);
    for (int c = 0; c < grey.cols; ++c) {
      double v = gain * src[c] + bias;
      if (pixel_noise) {
        // Normal()'s two draws, in its order.
        const double u1 = 1.0 - rng.Uniform();
        const double u2 = rng.Uniform();
        // floor(w) of w = v + 0.5 is lround(v) wherever w is not within the margin of an
        // integer (then also for the exact v: see kMargin); there the exact formula decides.
        const double w = v + sigma * InlineFastBoxMuller(u1, u2) + 0.5;
        long k = static_cast<long>(w);
        if (w < k) --k;
        const double d = w - k;
        if (d > margin && d < 1.0 - margin && std::fabs(w) < 1e9) {
          dst[c] = static_cast<unsigned char>(std::clamp(k, 0l, 255l));
          continue;
        }
        v += sigma * SplitMix64::BoxMuller(u1, u2);
      }
      dst[c] = static_cast<unsigned char>(std::clamp(std::lround(v), 0l, 255l));
    }
  }
  return out;
}

}  // namespace sim
