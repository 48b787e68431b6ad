#include "vo/motion_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/prior_motion.h"

namespace vo {
namespace {

using vobench_test::IsNearPose;
using vobench_test::RotationAngleRad;

constexpr double kDeg = M_PI / 180.0;

using test::HallwayCamera;
using test::MakePose;

Eigen::Isometry3d Motion(double yaw_deg, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = t;
  return T;
}

TEST(MotionModelTest, BlendIsSlerpAndLinear) {
  const Eigen::Isometry3d a = Motion(4.0, Eigen::Vector3d(0.0, 0.0, 0.1));
  const Eigen::Isometry3d b = Motion(20.0, Eigen::Vector3d(0.2, 0.0, 0.3));
  // w <= 0: the first motion itself, bit for bit.
  EXPECT_TRUE(Blend(a, b, 0.0).matrix() == a.matrix());
  EXPECT_TRUE(Blend(a, b, -1.0).matrix() == a.matrix());
  const Eigen::Isometry3d half = Blend(a, b, 0.5);
  EXPECT_NEAR(RotationAngleRad(half.linear(), Motion(12.0, Eigen::Vector3d::Zero()).linear()), 0.0,
              1e-12);
  EXPECT_TRUE(half.translation().isApprox(Eigen::Vector3d(0.1, 0.0, 0.2), 1e-15));
  const Eigen::Isometry3d all = Blend(a, b, 1.0);
  EXPECT_NEAR(RotationAngleRad(all.linear(), b.linear()), 0.0, 1e-12);
  EXPECT_TRUE(all.translation().isApprox(b.translation(), 1e-15));
}

TEST(MotionModelTest, RootSplitsAMotionIntoEqualFrames) {
  const Eigen::Isometry3d T = Motion(30.0, Eigen::Vector3d(0.3, 0.0, 0.6));
  EXPECT_TRUE(Root(T, 1).matrix() == T.matrix());
  EXPECT_TRUE(Root(T, 0).matrix() == T.matrix());
  const Eigen::Isometry3d r = Root(T, 3);
  EXPECT_NEAR(RotationAngleRad(r.linear(), Motion(10.0, Eigen::Vector3d::Zero()).linear()), 0.0,
              1e-12);
  EXPECT_TRUE(r.translation().isApprox(Eigen::Vector3d(0.1, 0.0, 0.2), 1e-15));
}

TEST(MotionModelTest, WorldUpInCameraIsTheWorldsZSeenFromTheCamera) {
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  // A camera looking along world x with its y down (cv axes): world z is its −y.
  T_world_cam.linear().col(0) = -Eigen::Vector3d::UnitY();
  T_world_cam.linear().col(1) = -Eigen::Vector3d::UnitZ();
  T_world_cam.linear().col(2) = Eigen::Vector3d::UnitX();
  T_world_cam.translation() = Eigen::Vector3d(5.0, 1.0, 1.2);
  EXPECT_TRUE(WorldUpInCamera(T_world_cam).isApprox(-Eigen::Vector3d::UnitY(), 1e-15));
}

TEST(MotionModelTest, ConstantVelocityTakesTheFirstMotionAndBlendsTheNextByWeight) {
  ConstantVelocity v;
  EXPECT_FALSE(v.known());
  EXPECT_TRUE(v.Prior(nullptr).matrix() == Eigen::Matrix4d::Identity());
  const Eigen::Isometry3d first = Motion(2.0, Eigen::Vector3d(0.0, 0.0, 0.05));
  v.Move(first, 0.0);  // the first measured motion is taken whatever its weight
  ASSERT_TRUE(v.known());
  EXPECT_TRUE(v.Prior(nullptr).matrix() == first.matrix());
  const Eigen::Isometry3d next = Motion(6.0, Eigen::Vector3d(0.0, 0.0, 0.09));
  v.Move(next, 0.0);  // once known, a weight of 0 leaves it
  EXPECT_TRUE(v.per_frame().matrix() == first.matrix());
  v.Move(next, 0.5);
  EXPECT_TRUE(v.per_frame().matrix() == Blend(first, next, 0.5).matrix());
  Eigen::Isometry3d bad = next;
  bad.translation().x() = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Matrix4d before = v.per_frame().matrix();
  v.Move(bad, 1.0);  // non-finite: ignored
  EXPECT_TRUE(v.per_frame().matrix() == before);
  // The caller's prior wins when finite.
  MotionPrior caller;
  caller.T_prev_curr = Motion(-3.0, Eigen::Vector3d(0.1, 0.0, 0.0));
  EXPECT_TRUE(v.Prior(&caller).matrix() == caller.T_prev_curr.matrix());
  caller.T_prev_curr = bad;
  EXPECT_TRUE(v.Prior(&caller).matrix() == before);
  v.ReplaceRotationIfKnown(Eigen::Matrix3d::Identity());
  EXPECT_TRUE(v.per_frame().linear() == Eigen::Matrix3d::Identity());
  EXPECT_TRUE((v.per_frame().translation() == before.block<3, 1>(0, 3)));
  v.SetLastMeasured(next, 7);
  EXPECT_EQ(v.last_measured_frame(), 7);
  EXPECT_TRUE(v.last_measured().matrix() == next.matrix());
  v.Reset();
  EXPECT_FALSE(v.known());
  EXPECT_EQ(v.last_measured_frame(), -1);
  v.ReplaceIfKnown(next);  // unknown: stays unknown (identity)
  EXPECT_FALSE(v.known());
  EXPECT_TRUE(v.per_frame().matrix() == Eigen::Matrix4d::Identity());
}

// The image shift a motion predicts at the image centre: f · tan(θ) for a pan θ (any depth),
// and for a sideways step b at depth z, −f · b / z.
TEST(MotionModelTest, PredictedCentreShiftIsExact) {
  const StereoCamera cam = HallwayCamera();
  const double theta = 3.0 * kDeg;
  const Eigen::Isometry3d pan =
      MakePose(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()).toRotationMatrix(),
               Eigen::Vector3d::Zero());
  // The camera turns right (+y in cv axes turns z towards x): the scene moves left.
  const Eigen::Vector2d s_far = PredictedCentreShift(cam, pan, -1.0);
  const Eigen::Vector2d s_near = PredictedCentreShift(cam, pan, 0.85);
  EXPECT_NEAR(s_far.x(), -cam.fx_px * std::tan(theta), 1e-9);
  EXPECT_NEAR(s_far.y(), 0.0, 1e-12);
  EXPECT_NEAR(s_near.x(), s_far.x(), 1e-9);
  const Eigen::Isometry3d step = MakePose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.02, 0, 0));
  EXPECT_NEAR(PredictedCentreShift(cam, step, 0.85).x(), -cam.fx_px * 0.02 / 0.85, 1e-9);
  EXPECT_NEAR(PredictedCentreShift(cam, step, -1.0).x(), 0.0, 1e-12);
}

