// The EuRoC/ASL IMU: mav0/imu0/ (data.csv, sensor.yaml) written and read, and with it the ground
// truth at the IMU rate. EuRoC's body frame is the IMU's (imu0's T_BS is the identity), so a
// dataset with an IMU gives the cameras' T_BS relative to the IMU (CameraInImuFrame) and its
// mav0/state_groundtruth_estimate0 is the IMU's pose, velocity and biases at every IMU sample.
//
//   mav0/imu0/data.csv      "#timestamp [ns],w_RS_S_x [rad s^-1],...,a_RS_S_z [m s^-2]": the
//                           measured rates and specific forces in the IMU frame
//   mav0/imu0/sensor.yaml   %YAML:1.0, T_BS identity, rate_hz, the four noise numbers
//   mav0/state_groundtruth_estimate0/data.csv   p, q (w x y z), v (world), b_w, b_a: the true
//                           biases in the measurements; and its sensor.yaml
//   mav0/body.yaml          the body frame's comment
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/imu.h"
#include "sim/scenario.h"

namespace harness {

// A camera's T_BS in a dataset whose body frame is the IMU: T_imu_cam = T_body_imu^-1 *
// T_body_cam, both given on the robot's body.
Eigen::Isometry3d CameraInImuFrame(const Eigen::Isometry3d& T_body_cam,
                                   const Eigen::Isometry3d& T_body_imu);

// Writes imu0/, body.yaml and, when every sample has its ground truth, state_groundtruth_estimate0/
// at the IMU rate under `mav0`; *wrote_ground_truth says which. Sample times are the frames'
// clock, stamped as the frames are (stamp_offset_ns + TimeToNs(time_s): DatasetWriter's
// Options::stamp_offset_ns); they must increase.
bool WriteEurocImu(const std::string& mav0, const std::vector<sim::ImuSample>& samples,
                   const sim::ImuOptions& imu, int64_t stamp_offset_ns, bool* wrote_ground_truth,
                   std::string* error);

// Reads an imu0/data.csv: a header (comment lines), then 7 numbers a line (stamp in ns, gyro xyz
// in rad/s, accelerometer xyz in m/s^2), stamps strictly increasing, values finite. Errors name
// file:line. Samples have time_s = t_ns * 1e-9 and has_gt = false.
bool ReadEurocImu(const std::string& path, std::vector<int64_t>* t_ns,
                  std::vector<sim::ImuSample>* samples, std::string* error);

// Reads the ground truth at the IMU rate (a state_groundtruth_estimate0/data.csv as WriteEurocImu
// writes it: a header, then 17 numbers a line: stamp in ns, p, q (w x y z), v, b_w, b_a) into the
// samples ReadEurocImu read (t_ns, *samples): one line per sample, with the sample's stamp, in
// order. Sets has_gt, T_world_imu (the quaternion normalized), v_world_mps, gyro_bias_radps and
// accel_bias_mps2; gyro_true_radps and accel_true_mps2 (not in the file) stay as they are. The
// numbers read back as written (FormatDouble); the rotation matrix of a quaternion gives that
// quaternion back only to ~1e-16 (its last bit differs for about half of them). Errors name
// file:line.
bool ReadEurocImuGroundTruth(const std::string& path, const std::vector<int64_t>& t_ns,
                             std::vector<sim::ImuSample>* samples, std::string* error);

// Reads an imu0/sensor.yaml (a leading "%YAML:1.0" accepted): rate_hz (> 0) and
// gyroscope_noise_density, gyroscope_random_walk, accelerometer_noise_density,
// accelerometer_random_walk (finite, >= 0) into *imu, its pose fields untouched; the other keys
// (T_BS, comment, ...) are not read. Errors name file:line and the key.
bool ReadEurocImuSensorYaml(const std::string& path, sim::ImuOptions* imu, std::string* error);

// The samples with stamps in (after_ns, up_to_ns] (sorted stamps), appended to *out.
void ImuSamplesBetween(const std::vector<int64_t>& t_ns, const std::vector<sim::ImuSample>& samples,
                       int64_t after_ns, int64_t up_to_ns, std::vector<sim::ImuSample>* out);

}  // namespace harness
