#include "vo/direct_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/vo/vo_test_util.h"
#include "vo/prior_motion.h"
#include "vo/recovery.h"

namespace vo {
namespace {

using test::FeatureAt;
using test::TestCamera;

constexpr double kDeg = M_PI / 180.0;
const Eigen::Vector3d kUp(0.0, -1.0, 0.0);  // camera frame: y down, a level camera
constexpr double kAxleM = 0.15;             // the camera 0.15 m ahead of the wheel axle
constexpr double kWallM = 0.85;             // the end wall, 0.85 m ahead of the first camera

double RecoveryDefaultsMaxTranslationSigma() {
  return RecoveryOptions::FreeDirectDefaults().max_forward_sigma_m;
}

// What a plain end wall shows (wall coordinates x right, y down, metres): grey paint, the lower
// edge of a picture frame, a soft shadow and a few specks; optionally nothing but the paint.
double WallGrey(double x, double y, bool textured) {
  double g = 120.0;
  if (!textured) return g;
  if (y < -0.22 && x > -0.35 && x < 0.10) g = 30.0;  // a picture frame's lower edge
  g -= 18.0 * std::exp(-((x - 0.15) * (x - 0.15) + (y - 0.05) * (y - 0.05)) / (2 * 0.06 * 0.06));
  const double specks[][2] = {{0.30, -0.10}, {-0.20, 0.15}, {0.05, 0.25}, {-0.32, -0.05}};
  for (const auto& s : specks) {
    const double r2 = (x - s[0]) * (x - s[0]) + (y - s[1]) * (y - s[1]);
    g -= 60.0 * std::exp(-r2 / (2 * 0.004 * 0.004));
  }
  return g;
}

// The left image of a camera at T_prev_cam (p_prev = T · p_cam) looking at the wall z = kWallM
// of the previous camera frame: 3 x 3 supersampled, with seeded noise of sigma 1.5 grey levels.
// gain: the camera's exposure times its analogue gain (1: the previous image's).
cv::Mat RenderWall(const StereoCamera& camera, const Eigen::Isometry3d& T_prev_cam, bool textured,
                   uint64_t seed, double gain = 1.0) {
  SplitMix64 rng(seed);
  cv::Mat image(camera.height, camera.width, CV_8UC1);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      double sum = 0.0;
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          const Eigen::Vector3d ray((u + (a - 1) / 3.0 - camera.cx_px) / camera.fx_px,
                                    (v + (b - 1) / 3.0 - camera.cy_px) / camera.fy_px, 1.0);
          const Eigen::Vector3d o = T_prev_cam.translation();
          const Eigen::Vector3d dir = T_prev_cam.linear() * ray;
          const double s = (kWallM - o.z()) / dir.z();
          const Eigen::Vector3d p = o + s * dir;
          sum += WallGrey(p.x(), p.y(), textured);
        }
      }
      const double g = gain * sum / 9.0 + 1.5 * test::Normal(&rng);
      image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(std::lround(g));
    }
  }
  return image;
}

ScenePlane WallPlane() {
  ScenePlane plane;
  plane.normal = Eigen::Vector3d::UnitZ();
  plane.distance_m = kWallM;
  return plane;
}

std::vector<ScenePlane> Wall() { return {WallPlane()}; }

TEST(DirectAlignmentTest, OptionsAreChecked) {
  std::string error;
  EXPECT_TRUE(DirectAlignmentOptions().IsValid(&error)) << error;
  DirectAlignmentOptions o;
  o.pyramid_levels = 0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("pyramid_levels"), std::string::npos) << error;
  o = DirectAlignmentOptions();
  o.min_gradient = std::nan("");
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("min_gradient"), std::string::npos) << error;
  o = DirectAlignmentOptions();
  o.min_depth_m = 2.0;
  o.max_depth_m = 1.0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("max_depth_m"), std::string::npos) << error;
}

