#include "vo/horn.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/ransac.h"  // vo::SplitMix64

namespace vo {
namespace {

using vobench_test::IsNearPose;

// Pose-level tolerances for IsNearPose: its angle comes from acos of a trace, which cannot
// resolve angles below ~2e-8 rad (acos(1 − ε) with ε one ulp of 1), hence 1e-7 rad; the
// rotation matrices themselves are compared with the tighter k*MatrixTol below.
constexpr double kExactTolRad = 1e-7;
constexpr double kExactTolM = 1e-10;
// Noise-free data: the closed form is exact up to rounding of a 4×4 eigen decomposition on
// coordinates of a few metres.
constexpr double kExactMatrixTol = 1e-12;
// Noisy data: Horn and Umeyama solve the same least-squares problem by different
// factorisations (eigen of M vs SVD of the cross-covariance); they agree to rounding, a bit
// looser than the exact case because the problem is less well conditioned.
constexpr double kSameSolutionTolRad = 1e-7;
constexpr double kSameSolutionTolM = 1e-9;
constexpr double kSameSolutionMatrixTol = 1e-10;
constexpr int kNumSeeds = 200;

using test::Normal;

Eigen::Isometry3d RandomPose(SplitMix64* rng) {
  Eigen::Quaterniond q(Normal(rng), Normal(rng), Normal(rng), Normal(rng));
  q.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = Eigen::Vector3d(Normal(rng), Normal(rng), Normal(rng)) * 2.0;
  return T;
}

Eigen::Matrix3Xd RandomPoints(SplitMix64* rng, int n) {
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i)
    p.col(i) = Eigen::Vector3d(4.0 * rng->Uniform() - 2.0, 4.0 * rng->Uniform() - 2.0,
                               1.0 + 8.0 * rng->Uniform());
  return p;
}

// Frobenius norm of the difference of the rotation parts.
double RotationDiff(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.linear() - b.linear()).norm();
}

Eigen::Isometry3d Umeyama(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst) {
  const Eigen::Matrix4d T = Eigen::umeyama(src, dst, false);
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = T.topLeftCorner<3, 3>();
  iso.translation() = T.topRightCorner<3, 1>();
  return iso;
}

