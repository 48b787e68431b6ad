// Tests of vo/back_end.h on exact synthetic observations: the initial pose's blend with the
// prior (its weight, none for a few-point motion or without a prior), the window's planar prior
// built from the vehicle's geometry (off unless every condition holds, the σ in radians, the flat
// floor only on a floor found), a window of exact frames that the bundle adjustment leaves at
// the truth with the motion from the reference exact, a perturbed newest pose pulled back, a
// reference outside the window refused, and the options' validation.
#include "vo/back_end.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/motion_model.h"

namespace vo {
namespace {

using test::TestCamera;

using test::OneToOneMatches;
Eigen::Isometry3d TruePose(int i) { return test::ForwardPose(i); }
std::vector<Feature> FeaturesOf(int i, const StereoCamera& cam) {
  return test::ForwardFrameFeatures(i, cam);
}

Eigen::Isometry3d Step(double x, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).matrix();
  T.translation() = Eigen::Vector3d(x, 0.0, 0.0);
  return T;
}

TEST(BackEndTest, InitialMotionBlendsThePriorByTheMissingSupport) {
  BackEndOptions o;  // prior_weight 0.5
  const Eigen::Isometry3d measured = Step(1.0, 0.0);
  const Eigen::Isometry3d prior = Step(0.0, 0.0);
  // 60 % inliers: the prior weighs 0.5 · 0.4 = 0.2, the translation 0.8 m.
  const Eigen::Isometry3d blended = InitialMotion(o, measured, &prior, 0.6, false);
  EXPECT_NEAR(blended.translation().x(), 0.8, 1e-15);
  EXPECT_TRUE(blended.isApprox(Blend(measured, prior, 0.5 * (1.0 - 0.6)), 0.0));
  // Every match an inlier (and a ratio above 1, clamped): the measured motion.
  EXPECT_TRUE(InitialMotion(o, measured, &prior, 1.5, false).isApprox(measured, 0.0));
  // A few-point motion already is the prior's fit; without a prior nothing to blend.
  EXPECT_TRUE(InitialMotion(o, measured, &prior, 0.1, true).isApprox(measured, 0.0));
  EXPECT_TRUE(InitialMotion(o, measured, nullptr, 0.1, false).isApprox(measured, 0.0));
  // prior_weight 1 and no inlier: the prior.
  o.prior_weight = 1.0;
  EXPECT_NEAR(InitialMotion(o, measured, &prior, 0.0, false).translation().norm(), 0.0, 1e-15);
}

TEST(BackEndTest, PlanarPriorOnlyForAVehicleWithItsUpAndTheFlatFloorOnlyOnAFloor) {
  BackEndOptions o;
  o.vehicle_planar.enabled = true;
  o.flat_floor.enabled = true;
  VehicleGeometry g;
  g.vehicle = true;
  g.up_known = true;
  g.up_cam = Eigen::Vector3d(0.0, -1.0, 0.0);
  g.R_world_cam0_initial = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).matrix();
  g.floor_found = true;
  g.axle_behind_camera_m = 0.15;
  PlanarMotionPrior p = WindowPlanarPrior(o, g);
  ASSERT_TRUE(p.enabled);
  EXPECT_EQ(p.up_cam, g.up_cam);
  EXPECT_EQ(p.axle_behind_camera_m, 0.15);
  EXPECT_DOUBLE_EQ(p.tilt_sigma_rad, 0.1 * M_PI / 180.0);
  EXPECT_EQ(p.lift_sigma_m, 0.002);
  EXPECT_EQ(p.slip_sigma_m, 0.002);
  EXPECT_TRUE(p.flat_floor);
  // The floor's up is R · up_cam: the camera's -y turned by +90° about x, the world's -z.
  EXPECT_TRUE(p.floor_up_world.isApprox(Eigen::Vector3d(0.0, 0.0, -1.0), 1e-15));
  EXPECT_EQ(p.floor_height_m, 0.0);
  EXPECT_DOUBLE_EQ(p.floor_tilt_sigma_rad, 0.3 * M_PI / 180.0);
  EXPECT_EQ(p.floor_height_sigma_m, 0.01);

