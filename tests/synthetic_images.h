// Synthetic test images shared by tests and benchmarks (OpenCV only, no gtest).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace vobench_test {

// Smooth random texture (three octaves of blurred noise), 8-bit, deterministic for a seed.
inline cv::Mat RandomTexture(int width, int height, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat sum = cv::Mat::zeros(height, width, CV_32F);
  for (double sigma : {1.5, 3.0, 6.0}) {
    cv::Mat noise(height, width, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    cv::GaussianBlur(noise, noise, cv::Size(), sigma);
    cv::normalize(noise, noise, 0.0, 1.0, cv::NORM_MINMAX);
    sum += noise;
  }
  cv::normalize(sum, sum, 20.0, 235.0, cv::NORM_MINMAX);
  cv::Mat out;
  sum.convertTo(out, CV_8U);
  return out;
}

}  // namespace vobench_test