TEST(HornTest, RotationFromQuaternionEq7MatchesEigen) {
  SplitMix64 rng(7);
  constexpr double kTol = 1e-14;  // same polynomial, different evaluation order
  for (int k = 0; k < 100; ++k) {
    Eigen::Quaterniond q(Normal(&rng), Normal(&rng), Normal(&rng), Normal(&rng));
    q.normalize();
    const Eigen::Matrix3d R =
        RotationFromQuaternionEq7(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
    EXPECT_TRUE(R.isApprox(q.toRotationMatrix(), kTol)) << R << "\n" << q.toRotationMatrix();
  }
}

// Property test: exact recovery and agreement with Eigen::umeyama on noise-free data.
TEST(HornTest, NoiseFreeEqualsUmeyamaAndGroundTruthOverManySeeds) {
  for (int seed = 0; seed < kNumSeeds; ++seed) {
    SplitMix64 rng(seed);
    const Eigen::Isometry3d T_dst_src = RandomPose(&rng);
    const int n = 3 + static_cast<int>(rng.UniformIndex(60));
    const Eigen::Matrix3Xd src = RandomPoints(&rng, n);
    const Eigen::Matrix3Xd dst = T_dst_src * src;
    const HornResult r = EstimateRigidMotionHorn(src, dst);
    ASSERT_TRUE(r.ok()) << "seed " << seed << ": " << r.message;
    EXPECT_EQ(r.num_points, n);
    EXPECT_THAT(r.T_dst_src, IsNearPose(T_dst_src, kExactTolRad, kExactTolM)) << "seed " << seed;
    EXPECT_THAT(r.T_dst_src, IsNearPose(Umeyama(src, dst), kExactTolRad, kExactTolM))
        << "seed " << seed;
    EXPECT_LT(RotationDiff(r.T_dst_src, T_dst_src), kExactMatrixTol) << "seed " << seed;
    EXPECT_LT(RotationDiff(r.T_dst_src, Umeyama(src, dst)), kExactMatrixTol) << "seed " << seed;
    EXPECT_LT(r.rms_residual_m, kExactTolM);
    EXPECT_NEAR(r.q_wxyz.norm(), 1.0, 1e-12);
    EXPECT_GE(r.q_wxyz[0], 0.0);
  }
}

// With noise, both are the least-squares estimate: they agree with each other, and the rms
// residual is the noise level.
TEST(HornTest, NoisyEqualsUmeyamaOverManySeeds) {
  constexpr double kSigmaM = 0.02;
  for (int seed = 0; seed < kNumSeeds; ++seed) {
    SplitMix64 rng(1000 + seed);
    const Eigen::Isometry3d T_dst_src = RandomPose(&rng);
    const int n = 10 + static_cast<int>(rng.UniformIndex(100));
    const Eigen::Matrix3Xd src = RandomPoints(&rng, n);
    Eigen::Matrix3Xd dst = T_dst_src * src;
    for (int i = 0; i < n; ++i)
      dst.col(i) += kSigmaM * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
    const HornResult r = EstimateRigidMotionHorn(src, dst);
    ASSERT_TRUE(r.ok()) << "seed " << seed << ": " << r.message;
    EXPECT_THAT(r.T_dst_src, IsNearPose(Umeyama(src, dst), kSameSolutionTolRad, kSameSolutionTolM))
        << "seed " << seed;
    EXPECT_LT(RotationDiff(r.T_dst_src, Umeyama(src, dst)), kSameSolutionMatrixTol)
        << "seed " << seed;
    // Least squares: no other rigid motion has a smaller residual, in particular not the truth.
    const double rms_truth = std::sqrt((dst - T_dst_src * src).squaredNorm() / n);
    EXPECT_LE(r.rms_residual_m, rms_truth + 1e-12) << "seed " << seed;
  }
}

TEST(HornTest, HalfTurnRotationHasZeroScalarPart) {
  // q0 = 0: the case where a sign choice on q0 could go wrong.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.3, -1.0, 2.0);
  SplitMix64 rng(3);
  const Eigen::Matrix3Xd src = RandomPoints(&rng, 20);
  const HornResult r = EstimateRigidMotionHorn(src, T * src);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_THAT(r.T_dst_src, IsNearPose(T, kExactTolRad, kExactTolM));
}

TEST(HornTest, IntegerWeightsEqualDuplicatedPoints) {
  SplitMix64 rng(11);
  constexpr int kN = 15;
  constexpr double kSigmaM = 0.05;
  const Eigen::Isometry3d T_dst_src = RandomPose(&rng);
  const Eigen::Matrix3Xd src = RandomPoints(&rng, kN);
  Eigen::Matrix3Xd dst = T_dst_src * src;
  for (int i = 0; i < kN; ++i)
    dst.col(i) += kSigmaM * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
  Eigen::VectorXd w(kN);
  int total = 0;
  for (int i = 0; i < kN; ++i)
    total += static_cast<int>(w[i] = 1 + static_cast<int>(rng.UniformIndex(3)));
  Eigen::Matrix3Xd src_dup(3, total), dst_dup(3, total);
  for (int i = 0, c = 0; i < kN; ++i)
    for (int k = 0; k < static_cast<int>(w[i]); ++k, ++c) {
      src_dup.col(c) = src.col(i);
      dst_dup.col(c) = dst.col(i);
    }
  const HornResult weighted = EstimateRigidMotionHorn(src, dst, w);
  const HornResult dup = EstimateRigidMotionHorn(src_dup, dst_dup);
  ASSERT_TRUE(weighted.ok() && dup.ok());
  EXPECT_THAT(weighted.T_dst_src,
              IsNearPose(dup.T_dst_src, kSameSolutionTolRad, kSameSolutionTolM));
  EXPECT_NEAR(weighted.rms_residual_m, dup.rms_residual_m, 1e-12);
}

TEST(HornTest, ZeroWeightIgnoresAnOutlier) {
  SplitMix64 rng(12);
  const Eigen::Isometry3d T_dst_src = RandomPose(&rng);
  const Eigen::Matrix3Xd src = RandomPoints(&rng, 10);
  Eigen::Matrix3Xd dst = T_dst_src * src;
  dst.col(4) += Eigen::Vector3d(5.0, -3.0, 2.0);  // gross outlier
  Eigen::VectorXd w = Eigen::VectorXd::Ones(10);
  w[4] = 0.0;
  const HornResult r = EstimateRigidMotionHorn(src, dst, w);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.num_points, 9);
  EXPECT_THAT(r.T_dst_src, IsNearPose(T_dst_src, kExactTolRad, kExactTolM));
}

TEST(HornTest, TwoPointsAreTooFew) {
  Eigen::Matrix3Xd src(3, 2);
  src << 0, 1, 0, 0, 1, 2;
  const HornResult r = EstimateRigidMotionHorn(src, src);
  EXPECT_EQ(r.status, HornResult::Status::kTooFewPoints);
  EXPECT_FALSE(r.message.empty());
}

