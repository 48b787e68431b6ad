// Tests of the windowed bundle adjustment's relative-rotation prior (a gyro's; rotation_prior.h,
// BundleAdjustmentProblem::rotation_priors) and of the back end's gyro chain that makes them
// (BackEnd::AddGyroRotation): the residual's value, the two backends agreeing to rounding with
// priors, a window whose rotation the points hardly determine (one small plane, noisy pixels)
// held to the truth by exact priors, empty or skipped priors leaving the result bit for bit
// what it is without them, bad priors refused, and the chain over lost frames and its breaks.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/ba_test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/back_end.h"
#include "vo/bundle_adjustment.h"
#include "vo/ransac.h"  // vo::SplitMix64
#include "vo/rotation_prior.h"

namespace vo {
namespace {

using test::Normal;
using test::TestCamera;
using vobench_test::IsNearPose;

// The two backends agree to rounding: test::ExpectSameSolution (tests/vo/ba_test_util.h).
using test::ExpectSameSolution;

Eigen::Matrix3d RotY(double deg) {
  return Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

double AngleRad(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

// The relative rotation R_a_b of two poses.
Eigen::Matrix3d Relative(const Eigen::Isometry3d& T_world_a, const Eigen::Isometry3d& T_world_b) {
  return T_world_a.linear().transpose() * T_world_b.linear();
}

struct Scene {
  BundleAdjustmentProblem truth;  // true poses and points, the noisy observations
  BundleAdjustmentProblem start;  // perturbed poses (all but the first) and points
};

// `num_frames` poses turning about y by `yaw_deg` each and moving `step_m` sideways; points
// at depth `depth_m` ± `depth_spread_m` within ±half_width_m of the first camera's axis,
// observed in stereo with σ `sigma_px`; the start poses' rotations `perturb_rad` off about a
// random axis, their translations 2 cm, the points 5 cm.
Scene MakeScene(uint64_t seed, int num_frames, int num_points, double yaw_deg, double step_m,
                double depth_m, double depth_spread_m, double half_width_m, double sigma_px,
                double perturb_rad) {
  const StereoCamera cam = TestCamera();
  SplitMix64 rng(seed);
  Scene s;
  for (int i = 0; i < num_frames; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = RotY(yaw_deg * i);
    T.translation() = Eigen::Vector3d(step_m * i, 0.0, 0.02 * i);
    s.truth.T_world_cam0.push_back(T);
  }
  int tries = 0;
  while (static_cast<int>(s.truth.points_world.size()) < num_points && ++tries < 100000) {
    const Eigen::Vector3d p(half_width_m * (2.0 * rng.Uniform() - 1.0),
                            half_width_m * (2.0 * rng.Uniform() - 1.0),
                            depth_m + depth_spread_m * (2.0 * rng.Uniform() - 1.0));
    const std::vector<BaObservation> obs = test::NoisyStereoObservations(
        cam, s.truth.T_world_cam0, p, static_cast<int>(s.truth.points_world.size()), sigma_px,
        false, &rng);
    if (obs.size() < 2) continue;
    s.truth.points_world.push_back(p);
    s.truth.observations.insert(s.truth.observations.end(), obs.begin(), obs.end());
  }
  s.start = s.truth;
  for (int i = 1; i < num_frames; ++i) {
    Eigen::Isometry3d& T = s.start.T_world_cam0[i];
    const Eigen::Vector3d axis(Normal(&rng), Normal(&rng), Normal(&rng));
    T.linear() = (Eigen::AngleAxisd(perturb_rad, axis.normalized()) * T.linear()).eval();
    T.translation() += 0.02 * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
  }
  for (Eigen::Vector3d& p : s.start.points_world)
    p += 0.05 * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
  return s;
}

// Priors between consecutive poses: the true relative rotation turned by `error_rad` about a
// random axis, σ sigma_rad.
std::vector<RotationPrior> ConsecutivePriors(const BundleAdjustmentProblem& truth, double error_rad,
                                             double sigma_rad, uint64_t seed) {
  SplitMix64 rng(seed);
  std::vector<RotationPrior> priors;
  for (size_t i = 1; i < truth.T_world_cam0.size(); ++i) {
    RotationPrior p;
    p.frame_a = static_cast<int>(i - 1);
    p.frame_b = static_cast<int>(i);
    const Eigen::Vector3d axis(Normal(&rng), Normal(&rng), Normal(&rng));
    p.R_a_b = Eigen::AngleAxisd(error_rad, axis.normalized()).toRotationMatrix() *
              Relative(truth.T_world_cam0[i - 1], truth.T_world_cam0[i]);
    p.sigma_rad = sigma_rad;
    priors.push_back(p);
  }
  return priors;
}

BundleAdjustmentSummary Solve(const BundleAdjustmentProblem& p, BundleAdjustmentOptions options,
                              BaSolver solver) {
  options.solver = solver;
  return RunBundleAdjustment(TestCamera(), p, options);
}

// Bit for bit the same result.
void ExpectIdentical(const BundleAdjustmentSummary& a, const BundleAdjustmentSummary& b) {
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.initial_cost, b.initial_cost);
  EXPECT_EQ(a.final_cost, b.final_cost);
  EXPECT_EQ(a.num_iterations, b.num_iterations);
  EXPECT_EQ(a.converged, b.converged);
  EXPECT_EQ(a.rms_reprojection_after_px, b.rms_reprojection_after_px);
  EXPECT_EQ(a.observation_is_outlier, b.observation_is_outlier);
  ASSERT_EQ(a.T_world_cam0.size(), b.T_world_cam0.size());
  for (size_t i = 0; i < a.T_world_cam0.size(); ++i)
    EXPECT_TRUE(a.T_world_cam0[i].matrix() == b.T_world_cam0[i].matrix()) << "frame " << i;
  ASSERT_EQ(a.points_world.size(), b.points_world.size());
  for (size_t j = 0; j < a.points_world.size(); ++j)
    EXPECT_TRUE(a.points_world[j] == b.points_world[j]) << "point " << j;
}

TEST(RotationPriorResidualTest, IsTheRotationVectorOfTheDisagreementOverSigma) {
  const Eigen::Isometry3d T_a(Eigen::Translation3d(0.1, 0.2, 0.3) *
                              Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  const Eigen::Matrix3d R_a_b = RotY(10.0);
  Eigen::Isometry3d T_b = T_a;
  T_b.linear() = T_a.linear() * R_a_b;
  T_b.translation() += Eigen::Vector3d(1.0, -2.0, 0.5);  // the translation does not enter
  RotationPrior prior;
  prior.frame_a = 0;
  prior.frame_b = 1;
  prior.R_a_b = R_a_b;
  prior.sigma_rad = 0.01;
  auto residual = [&](const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    auto block = [](const Eigen::Isometry3d& T) {
      const Eigen::Quaterniond q(T.linear());
      const Eigen::Vector3d& t = T.translation();
      return std::array<double, 7>{q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
    };
    const std::array<double, 7> pa = block(a), pb = block(b);
    Eigen::Vector3d r;
    const RotationPriorResidual f(prior);
    f(pa.data(), pb.data(), r.data());
    return r;
  };
  EXPECT_LT(residual(T_a, T_b).norm(), 1e-12);
  // Camera b turned by 0.2° more about its own x: r = 0.2° x / σ.
  Eigen::Isometry3d turned = T_b;
  turned.linear() = T_b.linear() * Eigen::AngleAxisd(0.2 * M_PI / 180.0, Eigen::Vector3d::UnitX());
  const Eigen::Vector3d r = residual(T_a, turned);
  EXPECT_NEAR(r.x(), 0.2 * M_PI / 180.0 / 0.01, 1e-9);
  EXPECT_NEAR(r.y(), 0.0, 1e-9);
  EXPECT_NEAR(r.z(), 0.0, 1e-9);
}

TEST(BaRotationPriorTest, SchurLmMatchesCeresWithRotationPriors) {
  Scene s = MakeScene(41, 5, 150, 2.0, 0.05, 5.0, 3.0, 3.0, 0.5, 0.02);
  // Priors 0.2° off the truth at σ 0.05°: the priors and the images disagree, both count.
  s.start.rotation_priors = ConsecutivePriors(s.truth, 0.2 * M_PI / 180.0, 0.05 * M_PI / 180.0, 42);
  RotationPrior skip;  // frame 0 to frame 4 as well
  skip.frame_a = 0;
  skip.frame_b = 4;
  skip.R_a_b = Relative(s.truth.T_world_cam0[0], s.truth.T_world_cam0[4]);
  skip.sigma_rad = 0.001;
  s.start.rotation_priors.push_back(skip);
  for (RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kNone}) {
    SCOPED_TRACE(ToString(loss));
    BundleAdjustmentOptions options;
    options.loss = loss;
    const BundleAdjustmentSummary ceres = Solve(s.start, options, BaSolver::kCeres);
    const BundleAdjustmentSummary lm = Solve(s.start, options, BaSolver::kSchurLm);
    ExpectSameSolution(ceres, lm);
    EXPECT_EQ(lm.num_rotation_priors, 5);
  }
  // Two constant poses: the prior between them is left out; one a point-less pose refers to too.
  BundleAdjustmentOptions options;
  options.num_fixed_poses = 2;
  BundleAdjustmentProblem unseen = s.start;
  unseen.T_world_cam0.push_back(unseen.T_world_cam0.back());  // no observation
  RotationPrior to_unseen = skip;
  to_unseen.frame_b = 5;
  unseen.rotation_priors.push_back(to_unseen);
  const BundleAdjustmentSummary ceres = Solve(unseen, options, BaSolver::kCeres);
  const BundleAdjustmentSummary lm = Solve(unseen, options, BaSolver::kSchurLm);
  ExpectSameSolution(ceres, lm);
  EXPECT_EQ(lm.num_rotation_priors, 4);  // (1, 2), (2, 3), (3, 4), (0, 4)
}

// One small plane 3 m ahead (±0.6 m: a 23° field), 30 points, 0.5 px noise, the start 0.5°
// off: a turn about y and a step along x move the pixels alike, so the images alone leave the
// relative rotations wrong by degrees (5.7° the worst of the 5 seeds). Exact priors (σ 0.01°)
// hold them to the truth (6e-4° the worst).
TEST(BaRotationPriorTest, ExactPriorsHoldAnIllDeterminedWindowsRotations) {
  double worst_without_rad = 0.0, worst_with_rad = 0.0;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE(seed);
    Scene s = MakeScene(100 + seed, 5, 30, 1.5, 0.03, 3.0, 0.0, 0.6, 0.5, 0.5 * M_PI / 180.0);
    const BundleAdjustmentSummary without =
        Solve(s.start, BundleAdjustmentOptions(), BaSolver::kSchurLm);
    s.start.rotation_priors = ConsecutivePriors(s.truth, 0.0, 0.01 * M_PI / 180.0, 7);
    const BundleAdjustmentSummary with =
        Solve(s.start, BundleAdjustmentOptions(), BaSolver::kSchurLm);
    ASSERT_TRUE(without.ok()) << without.message;
    ASSERT_TRUE(with.ok()) << with.message;
    EXPECT_EQ(with.num_rotation_priors, 4);
    for (int i = 1; i < 5; ++i) {
      const Eigen::Matrix3d truth = Relative(s.truth.T_world_cam0[i - 1], s.truth.T_world_cam0[i]);
      auto error = [&](const BundleAdjustmentSummary& r) {
        return AngleRad(truth.transpose() * Relative(r.T_world_cam0[i - 1], r.T_world_cam0[i]));
      };
      worst_without_rad = std::max(worst_without_rad, error(without));
      worst_with_rad = std::max(worst_with_rad, error(with));
    }
  }
  std::printf("worst relative rotation error: without priors %.4f deg, with %.4f deg\n",
              worst_without_rad * 180.0 / M_PI, worst_with_rad * 180.0 / M_PI);
  EXPECT_GT(worst_without_rad, 0.05 * M_PI / 180.0);  // the images alone: ill-determined
  EXPECT_LT(worst_with_rad, 0.01 * M_PI / 180.0);     // within the priors' σ
  EXPECT_LT(worst_with_rad, 0.2 * worst_without_rad);
}

TEST(BaRotationPriorTest, NoPriorsOrOnlySkippedOnesGiveTheSameResultBitForBit) {
  const Scene s = MakeScene(51, 5, 150, 2.0, 0.05, 5.0, 3.0, 3.0, 0.5, 0.02);
  BundleAdjustmentProblem skipped = s.start;
  // Both poses constant: left out.
  skipped.rotation_priors = {RotationPrior{0, 1, RotationPrior().R_a_b, 0.001}};
  for (BaSolver solver : {BaSolver::kSchurLm, BaSolver::kCeres}) {
    SCOPED_TRACE(ToString(solver));
    BundleAdjustmentOptions options;
    options.num_fixed_poses = 2;
    const BundleAdjustmentSummary none = Solve(s.start, options, solver);
    const BundleAdjustmentSummary left_out = Solve(skipped, options, solver);
    ASSERT_TRUE(none.ok()) << none.message;
    EXPECT_EQ(none.num_rotation_priors, 0);
    EXPECT_EQ(left_out.num_rotation_priors, 0);
    ExpectIdentical(none, left_out);
  }
}

TEST(BaRotationPriorTest, BadPriorsAreRefused) {
  const Scene s = MakeScene(61, 3, 50, 2.0, 0.05, 5.0, 3.0, 3.0, 0.5, 0.02);
  const RotationPrior good{0, 1, RotationPrior().R_a_b, 0.001};
  std::vector<RotationPrior> bad(6, good);
  bad[0].frame_b = 3;    // out of range
  bad[1].frame_a = -1;   // out of range
  bad[2].frame_b = 0;    // the same frame twice
  bad[3].sigma_rad = 0;  // σ not > 0
  bad[4].sigma_rad = std::nan("");
  bad[5].R_a_b(0, 1) = 0.5;  // not a rotation
  for (size_t k = 0; k < bad.size(); ++k) {
    BundleAdjustmentProblem p = s.start;
    p.rotation_priors = {good, bad[k]};
    const BundleAdjustmentSummary r = Solve(p, BundleAdjustmentOptions(), BaSolver::kSchurLm);
    EXPECT_EQ(r.status, BundleAdjustmentSummary::Status::kInvalidInput) << k;
    EXPECT_THAT(r.message, ::testing::HasSubstr("rotation prior 1")) << k;
  }
}

// The back end's gyro chain: frames 0, 1, 2 in the window, 3 lost (its gyro rotation given),
// 4 measured against 2, 5's gyro not ok. Priors (0, 1), (1, 2) and (2, 4) (chained over 3, σ²
// summed), none to 5.
TEST(BaRotationPriorTest, TheBackEndChainsTheGyroOverLostFramesAndBreaksWhereItIsMissing) {
  const StereoCamera cam = TestCamera();
  BackEndOptions o;
  BackEnd back_end(o);
  const double min_sigma_deg = 0.05;
  GyroRotation step;
  step.ok = true;
  step.R_prev_curr = RotY(1.0);
  step.covariance = Eigen::Matrix3d::Identity() * std::pow(0.1 * M_PI / 180.0, 2);  // σ 0.1°
  back_end.AddGyroRotation(0, GyroRotation(), min_sigma_deg);  // the first frame: not ok
  std::vector<Feature> f0 = test::ForwardFrameFeatures(0, cam);
  ASSERT_TRUE(back_end.Start(0, &f0, test::ForwardPose(0)).ok());
  for (int i = 1; i <= 5; ++i) {
    back_end.AddGyroRotation(i, i == 5 ? GyroRotation() : step, min_sigma_deg);
    if (i == 3) continue;  // lost
    std::vector<Feature> f = test::ForwardFrameFeatures(i, cam);
    const int ref = i == 4 ? 2 : i - 1;
    const Eigen::Isometry3d motion = test::ForwardPose(ref).inverse() * test::ForwardPose(i);
    ASSERT_TRUE(
        back_end.Add(i, ref, &f, test::OneToOneMatches(f.size()), motion, nullptr, 1.0, false)
            .update.ok());
  }
  const std::vector<WindowRotationPrior> priors = back_end.GyroRotationPriors();
  ASSERT_EQ(priors.size(), 3u);
  const double sigma_rad = 0.1 * M_PI / 180.0;
  const int64_t expected[3][2] = {{0, 1}, {1, 2}, {2, 4}};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(priors[k].frame_a, expected[k][0]);
    EXPECT_EQ(priors[k].frame_b, expected[k][1]);
    const int steps = static_cast<int>(expected[k][1] - expected[k][0]);
    EXPECT_LT(AngleRad(priors[k].R_a_b.transpose() * RotY(steps)), 1e-12) << k;
    EXPECT_NEAR(priors[k].sigma_rad, std::sqrt(steps) * sigma_rad, 1e-12) << k;
  }
  // The σ floor: a gyro σ below min_rotation_sigma_deg counts as the floor.
  back_end.Reset();
  step.covariance.setZero();
  back_end.AddGyroRotation(0, GyroRotation(), min_sigma_deg);
  back_end.AddGyroRotation(1, step, min_sigma_deg);
  std::vector<Feature> g0 = test::ForwardFrameFeatures(0, cam);
  ASSERT_TRUE(back_end.Start(0, &g0, test::ForwardPose(0)).ok());
  std::vector<Feature> g1 = test::ForwardFrameFeatures(1, cam);
  ASSERT_TRUE(back_end
                  .Add(1, 0, &g1, test::OneToOneMatches(g1.size()), test::ForwardPose(1), nullptr,
                       1.0, false)
                  .update.ok());
  const std::vector<WindowRotationPrior> floored = back_end.GyroRotationPriors();
  ASSERT_EQ(floored.size(), 1u);
  EXPECT_NEAR(floored[0].sigma_rad, min_sigma_deg * M_PI / 180.0, 1e-15);
}

}  // namespace
}  // namespace vo
