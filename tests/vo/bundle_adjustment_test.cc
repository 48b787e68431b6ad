#include "vo/bundle_adjustment.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <functional>

#include "tests/test_util.h"
#include "tests/vo/ba_test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/prior_motion.h"  // vo::VehicleMotion
#include "vo/ransac.h"        // vo::SplitMix64

namespace vo {
namespace {

using test::ExpectSameSolution;
using vobench_test::IsNearPose;

constexpr int kNumFrames = 5;
constexpr int kNumPoints = 200;
constexpr double kPixelSigma = 0.5;  // per pixel coordinate
// The rms reported is per image observation (2D error norm), so the noise level is √2 σ.
const double kNoiseRmsPx = std::sqrt(2.0) * kPixelSigma;
// Noise-free observations: LM converges to the exact solution; the limit is the solver's
// stopping tolerances, not rounding.
constexpr double kExactTolRad = 1e-6;
constexpr double kExactTolM = 1e-6;
constexpr double kExactRmsPx = 1e-6;
// 0.5 px noise, 5 frames, 200 points at 2–10 m: the poses are good to a few millimetres
// and milliradians.
constexpr double kNoisyTolRad = 2e-3;
constexpr double kNoisyTolM = 1e-2;

using test::Normal;

using test::TestCamera;

struct Scene {
  BundleAdjustmentProblem truth;  // true poses and points, the noisy observations
  BundleAdjustmentProblem start;  // perturbed poses (all but the first) and points
};

// 5 frames moving 0.15 m forward with 2° of yaw each (or the given kNumFrames poses); 200
// points at 2–10 m in front, observed in stereo wherever they project into both images.
Scene MakeScene(uint64_t seed, double sigma_px,
                const std::vector<Eigen::Isometry3d>* poses = nullptr) {
  const StereoCamera cam = TestCamera();
  SplitMix64 rng(seed);
  Scene s;
  for (int i = 0; i < kNumFrames; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.035 * i, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0.01 * i, 0.0, 0.15 * i);
    s.truth.T_world_cam0.push_back(poses != nullptr ? (*poses)[i] : T);
  }
  while (static_cast<int>(s.truth.points_world.size()) < kNumPoints) {
    const Eigen::Vector3d p(6.0 * rng.Uniform() - 3.0, 3.0 * rng.Uniform() - 1.5,
                            2.0 + 8.0 * rng.Uniform());
    const std::vector<BaObservation> obs = test::NoisyStereoObservations(
        cam, s.truth.T_world_cam0, p, static_cast<int>(s.truth.points_world.size()), sigma_px, true,
        &rng);
    if (obs.size() < 2) continue;
    s.truth.points_world.push_back(p);
    s.truth.observations.insert(s.truth.observations.end(), obs.begin(), obs.end());
  }
  s.start = s.truth;
  for (int i = 1; i < kNumFrames; ++i) {
    Eigen::Isometry3d& T = s.start.T_world_cam0[i];
    const Eigen::Vector3d axis(Normal(&rng), Normal(&rng), Normal(&rng));
    T.linear() = (Eigen::AngleAxisd(0.02, axis.normalized()) * T.linear()).eval();
    T.translation() += 0.05 * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
  }
  for (Eigen::Vector3d& p : s.start.points_world)
    p += 0.1 * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
  return s;
}

// Plain rms reprojection error (pixels) of given poses and points against the observations.
double Rms(const StereoCamera& cam, const BundleAdjustmentProblem& obs_from,
           const std::vector<Eigen::Isometry3d>& poses,
           const std::vector<Eigen::Vector3d>& points) {
  double sq = 0.0;
  int count = 0;
  for (const BaObservation& o : obs_from.observations) {
    const Eigen::Vector3d p = poses[o.frame_index].inverse() * points[o.point_index];
    Eigen::Vector2d l, r;
    cam.ProjectLeft(p, &l);
    cam.ProjectRight(p, &r);
    sq += (l - o.uv_left_px).squaredNorm() + (r - o.uv_right_px).squaredNorm();
    count += 2;
  }
  return std::sqrt(sq / count);
}

// The tests below run with both backends (BundleAdjustmentOptions::solver).
class BundleAdjustmentTest : public ::testing::TestWithParam<BaSolver> {
 protected:
  BundleAdjustmentOptions Options() const {
    BundleAdjustmentOptions options;
    options.solver = GetParam();
    return options;
  }
  // Tolerances tight enough to reach an exact solution.
  BundleAdjustmentOptions ExactOptions() const {
    BundleAdjustmentOptions options = Options();
    options.max_num_iterations = 50;
    options.function_tolerance = 1e-14;
    options.parameter_tolerance = 1e-14;
    return options;
  }
};

INSTANTIATE_TEST_SUITE_P(Backends, BundleAdjustmentTest,
                         ::testing::Values(BaSolver::kCeres, BaSolver::kSchurLm),
                         [](const ::testing::TestParamInfo<BaSolver>& info) {
                           return std::string(ToString(info.param));
                         });

TEST_P(BundleAdjustmentTest, NoiseFreeRecoversGroundTruth) {
  const Scene s = MakeScene(1, 0.0);
  const BundleAdjustmentSummary r = RunBundleAdjustment(TestCamera(), s.start, ExactOptions());
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_GT(r.rms_reprojection_before_px, 5.0);
  EXPECT_LT(r.rms_reprojection_after_px, kExactRmsPx);
  EXPECT_LT(r.final_cost, r.initial_cost);
  for (int i = 0; i < kNumFrames; ++i)
    EXPECT_THAT(r.T_world_cam0[i], IsNearPose(s.truth.T_world_cam0[i], kExactTolRad, kExactTolM))
        << "frame " << i;
  for (int j = 0; j < kNumPoints; ++j)
    EXPECT_LT((r.points_world[j] - s.truth.points_world[j]).norm(), 1e-5) << "point " << j;
  EXPECT_EQ(r.num_outliers, 0);
  EXPECT_EQ(r.num_points_optimized, kNumPoints);
}

TEST_P(BundleAdjustmentTest, NoisyReducesErrorToTheNoiseLevel) {
  const StereoCamera cam = TestCamera();
  const Scene s = MakeScene(2, kPixelSigma);
  const BundleAdjustmentSummary r = RunBundleAdjustment(cam, s.start, Options());
  ASSERT_TRUE(r.ok()) << r.message;
  // Residual-level checks: the optimum is at least as good as the truth, and near the noise
  // level (slightly below it: 3 of every ~4·frames residuals per point are absorbed by it).
  const double rms_truth = Rms(cam, s.truth, s.truth.T_world_cam0, s.truth.points_world);
  EXPECT_NEAR(rms_truth, kNoiseRmsPx, 0.05);
  EXPECT_GT(r.rms_reprojection_before_px, 10.0 * kNoiseRmsPx);
  EXPECT_LE(r.rms_reprojection_after_px, rms_truth + 1e-6);
  EXPECT_GT(r.rms_reprojection_after_px, 0.7 * kNoiseRmsPx);
  EXPECT_NEAR(r.rms_reprojection_after_px, Rms(cam, s.truth, r.T_world_cam0, r.points_world),
              1e-12);
  for (int i = 0; i < kNumFrames; ++i)
    EXPECT_THAT(r.T_world_cam0[i], IsNearPose(s.truth.T_world_cam0[i], kNoisyTolRad, kNoisyTolM))
        << "frame " << i;
  EXPECT_EQ(r.num_outliers, 0);  // 3 px threshold is 6σ per coordinate
}

TEST_P(BundleAdjustmentTest, FixedOldestPoseStaysBitIdentical) {
  Scene s = MakeScene(3, kPixelSigma);
  // A pose that does not survive a matrix → quaternion → matrix round trip bit for bit.
  s.start.T_world_cam0[0].linear() =
      Eigen::AngleAxisd(1e-3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  s.start.T_world_cam0[0].translation() = Eigen::Vector3d(0.1, 1.0 / 3.0, -0.7);
  for (int fixed = 1; fixed <= 2; ++fixed) {
    BundleAdjustmentOptions options = Options();
    options.num_fixed_poses = fixed;
    const BundleAdjustmentSummary r = RunBundleAdjustment(TestCamera(), s.start, options);
    ASSERT_TRUE(r.ok()) << r.message;
    for (int i = 0; i < fixed; ++i)
      EXPECT_TRUE(r.T_world_cam0[i].matrix() == s.start.T_world_cam0[i].matrix()) << "pose " << i;
    EXPECT_FALSE(r.T_world_cam0[fixed].matrix() == s.start.T_world_cam0[fixed].matrix());
  }
}

TEST_P(BundleAdjustmentTest, HuberIgnoresGrossOutliers) {
  const StereoCamera cam = TestCamera();
  Scene s = MakeScene(4, kPixelSigma);
  // Corrupt 5% of the observations by 20–50 px (a wrong match in a track).
  SplitMix64 rng(99);
  std::vector<bool> corrupted(s.start.observations.size(), false);
  for (size_t k = 0; k < s.start.observations.size(); ++k) {
    if (rng.Uniform() >= 0.05) continue;
    const double angle = 2.0 * M_PI * rng.Uniform();
    const Eigen::Vector2d shift =
        (20.0 + 30.0 * rng.Uniform()) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    s.start.observations[k].uv_left_px += shift;
    s.start.observations[k].uv_right_px += shift;
    corrupted[k] = true;
  }
  const BundleAdjustmentSummary huber = RunBundleAdjustment(cam, s.start, Options());
  BundleAdjustmentOptions plain = Options();
  plain.loss = RobustLoss::kNone;
  const BundleAdjustmentSummary squared = RunBundleAdjustment(cam, s.start, plain);
  ASSERT_TRUE(huber.ok() && squared.ok());
  double err_huber = 0.0, err_squared = 0.0;
  for (int i = 0; i < kNumFrames; ++i) {
    EXPECT_THAT(huber.T_world_cam0[i],
                IsNearPose(s.truth.T_world_cam0[i], kNoisyTolRad, kNoisyTolM))
        << "frame " << i;
    err_huber +=
        (huber.T_world_cam0[i].translation() - s.truth.T_world_cam0[i].translation()).norm();
    err_squared +=
        (squared.T_world_cam0[i].translation() - s.truth.T_world_cam0[i].translation()).norm();
  }
  EXPECT_LT(err_huber, err_squared);
  // Every corrupted observation is flagged; almost nothing else is.
  int missed = 0, false_flags = 0;
  for (size_t k = 0; k < corrupted.size(); ++k) {
    if (corrupted[k] && !huber.observation_is_outlier[k]) ++missed;
    if (!corrupted[k] && huber.observation_is_outlier[k]) ++false_flags;
  }
  EXPECT_EQ(missed, 0);
  EXPECT_LE(false_flags, 2);
  EXPECT_LT(huber.rms_inlier_reprojection_after_px, 1.1 * kNoiseRmsPx);
}

TEST(BundleAdjustmentCeresTest, DenseAndSparseSchurAgree) {
  const Scene s = MakeScene(5, kPixelSigma);
  BundleAdjustmentOptions dense;
  dense.solver = BaSolver::kCeres;
  dense.linear_solver = BaLinearSolver::kDenseSchur;
  BundleAdjustmentOptions sparse = dense;
  sparse.linear_solver = BaLinearSolver::kSparseSchur;
  const BundleAdjustmentSummary a = RunBundleAdjustment(TestCamera(), s.start, dense);
  const BundleAdjustmentSummary b = RunBundleAdjustment(TestCamera(), s.start, sparse);
  ASSERT_TRUE(a.ok()) << a.message;
  ASSERT_TRUE(b.ok()) << b.message;
  EXPECT_EQ(a.linear_solver, "DENSE_SCHUR");
  EXPECT_THAT(b.linear_solver, ::testing::StartsWith("SPARSE_SCHUR"));
  // Same minimum, reached through different factorisations.
  EXPECT_NEAR(a.final_cost, b.final_cost, 1e-6 * a.final_cost);
  for (int i = 0; i < kNumFrames; ++i)
    EXPECT_THAT(a.T_world_cam0[i], IsNearPose(b.T_world_cam0[i], 1e-6, 1e-6));
}

// The hand-derived Jacobians (default) against Ceres' automatic differentiation of the same
// residuals: the same iterations, hence the same solution to rounding.
TEST(BundleAdjustmentCeresTest, AnalyticJacobiansAgreeWithAutomaticDifferentiation) {
  Scene s = MakeScene(9, kPixelSigma);
  for (size_t k = 0; k < s.start.observations.size(); k += 4)
    s.start.observations[k].has_right = false;  // left-only blocks too
  BundleAdjustmentOptions analytic;
  analytic.solver = BaSolver::kCeres;
  analytic.analytic_jacobians = true;
  BundleAdjustmentOptions automatic = analytic;
  automatic.analytic_jacobians = false;
  const BundleAdjustmentSummary a = RunBundleAdjustment(TestCamera(), s.start, analytic);
  const BundleAdjustmentSummary b = RunBundleAdjustment(TestCamera(), s.start, automatic);
  ASSERT_TRUE(a.ok() && b.ok()) << a.message << b.message;
  EXPECT_NEAR(a.initial_cost, b.initial_cost, 1e-12 * b.initial_cost);
  EXPECT_NEAR(a.final_cost, b.final_cost, 1e-9 * b.final_cost);
  EXPECT_GT(a.initial_cost, 10.0 * a.final_cost);
  for (int i = 0; i < kNumFrames; ++i)
    EXPECT_THAT(a.T_world_cam0[i], IsNearPose(b.T_world_cam0[i], 1e-9, 1e-9)) << "frame " << i;
  for (int j = 0; j < kNumPoints; ++j)
    EXPECT_LT((a.points_world[j] - b.points_world[j]).norm(), 1e-8) << "point " << j;
}

TEST_P(BundleAdjustmentTest, Deterministic) {
  const Scene s = MakeScene(6, kPixelSigma);
  const BundleAdjustmentSummary a = RunBundleAdjustment(TestCamera(), s.start, Options());
  const BundleAdjustmentSummary b = RunBundleAdjustment(TestCamera(), s.start, Options());
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.final_cost, b.final_cost);
  EXPECT_EQ(a.num_iterations, b.num_iterations);
  for (int i = 0; i < kNumFrames; ++i)
    EXPECT_TRUE(a.T_world_cam0[i].matrix() == b.T_world_cam0[i].matrix());
  EXPECT_EQ(a.points_world, b.points_world);
}

TEST_P(BundleAdjustmentTest, SingleFramePointsAreKeptByDefault) {
  const StereoCamera cam = TestCamera();
  Scene s = MakeScene(7, 0.0);
  // A point seen in the last frame only, started 10 cm off.
  const Eigen::Vector3d p_cam0(0.2, -0.1, 4.0);
  const Eigen::Vector3d p_world = s.truth.T_world_cam0[4] * p_cam0;
  BaObservation o;
  o.frame_index = 4;
  o.point_index = static_cast<int>(s.start.points_world.size());
  cam.ProjectLeft(p_cam0, &o.uv_left_px);
  cam.ProjectRight(p_cam0, &o.uv_right_px);
  o.has_right = true;
  s.start.points_world.push_back(p_world + Eigen::Vector3d(0.1, 0.0, 0.0));
  s.start.observations.push_back(o);
  const BundleAdjustmentSummary kept = RunBundleAdjustment(cam, s.start, Options());
  ASSERT_TRUE(kept.ok());
  EXPECT_TRUE(kept.point_optimized.back());
  EXPECT_LT((kept.points_world.back() - p_world).norm(), 1e-4);
  BundleAdjustmentOptions two_frames = Options();
  two_frames.min_frames_per_point = 2;
  const BundleAdjustmentSummary left_out = RunBundleAdjustment(cam, s.start, two_frames);
  ASSERT_TRUE(left_out.ok());
  EXPECT_FALSE(left_out.point_optimized.back());
  EXPECT_EQ(left_out.points_world.back(), s.start.points_world.back());
  EXPECT_EQ(left_out.num_points_optimized, kNumPoints);
}

TEST_P(BundleAdjustmentTest, LeftOnlyObservationsAreUsed) {
  Scene s = MakeScene(8, 0.0);
  for (size_t k = 0; k < s.start.observations.size(); k += 3)
    s.start.observations[k].has_right = false;
  const BundleAdjustmentSummary r = RunBundleAdjustment(TestCamera(), s.start, Options());
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_LT(r.rms_reprojection_after_px, 1e-4);
  for (int i = 0; i < kNumFrames; ++i)
    EXPECT_THAT(r.T_world_cam0[i], IsNearPose(s.truth.T_world_cam0[i], 1e-5, 1e-5));
}

TEST_P(BundleAdjustmentTest, PointBehindTheCameraIsLeftOutAndFlagged) {
  Scene s = MakeScene(9, 0.0);
  const int j = s.start.observations[0].point_index;
  s.start.points_world[j] = s.start.T_world_cam0[0] * Eigen::Vector3d(0.0, 0.0, -2.0);
  const BundleAdjustmentSummary r = RunBundleAdjustment(TestCamera(), s.start, Options());
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_TRUE(r.observation_is_outlier[0]);
}

TEST_P(BundleAdjustmentTest, InvalidInputs) {
  const Scene s = MakeScene(10, 0.0);
  BundleAdjustmentProblem bad = s.start;
  bad.observations[0].point_index = kNumPoints;
  EXPECT_EQ(RunBundleAdjustment(TestCamera(), bad, Options()).status,
            BundleAdjustmentSummary::Status::kInvalidInput);
  BundleAdjustmentOptions options = Options();
  options.num_fixed_poses = kNumFrames + 1;
  EXPECT_EQ(RunBundleAdjustment(TestCamera(), s.start, options).status,
            BundleAdjustmentSummary::Status::kInvalidInput);
  options = Options();
  options.loss_scale_px = 0.0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("loss_scale_px"));
  BundleAdjustmentProblem empty = s.start;
  empty.observations.clear();
  EXPECT_EQ(RunBundleAdjustment(TestCamera(), empty, Options()).status,
            BundleAdjustmentSummary::Status::kInvalidInput);
}

