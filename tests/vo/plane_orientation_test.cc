#include "vo/plane_orientation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"
#include "vo/camera.h"
#include "vo/ransac.h"  // vo::SplitMix64

namespace vo {
namespace {

using vobench_test::RotationAngleRad;

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kOrientationTolRad = 0.5 * kDegToRad;  // the task's bound
constexpr double kHeightTolM = 0.02;       // 2 cm on a 1 m height, from ~1 cm point noise
constexpr double kIsotropicSigmaM = 0.01;  // point noise, every axis
constexpr double kDisparitySigmaPx =
    0.05;  // stereo depth noise along the ray: σ_z = z² σ_d / (f b)

// Hallway frame: x along the corridor, y left, z up; floor z = 0, walls y = ±1 m, ceiling
// z = 2.5 m. cam0's axes in the hallway at zero yaw/pitch/roll: z_cam = x_hall,
// x_cam = −y_hall, y_cam = −z_hall.
Eigen::Matrix3d CameraOrientation(double yaw_deg, double pitch_deg, double roll_deg) {
  Eigen::Matrix3d R_base;
  R_base.col(0) = -Eigen::Vector3d::UnitY();
  R_base.col(1) = -Eigen::Vector3d::UnitZ();
  R_base.col(2) = Eigen::Vector3d::UnitX();
  // Yaw about up, pitch about the left axis (positive = looking down), roll about forward.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pitch_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(roll_deg * kDegToRad, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  return R * R_base;  // R_hall_cam0
}

using test::Normal;

struct HallwaySpec {
  bool floor = true;
  bool left_wall = true;
  bool right_wall = true;
  bool ceiling = false;
  int points_per_plane = 300;
  int clutter_points = 40;  // random points in the corridor volume
};

// Visible points (in cam0, metres) of the chosen hallway planes, with noise.
std::vector<Eigen::Vector3d> MakeHallway(const Eigen::Matrix3d& R_hall_cam0,
                                         const Eigen::Vector3d& c_hall, const HallwaySpec& spec,
                                         uint64_t seed) {
  StereoCamera cam;
  cam.fx_px = cam.fy_px = 300.0;
  cam.cx_px = 159.5;
  cam.cy_px = 119.5;
  cam.baseline_m = 0.12;
  SplitMix64 rng(seed);
  std::vector<Eigen::Vector3d> out;
  auto add_visible = [&](const Eigen::Vector3d& p_hall) {
    const Eigen::Vector3d p_cam0 = R_hall_cam0.transpose() * (p_hall - c_hall);
    Eigen::Vector2d uv;
    if (!cam.ProjectLeft(p_cam0, &uv) || p_cam0.z() < 0.5 || p_cam0.z() > 8.0) return false;
    if (uv.x() < 0 || uv.y() < 0 || uv.x() > 319 || uv.y() > 239) return false;
    const double sigma_z =
        p_cam0.z() * p_cam0.z() * kDisparitySigmaPx / (cam.fx_px * cam.baseline_m);
    Eigen::Vector3d noisy = p_cam0 * (1.0 + sigma_z * Normal(&rng) / p_cam0.z());
    noisy += kIsotropicSigmaM * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
    out.push_back(noisy);
    return true;
  };
  auto sample_plane = [&](int which) {
    int made = 0;
    for (int attempt = 0; attempt < 200000 && made < spec.points_per_plane; ++attempt) {
      const double x = c_hall.x() + 10.0 * rng.Uniform() - 2.0;
      Eigen::Vector3d p;
      switch (which) {
        case 0:
          p = Eigen::Vector3d(x, 2.0 * rng.Uniform() - 1.0, 0.0);
          break;  // floor
        case 1:
          p = Eigen::Vector3d(x, 1.0, 2.5 * rng.Uniform());
          break;  // left wall
        case 2:
          p = Eigen::Vector3d(x, -1.0, 2.5 * rng.Uniform());
          break;  // right wall
        default:
          p = Eigen::Vector3d(x, 2.0 * rng.Uniform() - 1.0, 2.5);
          break;  // ceiling
      }
      if (add_visible(p)) ++made;
    }
  };
  if (spec.floor) sample_plane(0);
  if (spec.left_wall) sample_plane(1);
  if (spec.right_wall) sample_plane(2);
  if (spec.ceiling) sample_plane(3);
  int clutter = 0;
  for (int attempt = 0; attempt < 100000 && clutter < spec.clutter_points; ++attempt) {
    const Eigen::Vector3d p(c_hall.x() + 8.0 * rng.Uniform(), 1.6 * rng.Uniform() - 0.8,
                            0.2 + 2.0 * rng.Uniform());
    if (add_visible(p)) ++clutter;
  }
  return out;
}

struct Pose {
  double yaw_deg, pitch_deg, roll_deg;
};

TEST(PlaneOrientationTest, RecoversOrientationAndHeightInAHallway) {
  const Pose poses[] = {{0, 0, 0},   {10, 5, 2}, {-25, -8, -3}, {35, 12, 4},
                        {-40, 3, 1}, {5, -5, 0}, {20, 0, -5}};
  const Eigen::Vector3d c_hall(0.0, 0.2, 1.0);  // 20 cm left of the centre line, 1 m high
  uint64_t seed = 1;
  for (const Pose& pose : poses) {
    const Eigen::Matrix3d R_true = CameraOrientation(pose.yaw_deg, pose.pitch_deg, pose.roll_deg);
    HallwaySpec spec;
    const std::vector<Eigen::Vector3d> points = MakeHallway(R_true, c_hall, spec, seed++);
    const PlaneOrientationResult r = EstimateHallwayOrientation(points);
    ASSERT_TRUE(r.ok()) << "yaw " << pose.yaw_deg << ": " << ToString(r.status) << " " << r.message;
    const double err = RotationAngleRad(r.R_hall_cam0, R_true);
    EXPECT_LT(err, kOrientationTolRad)
        << "yaw " << pose.yaw_deg << " pitch " << pose.pitch_deg << " roll " << pose.roll_deg
        << ": error " << err / kDegToRad << " deg";
    EXPECT_NEAR(r.camera_height_m, c_hall.z(), kHeightTolM);
    ASSERT_GE(r.floor_index, 0);
    EXPECT_EQ(r.planes[r.floor_index].kind, Plane::Kind::kFloor);
    int walls = 0;
    for (const Plane& p : r.planes) walls += p.kind == Plane::Kind::kWall ? 1 : 0;
    EXPECT_GE(walls, 1);
    // R_hall_cam0 is a rotation.
    EXPECT_TRUE((r.R_hall_cam0 * r.R_hall_cam0.transpose()).isIdentity(1e-12));
    EXPECT_NEAR(r.R_hall_cam0.determinant(), 1.0, 1e-12);
  }
}

TEST(PlaneOrientationTest, NoFloorNoCeilingGivesNoFloor) {
  HallwaySpec spec;
  spec.floor = false;
  const std::vector<Eigen::Vector3d> points =
      MakeHallway(CameraOrientation(10, 0, 0), Eigen::Vector3d(0, 0, 1), spec, 5);
  const PlaneOrientationResult r = EstimateHallwayOrientation(points);
  EXPECT_EQ(r.status, PlaneOrientationResult::Status::kNoFloor) << r.message;
  EXPECT_EQ(r.floor_index, -1);
  EXPECT_FALSE(r.planes.empty());  // the walls were still extracted
}

TEST(PlaneOrientationTest, CeilingGivesUpWhenThereIsNoFloor) {
  HallwaySpec spec;
  spec.floor = false;
  spec.ceiling = true;
  const Eigen::Matrix3d R_true = CameraOrientation(-15, -10, 2);  // looking a bit up
  const std::vector<Eigen::Vector3d> points =
      MakeHallway(R_true, Eigen::Vector3d(0, 0, 1), spec, 6);
  const PlaneOrientationResult r = EstimateHallwayOrientation(points);
  ASSERT_TRUE(r.ok()) << ToString(r.status) << " " << r.message;
  EXPECT_EQ(r.floor_index, -1);
  EXPECT_GE(r.ceiling_index, 0);
  EXPECT_LT(RotationAngleRad(r.R_hall_cam0, R_true), kOrientationTolRad);
  EXPECT_EQ(r.camera_height_m, 0.0);
}

TEST(PlaneOrientationTest, FloorWithoutWallsGivesUpButNoYaw) {
  HallwaySpec spec;
  spec.left_wall = spec.right_wall = false;
  const Eigen::Matrix3d R_true = CameraOrientation(0, 8, -3);
  const std::vector<Eigen::Vector3d> points =
      MakeHallway(R_true, Eigen::Vector3d(0, 0, 1.2), spec, 7);
  const PlaneOrientationResult r = EstimateHallwayOrientation(points);
  EXPECT_EQ(r.status, PlaneOrientationResult::Status::kNoWall) << r.message;
  // Up is known: the angle between the estimated and the true up in cam0.
  const Eigen::Vector3d up_true = R_true.transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, r.up_cam0.dot(up_true))), kOrientationTolRad);
  EXPECT_NEAR(r.camera_height_m, 1.2, kHeightTolM);
  // Yaw 0 was assumed, which is the truth here, so the whole rotation matches.
  EXPECT_LT(RotationAngleRad(r.R_hall_cam0, R_true), kOrientationTolRad);
}

