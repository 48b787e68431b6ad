// The two bundle-adjustment backends (vo/bundle_adjustment.h: Ceres, the reference, and the
// hand-written Schur LM) minimise the same cost with the same trust-region rules: their iterates
// differ by rounding only, so the optimum, the iteration count, the termination, the problem's
// size and the outlier flags are the same. Shared by bundle_adjustment_test.cc and
// ba_rotation_prior_test.cc.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/bundle_adjustment.h"
#include "vo/camera.h"
#include "vo/ransac.h"  // vo::SplitMix64

namespace vo {
namespace test {

// The point p_world seen by the rectified stereo camera at each of T_world_cam0 (frames where it
// projects in front of both cameras, and with inside_image within both images): observations
// of point point_index with pixel noise of sigma_px, one vertical noise for both images.
inline std::vector<BaObservation> NoisyStereoObservations(
    const StereoCamera& cam, const std::vector<Eigen::Isometry3d>& T_world_cam0,
    const Eigen::Vector3d& p_world, int point_index, double sigma_px, bool inside_image,
    SplitMix64* rng) {
  auto in_image = [&](const Eigen::Vector2d& uv) {
    return uv.x() >= 0.0 && uv.y() >= 0.0 && uv.x() <= cam.width - 1.0 &&
           uv.y() <= cam.height - 1.0;
  };
  std::vector<BaObservation> obs;
  for (size_t i = 0; i < T_world_cam0.size(); ++i) {
    const Eigen::Vector3d p_cam0 = T_world_cam0[i].inverse() * p_world;
    Eigen::Vector2d l, r;
    if (!cam.ProjectLeft(p_cam0, &l) || !cam.ProjectRight(p_cam0, &r)) continue;
    if (inside_image && (!in_image(l) || !in_image(r))) continue;
    BaObservation o;
    o.frame_index = static_cast<int>(i);
    o.point_index = point_index;
    const double v_noise = sigma_px * Normal(rng);  // rectified: one v for both images
    o.uv_left_px = l + Eigen::Vector2d(sigma_px * Normal(rng), v_noise);
    o.has_right = true;
    o.uv_right_px = r + Eigen::Vector2d(sigma_px * Normal(rng), v_noise);
    obs.push_back(o);
  }
  return obs;
}

constexpr double kBackendCostRelTol = 1e-10;  // relative final-cost difference
constexpr double kBackendTolRad = 1e-9;       // pose rotation difference
constexpr double kBackendTolM = 1e-9;         // pose translation difference (metres)
// Point difference (metres): points up to 10 m, whose depth the 0.12 m baseline conditions
// poorly, amplify the rounding differences most (1.2e-8 m seen without a robust loss).
constexpr double kBackendPointTolM = 1e-7;

inline void ExpectSameSolution(const BundleAdjustmentSummary& ceres,
                               const BundleAdjustmentSummary& lm) {
  ASSERT_TRUE(ceres.ok()) << ceres.message;
  ASSERT_TRUE(lm.ok()) << lm.message;
  EXPECT_NEAR(lm.initial_cost, ceres.initial_cost, kBackendCostRelTol * ceres.initial_cost);
  EXPECT_NEAR(lm.final_cost, ceres.final_cost, kBackendCostRelTol * ceres.final_cost + 1e-20);
  EXPECT_EQ(lm.num_iterations, ceres.num_iterations);
  EXPECT_EQ(lm.converged, ceres.converged);
  EXPECT_EQ(lm.num_residual_blocks, ceres.num_residual_blocks);
  EXPECT_EQ(lm.num_rotation_priors, ceres.num_rotation_priors);
  EXPECT_EQ(lm.point_optimized, ceres.point_optimized);
  EXPECT_EQ(lm.observation_is_outlier, ceres.observation_is_outlier);
  ASSERT_EQ(lm.T_world_cam0.size(), ceres.T_world_cam0.size());
  for (size_t i = 0; i < lm.T_world_cam0.size(); ++i)
    EXPECT_THAT(lm.T_world_cam0[i],
                vobench_test::IsNearPose(ceres.T_world_cam0[i], kBackendTolRad, kBackendTolM))
        << "frame " << i;
  ASSERT_EQ(lm.points_world.size(), ceres.points_world.size());
  for (size_t j = 0; j < lm.points_world.size(); ++j)
    EXPECT_LT((lm.points_world[j] - ceres.points_world[j]).norm(), kBackendPointTolM)
        << "point " << j;
  EXPECT_NEAR(lm.rms_inlier_reprojection_after_px, ceres.rms_inlier_reprojection_after_px, 1e-9);
}

}  // namespace test
}  // namespace vo
