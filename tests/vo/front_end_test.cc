#include "vo/front_end.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "tests/vo/texture_util.h"
#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

constexpr double kTwoSubpixelStepsPx = 2.0 / 16.0 + 1e-9;

Feature WithDisparity(double u, double v, double d) {
  Feature f;
  f.uv_px = Eigen::Vector2d(u, v);
  f.disparity_px = d;
  return f;
}

TEST(FrontEndTest, SceneRangeCoversTheLargestDisparityWithItsMargins) {
  FrontEndOptions o;  // margin 25 % + 8 px
  o.disparity.num_disparities = 64;
  std::vector<Feature> f = {WithDisparity(10, 10, 4.0), WithDisparity(20, 10, 20.0)};
  EXPECT_EQ(SceneNumDisparities(f, o), 48);  // 20 · 1.25 + 8 = 33 → 48
  f[1].disparity_px = 2.0;                   // 4 · 1.25 + 8 = 13 → 16
  EXPECT_EQ(SceneNumDisparities(f, o), 16);
  f[1].disparity_px = 60.0;  // 83 → 96, not below 64: the full range
  EXPECT_EQ(SceneNumDisparities(f, o), 0);
  EXPECT_EQ(SceneNumDisparities({WithDisparity(1, 1, -1.0)}, o), 0);  // no depth
  o.disparity_range_from_scene = false;
  EXPECT_EQ(SceneNumDisparities({WithDisparity(1, 1, 4.0)}, o), 0);
}

TEST(FrontEndTest, TheSeamKeepsFeaturesWithDepthAndReindexesTheMatches) {
  const StereoCamera cam = test::TestCamera();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Feature> given = {WithDisparity(50, 60, 10.0), WithDisparity(nan, 60, 10.0),
                                WithDisparity(70, 80, 0.0), WithDisparity(90, 100, 12.0)};
  given[3].track_id = 42;
  given[3].track_age = 5;
  std::vector<int> map;
  const std::vector<Feature> kept = KeepFeaturesWithDepth(cam, given, &map);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(map, (std::vector<int>{0, -1, -1, 1}));
  EXPECT_TRUE(kept[1].p_cam0 == cam.Backproject(90, 100, 12.0));
  EXPECT_EQ(kept[1].track_id, -1);
  EXPECT_EQ(kept[1].track_age, 0);

  // Previous call: 3 given, the middle one dropped; current: the map above.
  const std::vector<int> prev_map = {0, -1, 1};
  const std::vector<Match> matches = {
      {2, 3, 0.9},   // → (1, 1)
      {0, 0, 0.8},   // → (0, 0)
      {1, 3, 0.7},   // the previous feature was dropped
      {2, 0, 0.6},   // the previous feature is used already
      {5, 0, 0.5},   // out of range
      {0, -1, 0.4},  // out of range
  };
  const std::vector<Match> out = ReindexMatches(matches, prev_map, map, 2, kept.size());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].prev, 0);
  EXPECT_EQ(out[0].curr, 0);
  EXPECT_EQ(out[0].score, 0.8);
  EXPECT_EQ(out[1].prev, 1);
  EXPECT_EQ(out[1].curr, 1);
}

