#include "vo/ransac.h"

#include <ceres/rotation.h>
#include <ceres/tiny_solver.h>
#include <ceres/tiny_solver_autodiff_function.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <climits>
#include <cmath>
#include <cstdio>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

using vobench_test::IsNearPose;

// Noise-free inliers: the task's bound (1e-3 rad, 1 mm); the estimate is exact to rounding.
constexpr double kExactTolRad = 1e-3;
constexpr double kExactTolM = 1e-3;
// 0.5 px Gaussian noise on every pixel coordinate (both frames, both images), depths 1.5–6 m,
// 180 inliers, two-frame refinement: the translation is good to a few millimetres.
constexpr double kNoisyTolRad = 2e-3;
constexpr double kNoisyTolM = 5e-3;
constexpr double kPixelSigma = 0.5;
// With that noise the per-image error of an inlier combines the current pixel noise and the
// previous disparity noise (σ ≈ 0.5–0.9 px per coordinate): 3 px keeps nearly all inliers.
constexpr double kNoisyThresholdPx = 3.0;

using test::Normal;

using test::TestCamera;

// Camera motion between the frames: a bit of yaw, pitch, roll and 25 cm mostly forward.
Eigen::Isometry3d TrueMotion() {
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();
  T_prev_curr.linear() = (Eigen::AngleAxisd(0.08, Eigen::Vector3d::UnitY()) *
                          Eigen::AngleAxisd(-0.02, Eigen::Vector3d::UnitX()) *
                          Eigen::AngleAxisd(0.015, Eigen::Vector3d::UnitZ()))
                             .toRotationMatrix();
  T_prev_curr.translation() = Eigen::Vector3d(0.04, -0.01, 0.25);
  return T_prev_curr;
}

bool InImage(const StereoCamera& cam, const Eigen::Vector2d& uv) {
  return uv.x() >= 0.0 && uv.y() >= 0.0 && uv.x() <= cam.width - 1.0 && uv.y() <= cam.height - 1.0;
}

struct Synthetic {
  std::vector<StereoCorrespondence> corr;
  std::vector<bool> is_inlier;
};

// n correspondences, a share `outlier_ratio` of them with a random current observation.
// Inliers: a point visible in both stereo pairs; observations with Gaussian pixel noise
// (sigma_px) on u_left, v, u_right in both frames; p_prev triangulated from the noisy
// previous observation. Track ages: inliers and outliers alike get random ages in [0, 5]
// unless old_inliers is set, in which case the first `old_inliers` inliers get age 10.
Synthetic MakeData(uint64_t seed, int n, double outlier_ratio, double sigma_px,
                   int old_inliers = 0) {
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_curr_prev = TrueMotion().inverse();
  SplitMix64 rng(seed);
  Synthetic s;
  const int num_outliers = static_cast<int>(std::round(outlier_ratio * n));
  int made_old = 0;
  while (static_cast<int>(s.corr.size()) < n) {
    // A pixel and depth in the previous left image.
    const Eigen::Vector2d uv_prev(rng.Uniform() * (cam.width - 1),
                                  rng.Uniform() * (cam.height - 1));
    const double z = 1.5 + 4.5 * rng.Uniform();
    const Eigen::Vector3d p_prev_true = cam.BackprojectDepth(uv_prev.x(), uv_prev.y(), z);
    const Eigen::Vector3d p_curr_true = T_curr_prev * p_prev_true;
    Eigen::Vector2d l, r, lp = Eigen::Vector2d::Zero(), rp = Eigen::Vector2d::Zero();
    if (!cam.ProjectLeft(p_curr_true, &l) || !cam.ProjectRight(p_curr_true, &r) ||
        !InImage(cam, l) || !InImage(cam, r))
      continue;
    cam.ProjectLeft(p_prev_true, &lp);
    cam.ProjectRight(p_prev_true, &rp);
    if (!InImage(cam, rp)) continue;
    StereoCorrespondence c;
    // Previous frame: noisy observation, triangulated.
    const double u_l_prev = lp.x() + sigma_px * Normal(&rng);
    const double v_prev = lp.y() + sigma_px * Normal(&rng);
    const double u_r_prev = rp.x() + sigma_px * Normal(&rng);
    c.p_prev_cam0 = cam.Backproject(u_l_prev, v_prev, u_l_prev - u_r_prev);
    c.uv_prev_px = Eigen::Vector2d(u_l_prev, v_prev);
    c.disparity_prev_px = u_l_prev - u_r_prev;
    const bool outlier = static_cast<int>(s.corr.size()) < num_outliers;
    if (outlier) {
      c.uv_curr_px =
          Eigen::Vector2d(rng.Uniform() * (cam.width - 1), rng.Uniform() * (cam.height - 1));
      c.disparity_curr_px = 2.0 + 30.0 * rng.Uniform();
    } else {
      c.uv_curr_px = l + sigma_px * Eigen::Vector2d(Normal(&rng), Normal(&rng));
      c.disparity_curr_px = c.uv_curr_px.x() - (r.x() + sigma_px * Normal(&rng));
    }
    if (!(c.disparity_curr_px > 0.5) || !(u_l_prev - u_r_prev > 0.5)) continue;
    c.track_age = static_cast<int>(rng.UniformIndex(6));
    if (!outlier && made_old < old_inliers) {
      c.track_age = 10;
      ++made_old;
    }
    s.corr.push_back(c);
    s.is_inlier.push_back(!outlier);
  }
  // Shuffle (Fisher-Yates) so that outliers are not all first.
  for (int i = n - 1; i > 0; --i) {
    const int j = static_cast<int>(rng.UniformIndex(i + 1));
    std::swap(s.corr[i], s.corr[j]);
    const bool tmp = s.is_inlier[i];
    s.is_inlier[i] = s.is_inlier[j];
    s.is_inlier[j] = tmp;
  }
  return s;
}