// l_hallway texture seed 3 in a few numbers: the robot turns in place 2.2 deg a frame, its
// camera swinging 0.15 m ahead of the axle, in front of a wall with a picture frame's edge, a
// shadow and four specks (fewer features than any matcher needs). Started where a prior that
// lags the turn and keeps the cruise speed would put it, the alignment finds the true motion.
TEST(DirectAlignmentTest, ATurnInFrontOfAPlainWallIsMeasured) {
  const StereoCamera camera = TestCamera();
  const double yaw = -2.2 * kDeg;
  const double forward = -0.0015;
  const Eigen::Isometry3d T_prev_curr = VehicleMotion(kUp, kAxleM, yaw, forward);
  const cv::Mat prev = RenderWall(camera, Eigen::Isometry3d::Identity(), true, 1);
  const cv::Mat curr = RenderWall(camera, T_prev_curr, true, 2);
  const DirectAlignmentResult r = AlignVehicleDirect(camera, prev, curr, Wall(), kUp, kAxleM,
                                                     yaw + 0.8 * kDeg, forward + 0.018, {});
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_NEAR(r.yaw_rad, yaw, 0.02 * kDeg);
  EXPECT_NEAR(r.forward_m, forward, 0.001);
  EXPECT_GE(r.pixels, DirectAlignmentOptions().min_pixels);
  EXPECT_LT(r.residual_sigma, 4.0);  // the images' noise, not a misalignment
}

// Driving straight at the wall: the forward step is the zoom of its texture (2.4 % here; 1 mm
// is 0.1 px at 100 px from the centre, about what bilinear interpolation of a sharp edge gets
// wrong, so the step is good to about a millimetre, not to the covariance's hundredths).
TEST(DirectAlignmentTest, ABrakingApproachIsMeasuredFromTheZoom) {
  const StereoCamera camera = TestCamera();
  const Eigen::Isometry3d T_prev_curr = VehicleMotion(kUp, kAxleM, 0.0, 0.020);
  const cv::Mat prev = RenderWall(camera, Eigen::Isometry3d::Identity(), true, 3);
  const cv::Mat curr = RenderWall(camera, T_prev_curr, true, 4);
  const DirectAlignmentResult r =
      AlignVehicleDirect(camera, prev, curr, Wall(), kUp, kAxleM, 0.3 * kDeg, 0.038, {});
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_NEAR(r.yaw_rad, 0.0, 0.02 * kDeg);
  EXPECT_NEAR(r.forward_m, 0.020, 0.0015);
}

// Nothing but paint and noise: no measurement, and the start comes back.
TEST(DirectAlignmentTest, APaintedWallWithoutMarksIsNoMeasurement) {
  const StereoCamera camera = TestCamera();
  const Eigen::Isometry3d T_prev_curr = VehicleMotion(kUp, kAxleM, -2.0 * kDeg, 0.0);
  const cv::Mat prev = RenderWall(camera, Eigen::Isometry3d::Identity(), false, 5);
  const cv::Mat curr = RenderWall(camera, T_prev_curr, false, 6);
  const DirectAlignmentResult r =
      AlignVehicleDirect(camera, prev, curr, Wall(), kUp, kAxleM, -1.0 * kDeg, 0.01, {});
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.message.empty());
  EXPECT_EQ(r.yaw_rad, -1.0 * kDeg);
  EXPECT_EQ(r.forward_m, 0.01);
}

TEST(DirectAlignmentTest, BadInputIsRefused) {
  const StereoCamera camera = TestCamera();
  const cv::Mat image = RenderWall(camera, Eigen::Isometry3d::Identity(), true, 7);
  DirectAlignmentResult r =
      AlignVehicleDirect(camera, image, cv::Mat(), Wall(), kUp, kAxleM, 0.0, 0.0, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("8-bit"), std::string::npos) << r.message;
  ScenePlane behind = WallPlane();
  behind.distance_m = -1.0;
  r = AlignVehicleDirect(camera, image, image, {behind}, kUp, kAxleM, 0.0, 0.0, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("plane"), std::string::npos) << r.message;
  r = AlignVehicleDirect(camera, image, image, {}, kUp, kAxleM, 0.0, 0.0, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("plane"), std::string::npos) << r.message;
}

