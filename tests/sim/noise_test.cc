// The camera noise (sim/noise.h): the fast pixel noise gives exactly the bytes of the exact
// formula (SplitMix64::Normal per pixel, as the simulator computed it before), and its normal
// values are within 1e-12 of the exact ones.
#include "sim/noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim/random.h"

namespace {

// The noise as the simulator computed it before the fast path: the reference.
cv::Mat ExactCameraNoise(const cv::Mat& grey, const sim::NoiseOptions& options, uint64_t seed) {
  sim::SplitMix64 rng(seed);
  const double gain = 1.0 + options.gain_sigma * rng.Normal();
  const double bias = options.bias_sigma * rng.Normal();
  cv::Mat out(grey.size(), CV_8UC1);
  for (int r = 0; r < grey.rows; ++r)
    for (int c = 0; c < grey.cols; ++c) {
      double v = gain * grey.at<float>(r, c) + bias;
      if (options.pixel_sigma > 0.0) v += options.pixel_sigma * rng.Normal();
      out.at<unsigned char>(r, c) =
          static_cast<unsigned char>(std::clamp(std::lround(v), 0l, 255l));
    }
  return out;
}

TEST(NoiseTest, FastNormalValuesAreWithin1e12OfTheExactOnes) {
  sim::SplitMix64 rng(42);
  double worst = 0.0;
  for (int i = 0; i < 4'000'000; ++i) {
    const double u1 = 1.0 - rng.Uniform(), u2 = rng.Uniform();
    worst =
        std::max(worst, std::fabs(sim::FastBoxMuller(u1, u2) - sim::SplitMix64::BoxMuller(u1, u2)));
  }
  EXPECT_LT(worst, 1e-12);
  // The ends of both ranges, and the points where the cosine's folding switches.
  for (double u1 : {1.0, 0.5, 0x1.0p-53, 1.0 - 0x1.0p-53, M_SQRT1_2, 0.7071067811865476})
    for (double u2 : {0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0 - 0x1.0p-53, 0.3})
      EXPECT_NEAR(sim::FastBoxMuller(u1, u2), sim::SplitMix64::BoxMuller(u1, u2), 1e-12)
          << u1 << " " << u2;
}

TEST(NoiseTest, TheImageBytesEqualTheExactFormulasForEverySigma) {
  cv::Mat grey(240, 320, CV_32FC1);
  sim::SplitMix64 rng(7);
  for (int r = 0; r < grey.rows; ++r)
    for (int c = 0; c < grey.cols; ++c)
      grey.at<float>(r, c) = static_cast<float>(-20.0 + 300.0 * rng.Uniform());
  // Values exactly on rounding boundaries too (k + 0.5 before the noise).
  for (int c = 0; c < grey.cols; ++c) grey.at<float>(0, c) = static_cast<float>(c % 256) + 0.5f;
  for (double sigma : {0.0, 0.5, 1.5, 3.0, 20.0, 100.0}) {
    sim::NoiseOptions options;
    options.pixel_sigma = sigma;
    options.gain_sigma = 0.02;
    options.bias_sigma = 2.0;
    for (uint64_t seed : {uint64_t{1}, uint64_t{99}, sim::DeriveSeed(5, 17, 1)}) {
      const cv::Mat fast = sim::ApplyCameraNoise(grey, options, seed);
      const cv::Mat exact = ExactCameraNoise(grey, options, seed);
      EXPECT_EQ(cv::countNonZero(fast != exact), 0) << "sigma " << sigma << " seed " << seed;
    }
  }
}

}  // namespace