TEST(RansacTest, RequiredIterations) {
  // log(0.01) / log(1 − 0.5³) = 34.5 → 35.
  EXPECT_EQ(RansacRequiredIterations(0.5, 3, 0.99), 35);
  EXPECT_EQ(RansacRequiredIterations(1.0, 3, 0.99), 0);
  EXPECT_EQ(RansacRequiredIterations(0.0, 3, 0.99), INT_MAX);
  // More confidence or fewer inliers need more iterations.
  EXPECT_GT(RansacRequiredIterations(0.5, 3, 0.999), 35);
  EXPECT_GT(RansacRequiredIterations(0.4, 3, 0.99), 35);
}

TEST(RansacTest, RecoversMotionWith40PercentOutliersNoiseFree) {
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const Synthetic data = MakeData(seed, 200, 0.4, 0.0);
    const RansacResult r = EstimateMotionRansac(TestCamera(), data.corr);
    ASSERT_TRUE(r.ok()) << "seed " << seed << ": " << r.message;
    EXPECT_THAT(r.T_prev_curr, IsNearPose(TrueMotion(), kExactTolRad, kExactTolM))
        << "seed " << seed;
    EXPECT_EQ(r.inlier_mask, data.is_inlier) << "seed " << seed;
    EXPECT_EQ(r.num_inliers, 120);
    EXPECT_LT(r.rms_reprojection_px, 1e-6);
    EXPECT_LE(r.num_iterations, RansacOptions().max_iterations);
    EXPECT_GE(r.num_iterations, RansacOptions().min_iterations);
  }
}