TEST_P(BundleAdjustmentTest, MakeWindowProblemFromTracks) {
  const StereoCamera cam = TestCamera();
  const Scene s = MakeScene(11, 0.0);
  // Feed the scene's frames to a TrackManager: feature k of frame i = the k-th point visible
  // in frame i, matched to the previous frame's feature of the same point.
  TrackManager tracks;
  std::map<int64_t, Eigen::Isometry3d> poses;
  std::vector<int> prev_point_of_feature;
  for (int i = 0; i < kNumFrames; ++i) {
    std::vector<Feature> features;
    std::vector<int> point_of_feature;
    for (const BaObservation& o : s.truth.observations) {
      if (o.frame_index != i) continue;
      Feature f;
      f.uv_px = o.uv_left_px;
      f.disparity_px = o.uv_left_px.x() - o.uv_right_px.x();
      f.p_cam0 = cam.Backproject(f.uv_px.x(), f.uv_px.y(), f.disparity_px);
      features.push_back(f);
      point_of_feature.push_back(o.point_index);
    }
    std::vector<Match> matches;
    for (size_t c = 0; c < point_of_feature.size(); ++c)
      for (size_t p = 0; p < prev_point_of_feature.size(); ++p)
        if (prev_point_of_feature[p] == point_of_feature[c])
          matches.push_back({static_cast<int>(p), static_cast<int>(c), 1.0});
    ASSERT_TRUE(tracks.AddFrame(100 + i, &features, matches).ok());
    poses[100 + i] = s.truth.T_world_cam0[i];
    prev_point_of_feature = point_of_feature;
  }
  std::vector<int64_t> frame_ids, track_ids;
  const BundleAdjustmentProblem p = MakeWindowProblem(tracks, poses, &frame_ids, &track_ids);
  EXPECT_THAT(frame_ids, ::testing::ElementsAre(100, 101, 102, 103, 104));
  ASSERT_EQ(p.points_world.size(), track_ids.size());
  // Every point is seen in consecutive frames in this scene, so tracks = points (the scene
  // keeps points seen in >= 2 frames; a point that leaves and re-enters would split).
  EXPECT_GE(p.points_world.size(), static_cast<size_t>(kNumPoints));
  EXPECT_EQ(p.observations.size(), s.truth.observations.size());
  const BundleAdjustmentSummary r = RunBundleAdjustment(cam, p, Options());
  ASSERT_TRUE(r.ok());
  EXPECT_LT(r.rms_reprojection_before_px, 1e-6);  // exact observations, true poses
}