// The free platform (6 DoF, issue #35): a camera that turns about a slanted axis and steps
// sideways, down and ahead in front of the same plain wall. The gyro gives the rotation (exact
// here, σ 0.05°); the start's translation is a constant velocity's, off by 8, 5 and 15 mm. The
// alignment keeps the gyro's rotation and measures the translation from the wall's few marks.
Eigen::Isometry3d FreeMotion() {
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();
  T_prev_curr.linear() = Eigen::AngleAxisd(1.6 * kDeg, Eigen::Vector3d(0.3, -1.0, 0.2).normalized())
                             .toRotationMatrix();
  T_prev_curr.translation() = Eigen::Vector3d(-0.006, 0.004, 0.012);
  return T_prev_curr;
}

Eigen::Isometry3d FreeStart() {  // the gyro's rotation, a constant velocity's translation
  Eigen::Isometry3d start = FreeMotion();
  start.translation() += Eigen::Vector3d(0.008, -0.005, 0.015);
  return start;
}

TEST(DirectAlignmentTest, AFreeMotionIsMeasuredWithTheGyrosRotation) {
  const StereoCamera camera = TestCamera();
  const Eigen::Isometry3d T_prev_curr = FreeMotion();
  const cv::Mat prev = RenderWall(camera, Eigen::Isometry3d::Identity(), true, 11);
  const cv::Mat curr = RenderWall(camera, T_prev_curr, true, 12);
  const Eigen::Isometry3d start = FreeStart();
  const FreeDirectAlignmentResult r =
      AlignFreeDirect(camera, prev, curr, Wall(), start, {}, 0.05 * kDeg);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.T_prev_curr.linear().isApprox(T_prev_curr.linear(), 1e-12));  // the gyro's
  const Eigen::Vector3d error = r.T_prev_curr.translation() - T_prev_curr.translation();
  EXPECT_LT(error.head<2>().norm(), 0.0005) << error.transpose();
  EXPECT_LT(std::abs(error.z()), 0.0015) << error.transpose();  // the zoom (see above)
  EXPECT_GE(r.pixels, DirectAlignmentOptions().min_pixels);
  EXPECT_LT(r.residual_sigma, 4.0);
  EXPECT_EQ(r.rotation_sigma_rad, 0.05 * kDeg);
  EXPECT_GT(r.translation_sigma_m, 0.0);
  EXPECT_LE(r.translation_sigma_m, RecoveryDefaultsMaxTranslationSigma());
}

// The same motion seen by a camera whose gain changed between the frames, +4 % (auto-exposure;
// l_hallway's camera.gain_sigma is 2 % a frame): +5 grey levels on the paint, and on a wall
// with one edge a step that moves the edge is the cheaper way to explain them. The alignment
// measures the gain (α = ln 1.04) beside the translation, which stays as exact as above.
TEST(DirectAlignmentTest, AFreeMotionIsMeasuredThroughAChangeOfGain) {
  const StereoCamera camera = TestCamera();
  const Eigen::Isometry3d T_prev_curr = FreeMotion();
  const cv::Mat prev = RenderWall(camera, Eigen::Isometry3d::Identity(), true, 11);
  const Eigen::Isometry3d start = FreeStart();
  for (const double gain : {1.04, 0.96}) {
    const cv::Mat curr = RenderWall(camera, T_prev_curr, true, 12, gain);
    const FreeDirectAlignmentResult r =
        AlignFreeDirect(camera, prev, curr, Wall(), start, {}, 0.05 * kDeg);
    ASSERT_TRUE(r.ok) << gain << ": " << r.message;
    const Eigen::Vector3d error = r.T_prev_curr.translation() - T_prev_curr.translation();
    EXPECT_LT(error.head<2>().norm(), 0.0005) << gain << ": " << error.transpose();
    EXPECT_LT(std::abs(error.z()), 0.0015) << gain << ": " << error.transpose();
    EXPECT_NEAR(r.log_gain, std::log(gain), 0.006) << gain;  // within 15 % of the change
    EXPECT_LT(r.residual_sigma, 4.0) << gain;
  }
}

