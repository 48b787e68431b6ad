#include "vo/tracker.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/texture_util.h"
#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

using vobench_test::RotationAngleRad;

constexpr double kExactTolM = 1e-6;  // exact feature positions: RANSAC/Horn must be exact
constexpr double kExactTolRad = 1e-6;

// A wall 3 m in front of the camera with a blurred random texture; the camera steps sideways so
// the wall moves 5 px to the right in the image: the reference sees texture columns 5.., the
// current frame columns 0.. . Features on a 20 px grid, at their exact positions.
struct Scene {
  StereoCamera camera = test::TestCamera();
  static constexpr int kShiftPx = 5;
  static constexpr double kDepthM = 3.0;
  Eigen::Isometry3d T_ref_curr = Eigen::Isometry3d::Identity();
  MatchFrame ref, curr;

  Scene() {
    T_ref_curr.translation().x() = -kShiftPx * kDepthM / camera.fx_px;
    const cv::Mat texture = test::BlurredNoise(camera.width + kShiftPx, camera.height, 9, 5, 1.2);
    ref.image = texture(cv::Rect(kShiftPx, 0, camera.width, camera.height)).clone();
    curr.image = texture(cv::Rect(0, 0, camera.width, camera.height)).clone();
    ref.frame_id = 0;
    curr.frame_id = 1;
    for (int v = 30; v <= 210; v += 20) {
      for (int u = 30; u <= 290; u += 20) {
        const Eigen::Vector3d p_ref = camera.BackprojectDepth(u, v, kDepthM);
        ref.features.push_back(test::FeatureAt(camera, p_ref));
        curr.features.push_back(test::FeatureAt(camera, T_ref_curr.inverse() * p_ref));
      }
    }
  }
  int n() const { return static_cast<int>(ref.features.size()); }
};

void ExpectExact(const MotionAttempt& a, const Eigen::Isometry3d& T) {
  ASSERT_TRUE(a.ransac.ok()) << a.ransac.message;
  EXPECT_LT(RotationAngleRad(a.ransac.T_prev_curr.linear(), T.linear()), kExactTolRad);
  EXPECT_LT((a.ransac.T_prev_curr.translation() - T.translation()).norm(), kExactTolM);
}

TEST(TrackerTest, ThePriorsPassAndTheGuidedPassFindEveryFeature) {
  const Scene s;
  std::string error;
  const std::unique_ptr<Tracker> tracker =
      Tracker::Create(s.camera, TrackerOptions(), MotionOptions(), &error);
  ASSERT_TRUE(tracker) << error;
  TrackingContext context;
  context.T_ref_curr_prior = &s.T_ref_curr;
  OdometryResult result;
  const MotionAttempt a = tracker->MatchAndEstimate(s.ref, s.curr, context, &result, &error);
  ASSERT_TRUE(error.empty()) << error;
  ExpectExact(a, s.T_ref_curr);
  EXPECT_EQ(a.inliers(), s.n());
  EXPECT_EQ(result.num_first_pass_inliers, s.n());
  // Confident at once: no coarse-to-fine pass; the guided pass keeps every match.
  EXPECT_FALSE(result.image_shift_ok);
  EXPECT_EQ(a.source, PredictionSource::kGuided);
}

TEST(TrackerTest, WithoutAPriorTheImageShiftCentresTheSearch) {
  const Scene s;
  TrackerOptions o;
  o.guided_rematch = false;
  std::string error;
  const std::unique_ptr<Tracker> tracker = Tracker::Create(s.camera, o, MotionOptions(), &error);
  ASSERT_TRUE(tracker) << error;
  OdometryResult result;
  const MotionAttempt a =
      tracker->MatchAndEstimate(s.ref, s.curr, TrackingContext(), &result, &error);
  ASSERT_TRUE(error.empty()) << error;
  ASSERT_TRUE(result.image_shift_ok);
  EXPECT_NEAR(result.image_shift_px.x(), Scene::kShiftPx, 0.5);
  EXPECT_NEAR(result.image_shift_px.y(), 0.0, 0.5);
  ExpectExact(a, s.T_ref_curr);
  EXPECT_GE(a.inliers(), s.n() - 2);
}

TEST(TrackerTest, ThePapersFormRunsOnePassAroundThePreviousPositions) {
  const Scene s;
  TrackerOptions o;
  o.matcher.prediction = PredictionMode::kNone;
  std::string error;
  const std::unique_ptr<Tracker> tracker = Tracker::Create(s.camera, o, MotionOptions(), &error);
  ASSERT_TRUE(tracker) << error;
  TrackingContext context;
  context.T_ref_curr_prior = &s.T_ref_curr;  // ignored by the paper's form
  OdometryResult result;
  const MotionAttempt a = tracker->MatchAndEstimate(s.ref, s.curr, context, &result, &error);
  ASSERT_TRUE(error.empty()) << error;
  EXPECT_EQ(a.source, PredictionSource::kNone);
  EXPECT_EQ(result.num_first_pass_inliers, a.inliers());
  EXPECT_EQ(result.times.predict_ms, 0.0);
  ExpectExact(a, s.T_ref_curr);
}

TEST(TrackerTest, EstimateIsRansacOnGivenMatches) {
  const Scene s;
  std::string error;
  const std::unique_ptr<Tracker> tracker =
      Tracker::Create(s.camera, TrackerOptions(), MotionOptions(), &error);
  ASSERT_TRUE(tracker) << error;
  std::vector<Match> matches;
  for (int i = 0; i < s.n(); ++i) matches.push_back(Match{i, i, 1.0});
  const MotionAttempt a =
      tracker->Estimate(s.ref.features, s.curr.features, matches, PredictionSource::kNone);
  ExpectExact(a, s.T_ref_curr);
  EXPECT_EQ(a.inliers(), s.n());
  EXPECT_EQ(tracker->matcher_type(), MatcherType::kSvdNccGabor);
}

TEST(TrackerTest, ABadMatcherIsRefused) {
  TrackerOptions o;
  o.matcher.type = static_cast<MatcherType>(99);
  std::string error;
  EXPECT_FALSE(Tracker::Create(test::TestCamera(), o, MotionOptions(), &error));
  EXPECT_FALSE(error.empty());
}

TEST(TrackerTest, OptionsRefuseABadFieldByName) {
  test::ExpectOptionsRefuseBadFields<TrackerOptions>({
      {"matcher: ", [](TrackerOptions* o) { o->matcher.type = static_cast<MatcherType>(99); }},
      {"image_shift: ", [](TrackerOptions* o) { o->image_shift.min_score = 2.0; }},
      {"prior_radius_scale", [](TrackerOptions* o) { o->prior_radius_scale = 0.0; }},
      {"shift_radius_scale", [](TrackerOptions* o) { o->shift_radius_scale = 21.0; }},
      {"confident_min_inliers", [](TrackerOptions* o) { o->confident_min_inliers = -1; }},
      {"confident_inlier_fraction", [](TrackerOptions* o) { o->confident_inlier_fraction = 1.5; }},
      {"guided_radius_scale", [](TrackerOptions* o) { o->guided_radius_scale = NAN; }},
  });
}

}  // namespace
}  // namespace vo