// --- the hand-written backend against Ceres ---
// Same problem, same trust-region rules: the iterates differ by rounding only, so the
// optimum, the iteration count, the termination and the outlier flags are the same.
// (tests/vo/ba_test_util.h: ExpectSameSolution and its tolerances.)

// Corrupts about `fraction` of the observations by 20–50 px (a wrong match in a track).
void Corrupt(double fraction, uint64_t seed, BundleAdjustmentProblem* p) {
  SplitMix64 rng(seed);
  for (BaObservation& o : p->observations) {
    if (rng.Uniform() >= fraction) continue;
    const double angle = 2.0 * M_PI * rng.Uniform();
    const Eigen::Vector2d shift =
        (20.0 + 30.0 * rng.Uniform()) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    o.uv_left_px += shift;
    o.uv_right_px += shift;
  }
}

BundleAdjustmentSummary Solve(const BundleAdjustmentProblem& p, BundleAdjustmentOptions options,
                              BaSolver solver) {
  options.solver = solver;
  return RunBundleAdjustment(TestCamera(), p, options);
}

TEST(BundleAdjustmentBackendTest, SchurLmMatchesCeresOnExactData) {
  const Scene s = MakeScene(21, 0.0);
  BundleAdjustmentOptions options;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  const BundleAdjustmentSummary ceres = Solve(s.start, options, BaSolver::kCeres);
  const BundleAdjustmentSummary lm = Solve(s.start, options, BaSolver::kSchurLm);
  ExpectSameSolution(ceres, lm);
  EXPECT_EQ(lm.linear_solver, "SCHUR_LM (dense Cholesky)");
  // Both at the exact ground truth.
  for (int i = 0; i < kNumFrames; ++i)
    EXPECT_THAT(lm.T_world_cam0[i], IsNearPose(s.truth.T_world_cam0[i], kExactTolRad, kExactTolM))
        << "frame " << i;
  for (int j = 0; j < kNumPoints; ++j)
    EXPECT_LT((lm.points_world[j] - s.truth.points_world[j]).norm(), 1e-5) << "point " << j;
}

