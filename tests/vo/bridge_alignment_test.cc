#include "vo/bridge_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/vo/vo_test_util.h"
#include "vo/prior_motion.h"

namespace vo {
namespace {

using test::FeatureAt;
using test::TestCamera;

constexpr double kDeg = M_PI / 180.0;
const Eigen::Vector3d kUp(0.0, -1.0, 0.0);  // camera frame: y down, a level camera
constexpr double kAxleM = 0.15;             // the camera 0.15 m ahead of the wheel axle

// The same points seen after the motion T_prev_curr (p_prev = T · p_curr).
std::vector<Feature> Moved(const StereoCamera& camera, const std::vector<Eigen::Vector3d>& points,
                           const Eigen::Isometry3d& T_prev_curr) {
  std::vector<Feature> out;
  for (const Eigen::Vector3d& p : points)
    out.push_back(FeatureAt(camera, T_prev_curr.inverse() * p));
  return out;
}

std::vector<Feature> Seen(const StereoCamera& camera, const std::vector<Eigen::Vector3d>& points) {
  return Moved(camera, points, Eigen::Isometry3d::Identity());
}

// What a plain end wall 0.85 m ahead leaves: a few specks, tens of pixels apart.
std::vector<Eigen::Vector3d> WallSpecks() {
  return {{0.30, -0.25, 0.85}, {-0.28, -0.27, 0.85}, {-0.05, 0.20, 0.86}, {0.12, 0.05, 0.84}};
}

TEST(BridgeAlignmentTest, OptionsAreChecked) {
  std::string error;
  EXPECT_TRUE(BridgeAlignmentOptions().IsValid(&error)) << error;
  BridgeAlignmentOptions o;
  o.gate_px = 0.0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("gate_px"), std::string::npos) << error;
  o = BridgeAlignmentOptions();
  o.min_pairs = 0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("min_pairs"), std::string::npos) << error;
  o = BridgeAlignmentOptions();
  o.disparity_sigma_px = std::nan("");
  EXPECT_FALSE(o.IsValid(&error));
  o = BridgeAlignmentOptions();
  o.step_sigma_m = -1.0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("step_sigma_m"), std::string::npos) << error;
}

// The robot turns in place (2.2° a frame, the camera swinging about the axle); the prior read
// 2.8° from the image shift. The alignment finds the true yaw on exact data.
TEST(BridgeAlignmentTest, YawOfATurnInPlaceIsRecoveredFromAnOverReadPrior) {
  const StereoCamera camera = TestCamera();
  const double forward_m = 0.0;
  const Eigen::Isometry3d T_true = VehicleMotion(kUp, kAxleM, 2.2 * kDeg, forward_m);
  const std::vector<Feature> prev = Seen(camera, WallSpecks());
  const std::vector<Feature> curr = Moved(camera, WallSpecks(), T_true);
  double yaw = 2.8 * kDeg;
  int pairs = 0;
  ASSERT_TRUE(AlignVehicleYaw(camera, prev, curr, kUp, kAxleM, forward_m, BridgeAlignmentOptions(),
                              &yaw, &pairs));
  EXPECT_EQ(pairs, 4);
  EXPECT_NEAR(yaw, 2.2 * kDeg, 1e-9);
}

// The camera's swing about the axle is part of the model: the same flow read without it (axle
// at 0) is a larger yaw, which is what a 6-DoF reading of a near wall does.
TEST(BridgeAlignmentTest, TheAxlesSwingIsNotReadAsYaw) {
  const StereoCamera camera = TestCamera();
  const Eigen::Isometry3d T_true = VehicleMotion(kUp, kAxleM, 2.2 * kDeg, 0.0);
  const std::vector<Feature> prev = Seen(camera, WallSpecks());
  const std::vector<Feature> curr = Moved(camera, WallSpecks(), T_true);
  double yaw = 2.2 * kDeg;
  int pairs = 0;
  ASSERT_TRUE(AlignVehicleYaw(camera, prev, curr, kUp, /*axle_behind_camera_m=*/0.0, 0.0,
                              BridgeAlignmentOptions(), &yaw, &pairs));
  EXPECT_GT(yaw, 2.2 * kDeg + 0.2 * kDeg);  // 0.15 m of swing at 0.85 m: ~0.4° more
}

TEST(BridgeAlignmentTest, TooFewPairsIsNoMeasurement) {
  const StereoCamera camera = TestCamera();
  const Eigen::Isometry3d T_true = VehicleMotion(kUp, kAxleM, 2.2 * kDeg, 0.0);
  std::vector<Eigen::Vector3d> two = WallSpecks();
  two.resize(2);
  const std::vector<Feature> prev = Seen(camera, two);
  const std::vector<Feature> curr = Moved(camera, two, T_true);
  double yaw = 2.8 * kDeg;
  int pairs = -1;
  EXPECT_FALSE(AlignVehicleYaw(camera, prev, curr, kUp, kAxleM, 0.0, BridgeAlignmentOptions(), &yaw,
                               &pairs));
  EXPECT_EQ(yaw, 2.8 * kDeg);  // outputs unchanged
  EXPECT_EQ(pairs, -1);
  // Nothing within the gate: a prior far off (10° = 50 px) pairs nothing either.
  const std::vector<Feature> prev4 = Seen(camera, WallSpecks());
  const std::vector<Feature> curr4 = Moved(camera, WallSpecks(), T_true);
  yaw = 12.0 * kDeg;
  EXPECT_FALSE(AlignVehicleYaw(camera, prev4, curr4, kUp, kAxleM, 0.0, BridgeAlignmentOptions(),
                               &yaw, &pairs));
  double t_z = 0.123;
  EXPECT_FALSE(ForwardStepFromDepth(camera, prev4, {}, Eigen::Isometry3d::Identity(),
                                    BridgeAlignmentOptions(), &t_z, &pairs));
  EXPECT_EQ(t_z, 0.123);
}

