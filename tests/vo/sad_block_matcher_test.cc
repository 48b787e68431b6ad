// Tests of vo/sad_block_matcher.h: both views from one cost volume. The left view must be
// cv::StereoBM's; the right view must be what StereoBM gives on the mirrored pair (the second
// pass it replaces) and match the ground truth of the right image.
#include "vo/sad_block_matcher.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace vo {
namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;

// A random texture and its copy shifted by a sub-pixel-free disparity field: the right image
// shows left point x_l = (x_r + a) / (1 - b) (a plane slanted along x).
struct Pair {
  cv::Mat left, right;
  double a = 0.0, b = 0.0;
  double RightDisparity(int x_r) const { return (x_r + a) / (1.0 - b) - x_r; }
};

Pair MakePair(double a, double b, uint64_t seed) {
  cv::Mat noise(kHeight, kWidth + 64, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.0);
  cv::normalize(noise, noise, 0.0, 255.0, cv::NORM_MINMAX);
  Pair p;
  p.a = a;
  p.b = b;
  noise(cv::Rect(0, 0, kWidth, kHeight)).convertTo(p.left, CV_8U);
  cv::Mat map_x(kHeight, kWidth, CV_32F), map_y(kHeight, kWidth, CV_32F);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      map_x.at<float>(y, x) = static_cast<float>((x + a) / (1.0 - b));
      map_y.at<float>(y, x) = static_cast<float>(y);
    }
  }
  cv::Mat right;
  cv::remap(noise, right, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REFLECT_101);
  right.convertTo(p.right, CV_8U);
  return p;
}

// cv::StereoBM with our options and the same replicate padding (search range + half a window
// on the left, half a window elsewhere), cropped back to the image.
cv::Mat StereoBmFixed(const cv::Mat& a, const cv::Mat& b, const SadBlockMatcherOptions& o) {
  cv::Ptr<cv::StereoBM> bm = cv::StereoBM::create(o.num_disparities, o.block_size);
  bm->setMinDisparity(o.min_disparity_px);
  bm->setPreFilterType(cv::StereoBM::PREFILTER_XSOBEL);
  bm->setPreFilterCap(o.prefilter_cap);
  bm->setUniquenessRatio(o.uniqueness_ratio);
  bm->setTextureThreshold(0);
  bm->setSpeckleWindowSize(0);
  bm->setDisp12MaxDiff(-1);
  const int half = o.block_size / 2;
  const int pad_left = o.min_disparity_px + o.num_disparities - 1 + half + 1;
  cv::Mat pa, pb, out;
  cv::copyMakeBorder(a, pa, half, half, pad_left, half, cv::BORDER_REPLICATE);
  cv::copyMakeBorder(b, pb, half, half, pad_left, half, cv::BORDER_REPLICATE);
  bm->compute(pa, pb, out);
  return out(cv::Rect(pad_left, half, a.cols, a.rows)).clone();
}

TEST(SadBlockMatcherTest, OptionsValidation) {
  SadBlockMatcherOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.num_disparities = 40;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("num_disparities"), std::string::npos);
  o = SadBlockMatcherOptions();
  o.block_size = 8;
  EXPECT_FALSE(o.IsValid(&error));
  o.block_size = 21;  // 21² · 62 = 27342 fits
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.block_size = 23;  // 23² · 62 = 32798 does not
  EXPECT_FALSE(o.IsValid(&error));
  o = SadBlockMatcherOptions();
  o.uniqueness_ratio = 101;
  EXPECT_FALSE(o.IsValid(&error));
}

