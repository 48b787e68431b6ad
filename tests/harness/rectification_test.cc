// Stereo rectification from EuRoC-style calibrations (dataset.h: ComputeStereoRectification,
// RectifyFrame), against a known answer: for a rectified pixel and a disparity, the 3D point is
// known; transformed into each raw camera with the calibration and projected with the
// distortion model (written out here, independently of OpenCV), it must land where the maps
// point. The same point must sit on the same row, `disparity` pixels to the left, in the right
// rectified image, and the rectified frames must be the raw ones turned as R_cam*_rect* say.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "harness/dataset.h"

namespace harness {
namespace {

using ::testing::HasSubstr;

constexpr double kMapTolerancePx = 2e-3;  // float maps (~1e-4 px) and iterative undistortion
constexpr double kGeometryTolerance = 1e-9;

// Radial-tangential (plumb bob): k1 k2 p1 p2.
Eigen::Vector2d ProjectRadtan(const EurocCameraCalibration& c, const Eigen::Vector3d& p) {
  const double x = p.x() / p.z(), y = p.y() / p.z(), r2 = x * x + y * y;
  const std::vector<double>& d = c.distortion_coefficients;
  const double radial = 1.0 + d[0] * r2 + d[1] * r2 * r2;
  const double xd = x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x);
  const double yd = y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y;
  return {c.fu_px * xd + c.cu_px, c.fv_px * yd + c.cv_px};
}

// Equidistant (Kannala-Brandt, as Kalibr and OpenCV's fisheye): k1..k4 on theta.
Eigen::Vector2d ProjectEquidistant(const EurocCameraCalibration& c, const Eigen::Vector3d& p) {
  const double x = p.x() / p.z(), y = p.y() / p.z(), r = std::hypot(x, y);
  const double theta = std::atan(r), t2 = theta * theta;
  const std::vector<double>& k = c.distortion_coefficients;
  const double theta_d =
      theta * (1 + k[0] * t2 + k[1] * t2 * t2 + k[2] * t2 * t2 * t2 + k[3] * t2 * t2 * t2 * t2);
  const double s = r > 1e-12 ? theta_d / r : 1.0;
  return {c.fu_px * s * x + c.cu_px, c.fv_px * s * y + c.cv_px};
}

Eigen::Isometry3d Pose(double angle_rad, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// A raw pair like EuRoC's: different intrinsics and distortion per camera, cam1 ~11 cm to the
// right, turned by ~1 deg, both mounted rotated in the body.
void MakePair(const std::string& model, EurocCameraCalibration* cam0,
              EurocCameraCalibration* cam1) {
  for (EurocCameraCalibration* c : {cam0, cam1}) {
    c->camera_model = "pinhole";
    c->distortion_model = model;
    c->width = 640;
    c->height = 480;
  }
  cam0->path = "left.yaml";
  cam1->path = "right.yaml";
  cam0->fu_px = 400.0, cam0->fv_px = 398.5, cam0->cu_px = 322.0, cam0->cv_px = 241.0;
  cam1->fu_px = 404.0, cam1->fv_px = 402.0, cam1->cu_px = 317.5, cam1->cv_px = 246.0;
  if (model == "equidistant") {
    cam0->distortion_coefficients = {0.01, -0.005, 0.002, -0.0005};
    cam1->distortion_coefficients = {0.012, -0.004, 0.001, -0.0004};
  } else {
    cam0->distortion_coefficients = {-0.28, 0.07, 2e-4, 2e-5};
    cam1->distortion_coefficients = {-0.27, 0.075, -1e-4, -3e-5};
  }
  cam0->T_body_cam = Pose(1.6, {0.1, 0.2, 1.0}, {-0.02, -0.06, 0.01});
  const Eigen::Isometry3d T_cam0_cam1 = Pose(0.018, {0.3, -1.0, 0.4}, {0.110, 0.002, -0.001});
  cam1->T_body_cam = cam0->T_body_cam * T_cam0_cam1;
}

void ExpectKnownAnswer(const EurocCameraCalibration& cam0, const EurocCameraCalibration& cam1,
                       const StereoRectification& r,
                       Eigen::Vector2d (*project)(const EurocCameraCalibration&,
                                                  const Eigen::Vector3d&)) {
  const vo::StereoCamera& k = r.camera;
  ASSERT_EQ(k.width, 640);
  ASSERT_EQ(k.height, 480);
  EXPECT_DOUBLE_EQ(k.fx_px, k.fy_px);
  // The baseline is the distance between the optical centres.
  const Eigen::Isometry3d T_cam0_cam1 = cam0.T_body_cam.inverse() * cam1.T_body_cam;
  EXPECT_NEAR(k.baseline_m, T_cam0_cam1.translation().norm(), kGeometryTolerance);
  // rect1 = rect0 moved by +baseline along x, same orientation.
  const Eigen::Matrix3d R_rect0_rect1 =
      r.R_cam0_rect0.transpose() * T_cam0_cam1.linear() * r.R_cam1_rect1;
  EXPECT_LT((R_rect0_rect1 - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(),
            kGeometryTolerance);
  const Eigen::Vector3d t_rect0_rect1 = r.R_cam0_rect0.transpose() * T_cam0_cam1.translation();
  EXPECT_NEAR(t_rect0_rect1.x(), k.baseline_m, kGeometryTolerance);
  EXPECT_NEAR(t_rect0_rect1.y(), 0.0, kGeometryTolerance);
  EXPECT_NEAR(t_rect0_rect1.z(), 0.0, kGeometryTolerance);

  int checked = 0;
  double worst = 0.0;
  for (int v = 8; v < k.height - 8; v += 24) {
    for (int u = 48; u < k.width - 8; u += 24) {
      for (int d : {4, 16, 40}) {
        // The point seen at (u, v) in rect0 with disparity d, and at (u - d, v) in rect1.
        const double z = k.fx_px * k.baseline_m / d;
        const Eigen::Vector3d p_rect0((u - k.cx_px) / k.fx_px * z, (v - k.cy_px) / k.fy_px * z, z);
        const Eigen::Vector3d p_cam0 = r.R_cam0_rect0 * p_rect0;
        const Eigen::Vector3d p_cam1 =
            r.R_cam1_rect1 * (p_rect0 - Eigen::Vector3d(k.baseline_m, 0.0, 0.0));
        // The same point through the calibration's extrinsics.
        const Eigen::Vector3d p_cam1_calib = T_cam0_cam1.inverse() * p_cam0;
        ASSERT_LT((p_cam1 - p_cam1_calib).norm(), 1e-9 * z);
        const Eigen::Vector2d raw0 = project(cam0, p_cam0), raw1 = project(cam1, p_cam1);
        const Eigen::Vector2d map0(r.map0_x.at<float>(v, u), r.map0_y.at<float>(v, u));
        const Eigen::Vector2d map1(r.map1_x.at<float>(v, u - d), r.map1_y.at<float>(v, u - d));
        worst = std::max({worst, (map0 - raw0).norm(), (map1 - raw1).norm()});
        ASSERT_LT((map0 - raw0).norm(), kMapTolerancePx) << "left (" << u << ", " << v << ")";
        ASSERT_LT((map1 - raw1).norm(), kMapTolerancePx)
            << "right (" << u - d << ", " << v << "), d " << d;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 500);
  std::printf("%d points, largest map error %.2e px\n", checked, worst);
}

TEST(RectificationTest, RadialTangentialPairKnownAnswer) {
  EurocCameraCalibration cam0, cam1;
  MakePair("radial-tangential", &cam0, &cam1);
  StereoRectification r;
  std::string error;
  ASSERT_TRUE(ComputeStereoRectification(cam0, cam1, RectificationOptions(), &r, &error)) << error;
  ASSERT_FALSE(r.IsIdentity());
  ExpectKnownAnswer(cam0, cam1, r, ProjectRadtan);
}

TEST(RectificationTest, EquidistantPairKnownAnswer) {
  EurocCameraCalibration cam0, cam1;
  MakePair("equidistant", &cam0, &cam1);
  StereoRectification r;
  std::string error;
  ASSERT_TRUE(ComputeStereoRectification(cam0, cam1, RectificationOptions(), &r, &error)) << error;
  ASSERT_FALSE(r.IsIdentity());
  ExpectKnownAnswer(cam0, cam1, r, ProjectEquidistant);
}

TEST(RectificationTest, AlphaZeroSamplesOnlyInsideTheRawImagesAlphaOneKeepsEverything) {
  EurocCameraCalibration cam0, cam1;
  MakePair("radial-tangential", &cam0, &cam1);
  std::string error;
  StereoRectification r0, r1;
  ASSERT_TRUE(ComputeStereoRectification(cam0, cam1, RectificationOptions(), &r0, &error)) << error;
  RectificationOptions all;
  all.alpha = 1.0;
  ASSERT_TRUE(ComputeStereoRectification(cam0, cam1, all, &r1, &error)) << error;
  auto inside = [](const cv::Mat& mx, const cv::Mat& my) {
    double x0, x1, y0, y1;
    cv::minMaxLoc(mx, &x0, &x1);
    cv::minMaxLoc(my, &y0, &y1);
    return x0 >= 0 && y0 >= 0 && x1 <= 639 && y1 <= 479;
  };
  EXPECT_TRUE(inside(r0.map0_x, r0.map0_y));
  EXPECT_TRUE(inside(r0.map1_x, r0.map1_y));
  EXPECT_FALSE(inside(r1.map0_x, r1.map0_y));   // black borders: the whole raw view is kept
  EXPECT_LT(r1.camera.fx_px, r0.camera.fx_px);  // ... at a smaller focal length
}

TEST(RectificationTest, AlreadyRectifiedPairIsTheIdentity) {
  EurocCameraCalibration cam0, cam1;
  MakePair("radial-tangential", &cam0, &cam1);
  cam1 = cam0;
  cam1.T_body_cam = cam0.T_body_cam * Pose(0.0, {0, 0, 1}, {0.12, 0, 0});
  cam0.distortion_coefficients = cam1.distortion_coefficients = {0, 0, 0, 0};
  StereoRectification r;
  std::string error;
  ASSERT_TRUE(ComputeStereoRectification(cam0, cam1, RectificationOptions(), &r, &error)) << error;
  EXPECT_TRUE(r.IsIdentity());
  EXPECT_NEAR(r.camera.baseline_m, 0.12, 1e-12);
  EXPECT_EQ(r.camera.fx_px, cam0.fu_px);
  EXPECT_EQ(r.camera.cy_px, cam0.cv_px);
  DatasetFrame f;
  f.left = cv::Mat(480, 640, CV_8UC1, cv::Scalar(7));
  f.right = f.left.clone();
  f.has_gt = true;
  f.T_world_cam0 = Pose(0.3, {1, 0, 0}, {1, 2, 3});
  const Eigen::Isometry3d before = f.T_world_cam0;
  const uchar* data = f.left.data;
  RectifyFrame(r, &f);
  EXPECT_EQ(f.left.data, data);  // untouched
  EXPECT_TRUE(f.T_world_cam0.isApprox(before, 0.0));
}

TEST(RectificationTest, RectifyFrameRemapsAndTurnsTheGroundTruth) {
  EurocCameraCalibration cam0, cam1;
  MakePair("radial-tangential", &cam0, &cam1);
  StereoRectification r;
  std::string error;
  ASSERT_TRUE(ComputeStereoRectification(cam0, cam1, RectificationOptions(), &r, &error)) << error;
  // Raw images whose grey level is x / 4 (left) and y / 2 (right): the rectified image must
  // show the raw coordinate the map points at (bilinear on a linear ramp is exact).
  DatasetFrame f;
  f.left.create(480, 640, CV_8UC1);
  f.right.create(480, 640, CV_8UC1);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      f.left.at<uchar>(y, x) = static_cast<uchar>(x / 4);
      f.right.at<uchar>(y, x) = static_cast<uchar>(y / 2);
    }
  f.depth_m = cv::Mat(480, 640, CV_32FC1, cv::Scalar(1.0f));
  f.has_gt = true;
  f.T_world_cam0 = Pose(0.7, {1, 2, 3}, {4, 5, 6});
  const Eigen::Isometry3d T_world_cam0 = f.T_world_cam0;
  RectifyFrame(r, &f);
  ASSERT_EQ(f.left.size(), cv::Size(640, 480));
  for (int v = 20; v < 460; v += 37)
    for (int u = 20; u < 620; u += 41) {
      EXPECT_NEAR(f.left.at<uchar>(v, u), std::floor(r.map0_x.at<float>(v, u) / 4), 1.0);
      EXPECT_NEAR(f.right.at<uchar>(v, u), std::floor(r.map1_y.at<float>(v, u) / 2), 1.0);
    }
  EXPECT_TRUE(f.depth_m.empty());  // the raw view's depth does not fit the rectified one
  EXPECT_TRUE(f.T_world_cam0.linear().isApprox(T_world_cam0.linear() * r.R_cam0_rect0, 1e-12));
  EXPECT_TRUE(f.T_world_cam0.translation().isApprox(T_world_cam0.translation(), 1e-12));
}

TEST(RectificationTest, UnsupportedCalibrationsAreRefusedNamingTheFiles) {
  EurocCameraCalibration cam0, cam1;
  StereoRectification r;
  std::string error;
  auto fails = [&](const EurocCameraCalibration& a, const EurocCameraCalibration& b) {
    return !ComputeStereoRectification(a, b, RectificationOptions(), &r, &error);
  };
  MakePair("radial-tangential", &cam0, &cam1);
  EurocCameraCalibration bad = cam1;
  bad.camera_model = "omni";
  EXPECT_TRUE(fails(cam0, bad));
  EXPECT_THAT(error, HasSubstr("right.yaml: camera_model 'omni' is not supported"));
  bad = cam0;
  bad.distortion_model = "fov";
  EXPECT_TRUE(fails(bad, cam1));
  EXPECT_THAT(error, HasSubstr("left.yaml: distortion_model 'fov' is not supported"));
  bad = cam0;
  bad.distortion_coefficients.push_back(0.001);
  EXPECT_TRUE(fails(bad, cam1));
  EXPECT_THAT(error, HasSubstr("left.yaml: distortion_coefficients: expected 4 numbers (k1 k2 "
                               "p1 p2), got 5"));
  bad = cam1;
  bad.width = 320;
  EXPECT_TRUE(fails(cam0, bad));
  EXPECT_THAT(error, HasSubstr("left.yaml, right.yaml: cam0 and cam1 resolutions differ"));
  bad = cam1;
  bad.distortion_model = "equidistant";
  EXPECT_TRUE(fails(cam0, bad));
  EXPECT_THAT(error, HasSubstr("different distortion models"));
  bad = cam0;
  bad.fu_px = std::nan("");
  EXPECT_TRUE(fails(bad, cam1));
  EXPECT_THAT(error, HasSubstr("left.yaml: intrinsics and resolution must be finite"));
  // Swapped cameras: cam1 on the left of cam0.
  EXPECT_TRUE(fails(cam1, cam0));
  EXPECT_THAT(error, HasSubstr("expected it to the right of cam0"));
  RectificationOptions options;
  options.alpha = 1.5;
  EXPECT_FALSE(ComputeStereoRectification(cam0, cam1, options, &r, &error));
  EXPECT_THAT(error, HasSubstr("alpha must be in [0, 1]"));
}

}  // namespace
}  // namespace harness
