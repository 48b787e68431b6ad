// Kalibr's camera-IMU calibration file, camchain-imucam.yaml (the format Kalibr's
// kalibr_calibrate_imu_camera writes and VIO systems such as OpenVINS, VINS-Fusion's and
// Basalt's converters read): the cameras' intrinsics and each camera's pose relative to the IMU.
// `vobench render --format rosbag` writes it beside the bag (the bag's camera_info carries no
// mounting on the IMU); `vobench eval --format rosbag` reads it (beside the bag, or named by
// --imu-extrinsics) so the VO can use the bag's gyro (imu.gyro_prior).
//
//   cam0:
//     T_cam_imu:                 # 4x4: a point in the IMU frame into the camera's, p_c = T p_i
//     - [r00, r01, r02, t0]
//     - [r10, r11, r12, t1]
//     - [r20, r21, r22, t2]
//     - [0.0, 0.0, 0.0, 1.0]
//     camera_model: pinhole
//     intrinsics: [fu, fv, cu, cv]
//     distortion_model: radtan
//     distortion_coeffs: [0.0, 0.0, 0.0, 0.0]
//     resolution: [width, height]
//     rostopic: /cam0/image_raw
//     timeshift_cam_imu: 0.0     # t_imu = t_cam + shift (s)
//   cam1:
//     T_cam_imu: ...
//     T_cn_cnm1: ...             # cam0 into cam1: [I | (-baseline, 0, 0)] for a rectified pair
//     ...
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "vo/camera.h"

namespace harness {

// The file name `render` writes beside a bag, and `eval --format rosbag` looks for there.
inline constexpr const char* kKalibrCamchainFileName = "camchain-imucam.yaml";

// camchain-imucam.yaml's text for a rectified stereo pair `camera` (pinhole, no distortion, cam1
// at +baseline_m along cam0's x) whose left camera is at T_imu_cam0 in the IMU frame, its images
// on the two topics. Numbers written so that they read back exactly (FormatDouble).
std::string KalibrCamchainYaml(const vo::StereoCamera& camera, const Eigen::Isometry3d& T_imu_cam0,
                               const std::string& left_topic, const std::string& right_topic);

// Reads cam0's pose in the IMU frame from a Kalibr camchain-imucam.yaml: T_imu_cam0 = the
// inverse of cam0's T_cam_imu (4 rows of 4 numbers, a rigid transform). Only cam0's T_cam_imu
// and timeshift_cam_imu are read (other keys are not refused: Kalibr writes more); a time shift
// other than 0 is refused (the IMU's stamps would need shifting, which the reader does not do).
// Errors name the file, line and key.
bool ReadKalibrImuExtrinsics(const std::string& path, Eigen::Isometry3d* T_imu_cam0,
                             std::string* error);

}  // namespace harness
