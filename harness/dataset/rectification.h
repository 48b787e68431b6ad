// Stereo rectification: a raw, possibly distorted pair (two camera calibrations as EuRoC's
// sensor.yaml gives them, read by ReadEurocSensorYaml in euroc.h) mapped onto the ideal
// rectified pair the VO expects, with OpenCV's stereoRectify (pinhole radial-tangential and
// equidistant cameras).
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "harness/dataset/common.h"
#include "vo/camera.h"

namespace harness {

// Calibration of one camera as sensor.yaml gives it (raw, possibly distorted): what the
// rectification starts from. It lives here, not in euroc.h, because EurocReader::Rectification
// (euroc.h) needs this file.
struct EurocCameraCalibration {
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();  // T_BS: camera in the body
  double fu_px = 0.0;                                            // focal length x (pixels)
  double fv_px = 0.0;                                            // focal length y (pixels)
  double cu_px = 0.0;                                            // principal point x (pixels)
  double cv_px = 0.0;                                            // principal point y (pixels)
  std::string camera_model;                                      // "pinhole"
  std::string distortion_model;  // "radial-tangential" (k1 k2 p1 p2) or "equidistant"
                                 // (k1 k2 k3 k4, Kannala-Brandt as OpenCV's fisheye model)
  std::vector<double> distortion_coefficients;  // as listed in the file
  int width = 0;                                // resolution (pixels)
  int height = 0;
  double rate_hz = 0.0;  // nominal frame rate (Hz)
  std::string path;      // the file it was read from ("" when made in code); named in errors
  int t_bs_line = 0;     // the line of its T_BS key (0: unknown); named in errors
};

// Maps a raw stereo pair onto the ideal rectified camera the VO expects (vo::StereoCamera:
// equal intrinsics, cam1 at +baseline_m along cam0's x, no distortion).
// Rectified frames: rect0 and rect1 are the raw camera frames turned by R_cam0_rect0 and
// R_cam1_rect1 (same origins), so that T_rect0_rect1 = [I | (baseline_m, 0, 0)]. A point seen by
// the VO in rect0 is p_cam0 = R_cam0_rect0 * p_rect0; the rectified left camera's pose in the
// world is T_world_rect0 = T_world_cam0 * [R_cam0_rect0 | 0].
struct StereoRectification {
  vo::StereoCamera camera;  // the rectified camera (output image size and intrinsics)
  Eigen::Matrix3d R_cam0_rect0 = Eigen::Matrix3d::Identity();  // rectified left frame in raw cam0
  Eigen::Matrix3d R_cam1_rect1 = Eigen::Matrix3d::Identity();  // rectified right frame in raw cam1
  // Raw cam0 in the calibration's body frame (cam0's T_BS; EuRoC's body is its IMU), identity
  // when the rectification was not computed from sensor.yaml files.
  Eigen::Isometry3d T_body_cam0 = Eigen::Isometry3d::Identity();
  cv::Mat map0_x, map0_y;  // CV_32FC1 (height x width): raw cam0 pixel of each rectified pixel;
                           // empty = identity (no remap needed)
  cv::Mat map1_x, map1_y;  // the same for cam1
  bool IsIdentity() const { return map0_x.empty() && map1_x.empty(); }
};

// The rectified left camera in a frame where raw cam0 is at T_frame_cam0: the same centre,
// turned by R_cam0_rect0 (a rotation about cam0's centre).
Eigen::Isometry3d RectifiedLeftIn(const Eigen::Isometry3d& T_frame_cam0,
                                  const Eigen::Matrix3d& R_cam0_rect0);

struct RectificationOptions {
  // Free scaling of the rectified view, in [0, 1] (cv::stereoRectify's alpha; the balance of
  // cv::fisheye::stereoRectify for equidistant cameras). 0 = zoomed so that every rectified
  // pixel has a raw source pixel (no black border, the VO sees no invalid area; OpenCV's zoom
  // is refined until that holds exactly); 1 = every raw pixel kept (black borders).
  double alpha = 0.0;
  // Pairs within these tolerances of an ideal rectified pair (pinhole, zero distortion, equal
  // intrinsics, same orientation, cam1 on +x of cam0) get the identity rectification: images
  // are used as they are, bit for bit (e.g. the simulator's exports).
  double identity_intrinsics_tolerance_px = 1e-6;  // |fu0 - fu1| etc. (pixels)
  double identity_rotation_tolerance = 1e-6;       // max |R_cam0_cam1 - I| entry
  double identity_offset_tolerance_m = 1e-6;       // |y|, |z| of cam1 in cam0 (metres)
  double identity_distortion_tolerance = 1e-12;    // max |distortion coefficient|

  bool IsValid(std::string* error) const;
};

// Rectification of a raw pair from its two calibrations (cam0 = left, cam1 = right):
//   T_cam1_cam0 = T_BS1^-1 * T_BS0 (both from sensor.yaml);
//   radial-tangential (k1 k2 p1 p2 -> OpenCV distCoeffs (k1, k2, p1, p2)):
//     cv::stereoRectify(CALIB_ZERO_DISPARITY, options.alpha) + cv::initUndistortRectifyMap;
//   equidistant (k1..k4): cv::fisheye::stereoRectify + cv::fisheye::initUndistortRectifyMap;
//   the rectified camera: fx = fy, cx, cy from P1; baseline_m = -P2[0][3] / P2[0][0]; the same
//   image size as the raw one; R_cam0_rect0 = R1^T, R_cam1_rect1 = R2^T. With alpha 0 the focal
//   length is raised in steps of 0.1 % until every map entry lies inside the raw images.
// Already-rectified pairs get the identity rectification (see RectificationOptions).
// Fails, naming the calibration files, on an unknown camera or distortion model, a wrong number
// of distortion coefficients, different resolutions, cam1 not to the right of cam0 (the VO needs
// the baseline along +x), or a degenerate result.
bool ComputeStereoRectification(const EurocCameraCalibration& cam0,
                                const EurocCameraCalibration& cam1,
                                const RectificationOptions& options,
                                StereoRectification* rectification, std::string* error);

// Remaps frame->left / frame->right onto the rectified pair (bilinear interpolation, black
// outside the raw image) and turns the ground truth into the rectified left camera's pose
// (T_world_rect0 = T_world_cam0 * R_cam0_rect0). Depth is dropped (it belongs to the raw view).
// Identity rectification: the frame is left as it is. The images must have the raw size the
// maps were made for (the readers check that); aborts otherwise (a programmer error).
void RectifyFrame(const StereoRectification& rectification, DatasetFrame* frame);

}  // namespace harness