TEST(DirectAlignmentTest, APaintedWallIsNoFreeMeasurementAndBadInputIsRefused) {
  const StereoCamera camera = TestCamera();
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();
  T_prev_curr.translation() = Eigen::Vector3d(0.0, 0.0, 0.01);
  const cv::Mat prev = RenderWall(camera, Eigen::Isometry3d::Identity(), false, 15);
  const cv::Mat curr = RenderWall(camera, T_prev_curr, false, 16);
  FreeDirectAlignmentResult r =
      AlignFreeDirect(camera, prev, curr, Wall(), T_prev_curr, {}, 0.05 * kDeg);
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.message.empty());
  EXPECT_TRUE(r.T_prev_curr.isApprox(T_prev_curr, 0.0));
  r = AlignFreeDirect(camera, prev, cv::Mat(), Wall(), T_prev_curr, {}, 0.05 * kDeg);
  EXPECT_NE(r.message.find("8-bit"), std::string::npos) << r.message;
  r = AlignFreeDirect(camera, prev, curr, {}, T_prev_curr, {}, 0.05 * kDeg);
  EXPECT_NE(r.message.find("plane"), std::string::npos) << r.message;
  Eigen::Isometry3d nan = T_prev_curr;
  nan.translation().x() = std::nan("");
  r = AlignFreeDirect(camera, prev, curr, Wall(), nan, {}, 0.05 * kDeg);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("invalid start"), std::string::npos) << r.message;
  r = AlignFreeDirect(camera, prev, curr, Wall(), T_prev_curr, {}, 0.0);  // no gyro
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("gyro"), std::string::npos) << r.message;
  DirectAlignmentOptions bad;
  bad.max_pixels = 0;
  r = AlignFreeDirect(camera, prev, curr, Wall(), T_prev_curr, bad, 0.05 * kDeg);
  EXPECT_NE(r.message.find("max_pixels"), std::string::npos) << r.message;
}

// Eight features on a wall turned 20 deg, three on the floor: the wall is the plane.
TEST(DirectAlignmentTest, TheDominantPlaneOfTheFeaturesIsFound) {
  const StereoCamera camera = TestCamera();
  const Eigen::Vector3d normal = Eigen::Vector3d(std::sin(20 * kDeg), 0.0, std::cos(20 * kDeg));
  const double d = 1.2;
  std::vector<Feature> features;
  const double xy[][2] = {{-0.4, -0.3}, {0.3, -0.25}, {0.1, 0.2},   {-0.2, 0.1},
                          {0.35, 0.3},  {-0.1, -0.1}, {0.2, -0.05}, {-0.35, 0.28}};
  for (const auto& q : xy) {  // z from n·p = d
    const double z = (d - normal.x() * q[0]) / normal.z();
    features.push_back(FeatureAt(camera, Eigen::Vector3d(q[0], q[1], z)));
  }
  for (const double x : {-0.3, 0.0, 0.3}) features.push_back(FeatureAt(camera, {x, 0.5, 1.0}));
  ScenePlane plane;
  ASSERT_TRUE(FitDominantPlane(camera, features, 1.0, 4, 0.6, 0.05, &plane));
  EXPECT_EQ(plane.inliers, 8);
  EXPECT_NEAR(plane.normal.dot(normal), 1.0, 1e-9);
  EXPECT_NEAR(plane.distance_m, d, 1e-9);
}

