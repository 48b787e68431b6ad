// The disparity evaluated at single pixels (DisparityEstimator::PrepareAtPixels / DisparityAt,
// SadBlockMatcher::LeftAt / RightAt) against the dense map it replaces: equal at every pixel,
// bit for bit, on synthetic pairs (several search ranges, uniqueness on and off, the texture
// filter and the left-right check on and off, both kernel sets) and on the Middlebury pairs in
// ../shared/data; and AttachDepth reading it equals AttachDepth on the dense map.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "tests/test_util.h"
#include "vo/disparity.h"
#include "vo/sad_block_matcher.h"

namespace vo {
namespace {

// A rectified pair of a random-textured scene: a slanted background plane, a nearer box and a
// flat (textureless) band, with sensor noise, so every post-filter has work to do.
struct Pair {
  cv::Mat left, right;
};

Pair SyntheticPair(int width, int height, double max_disparity_px, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat texture(height, width + 2 * static_cast<int>(max_disparity_px) + 8, CV_32F);
  rng.fill(texture, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.0);
  cv::Mat left(height, width, CV_8UC1), right(height, width, CV_8UC1);
  const int offset = static_cast<int>(max_disparity_px) + 4;
  auto disparity = [&](int x, int y) {  // slanted background 0.3-0.6 max, a box at 0.9 max
    const bool box = x > width / 3 && x < width / 2 && y > height / 4 && y < height / 2;
    return box ? 0.9 * max_disparity_px : max_disparity_px * (0.3 + 0.3 * x / width);
  };
  auto flat = [&](int y) { return y > 3 * height / 4 && y < 3 * height / 4 + 12; };
  auto sample = [&](int y, double u) {  // the texture at scene coordinate u
    const int u0 = static_cast<int>(std::floor(u));
    const double a = u - u0;
    return (1.0 - a) * texture.at<float>(y, u0) + a * texture.at<float>(y, u0 + 1);
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double l = flat(y) ? 128.0 : sample(y, offset + x);
      left.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(l + rng.gaussian(1.5));
    }
  }
  // Right image: right pixel x_r shows the scene point of the nearest surface (largest
  // disparity) whose left pixel x lands on it, x - d(x) = x_r (to half a pixel).
  for (int y = 0; y < height; ++y) {
    for (int xr = 0; xr < width; ++xr) {
      double value = 128.0, best_d = -1.0;
      for (int x = xr; x < std::min(width, xr + static_cast<int>(max_disparity_px) + 2); ++x) {
        const double d = disparity(x, y);
        if (std::abs(x - d - xr) < 0.5 && d > best_d) {
          best_d = d;
          value = flat(y) ? 128.0 : sample(y, offset + xr + d);
        }
      }
      right.at<uint8_t>(y, xr) = cv::saturate_cast<uint8_t>(value + rng.gaussian(1.5));
    }
  }
  return {left, right};
}

DisparityOptions OneVolumeNoSpeckle() {
  DisparityOptions o;
  o.algorithm = DisparityAlgorithm::kBlockMatchingOneVolume;
  o.speckle_window_size = 0;
  return o;
}

// Every pixel, visited in a shuffled order (the cache must not depend on the order).
void ExpectEqualEverywhere(const cv::Mat& left, const cv::Mat& right, const DisparityOptions& o,
                           int num_disparities, const std::string& what) {
  DisparityEstimator dense(o), sparse(o);
  const DisparityResult d = dense.Compute(left, right, num_disparities);
  ASSERT_TRUE(d.ok) << what << ": " << d.message;
  const DisparityResult p = sparse.PrepareAtPixels(left, right, num_disparities);
  ASSERT_TRUE(p.ok) << what << ": " << p.message;
  std::vector<int> order(left.rows * left.cols);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(5));
  int mismatches = 0, valid = 0;
  for (int i : order) {
    const int x = i % left.cols, y = i / left.cols;
    const float expected = d.disparity_px.at<float>(y, x);
    const float got = sparse.DisparityAt(x, y);
    if (expected >= 0.0f) ++valid;
    if (got != expected && ++mismatches <= 5) {
      ADD_FAILURE() << what << ": pixel (" << x << ", " << y << ") dense " << expected
                    << ", at pixels " << got;
    }
    ASSERT_EQ(sparse.DisparityAt(x, y), got) << "a second read differs";
  }
  EXPECT_EQ(mismatches, 0) << what;
  // The comparison means something: both valid and invalid pixels occur.
  EXPECT_GT(valid, left.rows * left.cols / 4) << what;
  EXPECT_LT(valid, left.rows * left.cols) << what;
  const DisparityEstimator::PixelCounts c = sparse.pixel_counts();
  EXPECT_EQ(c.left, left.rows * left.cols);
  printf("[ %s ] %d of %d valid; rejected: texture %d, left-right %d; right pixels %d\n",
         what.c_str(), valid, left.rows * left.cols, c.rejected_texture, c.rejected_left_right,
         c.right);
}

