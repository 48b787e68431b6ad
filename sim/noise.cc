#include "sim/noise.h"

#include <cmath>

#include "sim/random.h"

namespace sim {

cv::Mat ApplyCameraNoise(const cv::Mat& grey, const NoiseOptions& options, uint64_t seed) {
  CV_Assert(grey.type() == CV_32FC1);
  SplitMix64 rng(seed);
  // Per-image exposure: I' = gain * I + bias.
  const double gain = 1.0 + options.gain_sigma * rng.Normal();
  const double bias = options.bias_sigma * rng.Normal();
  const bool pixel_noise = options.pixel_sigma > 0.0;
  cv::Mat out(grey.size(), CV_8UC1);
  for (int r = 0; r < grey.rows; ++r) {
    const float* src = grey.ptr<float>(r);
    unsigned char* dst = out.ptr<unsigned char>(r);
    for (int c = 0; c < grey.cols; ++c) {
      double v = gain * src[c] + bias;
      if (pixel_noise) v += options.pixel_sigma * rng.Normal();
      dst[c] = static_cast<unsigned char>(std::clamp(std::lround(v), 0l, 255l));
    }
  }
  return out;
}

}  // namespace sim
