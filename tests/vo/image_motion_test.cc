// Dominant image shift (coarse-to-fine ZNCC): known integer and sub-pixel shifts on synthetic
// texture, photometric robustness, degenerate and bad input, determinism, option checks.
#include "vo/image_motion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>

namespace vo {
namespace {

constexpr double kIntegerTol = 0.5;    // integer shifts (px)
constexpr double kSubpixelTol = 0.25;  // sub-pixel shifts (px)

// Smooth random texture: seeded noise blurred at three scales (fine to coarse, so it survives
// the pyramid) plus random rectangles, mapped to about [20, 235].
cv::Mat Texture(int w, int h, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat acc = cv::Mat::zeros(h, w, CV_32F);
  const double sigmas[] = {1.5, 4.0, 12.0};
  const double weights[] = {0.5, 0.7, 1.0};
  for (int i = 0; i < 3; ++i) {
    cv::Mat noise(h, w, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    cv::GaussianBlur(noise, noise, cv::Size(), sigmas[i]);
    cv::Scalar mean, stddev;
    cv::meanStdDev(noise, mean, stddev);
    acc += noise * (weights[i] / stddev[0]);
  }
  for (int i = 0; i < 40; ++i) {
    const int x = rng.uniform(0, w), y = rng.uniform(0, h);
    const int rw = rng.uniform(4, 40), rh = rng.uniform(4, 40);
    cv::rectangle(acc, cv::Rect(x, y, rw, rh), cv::Scalar(rng.uniform(-1.0, 1.0)), cv::FILLED);
  }
  cv::Mat out;
  acc.convertTo(out, CV_8U, 45.0, 128.0);
  return out;
}

// A prev/curr pair with curr(x + shift) = prev(x): both are views into a larger texture
// ("world"), so the border that the shift uncovers in curr shows other texture, not zeros.
// Sub-pixel shifts resample the world with bilinear interpolation.
struct Pair {
  cv::Mat prev, curr;
};

Pair ShiftedPair(int w, int h, double sx, double sy, uint64_t seed = 7) {
  const int margin = static_cast<int>(std::ceil(std::max(std::abs(sx), std::abs(sy)))) + 8;
  const cv::Mat world = Texture(w + 2 * margin, h + 2 * margin, seed);
  Pair p;
  p.prev = world(cv::Rect(margin, margin, w, h)).clone();
  // curr(x) = world(x + margin − s) = prev(x − s).
  const cv::Matx23d m(1, 0, margin - sx, 0, 1, margin - sy);
  cv::warpAffine(world, p.curr, m, cv::Size(w, h), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
  return p;
}

void ExpectShift(const ImageShiftResult& r, double sx, double sy, double tol) {
  EXPECT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.message.empty()) << r.message;
  EXPECT_NEAR(r.shift_px.x(), sx, tol);
  EXPECT_NEAR(r.shift_px.y(), sy, tol);
  EXPECT_GT(r.score, 0.8);
  EXPECT_LE(r.score, 1.0);
  EXPECT_GE(r.second_best_ratio, 1.0);
}

TEST(ImageShift, RecoversIntegerShifts320x240) {
  const double shifts[][2] = {{0, 0},    {7, -3}, {29, 2},    {-60, 5}, {130, 0},
                              {-130, 0}, {3, 40}, {-11, -37}, {1, 1},   {-1, 0}};
  for (const auto& s : shifts) {
    SCOPED_TRACE(::testing::Message() << "shift (" << s[0] << ", " << s[1] << ")");
    const Pair p = ShiftedPair(320, 240, s[0], s[1]);
    const ImageShiftResult r = EstimateImageShift(p.prev, p.curr);
    ExpectShift(r, s[0], s[1], kIntegerTol);
    EXPECT_EQ(r.levels, 4);  // 320 → 160 → 80 → 40
  }
}

TEST(ImageShift, IntegerShiftWithoutSubpixelIsExact) {
  ImageShiftOptions options;
  options.subpixel = false;
  const Pair p = ShiftedPair(320, 240, -60, 5);
  const ImageShiftResult r = EstimateImageShift(p.prev, p.curr, options);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.shift_px.x(), -60.0);
  EXPECT_EQ(r.shift_px.y(), 5.0);
  EXPECT_NEAR(r.score, 1.0, 1e-12);  // identical pixels over the overlap
}

TEST(ImageShift, RecoversSubpixelShifts) {
  const double shifts[][2] = {{12.5, -3.25}, {-3.25, 12.5}, {0.5, 0.0}, {47.75, 6.5}};
  for (const auto& s : shifts) {
    SCOPED_TRACE(::testing::Message() << "shift (" << s[0] << ", " << s[1] << ")");
    const Pair p = ShiftedPair(320, 240, s[0], s[1]);
    ExpectShift(EstimateImageShift(p.prev, p.curr), s[0], s[1], kSubpixelTol);
  }
}

TEST(ImageShift, LargeShiftAt640x480) {
  const Pair p = ShiftedPair(640, 480, 200, -4);
  const ImageShiftResult r = EstimateImageShift(p.prev, p.curr);
  ExpectShift(r, 200, -4, kIntegerTol);
  EXPECT_EQ(r.levels, 5);  // 640 → 320 → 160 → 80 → 40
  const Pair q = ShiftedPair(640, 480, -200, 0);
  ExpectShift(EstimateImageShift(q.prev, q.curr), -200, 0, kIntegerTol);
}

TEST(ImageShift, RobustToGainOffsetAndNoise) {
  const Pair p = ShiftedPair(320, 240, 29.5, 2);
  cv::Mat curr;
  p.curr.convertTo(curr, CV_8U, 0.7, 30.0);  // curr = 0.7·prev + 30
  ExpectShift(EstimateImageShift(p.prev, curr), 29.5, 2, kSubpixelTol);

  cv::Mat noise(curr.size(), CV_16S);
  cv::RNG(11).fill(noise, cv::RNG::NORMAL, 0.0, 8.0);  // σ = 8 grey levels
  cv::Mat noisy16;
  curr.convertTo(noisy16, CV_16S);
  noisy16 += noise;
  cv::Mat noisy;
  noisy16.convertTo(noisy, CV_8U);
  const ImageShiftResult r = EstimateImageShift(p.prev, noisy);
  EXPECT_TRUE(r.ok) << r.message;
  EXPECT_NEAR(r.shift_px.x(), 29.5, kSubpixelTol);
  EXPECT_NEAR(r.shift_px.y(), 2.0, kSubpixelTol);
  EXPECT_GT(r.score, 0.5);
}

TEST(ImageShift, FinestLevelAboveFullResolution) {
  ImageShiftOptions options;
  options.finest_level = 1;  // stop at half resolution: accuracy ~1 px at full resolution
  const Pair p = ShiftedPair(320, 240, -60, 5);
  const ImageShiftResult r = EstimateImageShift(p.prev, p.curr, options);
  ExpectShift(r, -60, 5, 1.0);
  options.finest_level = 99;  // clamped to the coarsest level (factor 8)
  const ImageShiftResult c = EstimateImageShift(p.prev, p.curr, options);
  ExpectShift(c, -60, 5, 4.0);
}

TEST(ImageShift, SmallImageSingleLevel) {
  const Pair p = ShiftedPair(40, 30, 5, -2);  // already <= coarsest_max_width_px
  const ImageShiftResult r = EstimateImageShift(p.prev, p.curr);
  ExpectShift(r, 5, -2, kIntegerTol);
  EXPECT_EQ(r.levels, 1);
}

TEST(ImageShift, RoiInputGivesSameResultAsCopy) {
  const Pair p = ShiftedPair(400, 300, 21, -6);
  const cv::Rect roi(40, 30, 320, 240);
  const cv::Mat prev_roi = p.prev(roi), curr_roi = p.curr(roi);
  ASSERT_FALSE(prev_roi.isContinuous());
  const ImageShiftResult a = EstimateImageShift(prev_roi, curr_roi);
  const ImageShiftResult b = EstimateImageShift(prev_roi.clone(), curr_roi.clone());
  ExpectShift(a, 21, -6, kIntegerTol);
  EXPECT_EQ(a.shift_px.x(), b.shift_px.x());
  EXPECT_EQ(a.shift_px.y(), b.shift_px.y());
  EXPECT_EQ(a.score, b.score);
}

TEST(ImageShift, UniformImageIsNoTexture) {
  const cv::Mat flat(240, 320, CV_8UC1, cv::Scalar(128));
  const ImageShiftResult r = EstimateImageShift(flat, flat);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("no texture"), std::string::npos) << r.message;
  EXPECT_TRUE(std::isfinite(r.score));
  EXPECT_TRUE(std::isfinite(r.shift_px.x()) && std::isfinite(r.shift_px.y()));
  EXPECT_FALSE(std::isnan(r.second_best_ratio));