TEST(BundleAdjustmentBackendTest, SchurLmMatchesCeresWithNoiseAndOutliers) {
  Scene s = MakeScene(22, kPixelSigma);
  Corrupt(0.05, 23, &s.start);
  for (RobustLoss loss : {RobustLoss::kHuber, RobustLoss::kCauchy, RobustLoss::kNone}) {
    SCOPED_TRACE(ToString(loss));
    BundleAdjustmentOptions options;
    options.loss = loss;
    const BundleAdjustmentSummary ceres = Solve(s.start, options, BaSolver::kCeres);
    ExpectSameSolution(ceres, Solve(s.start, options, BaSolver::kSchurLm));
    if (loss != RobustLoss::kNone) {
      EXPECT_GT(ceres.num_outliers, 0);
    }
  }
}

// Two-frame points and an iteration limit that is reached, left-only observations, two
// constant poses, a frame no point is seen in.
TEST(BundleAdjustmentBackendTest, SchurLmMatchesCeresInOtherConfigurations) {
  Scene s = MakeScene(24, kPixelSigma);
  for (size_t k = 0; k < s.start.observations.size(); k += 5)
    s.start.observations[k].has_right = false;
  BundleAdjustmentOptions options;
  options.min_frames_per_point = 2;
  options.max_num_iterations = 3;  // stops at the limit
  BundleAdjustmentSummary ceres = Solve(s.start, options, BaSolver::kCeres);
  EXPECT_FALSE(ceres.converged);
  ExpectSameSolution(ceres, Solve(s.start, options, BaSolver::kSchurLm));

  options = BundleAdjustmentOptions();
  options.num_fixed_poses = 2;
  BundleAdjustmentProblem unseen = s.start;
  unseen.T_world_cam0.push_back(unseen.T_world_cam0.back());  // no observation
  ceres = Solve(unseen, options, BaSolver::kCeres);
  ExpectSameSolution(ceres, Solve(unseen, options, BaSolver::kSchurLm));
  EXPECT_TRUE(ceres.T_world_cam0.back().matrix() == unseen.T_world_cam0.back().matrix());
}

