#include "harness/dataset/rectification.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "harness/dataset/internal.h"
#include "harness/trajectory_io.h"

namespace harness {
namespace {

using dataset_internal::Fail;
using dataset_internal::IsRotation;
using dataset_internal::RigProblem;

// A rectified pair must have its baseline along x: |y|, |z| of rect1 in rect0 at most this
// fraction of the baseline (cv::stereoRectify gives ~1e-16).
constexpr double kRectifiedBaselineOffAxisFraction = 1e-6;
// Rectification with alpha 0: the focal length grows by this factor per step until no
// rectified pixel samples outside the raw images, at most kMaxRectificationZoomSteps times.
constexpr double kRectificationZoomStep = 1.001;
constexpr int kMaxRectificationZoomSteps = 200;  // 1.001^200 = 1.22

// The calibration files, for error messages.
std::string CalibrationFiles(const EurocCameraCalibration& cam0,
                             const EurocCameraCalibration& cam1) {
  const std::string a = cam0.path.empty() ? "cam0 calibration" : cam0.path;
  const std::string b = cam1.path.empty() ? "cam1 calibration" : cam1.path;
  return a + ", " + b;
}

// True when every (x, y) of the maps lies inside the raw image, so bilinear sampling never
// reads the black border: 0 <= x <= width - 1, 0 <= y <= height - 1.
bool MapInside(const cv::Mat& map_x, const cv::Mat& map_y, const cv::Size& raw) {
  double x_min, x_max, y_min, y_max;
  cv::minMaxLoc(map_x, &x_min, &x_max);
  cv::minMaxLoc(map_y, &y_min, &y_max);
  return x_min >= 0.0 && y_min >= 0.0 && x_max <= raw.width - 1 && y_max <= raw.height - 1;
}

cv::Mat CameraMatrix(const EurocCameraCalibration& c) {
  return (cv::Mat_<double>(3, 3) << c.fu_px, 0.0, c.cu_px, 0.0, c.fv_px, c.cv_px, 0.0, 0.0, 1.0);
}

cv::Mat ToCv(const Eigen::Matrix3d& R) {
  cv::Mat m(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m.at<double>(r, c) = R(r, c);
  return m;
}

Eigen::Matrix3d ToEigen3(const cv::Mat& m) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = m.at<double>(r, c);
  return R;
}

}  // namespace

bool RectificationOptions::IsValid(std::string* error) const {
  if (!(alpha >= 0.0 && alpha <= 1.0))
    return Fail(error, "rectification alpha must be in [0, 1], got " + FormatDouble(alpha));
  for (double t : {identity_intrinsics_tolerance_px, identity_rotation_tolerance,
                   identity_offset_tolerance_m, identity_distortion_tolerance})
    if (!(t >= 0.0) || !std::isfinite(t))
      return Fail(error, "rectification identity tolerances must be finite and >= 0");
  return true;
}

Eigen::Isometry3d RectifiedLeftIn(const Eigen::Isometry3d& T_frame_cam0,
                                  const Eigen::Matrix3d& R_cam0_rect0) {
  Eigen::Isometry3d T = T_frame_cam0;
  T.linear() = T_frame_cam0.linear() * R_cam0_rect0;
  return T;
}

bool ComputeStereoRectification(const EurocCameraCalibration& cam0,
                                const EurocCameraCalibration& cam1,
                                const RectificationOptions& options,
                                StereoRectification* rectification, std::string* error) {
  std::string why;
  if (!options.IsValid(&why)) return Fail(error, "RectificationOptions: " + why);
  const EurocCameraCalibration* cams[2] = {&cam0, &cam1};
  for (int k = 0; k < 2; ++k) {
    const EurocCameraCalibration& c = *cams[k];
    const std::string where =
        (c.path.empty() ? "cam" + std::to_string(k) + " calibration" : c.path) + ": ";
    if (c.camera_model != "pinhole")
      return Fail(error, where + "camera_model '" + c.camera_model +
                             "' is not supported (expected pinhole)");
    if (c.distortion_model != "radial-tangential" && c.distortion_model != "radtan" &&
        c.distortion_model != "equidistant")
      return Fail(error, where + "distortion_model '" + c.distortion_model +
                             "' is not supported (expected radial-tangential or equidistant)");
    if (c.distortion_coefficients.size() != 4)
      return Fail(error, where + "distortion_coefficients: expected 4 numbers (" +
                             (c.distortion_model == "equidistant" ? "k1 k2 k3 k4" : "k1 k2 p1 p2") +
                             "), got " + std::to_string(c.distortion_coefficients.size()));
    if (!(c.fu_px > 0.0) || !(c.fv_px > 0.0) || !std::isfinite(c.cu_px) ||
        !std::isfinite(c.cv_px) || c.width <= 0 || c.height <= 0)
      return Fail(error, where + "intrinsics and resolution must be finite and positive");
  }
  const std::string where = CalibrationFiles(cam0, cam1) + ": ";
  const bool equidistant = cam0.distortion_model == "equidistant";
  if (equidistant != (cam1.distortion_model == "equidistant"))
    return Fail(error, where + "cam0 and cam1 use different distortion models ('" +
                           cam0.distortion_model + "', '" + cam1.distortion_model +
                           "'); expected the same");
  if (cam0.width != cam1.width || cam0.height != cam1.height)
    return Fail(error, where + "cam0 and cam1 resolutions differ (" + std::to_string(cam0.width) +
                           "x" + std::to_string(cam0.height) + " vs " + std::to_string(cam1.width) +
                           "x" + std::to_string(cam1.height) + ")");
  const Eigen::Isometry3d T_cam0_cam1 = cam0.T_body_cam.inverse() * cam1.T_body_cam;
  const Eigen::Vector3d t = T_cam0_cam1.translation();

  // Already rectified: the identity, images used as they are.
  double max_distortion = 0.0;
  for (const EurocCameraCalibration* c : cams)
    for (double d : c->distortion_coefficients)
      max_distortion = std::max(max_distortion, std::abs(d));
  const double dk =
      std::max({std::abs(cam0.fu_px - cam1.fu_px), std::abs(cam0.fv_px - cam1.fv_px),
                std::abs(cam0.cu_px - cam1.cu_px), std::abs(cam0.cv_px - cam1.cv_px)});
  const double dr = (T_cam0_cam1.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!equidistant && max_distortion <= options.identity_distortion_tolerance &&
      dk <= options.identity_intrinsics_tolerance_px && dr <= options.identity_rotation_tolerance &&
      std::abs(t.y()) <= options.identity_offset_tolerance_m &&
      std::abs(t.z()) <= options.identity_offset_tolerance_m && t.x() > 0.0) {
    StereoRectification r;
    r.camera.width = cam0.width;
    r.camera.height = cam0.height;
    r.camera.fx_px = cam0.fu_px;
    r.camera.fy_px = cam0.fv_px;
    r.camera.cx_px = cam0.cu_px;
    r.camera.cy_px = cam0.cv_px;
    r.camera.baseline_m = t.x();
    r.T_body_cam0 = cam0.T_body_cam;
    if (!r.camera.IsValid(&why)) return Fail(error, where + why);
    *rectification = r;
    return true;
  }
  if (!(t.x() > 0.0) || std::abs(t.x()) <= std::max(std::abs(t.y()), std::abs(t.z())))
    return Fail(error, where + "cam1 sits at (" + FormatDouble(t.x()) + ", " + FormatDouble(t.y()) +
                           ", " + FormatDouble(t.z()) +
                           ") m in cam0: expected it to the right of cam0 (mostly +x); vertical "
                           "or swapped pairs are not supported");

  // OpenCV's R, T map cam0 points into cam1: p_cam1 = R p_cam0 + T.
  const Eigen::Isometry3d T_cam1_cam0 = T_cam0_cam1.inverse();
  const cv::Mat R = ToCv(T_cam1_cam0.linear());
  const cv::Mat T = (cv::Mat_<double>(3, 1) << T_cam1_cam0.translation().x(),
                     T_cam1_cam0.translation().y(), T_cam1_cam0.translation().z());
  const cv::Mat K0 = CameraMatrix(cam0), K1 = CameraMatrix(cam1);
  const cv::Mat D0(cam0.distortion_coefficients, true), D1(cam1.distortion_coefficients, true);
  const cv::Size size(cam0.width, cam0.height);
  cv::Mat R1, R2, P1, P2, Q;
  StereoRectification r;
  try {
    if (equidistant)
      cv::fisheye::stereoRectify(K0, D0, K1, D1, size, R, T, R1, R2, P1, P2, Q,
                                 cv::CALIB_ZERO_DISPARITY, size, options.alpha, 1.0);
    else
      cv::stereoRectify(K0, D0, K1, D1, size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY,
                        options.alpha, size);
    P1.convertTo(P1, CV_64F);
    P2.convertTo(P2, CV_64F);
    R1.convertTo(R1, CV_64F);
    R2.convertTo(R2, CV_64F);
    // alpha 0 promises no invalid pixel, but OpenCV finds its zoom on a sparse grid of points
    // (EuRoC: 26 map entries fall just outside the raw image). Zoom in further, about the
    // principal point, until every rectified pixel samples inside both raw images.
    for (int attempt = 0;; ++attempt) {
      if (equidistant) {
        cv::fisheye::initUndistortRectifyMap(K0, D0, R1, P1, size, CV_32FC1, r.map0_x, r.map0_y);
        cv::fisheye::initUndistortRectifyMap(K1, D1, R2, P2, size, CV_32FC1, r.map1_x, r.map1_y);
      } else {
        cv::initUndistortRectifyMap(K0, D0, R1, P1, size, CV_32FC1, r.map0_x, r.map0_y);
        cv::initUndistortRectifyMap(K1, D1, R2, P2, size, CV_32FC1, r.map1_x, r.map1_y);
      }
      if (options.alpha > 0.0 ||
          (MapInside(r.map0_x, r.map0_y, size) && MapInside(r.map1_x, r.map1_y, size)))
        break;
      if (attempt == kMaxRectificationZoomSteps)
        return Fail(error, where +
                               "rectification: no zoom puts every rectified pixel inside the "
                               "raw images (extreme distortion?); try a larger alpha");
      for (cv::Mat* P : {&P1, &P2}) {
        P->at<double>(0, 0) *= kRectificationZoomStep;
        P->at<double>(1, 1) *= kRectificationZoomStep;
        P->at<double>(0, 3) *= kRectificationZoomStep;  // -f * baseline follows f
      }
    }
  } catch (const cv::Exception& e) {
    return Fail(error, where + "rectification failed in OpenCV: " + e.what());
  }
  r.camera.width = cam0.width;
  r.camera.height = cam0.height;
  r.camera.fx_px = P1.at<double>(0, 0);
  r.camera.fy_px = P1.at<double>(1, 1);
  r.camera.cx_px = P1.at<double>(0, 2);
  r.camera.cy_px = P1.at<double>(1, 2);
  r.camera.baseline_m = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
  r.R_cam0_rect0 = ToEigen3(R1).transpose();
  r.R_cam1_rect1 = ToEigen3(R2).transpose();
  r.T_body_cam0 = cam0.T_body_cam;
  // The result must be the ideal pair the VO assumes: rect1 at +baseline along rect0's x.
  const Eigen::Vector3d t_rect0_rect1 = r.R_cam0_rect0.transpose() * t;
  const double off_axis = std::max(std::abs(t_rect0_rect1.y()), std::abs(t_rect0_rect1.z()));
  if (!r.camera.IsValid(&why) || !IsRotation(r.R_cam0_rect0, 1e-9) ||
      !IsRotation(r.R_cam1_rect1, 1e-9) || std::abs(P2.at<double>(1, 3)) > 0.0 ||
      off_axis > kRectifiedBaselineOffAxisFraction * t.norm() ||
      std::abs(t_rect0_rect1.x() - r.camera.baseline_m) > 1e-9 * t.norm() + 1e-12)
    return Fail(error, where + "rectification gave a degenerate pair" +
                           (why.empty() ? std::string() : ": " + why));
  if (const std::string problem = RigProblem(r.camera); !problem.empty())
    return Fail(error, where + "the rectified pair: " + problem);
  *rectification = r;
  return true;
}

void RectifyFrame(const StereoRectification& rectification, DatasetFrame* frame) {
  if (rectification.IsIdentity()) return;
  const cv::Size raw = rectification.map0_x.size();
  if (frame->left.size() != raw || frame->right.size() != raw) {
    std::fprintf(stderr, "harness::RectifyFrame: images %dx%d / %dx%d, maps made for %dx%d\n",
                 frame->left.cols, frame->left.rows, frame->right.cols, frame->right.rows,
                 raw.width, raw.height);
    std::abort();
  }
  cv::Mat left, right;
  cv::remap(frame->left, left, rectification.map0_x, rectification.map0_y, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::remap(frame->right, right, rectification.map1_x, rectification.map1_y, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  frame->left = left;
  frame->right = right;
  frame->depth_m = cv::Mat();
  if (frame->has_gt) {
    Eigen::Isometry3d T_cam0_rect0 = Eigen::Isometry3d::Identity();
    T_cam0_rect0.linear() = rectification.R_cam0_rect0;
    frame->T_world_cam0 = frame->T_world_cam0 * T_cam0_rect0;
  }
}

}  // namespace harness