TEST(HornTest, ThreePointsWithOneZeroWeightAreTooFew) {
  Eigen::Matrix3Xd src(3, 3);
  src << 0, 1, 0, 0, 0, 1, 1, 1, 1;
  const HornResult r = EstimateRigidMotionHorn(src, src, Eigen::Vector3d(1.0, 1.0, 0.0));
  EXPECT_EQ(r.status, HornResult::Status::kTooFewPoints);
}

TEST(HornTest, CollinearPointsAreDegenerate) {
  Eigen::Matrix3Xd src(3, 6);
  const Eigen::Vector3d p0(0.5, -0.2, 3.0), dir(0.3, 0.1, 0.9);
  for (int i = 0; i < 6; ++i) src.col(i) = p0 + 0.7 * i * dir;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const HornResult r = EstimateRigidMotionHorn(src, T * src);
  EXPECT_EQ(r.status, HornResult::Status::kDegenerate);
  EXPECT_THAT(r.message, ::testing::HasSubstr("collinear"));
}

TEST(HornTest, NearlyCollinearBelowToleranceIsDegenerate) {
  // Middle point lifted off the line by h: σ₂/σ₁ ≈ 0.58 h for these three points.
  auto points = [](double h) {
    Eigen::Matrix3Xd src(3, 3);
    src << 0.0, 1.0, 2.0,  //
        0.0, h, 0.0,       //
        2.0, 2.0, 2.0;
    return src;
  };
  EXPECT_EQ(EstimateRigidMotionHorn(points(1e-9), points(1e-9)).status,
            HornResult::Status::kDegenerate);                             // 6e-10 < default 1e-6
  EXPECT_TRUE(EstimateRigidMotionHorn(points(1e-4), points(1e-4)).ok());  // 6e-5 > 1e-6
  HornOptions loose;
  loose.collinear_tolerance = 1e-3;  // RANSAC's setting for minimal samples
  EXPECT_EQ(EstimateRigidMotionHorn(points(1e-4), points(1e-4), loose).status,
            HornResult::Status::kDegenerate);
}

TEST(HornTest, CoincidentPointsAreDegenerate) {
  const Eigen::Matrix3Xd src = Eigen::Vector3d(1.0, 2.0, 3.0).replicate(1, 5);
  const HornResult r = EstimateRigidMotionHorn(src, src);
  EXPECT_EQ(r.status, HornResult::Status::kDegenerate);
  EXPECT_THAT(r.message, ::testing::HasSubstr("coincide"));
}

TEST(HornTest, TwoDistinctPositionsAmongThreeAreDegenerate) {
  Eigen::Matrix3Xd src(3, 3);
  src << 0, 0, 1, 0, 0, 1, 1, 1, 2;  // points 0 and 1 coincide: the set is a line
  EXPECT_EQ(EstimateRigidMotionHorn(src, src).status, HornResult::Status::kDegenerate);
}

TEST(HornTest, CollinearTargetIsDegenerate) {
  SplitMix64 rng(5);
  const Eigen::Matrix3Xd src = RandomPoints(&rng, 5);
  Eigen::Matrix3Xd dst(3, 5);
  for (int i = 0; i < 5; ++i) dst.col(i) = Eigen::Vector3d(i, 2.0 * i, 1.0);
  EXPECT_EQ(EstimateRigidMotionHorn(src, dst).status, HornResult::Status::kDegenerate);
}

TEST(HornTest, InvalidInputs) {
  SplitMix64 rng(6);
  const Eigen::Matrix3Xd a = RandomPoints(&rng, 5);
  const Eigen::Matrix3Xd b = RandomPoints(&rng, 4);
  EXPECT_EQ(EstimateRigidMotionHorn(a, b).status, HornResult::Status::kInvalidInput);
  Eigen::Matrix3Xd nan = a;
  nan(1, 2) = std::nan("");
  EXPECT_EQ(EstimateRigidMotionHorn(a, nan).status, HornResult::Status::kInvalidInput);
  Eigen::VectorXd w = Eigen::VectorXd::Ones(5);
  w[0] = -1.0;
  EXPECT_EQ(EstimateRigidMotionHorn(a, a, w).status, HornResult::Status::kInvalidInput);
  HornOptions bad;
  bad.collinear_tolerance = 1.5;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("collinear_tolerance"));
  EXPECT_EQ(EstimateRigidMotionHorn(a, a, bad).status, HornResult::Status::kInvalidInput);
}

}  // namespace
}  // namespace vo
