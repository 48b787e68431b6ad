// Procedural textures: kind names, sizes, determinism, validation; rich kinds textured, full of
// corners and non-periodic; plain kinds nearly uniform. Measured figures are printed and
// recorded as test properties.
#include "sim/textures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace {

using sim::GenerateTexture;
using sim::TextureKind;
using sim::TextureOptions;

constexpr TextureKind kAllKinds[] = {TextureKind::kWall,       TextureKind::kFloor,
                                     TextureKind::kCeiling,    TextureKind::kPlainWall,
                                     TextureKind::kPlainFloor, TextureKind::kPlainCeiling};

// Largest normalised autocorrelation allowed at shifts of 0.3..3 m: well below what a repeated
// pattern gives (~1), so no shift makes the texture look like itself.
constexpr double kMaxShiftCorrelation = 0.5;
// Least ratio of gradient energy, rich kind over its plain kind (plain walls keep their doors
// and skirting, hence the lowest ratio).
constexpr double kMinRichOverPlainEnergy = 5.0;
// Corners of a rich wall seen at ~230 px/m (Shi-Tomasi, quality 0.001 of the strongest corner
// as in the VO pipeline): least mean per square metre, least in any 1 m x 1 m crop.
constexpr double kCornerQuality = 0.001;
constexpr double kMinWallCornersPerM2 = 50.0;
constexpr int kMinCornersPerCrop = 10;

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

// Largest normalised correlation of the texture with itself shifted horizontally by
// min_shift..max_shift texels (every second texel). What is the same all along a row (the skirting
// band, a vertical shading trend) is removed first: it correlates at any shift without being a
// repeated pattern. With `highpass_px` > 0 the local mean over a box of that size is removed too,
// leaving the detail a local matching window sees.
double MaxShiftCorrelation(const cv::Mat& grey, int min_shift, int max_shift, int highpass_px) {
  cv::Mat f;
  grey.convertTo(f, CV_64F);
  cv::Mat row_mean;
  cv::reduce(f, row_mean, 1, cv::REDUCE_AVG);
  f -= cv::repeat(row_mean, 1, f.cols);
  if (highpass_px > 0) {
    cv::Mat local;
    cv::blur(f, local, cv::Size(highpass_px, highpass_px));
    f -= local;
  }
  double best = -1.0;
  for (int s = min_shift; s <= max_shift; s += 2) {
    const int w = f.cols - s;
    const cv::Mat a = f(cv::Rect(0, 0, w, f.rows)), b = f(cv::Rect(s, 0, w, f.rows));
    cv::Scalar ma, sa, mb, sb;
    cv::meanStdDev(a, ma, sa);
    cv::meanStdDev(b, mb, sb);
    const double cov = (a - ma[0]).dot(b - mb[0]) / (static_cast<double>(w) * f.rows);
    best = std::max(best, cov / (sa[0] * sb[0] + 1e-12));
  }
  return best;
}

// Corners of the whole image (Shi-Tomasi, quality relative to the image's strongest corner),
// counted in 1 m x 1 m cells.
std::vector<int> CornersPerSquareMetre(const cv::Mat& grey, double px_per_m) {
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(grey, corners, 1000000, kCornerQuality, 5);
  const int cell = static_cast<int>(std::lround(px_per_m));
  const int nx = grey.cols / cell, ny = grey.rows / cell;
  std::vector<int> counts(static_cast<size_t>(nx) * ny, 0);
  for (const auto& p : corners) {
    const int i = static_cast<int>(p.x) / cell, j = static_cast<int>(p.y) / cell;
    if (i < nx && j < ny) ++counts[j * nx + i];
  }
  return counts;
}

double Mean(const std::vector<int>& v) {
  double s = 0;
  for (int x : v) s += x;
  return v.empty() ? 0.0 : s / v.size();
}