TEST(FrontEndTest, FeaturesReadTheDisparityOfAShiftedPairInBothModes) {
  const StereoCamera cam = test::TestCamera();
  const int d = 8;  // the right view is the left one shifted by 8 px: a plane at fx·b/8
  const cv::Mat texture = test::BlurredNoise(cam.width + d, cam.height, 3, 3, 0.8);
  const cv::Mat left = texture(cv::Rect(0, 0, cam.width, cam.height)).clone();
  const cv::Mat right = texture(cv::Rect(d, 0, cam.width, cam.height)).clone();
  for (const DisparityMode mode : {DisparityMode::kDense, DisparityMode::kAtFeatures}) {
    FrontEndOptions o;
    std::string error;
    const std::unique_ptr<FrontEnd> front = FrontEnd::Create(cam, o, &error);
    ASSERT_TRUE(front) << error;
    OdometryResult result;
    const FrontEndFrame f = front->Process(left, right, 32, mode == DisparityMode::kDense, &result);
    ASSERT_TRUE(f.ok) << f.message;
    EXPECT_EQ(f.disparity_px.empty(), mode == DisparityMode::kAtFeatures);
    EXPECT_EQ(result.num_disparities, 32);
    EXPECT_GT(result.num_features, 100);
    ASSERT_GT(result.num_features_with_depth, 100);
    EXPECT_EQ(result.num_features_with_depth, static_cast<int>(f.frame.features.size()));
    // The block matcher's subpixel disparities come in 1/16 px: most features read 8 exactly,
    // none more than two steps off.
    const double z = cam.fx_px * cam.baseline_m / d;
    std::vector<double> disparities;
    for (const Feature& feature : f.frame.features) {
      EXPECT_NEAR(feature.disparity_px, d, kTwoSubpixelStepsPx) << feature.uv_px.transpose();
      EXPECT_NEAR(feature.p_cam0.z(), z, z * kTwoSubpixelStepsPx / (d - kTwoSubpixelStepsPx));
      disparities.push_back(feature.disparity_px);
    }
    std::nth_element(disparities.begin(), disparities.begin() + disparities.size() / 2,
                     disparities.end());
    EXPECT_EQ(disparities[disparities.size() / 2], d);
  }
}

TEST(FrontEndTest, AFailedDisparitySaysSo) {
  const StereoCamera cam = test::TestCamera();
  std::string error;
  const std::unique_ptr<FrontEnd> front = FrontEnd::Create(cam, FrontEndOptions(), &error);
  ASSERT_TRUE(front) << error;
  OdometryResult result;
  const cv::Mat left(cam.height, cam.width, CV_8UC1, cv::Scalar(0));
  const cv::Mat right(cam.height / 2, cam.width / 2, CV_8UC1, cv::Scalar(0));
  const FrontEndFrame f = front->Process(left, right, 32, true, &result);
  EXPECT_FALSE(f.ok);
  EXPECT_THAT(f.message, ::testing::StartsWith("disparity: "));
  EXPECT_TRUE(f.frame.features.empty());
}

TEST(FrontEndTest, ABadDetectorIsRefused) {
  FrontEndOptions o;
  o.detector.max_features = -1;
  std::string error;
  EXPECT_FALSE(FrontEnd::Create(test::TestCamera(), o, &error));
  EXPECT_FALSE(error.empty());
}

TEST(FrontEndTest, OptionsRefuseABadFieldByName) {
  using test::BadField;
  test::ExpectOptionsRefuseBadFields<FrontEndOptions>({
      {"detector: ", [](FrontEndOptions* o) { o->detector.max_features = -1; }},
      {"disparity: ",
       [](FrontEndOptions* o) {
         o->derive_num_disparities = false;
         o->disparity.num_disparities = 20;
       }},
      {"depth: ", [](FrontEndOptions* o) { o->depth.min_depth_m = -1.0; }},
      {"disparity_min_depth_m", [](FrontEndOptions* o) { o->disparity_min_depth_m = 0.0; }},
      {"max_num_disparities", [](FrontEndOptions* o) { o->max_num_disparities = 40; }},
      {"disparity_mode: unknown",
       [](FrontEndOptions* o) { o->disparity_mode = static_cast<DisparityMode>(7); }},
      {"disparity_mode at_features needs disparity.algorithm",
       [](FrontEndOptions* o) { o->disparity.algorithm = DisparityAlgorithm::kBlockMatching; }},
      {"disparity_range_margin", [](FrontEndOptions* o) { o->disparity_range_margin = -0.1; }},
      {"disparity_range_margin_px", [](FrontEndOptions* o) { o->disparity_range_margin_px = NAN; }},
      {"adaptive_min_features", [](FrontEndOptions* o) { o->adaptive_min_features = -1; }},
      {"adaptive_quality_level", [](FrontEndOptions* o) { o->adaptive_quality_level = 1.0; }},
      {"min_features", [](FrontEndOptions* o) { o->min_features = 2; }},
  });
}

}  // namespace
}  // namespace vo