// The ground-vehicle gate (MotionOptions::vehicle_max_weak_tilt_deg / _lift_m): a yaw about up and
// a step across it pass whatever their size; a tilt (rotation about an axis across up) or a
// lift along up passes up to its limit and not beyond, also for a pitched camera.
TEST(MotionModelTest, VehicleLikeMotionIsAYawAndAStepInThePlane) {
  for (double camera_pitch_deg : {0.0, 10.0}) {
    // The world's up in the camera frame (cv axes: y down), for a camera pitched down.
    const Eigen::Vector3d up =
        Eigen::AngleAxisd(-camera_pitch_deg * kDeg, Eigen::Vector3d::UnitX()) *
        Eigen::Vector3d(0.0, -1.0, 0.0);
    const Eigen::Vector3d across = up.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d forward = across.cross(up).normalized();
    auto motion = [&](double yaw_deg, double tilt_deg, double step_m, double lift_m) {
      return MakePose(
          (Eigen::AngleAxisd(yaw_deg * kDeg, up) * Eigen::AngleAxisd(tilt_deg * kDeg, across))
              .toRotationMatrix(),
          step_m * forward + 0.3 * step_m * across + lift_m * up);
    };
    const std::string at = "camera pitch " + std::to_string(camera_pitch_deg);
    EXPECT_TRUE(IsVehicleLike(motion(0.0, 0.0, 0.0, 0.0), up, 2.0, 0.03)) << at;
    EXPECT_TRUE(IsVehicleLike(motion(45.0, 0.0, 0.5, 0.0), up, 2.0, 0.03)) << at;
    EXPECT_TRUE(IsVehicleLike(motion(-20.0, 1.9, 0.1, 0.0), up, 2.0, 0.03)) << at;
    EXPECT_FALSE(IsVehicleLike(motion(-20.0, 2.1, 0.1, 0.0), up, 2.0, 0.03)) << at;
    EXPECT_FALSE(IsVehicleLike(motion(0.0, -9.0, 0.0, 0.0), up, 2.0, 0.03)) << at;
    EXPECT_TRUE(IsVehicleLike(motion(5.0, 0.0, 0.1, 0.029), up, 2.0, 0.03)) << at;
    EXPECT_FALSE(IsVehicleLike(motion(5.0, 0.0, 0.1, -0.031), up, 2.0, 0.03)) << at;
    EXPECT_TRUE(IsVehicleLike(motion(5.0, 0.0, 0.1, -0.031), 3.0 * up, 2.0, 0.04)) << at;
    Eigen::Isometry3d bad = motion(5.0, 0.0, 0.1, 0.0);
    bad.translation().x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(IsVehicleLike(bad, up, 2.0, 0.03)) << at;
  }
}

