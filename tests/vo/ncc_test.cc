// NCC of eq. (2): direct and fast (patch-vector) forms, invariances, undefined cases.
#include "vo/ncc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace vo {
namespace {

constexpr double kExactTol = 1e-12;    // same pixels, double arithmetic
constexpr double kFloatTol = 1e-5;     // fast form: float patches, float dot product
constexpr double kRoundingTol = 2e-3;  // contrast-scaled copy re-quantised to 8 bits

// Random texture in [40, 140] so that 1.5·I + 20 stays inside [0, 255] (no clipping).
cv::Mat Texture(uint64_t seed) {
  cv::Mat noise(120, 160, CV_32F);
  cv::RNG(seed).fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(), 1.5);
  cv::normalize(noise, noise, 40.0, 140.0, cv::NORM_MINMAX);
  cv::Mat out;
  noise.convertTo(out, CV_8U);
  return out;
}

Feature At(double u, double v) {
  Feature f;
  f.uv_px = Eigen::Vector2d(u, v);
  return f;
}

TEST(NccTest, PatchWithItselfIsOne) {
  const cv::Mat image = Texture(1);
  const NccOptions options;
  NccStatus status;
  EXPECT_NEAR(NccScore(image, {50, 60}, image, {50, 60}, options, &status), 1.0, kExactTol);
  EXPECT_EQ(status, NccStatus::kOk);
  NccPatches patches;
  patches.Compute(image, {At(50, 60), At(80, 40)}, options);
  EXPECT_NEAR(patches.Score(0, patches, 0), 1.0, kFloatTol);
  EXPECT_NEAR(patches.Score(1, patches, 1), 1.0, kFloatTol);
}

TEST(NccTest, InvariantToGainAndOffset) {
  const cv::Mat image = Texture(2);
  cv::Mat brighter, scaled;
  image.convertTo(brighter, CV_8U, 1.0, 60.0);  // offset
  image.convertTo(scaled, CV_8U, 1.5, 20.0);    // gain and offset (no clipping: max 230)
  const NccOptions options;
  EXPECT_NEAR(NccScore(image, {70, 50}, brighter, {70, 50}, options), 1.0, kExactTol);
  EXPECT_NEAR(NccScore(image, {70, 50}, scaled, {70, 50}, options), 1.0, kRoundingTol);
  NccPatches a, b;
  a.Compute(image, {At(70, 50)}, options);
  b.Compute(scaled, {At(70, 50)}, options);
  EXPECT_NEAR(a.Score(0, b, 0), 1.0, kRoundingTol);
}

TEST(NccTest, NegativeIsZeroAndUnrelatedIsAboutHalf) {
  const cv::Mat image = Texture(3);
  cv::Mat negative;
  cv::subtract(cv::Scalar(255), image, negative);
  const NccOptions options;
  EXPECT_NEAR(NccScore(image, {60, 60}, negative, {60, 60}, options), 0.0, kExactTol);
  NccPatches a, b;
  a.Compute(image, {At(60, 60)}, options);
  b.Compute(negative, {At(60, 60)}, options);
  EXPECT_NEAR(a.Score(0, b, 0), 0.0, kFloatTol);
  EXPECT_NEAR(a.Correlation(0, b, 0), -1.0, kFloatTol);

  // Patches of two independent textures: ρ averages 0, i.e. C averages ½.
  const cv::Mat other = Texture(4);
  double sum = 0.0;
  int n = 0;
  for (int y = 10; y < 110; y += 12) {
    for (int x = 10; x < 150; x += 12, ++n) sum += NccScore(image, {x, y}, other, {x, y}, options);
  }
  constexpr double kMeanTol = 0.05;  // ~100 samples of a ρ with std ~0.3
  EXPECT_NEAR(sum / n, 0.5, kMeanTol);
}