TEST(PlaneOrientationTest, SameSeedSameResult) {
  HallwaySpec spec;
  const std::vector<Eigen::Vector3d> points =
      MakeHallway(CameraOrientation(12, 4, 1), Eigen::Vector3d(0, 0, 1), spec, 8);
  const PlaneOrientationResult a = EstimateHallwayOrientation(points);
  const PlaneOrientationResult b = EstimateHallwayOrientation(points);
  ASSERT_TRUE(a.ok());
  EXPECT_TRUE(a.R_hall_cam0 == b.R_hall_cam0);
  EXPECT_EQ(a.planes.size(), b.planes.size());
}

TEST(PlaneOrientationTest, InvalidInput) {
  std::vector<Eigen::Vector3d> points(10, Eigen::Vector3d(1, 2, 3));
  points[4].x() = std::nan("");
  EXPECT_EQ(EstimateHallwayOrientation(points).status,
            PlaneOrientationResult::Status::kInvalidInput);
  PlaneOrientationOptions options;
  options.max_normal_deviation_deg = 60.0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("max_normal_deviation_deg"));
  // Too few points for any plane: no floor.
  EXPECT_EQ(
      EstimateHallwayOrientation(std::vector<Eigen::Vector3d>(5, Eigen::Vector3d(0, 0, 1))).status,
      PlaneOrientationResult::Status::kNoFloor);
}

}  // namespace
}  // namespace vo
