#include "vo/schur_lm.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/ransac.h"  // vo::SplitMix64

namespace vo {
namespace {

// Central differences of a smooth function with O(h²) error: h = 1e-6 leaves ~1e-9 relative.
constexpr double kNumericStep = 1e-6;
constexpr double kJacobianRelTol = 1e-6;  // relative to the largest entry of the Jacobian

using test::TestCamera;

using test::Normal;

using vobench_test::IsNearPose;

Eigen::Isometry3d FromBlock(const PoseBlock7& b) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(b[3], b[0], b[1], b[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(b[4], b[5], b[6]);
  return T;
}

PoseBlock7 ToBlock(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  return {
      q.x(), q.y(), q.z(), q.w(), T.translation().x(), T.translation().y(), T.translation().z()};
}

// The pose block moved by the tangent δ = [δθ δt] as ceres::EigenQuaternionManifold ×
// EuclideanManifold<3> does: q ← [cos|δθ|, sin|δθ| δθ/|δθ|] ⊗ q, t ← t + δt.
PoseBlock7 Plus(const PoseBlock7& x, const Eigen::Matrix<double, 6, 1>& delta) {
  const Eigen::Vector3d d = delta.head<3>();
  const double n = d.norm();
  Eigen::Quaterniond dq = Eigen::Quaterniond::Identity();
  if (n > 0.0) {
    const Eigen::Vector3d v = std::sin(n) / n * d;
    dq = Eigen::Quaterniond(std::cos(n), v.x(), v.y(), v.z());
  }
  const Eigen::Quaterniond q = dq * Eigen::Quaterniond(x[3], x[0], x[1], x[2]);
  return {q.x(), q.y(), q.z(), q.w(), x[4] + delta[3], x[5] + delta[4], x[6] + delta[5]};
}

Eigen::Vector4d Residual(const StereoCamera& cam, const PoseBlock7& pose,
                         const Eigen::Vector3d& p_world, const SchurLmResidual& obs) {
  const Eigen::Matrix3d R_cam0_world =
      Eigen::Quaterniond(pose[3], pose[0], pose[1], pose[2]).toRotationMatrix().transpose();
  Eigen::Vector4d r;
  EXPECT_TRUE(StereoResidualAndJacobians(cam, R_cam0_world,
                                         Eigen::Vector3d(pose[4], pose[5], pose[6]), p_world, obs,
                                         &r, nullptr, nullptr));
  return r;
}

// Property test over random poses and points: the analytic Jacobians against central
// differences through the manifold's Plus, for stereo and left-only observations.
TEST(SchurLmTest, JacobiansMatchNumericDifferentiationThroughTheManifold) {
  const StereoCamera cam = TestCamera();
  SplitMix64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
    T_world_cam0.linear() =
        Eigen::AngleAxisd(0.5 * rng.Uniform(),
                          Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng)).normalized())
            .toRotationMatrix();
    T_world_cam0.translation() = Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
    const Eigen::Vector3d p_cam0(2.0 * rng.Uniform() - 1.0, 2.0 * rng.Uniform() - 1.0,
                                 1.0 + 9.0 * rng.Uniform());
    const Eigen::Vector3d p_world = T_world_cam0 * p_cam0;
    SchurLmResidual obs;
    obs.uv_left_px = Eigen::Vector2d(100.0 * rng.Uniform(), 100.0 * rng.Uniform());
    obs.has_right = trial % 3 != 0;
    obs.uv_right_px = obs.uv_left_px - Eigen::Vector2d(10.0 * rng.Uniform(), 0.0);
    const PoseBlock7 pose = ToBlock(T_world_cam0);

