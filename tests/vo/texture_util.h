// A synthetic texture for the vo/ stage tests that need images (front end, tracker, recovery).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "vo/ransac.h"  // vo::SplitMix64

namespace vo {
namespace test {

// Uniform random grey levels from the seeded generator (row by row), blurred by a Gaussian of
// kernel × kernel pixels and σ sigma_px: distinct at every shift, so that block matching,
// corners, the matchers and the image shift all find it.
inline cv::Mat BlurredNoise(int width, int height, uint64_t seed, int kernel, double sigma_px) {
  SplitMix64 rng(seed);
  cv::Mat t(height, width, CV_8UC1);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) t.at<uint8_t>(v, u) = static_cast<uint8_t>(255 * rng.Uniform());
  }
  cv::GaussianBlur(t, t, cv::Size(kernel, kernel), sigma_px);
  return t;
}

}  // namespace test
}  // namespace vo
