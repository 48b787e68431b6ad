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
    gt.push_back(Pose(0.2 * i, 0, 0, 0.05 * i));
    est.push_back(offset * gt.back());
  }
  const harness::TrajectoryMetrics m = harness::ComputeTrajectoryMetrics(est, gt);
  EXPECT_EQ(m.frames, 11);
  EXPECT_NEAR(m.path_length_m, 2.0, kTol);
  EXPECT_NEAR(m.end_pose_error_m, 0.0, kTol);
  EXPECT_NEAR(m.ate_rmse_m, 0.0, 1e-6);
  EXPECT_NEAR(m.ate_rmse_unaligned_m, 0.0, kTol);
  EXPECT_NEAR(m.rpe_trans_rmse_m, 0.0, kTol);
  EXPECT_NEAR(m.drift_pct, 0.0, 1e-7);
  EXPECT_NEAR(m.kitti_drift_pct, 0.0, 1e-7);
  EXPECT_NEAR(m.kitti_drift_deg_per_m, 0.0, 1e-7);
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
  // A 0.55 m step pairs i with i + 2 (0.5 m, 0.05 m off: within evo's 10 %): error 0.05 m,
  // 7 pairs.
  m = harness::ComputeTrajectoryMetrics(est, gt, 0.55);
  EXPECT_EQ(m.rpe_distance_pairs, 7);
  EXPECT_NEAR(m.rpe_distance_trans_rmse_m, 0.05, kTol);
  // A 0.6 m step: the nearest frame is 0.1 m off (0.5 m, 0.75 m is 0.15 m off), more than
  // 10 % of 0.6 m: no pair (evo skips it too).
  m = harness::ComputeTrajectoryMetrics(est, gt, 0.6);
  EXPECT_EQ(m.rpe_distance_pairs, 0);
  // A step longer than the path: no pair, the RMSEs not applicable (NaN, with the reason).
  m = harness::ComputeTrajectoryMetrics(est, gt, 5.0);
  EXPECT_EQ(m.rpe_distance_pairs, 0);
  EXPECT_TRUE(std::isnan(m.rpe_distance_trans_rmse_m));
  EXPECT_TRUE(std::isnan(m.rpe_distance_rot_rmse_deg));
  EXPECT_NE(m.rpe_distance_reason.find("no frame pair 5.000 m"), std::string::npos)
      << m.rpe_distance_reason;
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

// evo's filters.filter_pairs_by_path(all_pairs=True), hand-run on binary-exact distances: for
// each i the j > i nearest to delta (the first on a tie), kept within 0.1 × delta.
TEST(MetricsTest, RpeDistancePairsAreEvosAllPairs) {
  const std::vector<double> dist = {0, 0.5, 0.9375, 1.0625, 1.5, 2.5};
  // i = 0: 0.9375 and 1.0625 both 0.0625 off -> the first (2). i = 1: 1.5 is exactly 1 on.
  // i = 2: the nearest, 1.5 (0.5625 on), is 0.4375 off; i = 3: 1.4375 on is 0.4375 off: none.
  // i = 4: 2.5 is exactly 1 on. The last frame starts no pair.
  const std::vector<std::pair<size_t, size_t>> expected = {{0, 2}, {1, 4}, {4, 5}};
  EXPECT_EQ(harness::RpeDistancePairs(dist, 1.0), expected);
  // The tolerance scales with delta. 2 m (0.2 m): only 1 -> 5 (exactly 2 m; from 0 the
  // nearest, 1.5 m, is 0.5 m off).
  EXPECT_EQ(harness::RpeDistancePairs(dist, 2.0), (std::vector<std::pair<size_t, size_t>>{{1, 5}}));
  // 1.5 m (0.15 m): 0 -> 4 exactly; from 1 the nearest is 0.5 m off (1.0 and 2.0 m, a tie);
  // 2 -> 5 (1.5625 m) and 3 -> 5 (1.4375 m) are 0.0625 m off.
  EXPECT_EQ(harness::RpeDistancePairs(dist, 1.5),
            (std::vector<std::pair<size_t, size_t>>{{0, 4}, {2, 5}, {3, 5}}));
}

TEST(MetricsTest, KittiSegmentLengthsScaleBelowAThousandMetres) {
  EXPECT_EQ(harness::KittiSegmentLengths(2500.0),
            (std::vector<double>{100, 200, 300, 400, 500, 600, 700, 800}));
  EXPECT_EQ(harness::KittiSegmentLengths(1000.0),
            (std::vector<double>{100, 200, 300, 400, 500, 600, 700, 800}));
  EXPECT_EQ(harness::KittiSegmentLengths(20.0), (std::vector<double>{2, 4, 6, 8, 10, 12, 14, 16}));
}