    Eigen::Vector4d r;
    Eigen::Matrix<double, 4, 6> J_pose;
    Eigen::Matrix<double, 4, 3> J_point;
    ASSERT_TRUE(StereoResidualAndJacobians(cam, T_world_cam0.linear().transpose(),
                                           T_world_cam0.translation(), p_world, obs, &r, &J_pose,
                                           &J_point));
    EXPECT_LT((r - Residual(cam, pose, p_world, obs)).norm(), 1e-9);
    Eigen::Matrix<double, 4, 6> N_pose;
    for (int c = 0; c < 6; ++c) {
      Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
      d[c] = kNumericStep;
      N_pose.col(c) = (Residual(cam, Plus(pose, d), p_world, obs) -
                       Residual(cam, Plus(pose, -d), p_world, obs)) /
                      (2.0 * kNumericStep);
    }
    Eigen::Matrix<double, 4, 3> N_point;
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d d = kNumericStep * Eigen::Vector3d::Unit(c);
      N_point.col(c) =
          (Residual(cam, pose, p_world + d, obs) - Residual(cam, pose, p_world - d, obs)) /
          (2.0 * kNumericStep);
    }
    EXPECT_LT((J_pose - N_pose).cwiseAbs().maxCoeff(),
              kJacobianRelTol * J_pose.cwiseAbs().maxCoeff())
        << "trial " << trial << "\n"
        << J_pose << "\n"
        << N_pose;
    EXPECT_LT((J_point - N_point).cwiseAbs().maxCoeff(),
              kJacobianRelTol * J_point.cwiseAbs().maxCoeff())
        << "trial " << trial;
    if (!obs.has_right) {
      EXPECT_EQ(r.tail<2>(), Eigen::Vector2d::Zero());
      EXPECT_TRUE(J_pose.bottomRows<2>().isZero(0.0));
      EXPECT_TRUE(J_point.bottomRows<2>().isZero(0.0));
    }
  }
}

TEST(SchurLmTest, BehindTheCameraHasNoResidual) {
  SchurLmResidual obs;
  Eigen::Vector4d r;
  EXPECT_FALSE(StereoResidualAndJacobians(TestCamera(), Eigen::Matrix3d::Identity(),
                                          Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, -1), obs,
                                          &r, nullptr, nullptr));
}

struct Problem {
  std::vector<PoseBlock7> poses;  // start
  std::vector<PoseBlock7> true_poses;
  std::vector<Eigen::Vector3d> points;  // start
  std::vector<Eigen::Vector3d> true_points;
  std::vector<SchurLmResidual> residuals;
};

// 4 frames moving forward, 60 points seen in every frame (exact stereo observations), a start
// off by ~1° and 3 cm per pose and 5 cm per point. Pose 4 and point 60 are referred to by no
// residual.
Problem MakeProblem(uint64_t seed) {
  const StereoCamera cam = TestCamera();
  SplitMix64 rng(seed);
  Problem p;
  std::vector<Eigen::Isometry3d> T(5, Eigen::Isometry3d::Identity());
  for (int i = 0; i < 5; ++i) {
    T[i].linear() = Eigen::AngleAxisd(0.03 * i, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T[i].translation() = Eigen::Vector3d(0.02 * i, 0.0, 0.2 * i);
    p.true_poses.push_back(ToBlock(T[i]));
  }
  for (int j = 0; j <= 60; ++j) {
    const Eigen::Vector3d x(4.0 * rng.Uniform() - 2.0, 2.0 * rng.Uniform() - 1.0,
                            3.0 + 6.0 * rng.Uniform());
    p.true_points.push_back(x);
    if (j == 60) break;
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d p_cam0 = T[i].inverse() * x;
      SchurLmResidual o;
      o.pose = i;
      o.point = j;
      cam.ProjectLeft(p_cam0, &o.uv_left_px);
      o.has_right = (i + j) % 4 != 0;
      cam.ProjectRight(p_cam0, &o.uv_right_px);
      p.residuals.push_back(o);
    }
  }
  p.poses = p.true_poses;
  for (int i = 1; i < 5; ++i) {
    Eigen::Matrix<double, 6, 1> d;
    d << 0.01 * Normal(&rng), 0.01 * Normal(&rng), 0.01 * Normal(&rng), 0.03 * Normal(&rng),
        0.03 * Normal(&rng), 0.03 * Normal(&rng);
    p.poses[i] = Plus(p.poses[i], d);
  }
  p.points = p.true_points;
  for (Eigen::Vector3d& x : p.points)
    x += 0.05 * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
  return p;
}

BundleAdjustmentOptions TightOptions() {
  BundleAdjustmentOptions options;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  return options;
}