TEST(NccTest, FlatAndBorderPatchesAreReportedAndScoreZero) {
  const cv::Mat image = Texture(5);
  cv::Mat flat(image.size(), CV_8U, cv::Scalar(90));
  const NccOptions options;  // W = 11: half window 5
  NccStatus status;
  EXPECT_EQ(NccScore(flat, {50, 50}, image, {50, 50}, options, &status), 0.0);
  EXPECT_EQ(status, NccStatus::kFlat);
  EXPECT_EQ(NccScore(flat, {50, 50}, flat, {50, 50}, options, &status), 0.0);
  EXPECT_EQ(status, NccStatus::kFlat);
  EXPECT_EQ(NccScore(image, {4, 50}, image, {50, 50}, options, &status), 0.0);
  EXPECT_EQ(status, NccStatus::kOutOfBounds);
  EXPECT_EQ(NccScore(image, {50, 50}, image, {50, image.rows - 5}, options, &status), 0.0);
  EXPECT_EQ(status, NccStatus::kOutOfBounds);
  EXPECT_GT(NccScore(image, {5, 5}, image, {5, 5}, options, &status), 0.99);  // just inside
  EXPECT_EQ(status, NccStatus::kOk);

  NccPatches patches;
  patches.Compute(image, {At(4.4, 50), At(50, 50), At(image.cols - 5.6, 50)}, options);
  EXPECT_EQ(patches.status(0), NccStatus::kOutOfBounds);  // rounds to x = 4
  EXPECT_EQ(patches.status(1), NccStatus::kOk);
  EXPECT_EQ(patches.status(2), NccStatus::kOk);  // rounds to x = cols − 6
  EXPECT_EQ(patches.Score(0, patches, 0), 0.0);
  NccPatches flat_patches;
  flat_patches.Compute(flat, {At(50, 50)}, options);
  EXPECT_EQ(flat_patches.status(0), NccStatus::kFlat);
  EXPECT_FALSE(flat_patches.valid(0));
  EXPECT_EQ(flat_patches.Score(0, patches, 1), 0.0);

  // A raised min_stddev also rejects low-contrast texture.
  cv::Mat faint;
  image.convertTo(faint, CV_8U, 0.05, 100.0);
  NccOptions strict;
  strict.min_stddev = 5.0;
  EXPECT_EQ(NccScore(faint, {50, 50}, faint, {50, 50}, strict, &status), 0.0);
  EXPECT_EQ(status, NccStatus::kFlat);
}

TEST(NccTest, FastFormEqualsDirectForm) {
  const cv::Mat a = Texture(6), b = Texture(7);
  for (int window : {3, 7, 11, 21}) {
    NccOptions options;
    options.window_px = window;
    std::vector<Feature> fa, fb;
    cv::RNG rng(window);
    for (int k = 0; k < 40; ++k) {
      fa.push_back(At(rng.uniform(0.0, 159.0), rng.uniform(0.0, 119.0)));
      fb.push_back(At(rng.uniform(0.0, 159.0), rng.uniform(0.0, 119.0)));
    }
    NccPatches pa, pb;
    pa.Compute(a, fa, options);
    pb.Compute(b, fb, options);
    for (int i = 0; i < 40; ++i) {
      for (int j = 0; j < 40; ++j) {
        NccStatus status;
        const double direct = NccScore(a, fa[i].uv_px, b, fb[j].uv_px, options, &status);
        EXPECT_NEAR(pa.Score(i, pb, j), direct, kFloatTol) << "W " << window;
        EXPECT_EQ(pa.valid(i) && pb.valid(j), status == NccStatus::kOk);
      }
    }
  }
}

TEST(NccTest, OptionsValidation) {
  NccOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error));
  options.window_px = 10;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("window_px"), std::string::npos);
  options.window_px = 1;
  EXPECT_FALSE(options.IsValid(&error));
  options.window_px = 11;
  options.min_stddev = -1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("min_stddev"), std::string::npos);
}

}  // namespace
}  // namespace vo