// --- the planar motion prior of a ground vehicle ---
constexpr double kPitchRad = 10.0 * M_PI / 180.0;
constexpr double kAxleM = 0.15;

// The vehicle's up in a camera pitched down by 10° (x right, y down, z forward).
Eigen::Vector3d PitchedUp() {
  return Eigen::AngleAxisd(kPitchRad, Eigen::Vector3d::UnitX()) * Eigen::Vector3d(0, -1, 0);
}

PlanarMotionPrior Prior() {
  PlanarMotionPrior prior;
  prior.enabled = true;
  prior.up_cam = PitchedUp();
  prior.axle_behind_camera_m = kAxleM;
  return prior;
}

// A wheeled vehicle's poses: each step turns by `yaw_rad` and drives 0.15 m (VehicleMotion).
std::vector<Eigen::Isometry3d> VehiclePoses(double yaw_rad) {
  std::vector<Eigen::Isometry3d> poses{Eigen::Isometry3d::Identity()};
  poses[0].linear() = Eigen::AngleAxisd(-kPitchRad, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (int i = 1; i < kNumFrames; ++i)
    poses.push_back(poses.back() * VehicleMotion(PitchedUp(), kAxleM, yaw_rad * i, 0.15));
  return poses;
}

using LinkResidual = Eigen::Matrix<double, PlanarMotionResidual::kNumResiduals, 1>;
LinkResidual PlanarResidual(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b,
                            const PlanarMotionPrior& prior) {
  auto block = [](const Eigen::Isometry3d& T) {
    const Eigen::Quaterniond q(T.linear());
    return std::array<double, 7>{
        q.x(), q.y(), q.z(), q.w(), T.translation().x(), T.translation().y(), T.translation().z()};
  };
  const std::array<double, 7> a = block(T_a), b = block(T_b);
  LinkResidual r;
  const PlanarMotionResidual residual(prior);
  residual(a.data(), b.data(), r.data());
  return r;
}

TEST(PlanarMotionPriorTest, ZeroForAVehicleMotionAndTheSizeOfATiltALiftAndASlip) {
  const PlanarMotionPrior prior = Prior();
  const Eigen::Vector3d u = PitchedUp();
  const Eigen::Vector3d e1 = HorizontalForwardAxis(u), e2 = u.cross(e1);
  Eigen::Isometry3d T_a = Eigen::Isometry3d::Identity();
  T_a.translation() = Eigen::Vector3d(0.3, -0.2, 1.0);
  T_a.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (double yaw : {-0.6, -0.05, 0.0, 0.02, 0.3, 1.2}) {
    for (double forward : {0.0, 0.04, -0.1}) {
      SCOPED_TRACE(testing::Message() << "yaw " << yaw << " forward " << forward);
      const Eigen::Isometry3d T_ab = VehicleMotion(u, kAxleM, yaw, forward);
      EXPECT_LT(PlanarResidual(T_a, T_a * T_ab, prior).norm(), 1e-10);
      // A tilt about the forward axis (roll) then about the lateral one (pitch): the sine over
      // σ in r1 resp. r0 (R u moves towards ∓e2 resp. ±e1).
      Eigen::Isometry3d tilted = T_ab;
      tilted.linear() = Eigen::AngleAxisd(0.01, e1) * T_ab.linear();
      LinkResidual r = PlanarResidual(T_a, T_a * tilted, prior);
      EXPECT_NEAR(std::hypot(r(0), r(1)), std::sin(0.01) / prior.tilt_sigma_rad, 1e-6);
      // A lift of 1 cm along up.
      Eigen::Isometry3d lifted = T_ab;
      lifted.translation() += 0.01 * u;
      r = PlanarResidual(T_a, T_a * lifted, prior);
      EXPECT_NEAR(r(2), 0.01 / prior.lift_sigma_m, 1e-9);
      EXPECT_NEAR(r(0), 0.0, 1e-9);
      EXPECT_NEAR(r(3), 0.0, 1e-9);
      // A sideways step of 1 cm across the heading at half the turn.
      Eigen::Isometry3d slipped = T_ab;
      slipped.translation() += 0.01 * (Eigen::AngleAxisd(0.5 * yaw, u) * e2);
      r = PlanarResidual(T_a, T_a * slipped, prior);
      EXPECT_NEAR(r(3), 0.01 / prior.slip_sigma_m, 1e-9);
      EXPECT_NEAR(r.head<3>().norm(), 0.0, 1e-9);
    }
  }
}

// The flat floor's rows: zero for every pose of a vehicle on the first pose's floor (any yaw,
// anywhere), the sine of a tilt against the floor over σ, a height step over σ; zero when off.
TEST(PlanarMotionPriorTest, FlatFloorRowsHoldEachPoseOnTheFirstPosesFloor) {
  PlanarMotionPrior prior = Prior();
  prior.flat_floor = true;
  const std::vector<Eigen::Isometry3d> poses = VehiclePoses(0.2);
  const Eigen::Vector3d u = PitchedUp();
  const Eigen::Vector3d w = poses[0].linear() * u;  // the floor's up in the world
  prior.floor_up_world = 3.0 * w;                   // normalised by the residual
  prior.floor_height_m = w.dot(poses[0].translation());
  for (int i = 1; i < kNumFrames; ++i) {
    SCOPED_TRACE(i);
    // The relative rows link the neighbour; the floor rows see the later pose only.
    EXPECT_LT(PlanarResidual(poses[i - 1], poses[i], prior).norm(), 1e-10);
    EXPECT_LT(PlanarResidual(poses[0], poses[i], prior).tail<3>().norm(), 1e-10);
    const Eigen::Vector3d f1 = HorizontalForwardAxis(w), f2 = w.cross(f1);
    for (const Eigen::Vector3d& tilt_axis : {f1, f2, (f1 + f2).normalized()}) {
      Eigen::Isometry3d tilted = poses[i];
      tilted.linear() = Eigen::AngleAxisd(0.02, tilt_axis) * poses[i].linear();
      const LinkResidual r = PlanarResidual(poses[i - 1], tilted, prior);
      EXPECT_NEAR(r.segment<2>(4).norm(), std::sin(0.02) / prior.floor_tilt_sigma_rad, 1e-6);
      EXPECT_NEAR(r(6), 0.0, 1e-9);
    }
    Eigen::Isometry3d raised = poses[i];
    raised.translation() += 0.03 * w + 0.5 * HorizontalForwardAxis(w);  // up 3 cm, and along
    const LinkResidual r = PlanarResidual(poses[i - 1], raised, prior);
    EXPECT_NEAR(r(6), 0.03 / prior.floor_height_sigma_m, 1e-9);
    EXPECT_LT(r.segment<2>(4).norm(), 1e-10);
    prior.flat_floor = false;
    EXPECT_EQ(PlanarResidual(poses[i - 1], raised, prior).tail<3>().norm(), 0.0);
    prior.flat_floor = true;
  }
}

TEST(PlanarMotionPriorTest, InvalidPriorIsRejected) {
  Scene s = MakeScene(31, kPixelSigma, nullptr);
  for (auto spoil : std::vector<std::function<void(PlanarMotionPrior*)>>{
           [](PlanarMotionPrior* p) { p->up_cam.setZero(); },
           [](PlanarMotionPrior* p) { p->up_cam.x() = NAN; },
           [](PlanarMotionPrior* p) { p->axle_behind_camera_m = -0.1; },
           [](PlanarMotionPrior* p) { p->tilt_sigma_rad = 0.0; },
           [](PlanarMotionPrior* p) { p->slip_sigma_m = INFINITY; },
           [](PlanarMotionPrior* p) {
             p->flat_floor = true;
             p->floor_up_world.setZero();
           },
           [](PlanarMotionPrior* p) {
             p->flat_floor = true;
             p->floor_height_sigma_m = 0.0;
           },
           [](PlanarMotionPrior* p) {
             p->flat_floor = true;
             p->floor_height_m = NAN;
           }}) {
    s.start.planar = Prior();
    spoil(&s.start.planar);
    const BundleAdjustmentSummary r = RunBundleAdjustment(TestCamera(), s.start);
    EXPECT_EQ(r.status, BundleAdjustmentSummary::Status::kInvalidInput);
    EXPECT_THAT(r.message, testing::HasSubstr("planar motion prior"));
  }
}

TEST_P(BundleAdjustmentTest, PlanarPriorKeepsTheTrueVehicleMotionOnExactData) {
  const std::vector<Eigen::Isometry3d> poses = VehiclePoses(0.03);
  Scene s = MakeScene(32, 0.0, &poses);
  s.start.planar = Prior();
  const BundleAdjustmentSummary r = RunBundleAdjustment(TestCamera(), s.start, ExactOptions());
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.num_planar_links, kNumFrames - 1);
  EXPECT_LT(r.rms_reprojection_after_px, kExactRmsPx);
  for (int i = 0; i < kNumFrames; ++i)
    EXPECT_THAT(r.T_world_cam0[i], IsNearPose(poses[i], kExactTolRad, kExactTolM)) << i;
}