TEST(TexturesTest, ParsesEveryKindName) {
  for (TextureKind kind : kAllKinds) {
    TextureKind parsed = TextureKind::kWall;
    ASSERT_TRUE(sim::ParseTextureKind(sim::TextureKindName(kind), &parsed))
        << sim::TextureKindName(kind);
    EXPECT_EQ(parsed, kind);
  }
  const std::vector<std::string> names = {"wall",      "floor",      "ceiling",
                                          "plainwall", "plainfloor", "plainceiling"};
  for (size_t i = 0; i < names.size(); ++i) {
    TextureKind k = TextureKind::kWall;
    EXPECT_TRUE(sim::ParseTextureKind(names[i], &k));
    EXPECT_EQ(k, kAllKinds[i]);
    EXPECT_EQ(sim::IsPlainTexture(k), i >= 3);
  }
  for (const char* bad : {"carpet", "Wall", "", "wall_1", "plain"}) {
    TextureKind k = TextureKind::kCeiling;
    EXPECT_FALSE(sim::ParseTextureKind(bad, &k)) << bad;
    EXPECT_EQ(k, TextureKind::kCeiling) << "untouched on failure";
  }
}

TEST(TexturesTest, SizeIsRoundedProduct) {
  const struct {
    double w_m, h_m, ppm;
  } cases[] = {{6.0, 2.5, 100.0}, {2.3, 1.7, 97.3}, {0.013, 0.011, 100.0}, {10.5, 2.0, 160.0}};
  for (const auto& c : cases) {
    TextureOptions o;
    o.px_per_m = c.ppm;
    const cv::Size expected(static_cast<int>(std::round(c.w_m * c.ppm)),
                            static_cast<int>(std::round(c.h_m * c.ppm)));
    EXPECT_EQ(sim::TextureSizePx(c.w_m, c.h_m, o), expected);
    for (TextureKind kind : kAllKinds) {
      const cv::Mat t = GenerateTexture(kind, c.w_m, c.h_m, 5, o);
      ASSERT_EQ(t.type(), CV_8UC3) << sim::TextureKindName(kind);
      EXPECT_EQ(t.size(), expected) << sim::TextureKindName(kind) << " " << c.w_m << "x" << c.h_m;
    }
  }
}

TEST(TexturesTest, DeterministicAndSeedDependent) {
  TextureOptions o;
  o.px_per_m = 64;
  for (TextureKind kind : kAllKinds) {
    const cv::Mat a = GenerateTexture(kind, 6.0, 2.5, 42, o);
    const cv::Mat b = GenerateTexture(kind, 6.0, 2.5, 42, o);
    const cv::Mat c = GenerateTexture(kind, 6.0, 2.5, 43, o);
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << sim::TextureKindName(kind);
    EXPECT_GT(cv::norm(a, c, cv::NORM_L1), 0.0) << sim::TextureKindName(kind);
  }
}

TEST(TexturesTest, UntintedTexturesAreGrey) {
  TextureOptions o;
  o.px_per_m = 64;
  o.tinted = false;
  for (TextureKind kind : kAllKinds) {
    const cv::Mat t = GenerateTexture(kind, 4.0, 2.5, 9, o);
    std::vector<cv::Mat> ch;
    cv::split(t, ch);
    EXPECT_EQ(cv::norm(ch[0], ch[1], cv::NORM_INF), 0.0) << sim::TextureKindName(kind);
    EXPECT_EQ(cv::norm(ch[1], ch[2], cv::NORM_INF), 0.0) << sim::TextureKindName(kind);
  }
}