TEST(RansacTest, RecoversMotionWith40PercentOutliersAndHalfPixelNoise) {
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const Synthetic data = MakeData(100 + seed, 300, 0.4, kPixelSigma);
    RansacOptions options;
    options.inlier_threshold_px = kNoisyThresholdPx;
    const RansacResult r = EstimateMotionRansac(TestCamera(), data.corr, options);
    ASSERT_TRUE(r.ok()) << "seed " << seed << ": " << r.message;
    EXPECT_THAT(r.T_prev_curr, IsNearPose(TrueMotion(), kNoisyTolRad, kNoisyTolM))
        << "seed " << seed;
    // No outlier accepted; nearly all inliers kept.
    int false_inliers = 0, true_inliers = 0;
    for (size_t i = 0; i < data.corr.size(); ++i) {
      if (r.inlier_mask[i] && !data.is_inlier[i]) ++false_inliers;
      if (r.inlier_mask[i] && data.is_inlier[i]) ++true_inliers;
    }
    EXPECT_EQ(false_inliers, 0) << "seed " << seed;
    EXPECT_GT(true_inliers, 0.9 * 180) << "seed " << seed;
    // The rms is taken with the fixed, noisy p_prev: current noise + previous depth error.
    EXPECT_GT(r.rms_reprojection_px, 0.5);
    EXPECT_LT(r.rms_reprojection_px, 1.5);
  }
}

TEST(RansacTest, NonlinearRefinementDoesNotIncreaseReprojectionError) {
  // With fixed points the refinement minimises exactly the current-frame reprojection error
  // that is measured here, starting from the Horn estimate.
  const Synthetic data = MakeData(42, 300, 0.3, kPixelSigma);
  RansacOptions fixed_points;
  fixed_points.inlier_threshold_px = kNoisyThresholdPx;
  fixed_points.refine_points = false;
  RansacOptions no_refine = fixed_points;
  no_refine.refine_nonlinear = false;
  const RansacResult plain = EstimateMotionRansac(TestCamera(), data.corr, no_refine);
  const RansacResult refined = EstimateMotionRansac(TestCamera(), data.corr, fixed_points);
  ASSERT_TRUE(plain.ok() && refined.ok());
  EXPECT_FALSE(plain.refined);
  EXPECT_TRUE(refined.refined);
  // Compare on the inliers of the unrefined estimate.
  auto rms_on = [&](const Eigen::Isometry3d& T_prev_curr, const std::vector<bool>& mask) {
    double sq = 0.0;
    int count = 0;
    Eigen::Vector2d el, er;
    for (size_t i = 0; i < data.corr.size(); ++i) {
      if (!mask[i]) continue;
      EXPECT_TRUE(StereoReprojectionErrors(TestCamera(), T_prev_curr.inverse(), data.corr[i], 1e-3,
                                           &el, &er));
      sq += el.squaredNorm() + er.squaredNorm();
      count += 2;
    }
    return std::sqrt(sq / count);
  };
  EXPECT_LE(rms_on(refined.T_prev_curr, plain.inlier_mask),
            rms_on(plain.T_prev_curr, plain.inlier_mask) + 1e-9);
}

// Mean translation error (metres) over 10 noisy data sets.
double MeanTranslationError(const RansacOptions& options) {
  double sum = 0.0;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const Synthetic data = MakeData(200 + seed, 300, 0.4, kPixelSigma);
    const RansacResult r = EstimateMotionRansac(TestCamera(), data.corr, options);
    EXPECT_TRUE(r.ok());
    sum += (r.T_prev_curr.translation() - TrueMotion().translation()).norm();
  }
  return sum / 10.0;
}

// The final two-frame refinement (free points) beats holding the noisy p_prev fixed, which
// beats stopping after the sampling loop (LO fits + depth-weighted Horn refit), which beats
// plain Horn refits without LO (3D errors weighted equally: far points dominate).
TEST(RansacTest, TwoFrameRefinementIsMoreAccurate) {
  RansacOptions two_frame;
  two_frame.inlier_threshold_px = kNoisyThresholdPx;
  RansacOptions fixed_points = two_frame;
  fixed_points.refine_points = false;
  RansacOptions no_refinement = two_frame;
  no_refinement.refine_nonlinear = false;
  RansacOptions plain_horn = no_refinement;
  plain_horn.local_optimization_iterations = 0;
  plain_horn.refit_depth_weighted = false;
  const double e_two_frame = MeanTranslationError(two_frame);
  const double e_fixed = MeanTranslationError(fixed_points);
  const double e_no_refinement = MeanTranslationError(no_refinement);
  const double e_plain_horn = MeanTranslationError(plain_horn);
  std::printf(
      "mean translation error: two-frame %.2f mm, fixed points %.2f mm, "
      "no final refinement %.2f mm, plain Horn %.2f mm\n",
      1e3 * e_two_frame, 1e3 * e_fixed, 1e3 * e_no_refinement, 1e3 * e_plain_horn);
  EXPECT_LT(e_two_frame, kNoisyTolM);
  EXPECT_LT(e_two_frame, e_fixed);
  EXPECT_LT(e_fixed, e_no_refinement);
  EXPECT_LT(e_no_refinement, e_plain_horn);
}

