// Procedural textures: deterministic, sized as asked, rich kinds textured and non-periodic,
// plain kinds nearly uniform.
#include "sim/textures.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace {

cv::Mat Grey(const cv::Mat& bgr) {
  cv::Mat g;
  cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
  return g;
}

double GradientEnergy(const cv::Mat& grey) {
  cv::Mat gx, gy;
  cv::Sobel(grey, gx, CV_32F, 1, 0);
  cv::Sobel(grey, gy, CV_32F, 0, 1);
  return cv::mean(gx.mul(gx) + gy.mul(gy))[0];
}

// Largest normalised correlation of a band of the texture with itself shifted horizontally by
// min_shift..max_shift texels.
double MaxShiftCorrelation(const cv::Mat& grey, int min_shift, int max_shift) {
  cv::Mat f;
  grey.convertTo(f, CV_32F);
  // Remove what is the same along every row (skirting band, vertical shading): it correlates
  // at any shift without being a repeated pattern.
  cv::Mat row_mean;
  cv::reduce(f, row_mean, 1, cv::REDUCE_AVG);
  f -= cv::repeat(row_mean, 1, f.cols);
  double best = -1.0;
  for (int s = min_shift; s <= max_shift; s += 4) {
    const int w = f.cols - s;
    cv::Mat a = f(cv::Rect(0, 0, w, f.rows)), b = f(cv::Rect(s, 0, w, f.rows));
    cv::Scalar ma, sa, mb, sb;
    cv::meanStdDev(a, ma, sa);
    cv::meanStdDev(b, mb, sb);
    const double cov = cv::mean((a - ma[0]).mul(b - mb[0]))[0];
    best = std::max(best, cov / (sa[0] * sb[0] + 1e-9));
  }
  return best;
}

TEST(TexturesTest, ParseKinds) {
  sim::TextureKind k;
  for (const char* n : {"wall", "floor", "ceiling", "plainwall", "plainfloor", "plainceiling"}) {
    ASSERT_TRUE(sim::ParseTextureKind(n, &k)) << n;
    EXPECT_STREQ(sim::TextureKindName(k), n);
  }
  EXPECT_FALSE(sim::ParseTextureKind("carpet", &k));
}

TEST(TexturesTest, DeterministicAndSized) {
  sim::TextureOptions o;
  o.px_per_m = 100;
  const cv::Mat a = sim::GenerateTexture(sim::TextureKind::kWall, 6.0, 2.5, 42, o);
  const cv::Mat b = sim::GenerateTexture(sim::TextureKind::kWall, 6.0, 2.5, 42, o);
  const cv::Mat c = sim::GenerateTexture(sim::TextureKind::kWall, 6.0, 2.5, 43, o);
  ASSERT_EQ(a.type(), CV_8UC3);
  EXPECT_EQ(a.cols, 600);
  EXPECT_EQ(a.rows, 250);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1), 0);
}

TEST(TexturesTest, RichKindsAreNotPeriodic) {
  sim::TextureOptions o;
  o.px_per_m = 64;
  for (auto kind : {sim::TextureKind::kWall, sim::TextureKind::kFloor, sim::TextureKind::kCeiling}) {
    const cv::Mat g = Grey(sim::GenerateTexture(kind, 10.0, kind == sim::TextureKind::kWall ? 2.5 : 2.0, 7, o));
    // Shifts of 0.3 m .. 3 m: no copy of the pattern (tiles and panels vary per cell).
    const double corr = MaxShiftCorrelation(g, static_cast<int>(0.3 * o.px_per_m), static_cast<int>(3.0 * o.px_per_m));
    EXPECT_LT(corr, 0.5) << sim::TextureKindName(kind);
  }
}

TEST(TexturesTest, PlainKindsHaveLittleTexture) {
  sim::TextureOptions o;
  o.px_per_m = 128;
  const double rich = GradientEnergy(Grey(sim::GenerateTexture(sim::TextureKind::kWall, 8.0, 2.5, 3, o)));
  const double plain = GradientEnergy(Grey(sim::GenerateTexture(sim::TextureKind::kPlainWall, 8.0, 2.5, 3, o)));
  EXPECT_LT(plain * 3.0, rich);
}

TEST(TexturesTest, RichWallsHaveCorners) {
  sim::TextureOptions o;
  o.px_per_m = 230;  // about the image scale at 1 m from the wall
  const cv::Mat g = Grey(sim::GenerateTexture(sim::TextureKind::kWall, 10.0, 2.5, 11, o));
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(g, corners, 100000, 0.01, 5);
  const double per_m2 = corners.size() / 25.0;
  EXPECT_GT(per_m2, 20.0) << corners.size() << " corners";
}

TEST(TexturesTest, InvalidOptionsRefused) {
  sim::TextureOptions o;
  o.px_per_m = 0;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_FALSE(error.empty());
  EXPECT_TRUE(sim::GenerateTexture(sim::TextureKind::kWall, 2, 2, 1, o).empty());
  o.px_per_m = std::nan("");
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_TRUE(sim::GenerateTexture(sim::TextureKind::kWall, -1.0, 2, 1, sim::TextureOptions()).empty());
}

}  // namespace