TEST(TexturesTest, RichKindsAreNotPeriodic) {
  TextureOptions o;
  o.px_per_m = 100;
  const struct {
    TextureKind kind;
    double h_m;
  } cases[] = {{TextureKind::kWall, 2.5}, {TextureKind::kFloor, 2.0}, {TextureKind::kCeiling, 2.0}};
  for (const auto& c : cases) {
    for (uint64_t seed : {7u, 8u, 9u}) {
      const cv::Mat g = Grey(GenerateTexture(c.kind, 10.0, c.h_m, seed, o));
      const int lo = static_cast<int>(0.3 * o.px_per_m), hi = static_cast<int>(3.0 * o.px_per_m);
      const double raw = MaxShiftCorrelation(g, lo, hi, 0);
      const double detail = MaxShiftCorrelation(g, lo, hi, static_cast<int>(0.1 * o.px_per_m));
      std::printf(
          "[ measured ] %s seed %d: max autocorrelation at 0.3..3 m shifts %.3f "
          "(detail within 0.1 m: %.3f)\n",
          sim::TextureKindName(c.kind), static_cast<int>(seed), raw, detail);
      const std::string key =
          std::string(sim::TextureKindName(c.kind)) + "_" + std::to_string(seed);
      RecordProperty("max_shift_corr_" + key, std::to_string(raw));
      RecordProperty("max_shift_corr_detail_" + key, std::to_string(detail));
      EXPECT_LT(raw, kMaxShiftCorrelation) << key;
      EXPECT_LT(detail, kMaxShiftCorrelation) << key;
    }
  }
}

TEST(TexturesTest, PlainKindsHaveFarLessTexture) {
  TextureOptions o;
  o.px_per_m = 128;
  const struct {
    TextureKind rich, plain;
    double h_m;
  } pairs[] = {{TextureKind::kWall, TextureKind::kPlainWall, 2.5},
               {TextureKind::kFloor, TextureKind::kPlainFloor, 2.0},
               {TextureKind::kCeiling, TextureKind::kPlainCeiling, 2.0}};
  for (const auto& p : pairs) {
    const double rich = GradientEnergy(Grey(GenerateTexture(p.rich, 10.0, p.h_m, 3, o)));
    const double plain = GradientEnergy(Grey(GenerateTexture(p.plain, 10.0, p.h_m, 3, o)));
    std::printf("[ measured ] gradient energy %s %.1f / %s %.1f = %.1f\n",
                sim::TextureKindName(p.rich), rich, sim::TextureKindName(p.plain), plain,
                rich / plain);
    RecordProperty(std::string("energy_ratio_") + sim::TextureKindName(p.rich),
                   std::to_string(rich / plain));
    EXPECT_GT(rich, kMinRichOverPlainEnergy * plain) << sim::TextureKindName(p.rich);
  }
}

TEST(TexturesTest, RichWallsHaveManyCorners) {
  TextureOptions o;
  o.px_per_m = 230;  // about the image scale of a wall 1 m from the camera (fy ~ 230 px)
  const cv::Mat rich = Grey(GenerateTexture(TextureKind::kWall, 10.0, 2.5, 11, o));
  const cv::Mat plain = Grey(GenerateTexture(TextureKind::kPlainWall, 10.0, 2.5, 11, o));
  std::vector<int> rich_counts = CornersPerSquareMetre(rich, o.px_per_m);
  std::vector<int> plain_counts = CornersPerSquareMetre(plain, o.px_per_m);
  const int rich_min = *std::min_element(rich_counts.begin(), rich_counts.end());
  std::printf(
      "[ measured ] corners per m^2 (%zu crops of 1 m x 1 m at 230 px/m): wall mean %.1f, "
      "fewest %d; plainwall mean %.1f\n",
      rich_counts.size(), Mean(rich_counts), rich_min, Mean(plain_counts));
  RecordProperty("wall_corners_per_m2", std::to_string(Mean(rich_counts)));
  RecordProperty("wall_corners_fewest_per_m2", std::to_string(rich_min));
  RecordProperty("plainwall_corners_per_m2", std::to_string(Mean(plain_counts)));
  EXPECT_GT(Mean(rich_counts), kMinWallCornersPerM2);
  EXPECT_GE(rich_min, kMinCornersPerCrop);
  EXPECT_GT(Mean(rich_counts), 20.0 * Mean(plain_counts));
}