// The KITTI devkit's calcSequenceErrors, hand-run: frames 1 m apart along x (25 frames, 24 m),
// the estimate 10 % too long and rolling 0.01 rad per frame about the direction of travel
// (which leaves its positions on the x axis). Lengths 2 and 5 m: from frames 0, 10, 20 the
// first frame *past* L is 3 (L = 2) and 6 (L = 5) frames on, the error is 0.1 m per frame in
// translation and 0.01 rad per frame in rotation, divided by L (not by 3 or 6 m).
TEST(MetricsTest, KittiDriftIsTheDevkitsOnACraftedTrajectory) {
  std::vector<Eigen::Isometry3d> gt, est;
  for (int i = 0; i <= 24; ++i) {
    gt.push_back(Pose(i, 0, 0));
    Eigen::Isometry3d T = Pose(1.1 * i, 0, 0);
    T.linear() = Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitX()).toRotationMatrix();
    est.push_back(T);
  }
  harness::TrajectoryMetrics m;
  harness::KittiDrift(est, gt, {2.0, 5.0}, &m);
  // L = 2 from 0, 10, 20 (last 3, 13, 23): 0.3 / 2 each; L = 5 from 0, 10 (last 6, 16; from
  // 20 frame 26 is past the end): 0.6 / 5 each. Mean of the five.
  EXPECT_EQ(m.kitti_drift_segments, 5);
  EXPECT_NEAR(m.kitti_drift_pct, 100.0 * (3 * 0.3 / 2 + 2 * 0.6 / 5) / 5, 1e-9);
  EXPECT_NEAR(m.kitti_drift_deg_per_m, (3 * 0.03 / 2 + 2 * 0.06 / 5) / 5 * 180 / M_PI, 1e-9);
  EXPECT_TRUE(m.kitti_drift_reason.empty());
  // Lengths no segment fits: NaN with the reason.
  harness::KittiDrift(est, gt, {30.0}, &m);
  EXPECT_EQ(m.kitti_drift_segments, 0);
  EXPECT_TRUE(std::isnan(m.kitti_drift_pct));
  EXPECT_FALSE(m.kitti_drift_reason.empty());

  // Through ComputeTrajectoryMetrics: 21 frames (20 m), lengths 2, 4, ..., 16 m. From frame 0
  // every L fits (last L + 1 <= 20), from 10 those up to 8 m, from 20 none: 12 segments, each
  // 0.1 (L + 1) / L. vobench's drift divides by the actual L + 1 m instead: exactly 10 %.
  gt.resize(21);
  est.resize(21);
  m = harness::ComputeTrajectoryMetrics(est, gt);
  double sum = 0.0;
  for (double L : {2, 4, 6, 8, 10, 12, 14, 16, 2, 4, 6, 8}) sum += 0.1 * (L + 1) / L;
  EXPECT_EQ(m.kitti_drift_segments, 12);
  EXPECT_NEAR(m.kitti_drift_pct, 100.0 * sum / 12, 1e-9);
  EXPECT_NEAR(m.drift_pct, 10.0, 1e-9);
}

// A path shorter than kMinPathForRatiosM (a standing-still clip): no figures relative to the
// path length, each with its reason; the others stay.
TEST(MetricsTest, ShortPathHasNoPercentages) {
  std::vector<Eigen::Isometry3d> gt, est;
  for (int i = 0; i <= 10; ++i) {
    gt.push_back(Pose(0.05 * i, 0, 0));
    est.push_back(Pose(0.06 * i, 0, 0));
  }
  const harness::TrajectoryMetrics m = harness::ComputeTrajectoryMetrics(est, gt);
  EXPECT_NEAR(m.path_length_m, 0.5, kTol);
  EXPECT_NEAR(m.end_pose_error_m, 0.1, kTol);
  for (double v : {m.end_pose_error_pct, m.drift_pct, m.drift_deg_per_m, m.kitti_drift_pct,
                   m.kitti_drift_deg_per_m})
    EXPECT_TRUE(std::isnan(v)) << v;
  for (const std::string& why : {m.end_pose_error_pct_reason, m.drift_reason, m.kitti_drift_reason})
    EXPECT_EQ(why,
              "ground-truth path 0.500 m shorter than 1.000 m: no figures relative to the path "
              "length");
  // Standing still: the same.
  const std::vector<Eigen::Isometry3d> still(5, Pose(1, 2, 3));
  const harness::TrajectoryMetrics s = harness::ComputeTrajectoryMetrics(still, still);
  EXPECT_TRUE(std::isnan(s.end_pose_error_pct));
  EXPECT_TRUE(std::isnan(s.drift_pct));
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
