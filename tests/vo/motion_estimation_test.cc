#include "vo/motion_estimation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/front_end.h"
#include "vo/motion_model.h"

namespace vo {
namespace {

using vobench_test::RotationAngleRad;

constexpr double kDeg = M_PI / 180.0;
constexpr double kExactTolM = 1e-6;  // exact correspondences: the motion must be exact
constexpr double kExactTolRad = 1e-6;

// A camera motion T_ref_curr (p_ref = T · p_curr): yaw about the camera's y, pitch about its
// x, and a translation.
Eigen::Isometry3d Motion(double yaw_deg, double pitch_deg, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(pitch_deg * kDeg, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = t;
  return T;
}

// n exact features in the reference and the current frame under T_ref_curr, matched one to one.
struct Pair {
  std::vector<Feature> ref, curr;
  std::vector<Match> matches;
};
Pair ExactPair(const Eigen::Isometry3d& T_ref_curr, int n) {
  const StereoCamera cam = test::TestCamera();
  SplitMix64 rng(11);
  Pair p;
  while (static_cast<int>(p.ref.size()) < n) {
    const Eigen::Vector3d p_ref(-1.5 + 3.0 * rng.Uniform(), -1.0 + 2.0 * rng.Uniform(),
                                2.0 + 4.0 * rng.Uniform());
    const Eigen::Vector3d p_curr = T_ref_curr.inverse() * p_ref;
    Eigen::Vector2d a, b;
    if (!cam.ProjectLeft(p_ref, &a) || !cam.ProjectLeft(p_curr, &b)) continue;
    if (a.x() < 0 || a.y() < 0 || a.x() > 319 || a.y() > 239) continue;
    if (b.x() < 0 || b.y() < 0 || b.x() > 319 || b.y() > 239) continue;
    const int i = static_cast<int>(p.ref.size());
    p.ref.push_back(test::FeatureAt(cam, p_ref));
    p.curr.push_back(test::FeatureAt(cam, p_curr));
    p.matches.push_back(Match{i, i, 1.0});
  }
  return p;
}

TEST(MotionEstimationTest, RansacOnExactMatchesIsTheMotion) {
  const Eigen::Isometry3d T = Motion(3.0, 0.5, Eigen::Vector3d(0.02, -0.01, 0.08));
  const Pair p = ExactPair(T, 60);
  const MotionAttempt a = EstimateMotion(test::TestCamera(), RansacOptions(), p.ref, p.curr,
                                         p.matches, PredictionSource::kImageShift);
  ASSERT_TRUE(a.ransac.ok()) << a.ransac.message;
  EXPECT_EQ(a.inliers(), 60);
  EXPECT_EQ(a.source, PredictionSource::kImageShift);
  ASSERT_EQ(a.match_index.size(), a.correspondences.size());
  EXPECT_LT(RotationAngleRad(a.ransac.T_prev_curr.linear(), T.linear()), kExactTolRad);
  EXPECT_LT((a.ransac.T_prev_curr.translation() - T.translation()).norm(), kExactTolM);
}

TEST(MotionEstimationTest, PriorUpdateWeightIsTheSupportToItsExponent) {
  MotionOptions o;  // reliable_min_inliers 30, exponent 2
  EXPECT_DOUBLE_EQ(PriorUpdateWeight(15, o), 0.25);
  EXPECT_DOUBLE_EQ(PriorUpdateWeight(30, o), 1.0);
  EXPECT_DOUBLE_EQ(PriorUpdateWeight(90, o), 1.0);
  EXPECT_DOUBLE_EQ(PriorUpdateWeight(0, o), 0.0);
}

TEST(MotionEstimationTest, AFewPointMotionMustAgreeWithTheImageShift) {
  const StereoCamera cam = test::TestCamera();
  const Eigen::Isometry3d truth = Motion(2.0, 0.0, Eigen::Vector3d::Zero());
  const Pair p = ExactPair(truth, 20);
  // The shift the true motion shows at the image centre (far away: rotation only, as no
  // feature of the reference is farther than 6 m the median depth is used; take it from there).
  std::vector<double> z;
  for (const Feature& f : p.ref) z.push_back(f.p_cam0.z());
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  const Eigen::Vector2d shift = PredictedCentreShift(cam, truth, z[z.size() / 2]);
  const Eigen::Isometry3d prior = Eigen::Isometry3d::Identity();
  EXPECT_TRUE(AgreesWithImageShift(cam, p.ref, truth, prior, true, shift, 3.0));
  // 5° the other way: farther from the shift than the prior by more than 3 px.
  const Eigen::Isometry3d wrong = Motion(-5.0, 0.0, Eigen::Vector3d::Zero());
  EXPECT_FALSE(AgreesWithImageShift(cam, p.ref, wrong, prior, true, shift, 3.0));
  EXPECT_TRUE(AgreesWithImageShift(cam, p.ref, wrong, prior, false, shift, 3.0));  // no shift
}

TEST(MotionEstimationTest, TooFewFeaturesTakeTheFewPointMotionOnlyAfterAMeasuredMotion) {
  const StereoCamera cam = test::TestCamera();
  const Eigen::Isometry3d truth = Motion(1.5, 0.0, Eigen::Vector3d(0.0, 0.0, 0.05));
  const Pair p = ExactPair(truth, 6);  // fewer than min_features (15) and min_inliers (12)
  MotionOptions o;
  o.few_point_motion = true;
  MotionAttempt a =
      EstimateMotion(cam, o.ransac, p.ref, p.curr, p.matches, PredictionSource::kMotionPrior);
  const Eigen::Vector2d no_shift = Eigen::Vector2d::Zero();
  const bool few_features = 6 < FrontEndOptions().min_features;
  // After a loss (the prior is a bridge, not a measurement): no few-point motion.
  MotionAttempt after_loss = a;
  const FrameMotion lost = ResolveFrameMotion(cam, o, few_features, p.ref, nullptr, &truth, false,
                                              false, no_shift, &after_loss);
  EXPECT_TRUE(lost.few_features);
  EXPECT_FALSE(lost.ok());
  EXPECT_THAT(MotionFailureMessage(lost, after_loss, o.min_inliers),
              ::testing::StartsWith("motion failed: too few features for RANSAC"));
  // Tracking normally, with the true motion as the prior: the few-point motion is exact.
  const FrameMotion m =
      ResolveFrameMotion(cam, o, few_features, p.ref, nullptr, &truth, true, false, no_shift, &a);
  ASSERT_TRUE(m.few_point);
  EXPECT_TRUE(m.ok());
  EXPECT_THAT(m.message, ::testing::HasSubstr("few-point motion with the prior"));
  EXPECT_TRUE(a.ransac.ok());
  EXPECT_EQ(a.ransac.num_inliers, 6);
  EXPECT_LT(RotationAngleRad(a.ransac.T_prev_curr.linear(), truth.linear()), kExactTolRad);
  EXPECT_LT((a.ransac.T_prev_curr.translation() - truth.translation()).norm(), kExactTolM);
}

TEST(MotionEstimationTest, AWeakMotionThatTiltsTheGroundVehicleIsRefused) {
  const StereoCamera cam = test::TestCamera();
  // 20 inliers: above min_inliers (12), below reliable_min_inliers (30); 4° of pitch.
  const Eigen::Isometry3d tilting = Motion(0.0, 4.0, Eigen::Vector3d(0.0, 0.0, 0.05));
  const Pair p = ExactPair(tilting, 20);
  MotionOptions o;
  MotionAttempt a =
      EstimateMotion(cam, o.ransac, p.ref, p.curr, p.matches, PredictionSource::kNone);
  ASSERT_EQ(a.inliers(), 20);
  const Eigen::Vector3d up(0.0, -1.0, 0.0);  // a level camera: the world's up is its −y
  MotionAttempt six_dof = a;
  EXPECT_TRUE(ResolveFrameMotion(cam, o, false, p.ref, nullptr, nullptr, true, false,
                                 Eigen::Vector2d::Zero(), &six_dof)
                  .ok());
  const FrameMotion vehicle = ResolveFrameMotion(cam, o, false, p.ref, &up, nullptr, true, false,
                                                 Eigen::Vector2d::Zero(), &a);
  EXPECT_TRUE(vehicle.not_vehicle_like);
  EXPECT_FALSE(vehicle.ok());
  EXPECT_THAT(MotionFailureMessage(vehicle, a, o.min_inliers),
              ::testing::HasSubstr("tilts or lifts the ground vehicle"));
  // The same pitch with reliable support is believed.
  const Pair strong = ExactPair(tilting, 40);
  MotionAttempt b = EstimateMotion(cam, o.ransac, strong.ref, strong.curr, strong.matches,
                                   PredictionSource::kNone);
  EXPECT_TRUE(ResolveFrameMotion(cam, o, false, strong.ref, &up, nullptr, true, false,
                                 Eigen::Vector2d::Zero(), &b)
                  .ok());
}

TEST(MotionEstimationTest, OptionsRefuseABadFieldByName) {
  test::ExpectOptionsRefuseBadFields<MotionOptions>({
      {"ransac: ", [](MotionOptions* o) { o->ransac.confidence = 1.0; }},
      {"few_point: ",
       [](MotionOptions* o) {
         o->few_point_motion = true;
         o->few_point.min_inliers = 0;
       }},
      {"min_inliers", [](MotionOptions* o) { o->min_inliers = 2; }},
      {"reliable_min_inliers", [](MotionOptions* o) { o->reliable_min_inliers = 2; }},
      {"prior_update_exponent", [](MotionOptions* o) { o->prior_update_exponent = 0.5; }},
      {"few_point_max_shift_disagreement_px",
       [](MotionOptions* o) { o->few_point_max_shift_disagreement_px = -1.0; }},
      {"vehicle_max_weak_tilt_deg", [](MotionOptions* o) { o->vehicle_max_weak_tilt_deg = 0.0; }},
      {"vehicle_max_weak_lift_m",
       [](MotionOptions* o) {
         o->vehicle_max_weak_lift_m = std::numeric_limits<double>::infinity();
       }},
      {"few_point_min_features", [](MotionOptions* o) { o->few_point_min_features = 0; }},
      {"few_point_prior_update", [](MotionOptions* o) { o->few_point_prior_update = 1.5; }},
  });
}

}  // namespace
}  // namespace vo