// LO-RANSAC: the best model's support reaches the true inlier ratio at once, so the adaptive
// count stops much earlier than with raw 3-point Horn models.
TEST(RansacTest, LocalOptimizationShortensTheSearch) {
  const Synthetic data = MakeData(300, 300, 0.4, kPixelSigma);
  RansacOptions with_lo;
  with_lo.inlier_threshold_px = kNoisyThresholdPx;
  RansacOptions without_lo = with_lo;
  without_lo.local_optimization_iterations = 0;
  const RansacResult a = EstimateMotionRansac(TestCamera(), data.corr, with_lo);
  const RansacResult b = EstimateMotionRansac(TestCamera(), data.corr, without_lo);
  ASSERT_TRUE(a.ok() && b.ok());
  std::printf("iterations: with LO %d, without %d\n", a.num_iterations, b.num_iterations);
  EXPECT_LT(a.num_iterations, b.num_iterations);
  EXPECT_THAT(a.T_prev_curr, IsNearPose(TrueMotion(), kNoisyTolRad, kNoisyTolM));
}

TEST(RansacTest, SameSeedGivesTheSameResult) {
  const Synthetic data = MakeData(7, 250, 0.4, kPixelSigma);
  RansacOptions options;
  options.seed = 1234;
  const RansacResult a = EstimateMotionRansac(TestCamera(), data.corr, options);
  const RansacResult b = EstimateMotionRansac(TestCamera(), data.corr, options);
  ASSERT_TRUE(a.ok());
  EXPECT_TRUE(a.T_prev_curr.matrix() == b.T_prev_curr.matrix());  // bit for bit
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  EXPECT_EQ(a.num_iterations, b.num_iterations);
  EXPECT_EQ(a.rms_reprojection_px, b.rms_reprojection_px);
}

TEST(RansacTest, SeedsWithTheOldestTracks) {
  // 75% outliers overall, but the 40 oldest tracks are all inliers: the seeded phase finds
  // the motion at once.
  const Synthetic data = MakeData(9, 200, 0.75, 0.0, /*old_inliers=*/40);
  RansacOptions options;
  options.num_seeded_iterations = 10;
  options.stable_pool_fraction = 0.2;  // 40 of 200: exactly the age-10 tracks
  options.min_iterations = 10;
  options.max_iterations = 10;  // only the seeded iterations run
  const RansacResult r = EstimateMotionRansac(TestCamera(), data.corr, options);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.stable_pool_size, 40);
  EXPECT_EQ(r.num_seeded_iterations, 10);
  EXPECT_EQ(r.num_inliers, 50);
  EXPECT_THAT(r.T_prev_curr, IsNearPose(TrueMotion(), kExactTolRad, kExactTolM));
}

TEST(RansacTest, StablePoolIsClosedUnderEqualAges) {
  Synthetic data = MakeData(10, 100, 0.2, 0.0);
  for (StereoCorrespondence& c : data.corr) c.track_age = 3;  // all equal: no seeding
  const RansacResult r = EstimateMotionRansac(TestCamera(), data.corr);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.stable_pool_size, 0);
  EXPECT_EQ(r.num_seeded_iterations, 0);
  // Ages 5 for 10 correspondences, 4 for 20, the rest 0: a pool of 25 (fraction 0.25 of 100)
  // would split the age-4 group, so it is extended to the 30 oldest.
  for (size_t i = 0; i < data.corr.size(); ++i)
    data.corr[i].track_age = i < 10 ? 5 : i < 30 ? 4 : 0;
  RansacOptions options;
  options.stable_pool_fraction = 0.25;
  const RansacResult r2 = EstimateMotionRansac(TestCamera(), data.corr, options);
  ASSERT_TRUE(r2.ok());
  EXPECT_EQ(r2.stable_pool_size, 30);
}