// The start of a scene with only its points farther than 6 m from the first pose, at most 15
// (a plain wall's few features at 6-10 m).
BundleAdjustmentProblem FarPointsOnly(const Scene& s) {
  BundleAdjustmentProblem weak = s.start;
  weak.observations.clear();
  int kept = 0;
  for (size_t j = 0; j < s.truth.points_world.size() && kept < 15; ++j) {
    if ((s.truth.T_world_cam0[0].inverse() * s.truth.points_world[j]).z() < 6.0) continue;
    ++kept;
    for (const BaObservation& o : s.start.observations)
      if (o.point_index == static_cast<int>(j)) weak.observations.push_back(o);
  }
  EXPECT_EQ(kept, 15);
  return weak;
}

// Few, far points: the visual evidence alone lets the poses tilt and lift; with the prior they
// stay a vehicle's.
TEST_P(BundleAdjustmentTest, PlanarPriorKeepsAWeaklyObservedVehicleLevel) {
  const std::vector<Eigen::Isometry3d> poses = VehiclePoses(0.02);
  Scene s = MakeScene(33, 1.0, &poses);
  BundleAdjustmentProblem weak = FarPointsOnly(s);
  const BundleAdjustmentSummary free = RunBundleAdjustment(TestCamera(), weak, Options());
  weak.planar = Prior();
  const BundleAdjustmentSummary planar = RunBundleAdjustment(TestCamera(), weak, Options());
  ASSERT_TRUE(free.ok()) << free.message;
  ASSERT_TRUE(planar.ok()) << planar.message;
  double free_tilt = 0.0, planar_tilt = 0.0, free_lift = 0.0, planar_lift = 0.0;
  for (int i = 1; i < kNumFrames; ++i) {
    const LinkResidual rf = PlanarResidual(free.T_world_cam0[i - 1], free.T_world_cam0[i], Prior());
    const LinkResidual rp =
        PlanarResidual(planar.T_world_cam0[i - 1], planar.T_world_cam0[i], Prior());
    free_tilt = std::max(free_tilt, rf.head<2>().norm() * Prior().tilt_sigma_rad);
    planar_tilt = std::max(planar_tilt, rp.head<2>().norm() * Prior().tilt_sigma_rad);
    free_lift = std::max(free_lift, std::abs(rf(2)) * Prior().lift_sigma_m);
    planar_lift = std::max(planar_lift, std::abs(rp(2)) * Prior().lift_sigma_m);
  }
  std::printf(
      "weak vehicle: largest tilt per link %.5f rad free, %.5f rad planar; lift %.5f / %.5f m\n",
      free_tilt, planar_tilt, free_lift, planar_lift);
  // The scene's random draws depend on the compiler's argument evaluation order (GCC: free
  // 0.0137 / planar 0.0009 rad, lift 0.10 / 0.0004 m; clang: 0.028 / 0.0020 rad, 0.19 /
  // 0.0003 m), so the bounds are relative to the prior's σ (0.002 rad, 2 mm) and to the free fit.
  EXPECT_GT(free_tilt, 3e-3);  // the start's 0.02 rad perturbations are not fully undone
  EXPECT_LT(planar_tilt, 1.5 * Prior().tilt_sigma_rad);
  EXPECT_LT(planar_lift, Prior().lift_sigma_m);
  EXPECT_LT(planar_tilt, 0.15 * free_tilt);
  EXPECT_LT(planar_lift, 0.1 * free_lift);
}