// The top edge of a fronto-parallel end wall: every feature at one depth. The current frame's
// features are other points of the same edge (corners along a line are not repeatable), yet
// the depth change gives the forward step exactly when the prior's σ is uninformative.
TEST(BridgeAlignmentTest, ForwardStepFromTheDepthOfAWallEdge) {
  const StereoCamera camera = TestCamera();
  const double z_prev = 1.00, step = 0.03;
  std::vector<Eigen::Vector3d> prev_points, curr_points;
  for (int i = 0; i < 8; ++i) {
    prev_points.push_back({-0.40 + 0.1 * i, -0.35, z_prev});
    curr_points.push_back({-0.39 + 0.1 * i, -0.35, z_prev - step});  // 1 cm along the edge
  }
  Eigen::Isometry3d prior = Eigen::Isometry3d::Identity();
  prior.translation().z() = 0.042;  // the cruise speed the constant velocity keeps
  BridgeAlignmentOptions o;
  o.step_sigma_m = 1e6;
  double t_z = 0.0;
  int pairs = 0;
  ASSERT_TRUE(ForwardStepFromDepth(camera, Seen(camera, prev_points), Seen(camera, curr_points),
                                   prior, o, &t_z, &pairs));
  EXPECT_EQ(pairs, 8);
  EXPECT_NEAR(t_z, step, 1e-9);

  // With the default σ the prior is fused in by inverse variance: between the two, and near
  // the measurement (eight points at 1 m, σ 1.4 cm each, against the prior's 1 cm).
  const double sigma = o.disparity_sigma_px / (camera.fx_px * camera.baseline_m) *
                       std::sqrt(std::pow(z_prev, 4) + std::pow(z_prev - step, 4));
  const double sigma_prior = BridgeAlignmentOptions().step_sigma_m;
  const double expected = (0.042 / (sigma_prior * sigma_prior) + 8 * step / (sigma * sigma)) /
                          (1.0 / (sigma_prior * sigma_prior) + 8 / (sigma * sigma));
  ASSERT_TRUE(ForwardStepFromDepth(camera, Seen(camera, prev_points), Seen(camera, curr_points),
                                   prior, BridgeAlignmentOptions(), &t_z, &pairs));
  EXPECT_NEAR(t_z, expected, 1e-12);
  EXPECT_GT(t_z, step);
  EXPECT_LT(t_z, 0.5 * (step + 0.042));
}

// Far points (a long corridor, 20 m) cannot measure a step of centimetres: the prior stands.
TEST(BridgeAlignmentTest, FarPointsLeaveThePrior) {
  const StereoCamera camera = TestCamera();
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 6; ++i) points.push_back({-5.0 + 2.0 * i, -1.0, 20.0});
  Eigen::Isometry3d T_true = Eigen::Isometry3d::Identity();
  T_true.translation().z() = 0.01;  // the robot braked
  Eigen::Isometry3d prior = Eigen::Isometry3d::Identity();
  prior.translation().z() = 0.04;
  double t_z = 0.0;
  int pairs = 0;
  ASSERT_TRUE(ForwardStepFromDepth(camera, Seen(camera, points), Moved(camera, points, T_true),
                                   prior, BridgeAlignmentOptions(), &t_z, &pairs));
  EXPECT_NEAR(t_z, 0.04, 1e-4);
}

// A wrong neighbour (a floor point next to a wall point in the image) is dropped by the 3σ test
// around the median, not averaged in.
TEST(BridgeAlignmentTest, AnOutlyingPairIsDropped) {
  const StereoCamera camera = TestCamera();
  std::vector<Eigen::Vector3d> prev_points, curr_points;
  for (int i = 0; i < 5; ++i) {
    prev_points.push_back({-0.30 + 0.15 * i, 0.0, 0.90});
    curr_points.push_back({-0.30 + 0.15 * i, 0.0, 0.88});
  }
  curr_points[2].z() = 0.50;  // at the same pixel, much nearer: not the wall
  curr_points[2].x() *= 0.50 / 0.90;
  BridgeAlignmentOptions o;
  o.step_sigma_m = 1e6;
  double t_z = 0.0;
  int pairs = 0;
  ASSERT_TRUE(ForwardStepFromDepth(camera, Seen(camera, prev_points), Seen(camera, curr_points),
                                   Eigen::Isometry3d::Identity(), o, &t_z, &pairs));
  EXPECT_EQ(pairs, 4);
  EXPECT_NEAR(t_z, 0.02, 1e-9);
}

}  // namespace
}  // namespace vo