TEST(RansacTest, TooFewMatches) {
  const Synthetic data = MakeData(11, 5, 0.0, 0.0);
  const RansacResult r = EstimateMotionRansac(TestCamera(), data.corr);  // min_inliers = 6
  EXPECT_EQ(r.status, RansacResult::Status::kTooFewMatches);
  EXPECT_EQ(r.inlier_mask.size(), 5u);
  EXPECT_EQ(EstimateMotionRansac(TestCamera(), {}).status, RansacResult::Status::kTooFewMatches);
}

TEST(RansacTest, AllOutliersGiveNoConsensus) {
  const Synthetic data = MakeData(12, 100, 1.0, 0.0);
  const RansacResult r = EstimateMotionRansac(TestCamera(), data.corr);
  EXPECT_EQ(r.status, RansacResult::Status::kNoConsensus) << r.num_inliers;
  EXPECT_EQ(r.num_iterations, RansacOptions().max_iterations);
}

TEST(RansacTest, InvalidInput) {
  Synthetic data = MakeData(13, 20, 0.0, 0.0);
  data.corr[3].disparity_curr_px = 0.0;
  EXPECT_EQ(EstimateMotionRansac(TestCamera(), data.corr).status,
            RansacResult::Status::kInvalidInput);
  RansacOptions bad;
  bad.confidence = 1.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("confidence"));
  StereoCamera no_baseline = TestCamera();
  no_baseline.baseline_m = 0.0;
  EXPECT_EQ(EstimateMotionRansac(no_baseline, MakeData(13, 20, 0.0, 0.0).corr).status,
            RansacResult::Status::kInvalidInput);
}

TEST(RansacTest, MakeStereoCorrespondencesSkipsFeaturesWithoutDepth) {
  const StereoCamera cam = TestCamera();
  std::vector<Feature> prev(3), curr(3);
  for (int i = 0; i < 3; ++i) {
    prev[i].uv_px = Eigen::Vector2d(100 + 10 * i, 100);
    prev[i].disparity_px = 10.0;
    prev[i].p_cam0 = cam.Backproject(prev[i].uv_px.x(), prev[i].uv_px.y(), 10.0);
    prev[i].track_age = i;
    curr[i] = prev[i];
  }
  curr[1].disparity_px = -1.0;  // no depth
  const std::vector<Match> matches = {{0, 2, 1.0}, {1, 1, 1.0}, {2, 0, 1.0}, {5, 0, 1.0}};
  std::vector<int> index;
  const std::vector<StereoCorrespondence> c =
      MakeStereoCorrespondences(prev, curr, matches, &index);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(index, (std::vector<int>{0, 2}));
  EXPECT_EQ(c[0].p_prev_cam0, prev[0].p_cam0);
  EXPECT_EQ(c[0].uv_curr_px, curr[2].uv_px);
  EXPECT_EQ(c[0].disparity_curr_px, 10.0);
  EXPECT_EQ(c[1].track_age, 2);
}

// The local fit as first written: ceres::TinySolverAutoDiffFunction over a functor rotating
// each point with ceres::AngleAxisRotatePoint, its constants as Jets. FitReprojectionFixedPoints
// computes the rotation's terms once per evaluation and its constants as doubles; the fit must
// not change by a bit.
struct ReferenceFixedPointsFunctor {
  const StereoCamera* cam;
  const std::vector<StereoCorrespondence>* corr;
  const std::vector<int>* indices;

  int NumResiduals() const { return 4 * static_cast<int>(indices->size()); }