// The neighbour links let each weakly observed pose tilt and rise a little more than the one
// before (within σ per link, summing along the window); the flat floor holds every pose against
// the first one's floor. The fixed first pose is the truth, the floor is the true one.
TEST_P(BundleAdjustmentTest, FlatFloorHoldsTheTiltAndHeightOfAWeaklyObservedVehicle) {
  const std::vector<Eigen::Isometry3d> poses = VehiclePoses(0.02);
  const Eigen::Vector3d w = poses[0].linear() * PitchedUp();
  double worst[2][2] = {{0, 0}, {0, 0}};  // [links only, flat floor][tilt rad, height m]
  for (uint64_t seed : {41, 42, 43, 44}) {
    Scene s = MakeScene(seed, 1.0, &poses);
    BundleAdjustmentProblem weak = FarPointsOnly(s);
    for (int floor = 0; floor < 2; ++floor) {
      weak.planar = Prior();
      weak.planar.tilt_sigma_rad = 0.01;  // loose links: the drift the floor is for
      weak.planar.lift_sigma_m = 0.01;
      weak.planar.flat_floor = floor == 1;
      weak.planar.floor_up_world = w;
      weak.planar.floor_height_m = w.dot(poses[0].translation());
      const BundleAdjustmentSummary r = RunBundleAdjustment(TestCamera(), weak, Options());
      ASSERT_TRUE(r.ok()) << r.message;
      for (int i = 1; i < kNumFrames; ++i) {
        const Eigen::Vector3d up = r.T_world_cam0[i].linear() * PitchedUp();
        worst[floor][0] = std::max(worst[floor][0], std::asin(std::min(1.0, up.cross(w).norm())));
        worst[floor][1] =
            std::max(worst[floor][1],
                     std::abs(w.dot(r.T_world_cam0[i].translation() - poses[0].translation())));
      }
    }
  }
  std::printf(
      "weak vehicle, largest tilt / height against the floor: links only %.5f rad / "
      "%.4f m, flat floor %.5f rad / %.4f m\n",
      worst[0][0], worst[0][1], worst[1][0], worst[1][1]);
  // The draws depend on the compiler's argument evaluation order (MakeScene; GCC: links 0.0095
  // rad / 7.0 mm, floor 0.0035 rad / 1.2 mm; clang: 0.0072 rad / 13.5 mm, 0.0037 rad / 2.5 mm),
  // so the bounds are the floor's σ (0.005 rad, 1 cm) and the links-only fit.
  const PlanarMotionPrior floor = Prior();
  EXPECT_GT(worst[0][0], floor.floor_tilt_sigma_rad);
  EXPECT_LT(worst[1][0], floor.floor_tilt_sigma_rad);
  EXPECT_LT(worst[1][1], 0.5 * floor.floor_height_sigma_m);
  EXPECT_LT(worst[1][1], 0.5 * worst[0][1]);
}

