// The two bundle-adjustment backends (vo/bundle_adjustment.h: Ceres, the reference, and the
// hand-written Schur LM) minimise the same cost with the same trust-region rules: their iterates
// differ by rounding only, so the optimum, the iteration count, the termination, the problem's
// size and the outlier flags are the same. Shared by bundle_adjustment_test.cc and
// ba_rotation_prior_test.cc.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/test_util.h"
#include "vo/bundle_adjustment.h"

namespace vo {
namespace test {

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