TEST(DisparityAtPixelsTest, EqualsTheDenseMapEverywhere) {
  const Pair pair = SyntheticPair(160, 96, 20.0, 3);
  DisparityOptions o = OneVolumeNoSpeckle();
  o.num_disparities = 32;
  ExpectEqualEverywhere(pair.left, pair.right, o, 0, "defaults, 32");
  ExpectEqualEverywhere(pair.left, pair.right, o, 48, "range 48 given per call");
  DisparityOptions no_uniqueness = o;
  no_uniqueness.uniqueness_ratio = 0;
  ExpectEqualEverywhere(pair.left, pair.right, no_uniqueness, 0, "uniqueness off");
  DisparityOptions no_lr = o;
  no_lr.left_right_max_diff_px = -1.0;
  ExpectEqualEverywhere(pair.left, pair.right, no_lr, 0, "left-right check off");
  DisparityOptions no_texture = o;
  no_texture.min_texture = 0.0;
  ExpectEqualEverywhere(pair.left, pair.right, no_texture, 0, "texture filter off");
  DisparityOptions strict = o;
  strict.min_texture = 3.0;
  strict.block_size = 7;
  strict.min_disparity_px = 2;
  strict.uniqueness_ratio = 30;
  ExpectEqualEverywhere(pair.left, pair.right, strict, 0, "block 7, min 2, strict");
}

TEST(DisparityAtPixelsTest, MatcherPixelsEqualComputeForBothKernelSets) {
  const Pair pair = SyntheticPair(128, 64, 24.0, 8);
  for (bool avx2 : {false, true}) {
    SadBlockMatcherOptions o;
    o.num_disparities = 32;
    o.allow_avx2 = avx2;
    SadBlockMatcher dense(o), sparse(o);
    cv::Mat left_fixed, right_fixed;
    dense.Compute(pair.left, pair.right, &left_fixed, &right_fixed);
    sparse.Prepare(pair.left, pair.right);
    int ties_possible = 0;
    for (int y = 0; y < pair.left.rows; ++y) {
      for (int x = 0; x < pair.left.cols; ++x) {
        ASSERT_EQ(sparse.LeftAt(x, y), left_fixed.at<int16_t>(y, x))
            << "left (" << x << ", " << y << ") avx2 " << avx2;
        ASSERT_EQ(sparse.RightAt(x, y), right_fixed.at<int16_t>(y, x))
            << "right (" << x << ", " << y << ") avx2 " << avx2;
        ties_possible += right_fixed.at<int16_t>(y, x) >= 0;
      }
    }
    EXPECT_GT(ties_possible, 0);
  }
}