TEST(SadBlockMatcherTest, BothViewsEqualStereoBmOnThePairAndItsMirror) {
  // Fractions of the pixels (interior, valid in both) with identical 1/16 px values.
  constexpr double kMinIdentical = 0.995;
  const Pair p = MakePair(9.3, 0.03, 5);
  for (int min_disparity : {0, 4}) {
    SadBlockMatcherOptions o;
    o.num_disparities = 32;
    o.min_disparity_px = min_disparity;
    SadBlockMatcher matcher(o);
    cv::Mat left_fixed, right_fixed;
    matcher.Compute(p.left, p.right, &left_fixed, &right_fixed);
    ASSERT_EQ(left_fixed.type(), CV_16S);
    ASSERT_EQ(right_fixed.size(), p.left.size());
    const cv::Mat bm_left = StereoBmFixed(p.left, p.right, o);
    cv::Mat fa, fb, bm_right;
    cv::flip(p.right, fa, 1);
    cv::flip(p.left, fb, 1);
    cv::flip(StereoBmFixed(fa, fb, o), bm_right, 1);
    // The right view searches only candidates inside the left image: compare away from the
    // right border (and away from the rows where the padding enters the window).
    const int half = o.block_size / 2;
    const int dmax = o.min_disparity_px + o.num_disparities - 1;
    int both_l = 0, same_l = 0, both_r = 0, same_r = 0;
    for (int y = half; y < kHeight - half; ++y) {
      for (int x = 0; x < kWidth - dmax - half - 1; ++x) {
        const int16_t l = left_fixed.at<int16_t>(y, x), bl = bm_left.at<int16_t>(y, x);
        const int16_t r = right_fixed.at<int16_t>(y, x), br = bm_right.at<int16_t>(y, x);
        if (l >= 0 && bl >= o.min_disparity_px * 16) {
          ++both_l;
          same_l += l == bl;
        }
        if (r >= 0 && br >= o.min_disparity_px * 16) {
          ++both_r;
          same_r += r == br;
        }
      }
    }
    std::printf("[ min disparity %d ] left identical %.4f of %d, right identical %.4f of %d\n",
                min_disparity, static_cast<double>(same_l) / both_l, both_l,
                static_cast<double>(same_r) / both_r, both_r);
    EXPECT_GT(both_l, kHeight * kWidth / 2);
    EXPECT_GT(both_r, kHeight * kWidth / 2);
    EXPECT_GT(static_cast<double>(same_l) / both_l, kMinIdentical);
    EXPECT_GT(static_cast<double>(same_r) / both_r, kMinIdentical);
  }
}

TEST(SadBlockMatcherTest, RightViewMatchesTheRightImagesGroundTruth) {
  constexpr double kTolPx = 0.25;
  constexpr double kMinGood = 0.95;
  const Pair p = MakePair(6.5, 0.02, 9);
  SadBlockMatcherOptions o;
  o.num_disparities = 32;
  SadBlockMatcher matcher(o);
  cv::Mat left_fixed, right_fixed;
  matcher.Compute(p.left, p.right, &left_fixed, &right_fixed);
  const int half = o.block_size / 2;
  int good = 0, total = 0;
  for (int y = half; y < kHeight - half; ++y) {
    for (int x = half; x < kWidth - 32 - half; ++x) {
      ++total;
      const int16_t r = right_fixed.at<int16_t>(y, x);
      good += r >= 0 && std::abs(r / 16.0 - p.RightDisparity(x)) <= kTolPx;
    }
  }
  EXPECT_GT(static_cast<double>(good) / total, kMinGood);
  // Without the right view requested, the left view is the same.
  cv::Mat left_only;
  matcher.Compute(p.left, p.right, &left_only, nullptr);
  EXPECT_EQ(cv::norm(left_only, left_fixed, cv::NORM_INF), 0.0);
}

// The AVX2 kernels (chosen at run time) and the SSE2/scalar baseline give identical outputs.
TEST(SadBlockMatcherTest, VectorWidthsGiveIdenticalResults) {
  const Pair p = MakePair(7.7, 0.025, 13);
  for (int nd : {16, 32, 48}) {
    SadBlockMatcherOptions o;
    o.num_disparities = nd;
    o.min_disparity_px = nd == 48 ? 3 : 0;
    SadBlockMatcher fast(o);
    o.allow_avx2 = false;
    SadBlockMatcher baseline(o);
    cv::Mat la, ra, lb, rb;
    cv::Mat discard(p.left.size(), CV_8UC1, cv::Scalar(0));
    discard(cv::Rect(0, 0, kWidth, 40)).setTo(1);
    fast.Compute(p.left, p.right, &la, &ra, &discard);
    baseline.Compute(p.left, p.right, &lb, &rb, &discard);
    EXPECT_EQ(cv::norm(la, lb, cv::NORM_INF), 0.0) << nd;
    EXPECT_EQ(cv::norm(ra, rb, cv::NORM_INF), 0.0) << nd;
  }
}

TEST(SadBlockMatcherTest, DiscardedPixelsSkipOnlyTheUniquenessTest) {
  // A flat image: every disparity costs the same, so uniqueness fails everywhere; pixels
  // marked as discarded keep an estimate (the caller removes them), the others are invalid.
  const cv::Mat flat(64, 96, CV_8UC1, cv::Scalar(100));
  SadBlockMatcherOptions o;
  o.num_disparities = 16;
  SadBlockMatcher matcher(o);
  cv::Mat discard(flat.size(), CV_8UC1, cv::Scalar(0));
  discard(cv::Rect(0, 0, 96, 32)).setTo(1);
  cv::Mat left_fixed;
  matcher.Compute(flat, flat, &left_fixed, nullptr, &discard);
  EXPECT_EQ(cv::countNonZero(left_fixed(cv::Rect(0, 32, 96, 32)) != kSadInvalidFixed), 0);
  EXPECT_EQ(cv::countNonZero(left_fixed(cv::Rect(0, 0, 96, 32)) == kSadInvalidFixed), 0);
}

}  // namespace
}  // namespace vo