// A hallway's end wall 1.5 m ahead, its floor 0.3 m below the camera and a side wall 0.4 m to
// the right: three planes, one after the other, each exactly.
TEST(DirectAlignmentTest, TheFeaturesPlanesAreFoundOneAfterTheOther) {
  const StereoCamera camera = TestCamera();
  std::vector<Feature> features;
  for (int k = 0; k < 12; ++k)
    features.push_back(FeatureAt(camera, {-0.5 + 0.09 * k, -0.3 + 0.05 * (k % 5), 1.5}));
  for (int k = 0; k < 9; ++k)
    features.push_back(FeatureAt(camera, {-0.4 + 0.1 * k, 0.3, 0.9 + 0.06 * (k % 4)}));
  for (int k = 0; k < 7; ++k)
    features.push_back(FeatureAt(camera, {0.4, -0.2 + 0.07 * k, 1.0 + 0.15 * (k % 3)}));
  features.push_back(FeatureAt(camera, {0.1, 0.0, 1.2}));  // on none
  std::vector<ScenePlane> planes;
  ASSERT_TRUE(FitScenePlanes(camera, features, 1.0, 6, 0.6, 0.05, 3, &planes));
  ASSERT_EQ(planes.size(), 3u);
  const Eigen::Vector3d normals[] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(),
                                     Eigen::Vector3d::UnitX()};
  const double distances[] = {1.5, 0.3, 0.4};
  const int counts[] = {12, 9, 7};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(planes[k].normal.dot(normals[k]), 1.0, 1e-9) << k;
    EXPECT_NEAR(planes[k].distance_m, distances[k], 1e-9) << k;
    EXPECT_EQ(planes[k].inliers, counts[k]) << k;
  }
  // Only two planes asked for: the side wall's seven are not on them (21 of 29 still >= 60 %).
  ASSERT_TRUE(FitScenePlanes(camera, features, 1.0, 6, 0.6, 0.05, 2, &planes));
  EXPECT_EQ(planes.size(), 2u);
  EXPECT_FALSE(FitScenePlanes(camera, features, 1.0, 6, 0.8, 0.05, 2, &planes));
}

TEST(DirectAlignmentTest, FeaturesAlongOneEdgeGiveNoPlane) {
  const StereoCamera camera = TestCamera();
  std::vector<Feature> features;
  for (int k = 0; k < 6; ++k)
    features.push_back(FeatureAt(camera, {-0.3 + 0.12 * k, -0.22, kWallM}));
  ScenePlane plane;
  EXPECT_FALSE(FitDominantPlane(camera, features, 1.0, 4, 0.6, 0.05, &plane));
  features.resize(3);
  EXPECT_FALSE(FitDominantPlane(camera, features, 1.0, 4, 0.6, 0.0, &plane));
}

// A point on the plane in frame a lies on the transformed plane in frame b.
TEST(DirectAlignmentTest, APlaneIsCarriedByTheMotion) {
  ScenePlane a;
  a.normal = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
  a.distance_m = 0.9;
  const Eigen::Isometry3d T_a_b = VehicleMotion(kUp, kAxleM, 5.0 * kDeg, 0.04);
  const ScenePlane b = TransformPlane(a, T_a_b);
  for (const Eigen::Vector3d& q :
       {Eigen::Vector3d(0.1, 0.2, 0.0), Eigen::Vector3d(-0.3, 0.0, 0.1)}) {
    const Eigen::Vector3d p_a = q + (a.distance_m - a.normal.dot(q)) * a.normal;  // on plane a
    const Eigen::Vector3d p_b = T_a_b.inverse() * p_a;
    EXPECT_NEAR(b.normal.dot(p_b), b.distance_m, 1e-12);
  }
  EXPECT_NEAR(b.normal.norm(), 1.0, 1e-12);
}

}  // namespace
}  // namespace vo