  const cv::Mat textured = Texture(320, 240, 3);
  const ImageShiftResult c = EstimateImageShift(textured, flat);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.message.find("no texture: curr"), std::string::npos) << c.message;
}

TEST(ImageShift, UnrelatedImagesScoreLow) {
  const ImageShiftResult r = EstimateImageShift(Texture(320, 240, 1), Texture(320, 240, 2));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("min_score"), std::string::npos) << r.message;
  EXPECT_LT(r.score, 0.3);
}

TEST(ImageShift, PeriodicTextureIsAmbiguous) {
  // Vertical bars with a 40-px period: shifts of ±40 px look the same (ratio ≈ 1).
  cv::Mat bars(240, 320, CV_8UC1);
  for (int y = 0; y < bars.rows; ++y) {
    for (int x = 0; x < bars.cols; ++x) {
      bars.at<uint8_t>(y, x) = static_cast<uint8_t>(128 + 90 * std::sin(2 * CV_PI * x / 40.0));
    }
  }
  const ImageShiftResult r = EstimateImageShift(bars, bars);
  EXPECT_TRUE(r.ok) << r.message;
  EXPECT_LT(r.second_best_ratio, 1.1);
}

TEST(ImageShift, BadInputFailsWithMessage) {
  const Pair p = ShiftedPair(320, 240, 5, 0);
  auto expect_fail = [](const ImageShiftResult& r, const std::string& needle) {
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.message.find(needle), std::string::npos) << r.message;
    EXPECT_EQ(r.shift_px, Eigen::Vector2d::Zero());
  };
  expect_fail(EstimateImageShift(cv::Mat(), p.curr), "prev image is empty");
  expect_fail(EstimateImageShift(p.prev, cv::Mat()), "curr image is empty");
  cv::Mat color;
  cv::cvtColor(p.prev, color, cv::COLOR_GRAY2BGR);
  expect_fail(EstimateImageShift(color, p.curr), "CV_8UC1");
  cv::Mat wide;
  p.curr.convertTo(wide, CV_16U);
  expect_fail(EstimateImageShift(p.prev, wide), "curr must be CV_8UC1");
  expect_fail(EstimateImageShift(p.prev, p.curr(cv::Rect(0, 0, 300, 240))), "differ in size");
  const cv::Mat tiny(6, 40, CV_8UC1, cv::Scalar(0));
  expect_fail(EstimateImageShift(tiny, tiny), "too small");
  ImageShiftOptions options;
  options.refine_radius_px = 0;
  expect_fail(EstimateImageShift(p.prev, p.curr, options), "refine_radius_px");
}

