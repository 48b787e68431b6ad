// Matcher evaluation against ground truth (harness/match_eval.h) on hand-made scenes: a
// textured wall facing the camera, so every ground-truth position is known in closed form.
#include "harness/match_eval.h"

#include <gtest/gtest.h>

#include "tests/synthetic_images.h"

namespace {

constexpr double kWallDepthM = 2.0;

vo::StereoCamera Camera() {
  vo::StereoCamera cam;
  cam.width = 320;
  cam.height = 240;
  cam.fx_px = cam.fy_px = 230.0;
  cam.cx_px = 159.5;
  cam.cy_px = 119.5;
  cam.baseline_m = 0.09;
  return cam;
}

// A frame of a fronto-parallel wall at kWallDepthM, the camera at x = camera_x_m (moving along
// its own x axis): the image is the wall texture shifted by -fx · x / z pixels; the right image
// is shifted by another fx · b / z.
harness::GroundTruthFrame WallFrame(const cv::Mat& texture, double camera_x_m) {
  const vo::StereoCamera cam = Camera();
  auto view = [&](double x_m) {
    const double shift_px = cam.fx_px * x_m / kWallDepthM;
    const cv::Mat A = (cv::Mat_<double>(2, 3) << 1, 0, -shift_px - 40, 0, 1, 0);
    cv::Mat out;
    cv::warpAffine(texture, out, A, cv::Size(cam.width, cam.height), cv::INTER_LINEAR);
    return out;
  };
  harness::GroundTruthFrame f;
  f.left = view(camera_x_m);
  f.right = view(camera_x_m + cam.baseline_m);
  f.depth_m = cv::Mat(cam.height, cam.width, CV_32F, cv::Scalar(kWallDepthM));
  f.T_world_cam0.translation() = Eigen::Vector3d(camera_x_m, 0, 0);
  return f;
}

TEST(MatchEvalTest, ProjectGroundTruthOnAWall) {
  const vo::StereoCamera cam = Camera();
  const cv::Mat texture = vobench_test::RandomTexture(420, 240, 3);
  const harness::GroundTruthFrame a = WallFrame(texture, 0.0), b = WallFrame(texture, 0.1);
  Eigen::Vector2d uv;
  // 0.1 m to the right at 2 m: the point moves 230 · 0.1 / 2 = 11.5 px to the left.
  ASSERT_TRUE(harness::ProjectGroundTruth(cam, a, b, {100.0, 50.0}, kWallDepthM, 0.03, &uv));
  EXPECT_NEAR(uv.x(), 100.0 - 11.5, 1e-9);
  EXPECT_NEAR(uv.y(), 50.0, 1e-9);
  // Leaves the image: not visible.
  EXPECT_FALSE(harness::ProjectGroundTruth(cam, a, b, {5.0, 50.0}, kWallDepthM, 0.03, &uv));
  // Occluded: frame b's depth there is nearer than the point.
  harness::GroundTruthFrame occluded = b;
  occluded.depth_m.setTo(1.0);
  EXPECT_FALSE(
      harness::ProjectGroundTruth(cam, a, occluded, {100.0, 50.0}, kWallDepthM, 0.03, &uv));
}

TEST(MatchEvalTest, VoMatchStatsCountCorrectWrongAndLeftOut) {
  const vo::StereoCamera cam = Camera();
  const cv::Mat texture = vobench_test::RandomTexture(420, 240, 4);
  harness::GroundTruthFrame a = WallFrame(texture, 0.0);
  const harness::GroundTruthFrame b = WallFrame(texture, 0.1);
  // A depth edge around (200, 200) makes a feature there ambiguous (left out).
  a.depth_m(cv::Rect(201, 190, 20, 20)).setTo(1.0);
  auto feature = [](double u, double v) {
    vo::Feature f;
    f.uv_px = Eigen::Vector2d(u, v);
    return f;
  };
  const std::vector<vo::Feature> ref = {feature(100, 50), feature(150, 80), feature(120, 160),
                                        feature(200, 200)};
  const std::vector<vo::Feature> cur = {feature(88.5, 50),     // correct (exact)
                                        feature(139.5, 81),    // correct (1.1 px off)
                                        feature(111.5, 160),   // wrong (3 px off)
                                        feature(188.5, 200)};  // ambiguous reference depth
  std::vector<vo::Match> matches;
  for (int i = 0; i < 4; ++i) {
    vo::Match m;
    m.prev = i;
    m.curr = i;
    matches.push_back(m);
  }
  const std::vector<bool> inliers = {true, false, true, true};
  harness::VoMatchStats stats;
  harness::AccumulateVoMatchStats(cam, a, b, ref, cur, matches, inliers,
                                  harness::MatchEvalOptions(), &stats);
  EXPECT_EQ(stats.matches, 3);
  EXPECT_EQ(stats.correct, 2);
  EXPECT_EQ(stats.inliers, 2);
  EXPECT_EQ(stats.inliers_correct, 1);
  EXPECT_EQ(stats.frames, 1);
  EXPECT_NEAR(stats.precision(), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(stats.inlier_precision(), 0.5, 1e-12);
  // Without depth nothing is counted.
  harness::GroundTruthFrame no_depth = b;
  no_depth.depth_m = cv::Mat();
  harness::AccumulateVoMatchStats(cam, a, no_depth, ref, cur, matches, inliers,
                                  harness::MatchEvalOptions(), &stats);
  EXPECT_EQ(stats.matches, 3);
}

TEST(MatchEvalTest, MatchersOnATranslatingWallAreNearlyAllCorrect) {
  // The paper's matcher and NCC-mutual on a well-textured wall moving 2.3 px per frame.
  constexpr double kMinPrecision = 0.95;
  constexpr double kMinRecall = 0.5;
  const vo::StereoCamera cam = Camera();
  const cv::Mat texture = vobench_test::RandomTexture(420, 240, 5);
  std::vector<harness::GroundTruthFrame> frames;
  for (int k = 0; k < 3; ++k) frames.push_back(WallFrame(texture, 0.02 * k));
  harness::MatchEvalOptions o;
  o.strides = {1, 2};
  o.matchers = {vo::MatcherType::kSvdNccGabor, vo::MatcherType::kNccMutual};
  o.disparity.num_disparities = 32;
  std::vector<harness::MatchEvalRow> rows;
  std::string error;
  ASSERT_TRUE(harness::EvaluateMatchers(frames, cam, o, &rows, &error)) << error;
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& r : rows) {
    std::printf("[ %s stride %d ] matches %ld precision %.3f recall %.3f\n", r.matcher.c_str(),
                r.stride, r.matches, r.precision, r.recall);
    EXPECT_GT(r.matches, 50) << r.matcher;
    EXPECT_GT(r.precision, kMinPrecision) << r.matcher << " stride " << r.stride;
    EXPECT_GT(r.recall, kMinRecall) << r.matcher << " stride " << r.stride;
  }
  // Bad options are refused.
  o.strides = {0};
  EXPECT_FALSE(harness::EvaluateMatchers(frames, cam, o, &rows, &error));
  EXPECT_NE(error.find("strides"), std::string::npos);
}

}  // namespace