  g.floor_found = false;  // an up from the ceiling: planar, not flat
  p = WindowPlanarPrior(o, g);
  EXPECT_TRUE(p.enabled);
  EXPECT_FALSE(p.flat_floor);
  for (int off = 0; off < 3; ++off) {
    BackEndOptions o2 = o;
    VehicleGeometry g2 = g;
    if (off == 0) o2.vehicle_planar.enabled = false;
    if (off == 1) g2.vehicle = false;
    if (off == 2) g2.up_known = false;
    p = WindowPlanarPrior(o2, g2);
    EXPECT_FALSE(p.enabled) << off;
    EXPECT_FALSE(p.flat_floor) << off;
  }
}

TEST(BackEndTest, ExactFramesStayAtTheTruthAndThePerturbedNewestIsPulledBack) {
  const StereoCamera cam = TestCamera();
  BackEndOptions o;
  o.window_frames = 3;
  BackEnd back_end(o);
  std::vector<Feature> f0 = FeaturesOf(0, cam);
  ASSERT_TRUE(back_end.Start(0, &f0, TruePose(0)).ok());
  for (int i = 1; i <= 3; ++i) {
    std::vector<Feature> f = FeaturesOf(i, cam);
    // The measured motion exact; frame 3's 2 cm off sideways, with no prior to blend.
    Eigen::Isometry3d measured = TruePose(i - 1).inverse() * TruePose(i);
    if (i == 3) measured.translation().x() += 0.02;
    const BackEndAdd add =
        back_end.Add(i, i - 1, &f, OneToOneMatches(f.size()), measured, nullptr, 1.0, false);
    ASSERT_TRUE(add.update.ok()) << add.update.message;
    EXPECT_TRUE(add.T_ref_curr_initial.isApprox(measured, 0.0));
    EXPECT_TRUE(add.T_world_curr.isApprox(*back_end.Pose(i - 1) * measured, 1e-15));
    const WindowRefinement r = back_end.Refine(cam, i, VehicleGeometry());
    ASSERT_TRUE(r.ran) << i << " " << r.message;
    EXPECT_FALSE(r.rejected);
    EXPECT_LT((back_end.Pose(i)->translation() - TruePose(i).translation()).norm(), 1e-6) << i;
    const Eigen::Isometry3d motion =
        back_end.MotionFromReference(i - 1, *back_end.Pose(i), Eigen::Isometry3d::Identity());
    EXPECT_NEAR(motion.translation().z(), 0.1, 1e-6) << i;
    EXPECT_NEAR(motion.translation().x(), 0.0, 1e-6) << i;
  }
  EXPECT_EQ(back_end.Pose(0), nullptr);  // 3 frames kept: 1, 2, 3
  EXPECT_EQ(back_end.tracks().window_frame_ids().size(), 3u);
  // The reference left the window: the fallback.
  const Eigen::Isometry3d fallback = Step(5.0, 0.0);
  EXPECT_TRUE(back_end.MotionFromReference(0, TruePose(3), fallback).isApprox(fallback, 0.0));
  // A frame against a reference outside the window is refused, the window unchanged.
  std::vector<Feature> f4 = FeaturesOf(4, cam);
  const BackEndAdd refused =
      back_end.Add(4, 0, &f4, OneToOneMatches(f4.size()), Step(0.0, 0.0), nullptr, 1.0, false);
  EXPECT_FALSE(refused.update.ok());
  EXPECT_EQ(refused.update.message, "the reference frame has no pose in the window");
  EXPECT_EQ(back_end.Pose(4), nullptr);
}

TEST(BackEndTest, BadOptionsAreRefusedByName) {
  using O = BackEndOptions;
  test::ExpectOptionsRefuseBadFields<O>({
      {"ba: ", [](O* o) { o->ba.num_fixed_poses = 0; }},
      {"window_frames must be in [3, 10], got 11", [](O* o) { o->window_frames = 11; }},
      {"ba.num_fixed_poses (3) must be < window_frames (3)",
       [](O* o) {
         o->window_frames = 3;
         o->ba.num_fixed_poses = 3;
       }},
      {"prior_weight must be in [0, 1], got 1.5", [](O* o) { o->prior_weight = 1.5; }},
      {"max_correction_m", [](O* o) { o->max_correction_m = 0.0; }},
      {"max_points must be >= 0 (0 = no limit), got -1", [](O* o) { o->max_points = -1; }},
      {"vehicle_planar", [](O* o) { o->vehicle_planar.slip_sigma_m = 0.0; }},
      {"flat_floor", [](O* o) { o->flat_floor.height_sigma_m = NAN; }},
  });
}

}  // namespace
}  // namespace vo