TEST(ImageShift, Deterministic) {
  const Pair p = ShiftedPair(320, 240, 12.5, -3.25);
  const ImageShiftResult a = EstimateImageShift(p.prev, p.curr);
  const ImageShiftResult b = EstimateImageShift(p.prev, p.curr);
  ASSERT_TRUE(a.ok);
  EXPECT_EQ(a.shift_px.x(), b.shift_px.x());  // bit-identical
  EXPECT_EQ(a.shift_px.y(), b.shift_px.y());
  EXPECT_EQ(a.score, b.score);
  EXPECT_EQ(a.second_best_ratio, b.second_best_ratio);
  EXPECT_EQ(a.levels, b.levels);
}

TEST(ImageShift, IsValidRejectsEachOutOfRangeField) {
  std::string error;
  EXPECT_TRUE(ImageShiftOptions().IsValid(&error)) << error;
  EXPECT_TRUE(ImageShiftOptions().IsValid(nullptr));
  const double nan = std::nan("");
  struct Case {
    const char* field;
    void (*mutate)(ImageShiftOptions*, double);
    double value;
  };
  const Case cases[] = {
      {"coarsest_max_width_px",
       [](ImageShiftOptions* o, double v) { o->coarsest_max_width_px = static_cast<int>(v); }, 15},
      {"max_shift_fraction_x", [](ImageShiftOptions* o, double v) { o->max_shift_fraction_x = v; },
       0.0},
      {"max_shift_fraction_x", [](ImageShiftOptions* o, double v) { o->max_shift_fraction_x = v; },
       0.91},
      {"max_shift_fraction_x", [](ImageShiftOptions* o, double v) { o->max_shift_fraction_x = v; },
       nan},
      {"max_shift_fraction_y", [](ImageShiftOptions* o, double v) { o->max_shift_fraction_y = v; },
       -0.01},
      {"max_shift_fraction_y", [](ImageShiftOptions* o, double v) { o->max_shift_fraction_y = v; },
       0.91},
      {"max_shift_fraction_y", [](ImageShiftOptions* o, double v) { o->max_shift_fraction_y = v; },
       nan},
      {"refine_radius_px",
       [](ImageShiftOptions* o, double v) { o->refine_radius_px = static_cast<int>(v); }, 0},
      {"finest_level",
       [](ImageShiftOptions* o, double v) { o->finest_level = static_cast<int>(v); }, -1},
      {"min_overlap_fraction", [](ImageShiftOptions* o, double v) { o->min_overlap_fraction = v; },
       0.0},
      {"min_overlap_fraction", [](ImageShiftOptions* o, double v) { o->min_overlap_fraction = v; },
       1.01},
      {"min_overlap_fraction", [](ImageShiftOptions* o, double v) { o->min_overlap_fraction = v; },
       nan},
      {"min_score", [](ImageShiftOptions* o, double v) { o->min_score = v; }, -1.01},
      {"min_score", [](ImageShiftOptions* o, double v) { o->min_score = v; }, 1.01},
      {"min_score", [](ImageShiftOptions* o, double v) { o->min_score = v; }, nan},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(::testing::Message() << c.field << " = " << c.value);
    ImageShiftOptions options;
    c.mutate(&options, c.value);
    error.clear();
    EXPECT_FALSE(options.IsValid(&error));
    EXPECT_NE(error.find(c.field), std::string::npos) << error;
    EXPECT_FALSE(options.IsValid(nullptr));
  }
  // Boundary values that are allowed.
  ImageShiftOptions edge;
  edge.coarsest_max_width_px = 16;
  edge.max_shift_fraction_x = 0.9;
  edge.max_shift_fraction_y = 0.0;
  edge.refine_radius_px = 1;
  edge.min_overlap_fraction = 1.0;
  edge.min_score = -1.0;
  EXPECT_TRUE(edge.IsValid(&error)) << error;
}

}  // namespace
}  // namespace vo