TEST(DisparityAtPixelsTest, AttachDepthReadsTheSameValues) {
  const Pair pair = SyntheticPair(160, 96, 20.0, 11);
  DisparityOptions o = OneVolumeNoSpeckle();
  o.num_disparities = 32;
  StereoCamera cam;
  cam.width = 160;
  cam.height = 96;
  cam.fx_px = cam.fy_px = 120.0;
  cam.cx_px = 79.5;
  cam.cy_px = 47.5;
  cam.baseline_m = 0.1;
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-0.4, 159.4), v(-0.4, 95.4);
  std::vector<Feature> features(400);
  for (Feature& f : features) f.uv_px = Eigen::Vector2d(u(rng), v(rng));
  for (DisparitySampling sampling : {DisparitySampling::kBilinear, DisparitySampling::kNearest}) {
    DepthSamplingOptions s;
    s.sampling = sampling;
    DisparityEstimator dense(o), sparse(o);
    const DisparityResult d = dense.Compute(pair.left, pair.right);
    ASSERT_TRUE(d.ok);
    ASSERT_TRUE(sparse.PrepareAtPixels(pair.left, pair.right).ok);
    std::vector<Feature> a = features, b = features;
    const AttachDepthResult ra = AttachDepth(d.disparity_px, cam, &a, s);
    const AttachDepthResult rb = AttachDepth(&sparse, cam, &b, s);
    ASSERT_TRUE(ra.ok && rb.ok) << ra.message << rb.message;
    EXPECT_EQ(ra.num_with_depth, rb.num_with_depth);
    EXPECT_GT(ra.num_with_depth, 100);
    for (size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].disparity_px, b[i].disparity_px) << "feature " << i;
    }
    // Only the pixels read were evaluated: at most 9 per feature here.
    EXPECT_LE(sparse.pixel_counts().left, 9 * static_cast<int>(features.size()));
  }
}

TEST(DisparityAtPixelsTest, RejectsWhatItCannotDo) {
  const Pair pair = SyntheticPair(64, 48, 10.0, 1);
  DisparityOptions bm;  // cv::StereoBM: no single-pixel evaluation
  DisparityEstimator estimator(bm);
  const DisparityResult r = estimator.PrepareAtPixels(pair.left, pair.right);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("block_matching_one_volume"), std::string::npos) << r.message;
  EXPECT_EQ(estimator.DisparityAt(10, 10), kInvalidDisparity);
  StereoCamera cam;
  cam.width = 64;
  cam.height = 48;
  cam.fx_px = cam.fy_px = 50.0;
  cam.cx_px = 31.5;
  cam.cy_px = 23.5;
  cam.baseline_m = 0.1;
  std::vector<Feature> features(1);
  EXPECT_FALSE(AttachDepth(&estimator, cam, &features).ok);  // nothing prepared
  DisparityEstimator one(OneVolumeNoSpeckle());
  EXPECT_FALSE(one.PrepareAtPixels(pair.left, pair.right, 20).ok);  // not a multiple of 16
  EXPECT_FALSE(one.PrepareAtPixels(pair.left, cv::Mat()).ok);
  ASSERT_TRUE(one.PrepareAtPixels(pair.left, pair.right).ok);
  EXPECT_EQ(one.DisparityAt(-1, 0), kInvalidDisparity);
  EXPECT_EQ(one.DisparityAt(64, 0), kInvalidDisparity);
  cam.width = 80;  // the camera and the prepared pair differ in size
  const AttachDepthResult wrong_size = AttachDepth(&one, cam, &features);
  EXPECT_FALSE(wrong_size.ok);
  EXPECT_NE(wrong_size.message.find("64x48"), std::string::npos) << wrong_size.message;
}

bool IsDirectory(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

TEST(DisparityAtPixelsTest, EqualsTheDenseMapOnMiddlebury) {
  int pairs = 0;
  for (const char* name : {"tsukuba", "venus"}) {
    const std::string dir = vobench_test::SharedDataDir() + "/middlebury/" + name;
    if (!IsDirectory(dir)) continue;
    const bool tsukuba = std::string(name) == "tsukuba";
    const cv::Mat left =
        cv::imread(dir + (tsukuba ? "/im3.png" : "/im2.png"), cv::IMREAD_GRAYSCALE);
    const cv::Mat right =
        cv::imread(dir + (tsukuba ? "/im4.png" : "/im6.png"), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(left.empty() || right.empty()) << "unreadable images in " << dir;
    DisparityOptions o = OneVolumeNoSpeckle();
    o.num_disparities = 32;
    ExpectEqualEverywhere(left, right, o, 0, std::string("middlebury ") + name);
    ++pairs;
  }
  if (pairs == 0) GTEST_SKIP() << "no Middlebury data under " << vobench_test::SharedDataDir();
}

}  // namespace
}  // namespace vo