TEST(MotionModelTest, ImageShiftCorrectionRecoversAPan) {
  // The prior knows the translation but not the pan; the image shift of the centre point (at
  // 2 m) under the true motion gives back the true rotation.
  const StereoCamera cam = HallwayCamera();
  for (double yaw_deg : {-6.0, -1.0, 0.5, 4.0}) {
    const Eigen::Isometry3d T_true =
        MakePose(Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                 Eigen::Vector3d(0.02, 0.0, 0.04));
    const double depth_m = 2.0;
    const Eigen::Vector3d p_curr = T_true.inverse() * Eigen::Vector3d(0.0, 0.0, depth_m);
    const Eigen::Vector2d shift(cam.fx_px * p_curr.x() / p_curr.z(),
                                cam.fy_px * p_curr.y() / p_curr.z());
    const Eigen::Isometry3d T_prior = MakePose(Eigen::Matrix3d::Identity(), T_true.translation());
    const Eigen::Isometry3d T = CorrectPriorWithImageShift(cam, T_prior, shift, depth_m);
    EXPECT_THAT(T, IsNearPose(T_true, 1e-9, 1e-12)) << yaw_deg;
    // Without the depth (far away), the translation's parallax is taken as rotation.
    const Eigen::Isometry3d T_far = CorrectPriorWithImageShift(cam, T_prior, shift, -1.0);
    EXPECT_GT(RotationAngleRad(T_far.linear(), T_true.linear()), 1e-3) << yaw_deg;
  }
}

TEST(MotionModelTest, VehicleMotionFromImageShiftRecoversATurnWithTheSwing) {
  // A vehicle with its axle 0.15 m behind the camera turns in front of a wall; the prior knows
  // its forward step but not the turn. The shift of the centre point (at the wall's depth) under
  // the true motion gives back the true yaw, swing included; read as a rotation alone
  // (CorrectPriorWithImageShift) the near wall's parallax is taken as turn.
  const StereoCamera cam = HallwayCamera();
  const double axle_m = 0.15;
  for (double camera_pitch_deg : {0.0, 10.0}) {
    const Eigen::Vector3d up =
        Eigen::AngleAxisd(-camera_pitch_deg * kDeg, Eigen::Vector3d::UnitX()) *
        Eigen::Vector3d(0.0, -1.0, 0.0);
    for (double yaw_deg : {-11.0, -2.0, 0.7, 4.5}) {
      for (double forward_m : {0.0, 0.04}) {
        const Eigen::Isometry3d T_true = VehicleMotion(up, axle_m, yaw_deg * kDeg, forward_m);
        const Eigen::Isometry3d T_prior = VehicleMotion(up, axle_m, 0.0, forward_m);
        const double depth_m = 0.85;
        const Eigen::Vector3d p_curr = T_true.inverse() * Eigen::Vector3d(0.0, 0.0, depth_m);
        const Eigen::Vector2d shift(cam.fx_px * p_curr.x() / p_curr.z(),
                                    cam.fy_px * p_curr.y() / p_curr.z());
        const std::string at = "pitch " + std::to_string(camera_pitch_deg) + " yaw " +
                               std::to_string(yaw_deg) + " forward " + std::to_string(forward_m);
        const Eigen::Isometry3d T =
            VehicleMotionFromImageShift(cam, up, axle_m, T_prior, shift, depth_m);
        EXPECT_THAT(T, IsNearPose(T_true, 1e-9, 1e-10)) << at;
        const Eigen::Isometry3d T_rotation_only =
            PlanarPart(CorrectPriorWithImageShift(cam, T_prior, shift, depth_m), up);
        const double over_read =
            VehicleMotionParameters(T_rotation_only, up, axle_m).x() / (yaw_deg * kDeg);
        EXPECT_GT(over_read, 1.1) << at;  // ~1 + 0.15 / 0.85
      }
    }
    // No shift information (non-finite): the prior comes back.
    const Eigen::Isometry3d T_prior = VehicleMotion(up, axle_m, 0.02, 0.03);
    EXPECT_THAT(VehicleMotionFromImageShift(cam, up, axle_m, T_prior,
                                            Eigen::Vector2d(std::nan(""), 0.0), 0.85),
                IsNearPose(T_prior, 0.0, 0.0));
  }
}

}  // namespace
}  // namespace vo
