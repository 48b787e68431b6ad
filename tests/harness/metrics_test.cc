// Trajectory metrics on hand-computed cases.
#include "harness/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

constexpr double kTol = 1e-9;

Eigen::Isometry3d Pose(double x, double y, double z, double yaw_rad = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

TEST(MetricsTest, PerfectEstimateHasZeroErrorsInAnyWorldFrame) {
  std::vector<Eigen::Isometry3d> gt, est;
  const Eigen::Isometry3d offset = Pose(5, -2, 1, 0.7);  // the VO's world differs
  for (int i = 0; i <= 10; ++i) {
    gt.push_back(Pose(0.1 * i, 0, 0, 0.05 * i));
    est.push_back(offset * gt.back());
  }
  const harness::TrajectoryMetrics m = harness::ComputeTrajectoryMetrics(est, gt);
  EXPECT_EQ(m.frames, 11);
  EXPECT_NEAR(m.path_length_m, 1.0, kTol);
  EXPECT_NEAR(m.end_pose_error_m, 0.0, kTol);
  EXPECT_NEAR(m.ate_rmse_m, 0.0, 1e-6);
  EXPECT_NEAR(m.ate_rmse_unaligned_m, 0.0, kTol);
  EXPECT_NEAR(m.rpe_trans_rmse_m, 0.0, kTol);
  EXPECT_NEAR(m.drift_pct, 0.0, 1e-7);
}

TEST(MetricsTest, HandComputedStraightLine) {
  // Ground truth: 0, 1, 2, 3, 4 m along x. Estimate: 10 % too long (scale error).
  std::vector<Eigen::Isometry3d> gt, est;
  for (int i = 0; i <= 4; ++i) {
    gt.push_back(Pose(i, 0, 0));
    est.push_back(Pose(1.1 * i, 0, 0));
  }
  const harness::TrajectoryMetrics m = harness::ComputeTrajectoryMetrics(est, gt);
  EXPECT_NEAR(m.path_length_m, 4.0, kTol);
  EXPECT_NEAR(m.end_pose_error_m, 0.4, kTol);
  EXPECT_NEAR(m.end_pose_error_pct, 10.0, kTol);
  // Unaligned: errors 0, .1, .2, .3, .4 -> sqrt(0.3/5).
  EXPECT_NEAR(m.ate_rmse_unaligned_m, std::sqrt(0.30 / 5.0), kTol);
  // Aligned (rigid, no scale): shifting by the mean error -0.2 leaves -.2 -.1 0 .1 .2.
  EXPECT_NEAR(m.ate_rmse_m, std::sqrt(0.10 / 5.0), 1e-9);
  // RPE per frame: every step 0.1 m too long.
  EXPECT_NEAR(m.rpe_trans_rmse_m, 0.1, kTol);
  // Drift: every sub-path is 10 % too long.
  EXPECT_NEAR(m.drift_pct, 10.0, 1e-9);
  EXPECT_NEAR(m.drift_deg_per_m, 0.0, kTol);
}

TEST(MetricsTest, RpeOverADistanceStep) {
  // Ground truth every 0.25 m along x; the estimate's steps are 10 % too long. With a 1 m
  // step, frame i pairs with i + 4 (exactly 1 m further): error 0.1 m for each of the
  // 9 - 4 = 5 pairs of the 9 frames, no rotation.
  std::vector<Eigen::Isometry3d> gt, est;
  for (int i = 0; i <= 8; ++i) {
    gt.push_back(Pose(0.25 * i, 0, 0));
    est.push_back(Pose(0.275 * i, 0, 0));
  }
  harness::TrajectoryMetrics m = harness::ComputeTrajectoryMetrics(est, gt, 1.0);
  EXPECT_EQ(m.rpe_distance_pairs, 5);
  EXPECT_NEAR(m.rpe_distance_step_m, 1.0, kTol);
  EXPECT_NEAR(m.rpe_distance_trans_rmse_m, 0.1, kTol);
  EXPECT_NEAR(m.rpe_distance_rot_rmse_deg, 0.0, kTol);
  // A 0.6 m step pairs i with i + 3 (0.75 m): error 0.075 m, 6 pairs.
  m = harness::ComputeTrajectoryMetrics(est, gt, 0.6);
  EXPECT_EQ(m.rpe_distance_pairs, 6);
  EXPECT_NEAR(m.rpe_distance_trans_rmse_m, 0.075, kTol);
  // A step longer than the path: no pair, zeros.
  m = harness::ComputeTrajectoryMetrics(est, gt, 5.0);
  EXPECT_EQ(m.rpe_distance_pairs, 0);
  EXPECT_EQ(m.rpe_distance_trans_rmse_m, 0.0);
  // Rotation: a constant yaw-rate error of 0.01 rad per frame over 4 frames -> 0.04 rad.
  gt.clear();
  est.clear();
  for (int i = 0; i <= 8; ++i) {
    gt.push_back(Pose(0.25 * i, 0, 0));
    est.push_back(Pose(0.25 * i, 0, 0, 0.01 * i));
  }
  m = harness::ComputeTrajectoryMetrics(est, gt, 1.0);
  EXPECT_NEAR(m.rpe_distance_rot_rmse_deg, 0.04 * 180 / M_PI, 1e-9);
}

TEST(MetricsTest, EndRotationError) {
  std::vector<Eigen::Isometry3d> gt = {Pose(0, 0, 0), Pose(1, 0, 0, M_PI / 2)};
  std::vector<Eigen::Isometry3d> est = {Pose(0, 0, 0), Pose(1, 0, 0, M_PI / 2 + 0.1)};
  const harness::TrajectoryMetrics m = harness::ComputeTrajectoryMetrics(est, gt);
  EXPECT_NEAR(m.end_rotation_error_deg, 0.1 * 180 / M_PI, 1e-9);
  EXPECT_NEAR(m.rpe_rot_rmse_deg, 0.1 * 180 / M_PI, 1e-9);
}

TEST(MetricsTest, MedianAndPercentile) {
  EXPECT_DOUBLE_EQ(harness::Median({3, 1, 2}), 2);
  EXPECT_DOUBLE_EQ(harness::Percentile({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 95), 10);
  EXPECT_DOUBLE_EQ(harness::Percentile({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 50), 5);
  EXPECT_DOUBLE_EQ(harness::Median({}), 0);
}

TEST(MetricsTest, RotationAngleIsPreciseNearZero) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1e-10, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_NEAR(harness::RotationAngle(Eigen::Matrix3d::Identity(), R), 1e-10, 1e-15);
}

}  // namespace