TEST(SchurLmTest, ReachesTheExactSolutionAndLeavesTheRestAlone) {
  Problem p = MakeProblem(1);
  const std::vector<bool> free = {false, true, true, true, true};
  std::vector<PoseBlock7> poses = p.poses;
  std::vector<Eigen::Vector3d> points = p.points;
  const SchurLmSummary s =
      SolveSchurLm(TestCamera(), TightOptions(), p.residuals, free, &poses, &points);
  ASSERT_TRUE(s.usable()) << s.message;
  EXPECT_EQ(s.termination, SchurLmSummary::Termination::kConvergence) << s.message;
  EXPECT_GT(s.initial_cost, 1.0);
  EXPECT_LT(s.final_cost, 1e-16);
  EXPECT_GT(s.num_successful_steps, 1);
  EXPECT_EQ(poses[0], p.poses[0]);      // constant
  EXPECT_EQ(poses[4], p.poses[4]);      // free, but no residual refers to it
  EXPECT_EQ(points[60], p.points[60]);  // no residual refers to it
  for (int i = 1; i < 4; ++i)
    EXPECT_THAT(FromBlock(poses[i]), IsNearPose(FromBlock(p.true_poses[i]), 1e-8, 1e-8)) << i;
  for (int j = 0; j < 60; ++j) EXPECT_LT((points[j] - p.true_points[j]).norm(), 1e-7) << j;
}

TEST(SchurLmTest, PointsOnlyWhenEveryPoseIsConstant) {
  Problem p = MakeProblem(2);
  p.poses = p.true_poses;
  std::vector<Eigen::Vector3d> points = p.points;
  const SchurLmSummary s = SolveSchurLm(TestCamera(), TightOptions(), p.residuals,
                                        std::vector<bool>(5, false), &p.poses, &points);
  ASSERT_TRUE(s.usable()) << s.message;
  EXPECT_EQ(p.poses, p.true_poses);
  for (int j = 0; j < 60; ++j) EXPECT_LT((points[j] - p.true_points[j]).norm(), 1e-7) << j;
}

TEST(SchurLmTest, DeterministicBitForBit) {
  const Problem p = MakeProblem(3);
  const std::vector<bool> free = {false, true, true, true, true};
  std::vector<PoseBlock7> poses_a = p.poses, poses_b = p.poses;
  std::vector<Eigen::Vector3d> points_a = p.points, points_b = p.points;
  const BundleAdjustmentOptions options;
  const SchurLmSummary a =
      SolveSchurLm(TestCamera(), options, p.residuals, free, &poses_a, &points_a);
  const SchurLmSummary b =
      SolveSchurLm(TestCamera(), options, p.residuals, free, &poses_b, &points_b);
  EXPECT_EQ(a.final_cost, b.final_cost);
  EXPECT_EQ(a.num_successful_steps, b.num_successful_steps);
  EXPECT_EQ(poses_a, poses_b);
  EXPECT_EQ(points_a, points_b);
}

TEST(SchurLmTest, IterationLimitIsNoConvergence) {
  Problem p = MakeProblem(4);
  BundleAdjustmentOptions options = TightOptions();
  options.max_num_iterations = 1;
  const SchurLmSummary s = SolveSchurLm(TestCamera(), options, p.residuals,
                                        {false, true, true, true, true}, &p.poses, &p.points);
  EXPECT_EQ(s.termination, SchurLmSummary::Termination::kNoConvergence);
  EXPECT_TRUE(s.usable());
  EXPECT_EQ(s.num_successful_steps + s.num_unsuccessful_steps, 2);  // the start + one step
  EXPECT_LT(s.final_cost, s.initial_cost);
}

TEST(SchurLmTest, StartBehindTheCameraFails) {
  Problem p = MakeProblem(5);
  p.points[0] = Eigen::Vector3d(0.0, 0.0, -5.0);
  const SchurLmSummary s = SolveSchurLm(TestCamera(), BundleAdjustmentOptions(), p.residuals,
                                        {false, true, true, true, true}, &p.poses, &p.points);
  EXPECT_EQ(s.termination, SchurLmSummary::Termination::kFailure);
  EXPECT_FALSE(s.usable());
  EXPECT_THAT(s.message, ::testing::HasSubstr("evaluation failed"));
}

}  // namespace
}  // namespace vo