  template <typename T>
  bool operator()(const T* x, T* residuals) const {
    for (size_t k = 0; k < indices->size(); ++k) {
      const StereoCorrespondence& c = (*corr)[(*indices)[k]];
      const T p_prev[3] = {T(c.p_prev_cam0.x()), T(c.p_prev_cam0.y()), T(c.p_prev_cam0.z())};
      T p[3];
      ceres::AngleAxisRotatePoint(x, p_prev, p);
      const T px = p[0] + x[3], py = p[1] + x[4], pz = p[2] + x[5];
      if (!(pz > T(1e-9))) return false;
      const T inv_z = T(1.0) / pz;
      T* r = residuals + 4 * k;
      r[0] = T(cam->fx_px) * px * inv_z + T(cam->cx_px) - T(c.uv_curr_px.x());
      r[1] = T(cam->fy_px) * py * inv_z + T(cam->cy_px) - T(c.uv_curr_px.y());
      r[2] = T(cam->fx_px) * (px - T(cam->baseline_m)) * inv_z + T(cam->cx_px) -
             T(c.uv_curr_px.x() - c.disparity_curr_px);
      r[3] = r[1];
    }
    return true;
  }
};

bool ReferenceFit(const StereoCamera& cam, const std::vector<StereoCorrespondence>& corr,
                  const std::vector<int>& indices, int max_iterations, Eigen::Isometry3d* T) {
  using Function =
      ceres::TinySolverAutoDiffFunction<ReferenceFixedPointsFunctor, Eigen::Dynamic, 6>;
  const ReferenceFixedPointsFunctor functor{&cam, &corr, &indices};
  Function function(functor);
  Eigen::Matrix<double, 6, 1> x;
  const Eigen::AngleAxisd aa(T->linear());
  x.head<3>() = aa.angle() * aa.axis();
  x.tail<3>() = T->translation();
  ceres::TinySolver<Function> solver;
  solver.options.max_num_iterations = max_iterations;
  solver.Solve(function, &x);
  if (!x.allFinite()) return false;
  const double angle = x.head<3>().norm();
  T->setIdentity();
  if (angle > 0.0) T->linear() = Eigen::AngleAxisd(angle, x.head<3>() / angle).toRotationMatrix();
  T->translation() = x.tail<3>();
  return true;
}

TEST(RansacTest, TheLocalFitIsCeresAutoDiffFitBitForBit) {
  const StereoCamera cam = TestCamera();
  int compared = 0;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    // Noisy inliers and outliers (the fit sees both, as LO-RANSAC's may).
    const Synthetic data = MakeData(seed, 40, seed % 3 == 0 ? 0.3 : 0.0, 0.5);
    std::vector<int> indices;
    for (int i = 0; i < static_cast<int>(data.corr.size()); ++i) indices.push_back(i);
    // Starts: the truth moved a little, the identity (a rotation near zero: Ceres' first-order
    // branch below 1.5e-8 rad), and one a few degrees off.
    const Eigen::Isometry3d truth = TrueMotion().inverse();
    Eigen::Isometry3d tiny = Eigen::Isometry3d::Identity();
    tiny.linear() =
        Eigen::AngleAxisd(1e-9, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    Eigen::Isometry3d off = truth;
    off.linear() =
        Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix() * off.linear();
    off.translation() += Eigen::Vector3d(0.02, 0.0, -0.05);
    for (const Eigen::Isometry3d& start : {truth, tiny, off}) {
      for (int iterations : {1, 3, 10}) {
        Eigen::Isometry3d fast = start, reference = start;
        const bool fast_ok = FitReprojectionFixedPoints(cam, data.corr, indices, iterations, &fast);
        const bool reference_ok = ReferenceFit(cam, data.corr, indices, iterations, &reference);
        ASSERT_EQ(fast_ok, reference_ok) << "seed " << seed;
        if (!fast_ok) continue;
        for (int r = 0; r < 4; ++r)
          for (int c = 0; c < 4; ++c)
            ASSERT_EQ(fast.matrix()(r, c), reference.matrix()(r, c))
                << "seed " << seed << ", " << iterations << " iterations, entry " << r << "," << c;
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 12 * 3 * 3);
}

}  // namespace
}  // namespace vo