TEST(TexturesTest, DetailDensityScalesTheObjects) {
  TextureOptions o;
  o.px_per_m = 100;
  const double full = GradientEnergy(Grey(GenerateTexture(TextureKind::kWall, 10.0, 2.5, 4, o)));
  o.detail_density = 0.0;
  const double bare = GradientEnergy(Grey(GenerateTexture(TextureKind::kWall, 10.0, 2.5, 4, o)));
  EXPECT_GT(full, 1.5 * bare);
}

TEST(TexturesTest, InvalidOptionsAndSizesGiveEmpty) {
  std::string error;
  EXPECT_TRUE(TextureOptions().IsValid(&error)) << error;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* field;
    void (*spoil)(TextureOptions*);
  };
  const Case cases[] = {
      {"px_per_m", [](TextureOptions* o) { o->px_per_m = 0.0; }},
      {"px_per_m", [](TextureOptions* o) { o->px_per_m = -5.0; }},
      {"px_per_m",
       [](TextureOptions* o) { o->px_per_m = std::numeric_limits<double>::quiet_NaN(); }},
      {"px_per_m",
       [](TextureOptions* o) { o->px_per_m = std::numeric_limits<double>::infinity(); }},
      {"grain_amplitude", [](TextureOptions* o) { o->grain_amplitude = -1.0; }},
      {"shading_amplitude",
       [](TextureOptions* o) { o->shading_amplitude = std::numeric_limits<double>::quiet_NaN(); }},
      {"detail_density", [](TextureOptions* o) { o->detail_density = -0.1; }},
      {"door_gap_min_m", [](TextureOptions* o) { o->door_gap_min_m = 0.0; }},
      {"door_gap_max_m", [](TextureOptions* o) { o->door_gap_max_m = 1.0; }},  // < min 1.2
      {"plain_door_spacing_m", [](TextureOptions* o) { o->plain_door_spacing_m = 0.0; }},
      {"skirting_height_m", [](TextureOptions* o) { o->skirting_height_m = -0.1; }},
      {"floor_tile_m", [](TextureOptions* o) { o->floor_tile_m = 0.005; }},  // = grout
      {"grout_width_m", [](TextureOptions* o) { o->grout_width_m = -0.001; }},
      {"ceiling_panel_m", [](TextureOptions* o) { o->ceiling_panel_m = 0.02; }},  // < grid
      {"ceiling_grid_width_m", [](TextureOptions* o) { o->ceiling_grid_width_m = -1.0; }},
      {"plain_shading_amplitude", [](TextureOptions* o) { o->plain_shading_amplitude = -1.0; }},
      {"plain_grain_amplitude",
       [](TextureOptions* o) {
         o->plain_grain_amplitude = std::numeric_limits<double>::infinity();
       }},
  };
  for (const Case& c : cases) {
    TextureOptions o;
    c.spoil(&o);
    error.clear();
    EXPECT_FALSE(o.IsValid(&error)) << c.field;
    EXPECT_NE(error.find(c.field), std::string::npos)
        << "error '" << error << "' names " << c.field;
    EXPECT_FALSE(o.IsValid(nullptr));
    EXPECT_TRUE(GenerateTexture(TextureKind::kWall, 2.0, 2.0, 1, o).empty()) << c.field;
  }
  // Sizes that are not finite, round to under one texel, or exceed kMaxTextureSidePx.
  TextureOptions o;
  o.px_per_m = 100;
  for (double w : {-1.0, 0.0, 0.004, nan, inf, (sim::kMaxTextureSidePx + 1) / 100.0}) {
    for (TextureKind kind : kAllKinds) {
      EXPECT_TRUE(GenerateTexture(kind, w, 2.0, 1, o).empty()) << w;
      EXPECT_TRUE(GenerateTexture(kind, 2.0, w, 1, o).empty()) << w;
    }
  }
}

}  // namespace