TEST(BundleAdjustmentBackendTest, SchurLmMatchesCeresWithThePlanarPrior) {
  const std::vector<Eigen::Isometry3d> poses = VehiclePoses(0.03);
  Scene s = MakeScene(34, kPixelSigma, &poses);
  Corrupt(0.05, 35, &s.start);
  s.start.planar = Prior();
  s.start.planar.tilt_sigma_rad = 0.001;  // the prior and the images disagree: both count
  BundleAdjustmentOptions options;
  const BundleAdjustmentSummary ceres = Solve(s.start, options, BaSolver::kCeres);
  const BundleAdjustmentSummary lm = Solve(s.start, options, BaSolver::kSchurLm);
  ExpectSameSolution(ceres, lm);
  EXPECT_EQ(lm.num_planar_links, kNumFrames - 1);
  EXPECT_EQ(ceres.num_planar_links, kNumFrames - 1);
  // Two constant poses (one link between constants is left out) and a pose no point is seen
  // in (linked past).
  options.num_fixed_poses = 2;
  BundleAdjustmentProblem gap = s.start;
  for (BaObservation& o : gap.observations)
    if (o.frame_index == 3) o.frame_index = 4;  // frame 3 unseen; frame 4 sees its points
  gap.T_world_cam0[4] = gap.T_world_cam0[3];
  const BundleAdjustmentSummary ceres_gap = Solve(gap, options, BaSolver::kCeres);
  const BundleAdjustmentSummary lm_gap = Solve(gap, options, BaSolver::kSchurLm);
  ExpectSameSolution(ceres_gap, lm_gap);
  EXPECT_EQ(lm_gap.num_planar_links, 2);  // (1, 2) and (2, 4)
  // With a flat floor 0.5° and 2 cm off the true one (the prior and the images disagree).
  s.start.planar.flat_floor = true;
  s.start.planar.floor_up_world = Eigen::AngleAxisd(0.5 * M_PI / 180.0, Eigen::Vector3d::UnitZ()) *
                                  (poses[0].linear() * PitchedUp());
  s.start.planar.floor_height_m = 0.02;
  options.num_fixed_poses = 1;
  ExpectSameSolution(Solve(s.start, options, BaSolver::kCeres),
                     Solve(s.start, options, BaSolver::kSchurLm));
}

TEST(BundleAdjustmentBackendTest, SolverNames) {
  EXPECT_STREQ(ToString(BaSolver::kCeres), "ceres");
  EXPECT_STREQ(ToString(BaSolver::kSchurLm), "schur_lm");
  EXPECT_EQ(BundleAdjustmentOptions().solver, BaSolver::kSchurLm);
}

}  // namespace
}  // namespace vo
