// Rectified stereo pinhole camera model shared by every VO stage.
//
// Conventions (see docs/DESIGN.md): computer-vision camera axes (x right, y down, z forward);
// pixel centres at integer coordinates (OpenCV convention: the top-left pixel covers
// [-0.5, 0.5]^2). cam1 (right) sits at +baseline_m along cam0's x axis and has the same
// intrinsics and orientation: T_cam0_cam1 = [I | (baseline_m, 0, 0)].
#pragma once

#include <Eigen/Core>
#include <string>

namespace vo {

struct StereoCamera {
  int width = 320;          // image width (pixels)
  int height = 240;         // image height (pixels)
  double fx_px = 0.0;       // focal length along x (pixels)
  double fy_px = 0.0;       // focal length along y (pixels)
  double cx_px = 0.0;       // principal point x (pixels, integer = pixel centre)
  double cy_px = 0.0;       // principal point y (pixels)
  double baseline_m = 0.0;  // distance between the optical centres (metres), > 0

  // True when all numbers are finite and positive where they must be; otherwise fills *error.
  bool IsValid(std::string* error) const;

  // Projects p_cam0 (metres, cam0 frame) into the left image. False when z <= min_depth_m
  // (*uv_px is written in either case; it means nothing then). Inline: RANSAC projects every
  // correspondence under every hypothesis.
  bool ProjectLeft(const Eigen::Vector3d& p_cam0, Eigen::Vector2d* uv_px,
                   double min_depth_m = 1e-6) const {
    *uv_px << fx_px * p_cam0.x() / p_cam0.z() + cx_px, fy_px * p_cam0.y() / p_cam0.z() + cy_px;
    return p_cam0.z() > min_depth_m;
  }
  // Projects p_cam0 into the right image (cam1 = cam0 shifted by baseline_m along x).
  bool ProjectRight(const Eigen::Vector3d& p_cam0, Eigen::Vector2d* uv_px,
                    double min_depth_m = 1e-6) const {
    *uv_px << fx_px * (p_cam0.x() - baseline_m) / p_cam0.z() + cx_px,
        fy_px * p_cam0.y() / p_cam0.z() + cy_px;
    return p_cam0.z() > min_depth_m;
  }
  // 3D point in cam0 from a left-image pixel and its disparity (x_left - x_right, pixels > 0).
  Eigen::Vector3d Backproject(double u_px, double v_px, double disparity_px) const;
  // 3D point in cam0 from a left-image pixel and its depth z (metres).
  Eigen::Vector3d BackprojectDepth(double u_px, double v_px, double depth_m) const;
  // Depth z (metres) of a disparity (pixels > 0).
  double DepthFromDisparity(double disparity_px) const { return fx_px * baseline_m / disparity_px; }
  double DisparityFromDepth(double depth_m) const { return fx_px * baseline_m / depth_m; }
};

}  // namespace vo
