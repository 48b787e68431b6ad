#include "vo/initial_orientation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/ransac.h"  // vo::SplitMix64

namespace vo {
namespace {

using vobench_test::RotationAngleRad;

constexpr double kDeg = M_PI / 180.0;
constexpr double kExactTolRad = 1e-6;  // noise-free planes: the orientation is exact

// Hallway frame (x along the corridor, y left, z up; floor z = 0, walls y = ±1 m) seen by a
// camera at height 1 m with the given yaw, pitch (looking down) and roll: R_hall_cam0.
Eigen::Matrix3d CameraOrientation(double yaw_deg, double pitch_deg, double roll_deg) {
  Eigen::Matrix3d R_base;
  R_base.col(0) = -Eigen::Vector3d::UnitY();
  R_base.col(1) = -Eigen::Vector3d::UnitZ();
  R_base.col(2) = Eigen::Vector3d::UnitX();
  return (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_deg * kDeg, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_deg * kDeg, Eigen::Vector3d::UnitX()))
             .toRotationMatrix() *
         R_base;
}

// Exact points (camera frame) on the floor and/or the walls, in front of the camera.
std::vector<Eigen::Vector3d> Hallway(const Eigen::Matrix3d& R_hall_cam0, bool floor, bool walls) {
  const Eigen::Vector3d c_hall(0.0, 0.0, 1.0);
  SplitMix64 rng(7);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 3000; ++i) {
    const int which = static_cast<int>(rng.UniformIndex(3));
    const double x = 1.0 + 7.0 * rng.Uniform();
    Eigen::Vector3d p;
    if (which == 0) {
      if (!floor) continue;
      p = Eigen::Vector3d(x, 2.0 * rng.Uniform() - 1.0, 0.0);
    } else {
      if (!walls) continue;
      p = Eigen::Vector3d(x, which == 1 ? 1.0 : -1.0, 2.5 * rng.Uniform());
    }
    const Eigen::Vector3d p_cam0 = R_hall_cam0.transpose() * (p - c_hall);
    if (p_cam0.z() > 0.5) points.push_back(p_cam0);
  }
  return points;
}

InitialOrientationOptions NoRefinement() {
  InitialOrientationOptions o;
  o.refine_floor = false;
  return o;
}

TEST(InitialOrientationTest, FloorAndWallsGiveTheHallwayFrameExactly) {
  const Eigen::Matrix3d R_true = CameraOrientation(10.0, 5.0, 1.0);
  const InitialOrientation r =
      EstimateInitialOrientation(test::TestCamera(), NoRefinement(), Hallway(R_true, true, true),
                                 cv::Mat(), cv::Mat(), cv::Mat());
  ASSERT_TRUE(r.ok) << r.planes.message;
  EXPECT_LT(RotationAngleRad(r.R_hall_cam0, R_true), kExactTolRad);
  EXPECT_TRUE(r.R_hall_cam0 == r.planes.R_hall_cam0);
  EXPECT_NEAR(r.planes.camera_height_m, 1.0, 1e-6);
  // Not refined (no images): the geometric fit's σ for the vehicle's up, 1°.
  EXPECT_FALSE(r.floor_refined);
  EXPECT_TRUE(r.message.empty());
  EXPECT_DOUBLE_EQ(r.up_sigma_rad, 1.0 * M_PI / 180.0);
}

TEST(InitialOrientationTest, WithoutAFloorTheUpComesFromTheMountingOnlyWhenAsked) {
  const Eigen::Matrix3d R_true = CameraOrientation(0.0, 12.0, 0.0);
  const std::vector<Eigen::Vector3d> walls = Hallway(R_true, false, true);
  InitialOrientationOptions o = NoRefinement();
  const InitialOrientation off =
      EstimateInitialOrientation(test::TestCamera(), o, walls, cv::Mat(), cv::Mat(), cv::Mat());
  EXPECT_FALSE(off.ok);
  EXPECT_EQ(off.planes.status, PlaneOrientationResult::Status::kNoFloor);
  EXPECT_TRUE(off.R_hall_cam0 == Eigen::Matrix3d::Identity());

  o.up_from_mounting = true;
  const double p = 12.0 * kDeg;
  o.planes.expected_up_cam0 = Eigen::Vector3d(0.0, -std::cos(p), -std::sin(p));
  const InitialOrientation on =
      EstimateInitialOrientation(test::TestCamera(), o, walls, cv::Mat(), cv::Mat(), cv::Mat());
  ASSERT_TRUE(on.ok);
  // The mounting's up is the true up here, and the yaw is the camera's heading (zero).
  EXPECT_LT(RotationAngleRad(on.R_hall_cam0, R_true), kExactTolRad);
  EXPECT_THAT(on.message, ::testing::HasSubstr("camera's mounting"));
}

TEST(InitialOrientationTest, AFloorWithoutWallsCountsOnlyWhenNoWallIsRequired) {
  const Eigen::Matrix3d R_true = CameraOrientation(0.0, 8.0, 2.0);
  const std::vector<Eigen::Vector3d> floor = Hallway(R_true, true, false);
  InitialOrientationOptions o = NoRefinement();
  const InitialOrientation r =
      EstimateInitialOrientation(test::TestCamera(), o, floor, cv::Mat(), cv::Mat(), cv::Mat());
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.planes.status, PlaneOrientationResult::Status::kNoWall);
  // The up is exact: the third row of R_hall_cam0.
  EXPECT_LT((r.R_hall_cam0.row(2) - R_true.row(2)).norm(), kExactTolRad);
  o.requires_wall = true;
  EXPECT_FALSE(
      EstimateInitialOrientation(test::TestCamera(), o, floor, cv::Mat(), cv::Mat(), cv::Mat()).ok);
}

TEST(InitialOrientationTest, SampleDisparityPointsReadsEveryStepWithinTheDepthRange) {
  const StereoCamera cam = test::TestCamera();
  cv::Mat d(30, 40, CV_32F, cv::Scalar(10.0f));
  d.at<float>(0, 0) = 0.0f;  // invalid: skipped
  const std::vector<Eigen::Vector3d> points = SampleDisparityPoints(cam, d, 4, 0.1, 100.0);
  ASSERT_EQ(points.size(), 8u * 10u - 1u);  // rows 0..28, columns 0..36 by 4
  const double z = cam.fx_px * cam.baseline_m / 10.0;
  for (const Eigen::Vector3d& p : points) EXPECT_NEAR(p.z(), z, 1e-12);
  EXPECT_TRUE(points[0].isApprox(cam.Backproject(4, 0, 10.0f)));
  EXPECT_TRUE(SampleDisparityPoints(cam, d, 4, z + 0.01, 100.0).empty());
}

TEST(InitialOrientationTest, OptionsRefuseABadFieldByName) {
  using O = InitialOrientationOptions;
  test::ExpectOptionsRefuseBadFields<O>({
      {"planes: ", [](O* o) { o->planes.max_planes = 0; }},
      {"floor_refinement: ", [](O* o) { o->floor_refinement.max_iterations = 0; }},
      {"sample_step_px", [](O* o) { o->sample_step_px = 0; }},
  });
  // The plane extraction and the refinement are not checked when they are off.
  O off;
  off.refine_floor = false;
  off.floor_refinement.max_iterations = 0;
  EXPECT_TRUE(off.IsValid(nullptr));
  off.enabled = false;
  off.planes.max_planes = 0;
  EXPECT_TRUE(off.IsValid(nullptr));
}

}  // namespace
}  // namespace vo
