// The simulated IMU: MuJoCo's `gyro` and `accelerometer` sensors on the robot's site "imu"
// (scenes/robot_p2dx.xml; the simulator places the site from the scenario's `imu:` keys), read
// every imu.rate_hz, and the standard continuous-time noise model of a MEMS IMU on top (the four
// numbers of a Kalibr imu.yaml):
//
//   measured = true + bias + white,   white ~ N(0, sigma_c^2 / dt)       (noise density sigma_c)
//   bias_{k+1} = bias_k + sigma_bc * sqrt(dt) * N(0, 1)                  (random walk sigma_bc)
//
// per axis, for the gyro (rad/s) and the accelerometer (specific force, m/s^2: gravity
// included, +9.81 m/s^2 up at rest), with dt = 1 / rate_hz. The gyro's bias starts at a turn-on
// bias of σ imu.gyro_turn_on_bias_sigma_radps per axis (default 0), the accelerometer's at 0.
// With imu.pre_roll_s the samples start that long before frame 0 (the robot standing while it
// settles). The noise has its own random stream derived from the scenario seed (ImuNoiseSeed), so
// the camera images do not depend on it.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "sim/random.h"
#include "sim/scenario.h"

namespace sim {

// One IMU sample: the measurement and its ground truth. Frames are the IMU's own (site "imu",
// axes of the robot body rotated by imu.roll/pitch/yaw_deg).
struct ImuSample {
  double time_s = 0.0;                                   // from frame 0 (s)
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();  // measured angular rate (rad/s)
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();  // measured specific force (m/s^2)
  bool has_gt = false;  // the fields below are known (simulated samples; not a dataset's)
  Eigen::Vector3d gyro_true_radps = Eigen::Vector3d::Zero();  // noise- and bias-free
  Eigen::Vector3d accel_true_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();      // bias in `gyro_radps`
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();      // bias in `accel_mps2`
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity();  // the IMU's pose
  Eigen::Vector3d v_world_mps = Eigen::Vector3d::Zero();          // the IMU's velocity in the world
};

// The seed of the IMU noise stream of a scenario seeded `scenario_seed` (the camera noise uses
// DeriveSeed(seed, frame, camera) with camera 0/1: this stream never meets it).
uint64_t ImuNoiseSeed(uint64_t scenario_seed);

// The noise model above for a sequence of samples taken every 1 / options.rate_hz.
class ImuNoiseModel {
 public:
  ImuNoiseModel(const ImuOptions& options, uint64_t seed);
  // Sets s->gyro_radps / accel_mps2 from s->gyro_true_radps / accel_true_mps2 with the current
  // biases and fresh white noise, records the biases in *s, then advances the biases by one
  // sample period.
  void Apply(ImuSample* s);

 private:
  ImuOptions options_;
  SplitMix64 rng_;
  double dt_s_;
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_ = Eigen::Vector3d::Zero();
};

// The pose of the IMU on the robot body (x forward, y left, z up, origin at the wheel axle)
// from the scenario's imu keys: rotation Rz(yaw) * Ry(pitch) * Rx(roll), then the offset.
Eigen::Isometry3d ImuPoseOnBody(const ImuOptions& options);

// Overlapping Allan deviation of the rate samples `x` (taken every dt_s) at cluster time
// tau = m * dt_s (IEEE Std 952): sqrt(sum_k (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2 /
// (2 tau^2 (N - 2m))) with theta the integrated signal. 0 when fewer than 2m + 1 samples.
double AllanDeviation(const std::vector<double>& x, double dt_s, int m);

}  // namespace sim
