// The gyro prior (issue #35): the rotation between two frames integrated from a gyro's samples,
// in the camera frame, with its covariance, for the motion prior of the frame. A plain wall
// hides the rotation from the images; a gyro measures it. StereoOdometry (odometry.h) takes the
// samples (AddGyroSamples) and the IMU's mounting (SetGyro) from its caller and, with
// ImuOptions::gyro_prior on, the prior's rotation of each frame is the gyro's (its translation
// stays the constant velocity's): the matching gates, the bridge of a frame without matches,
// the lost-frame chain, the few-point motion (whose rotation prior σ becomes the gyro's) and
// the blend with the measured motion all use it, and the windowed bundle adjustment holds
// consecutive window frames to the gyro's rotation between them (imu.ba_rotation_prior,
// back_end.h, rotation_prior.h). Without samples, or with gyro_prior off,
// nothing changes (bit for bit).
//
// Integration. The samples are rates ω_i (rad/s, IMU frame) at times t_i; between two frames
// at t0 < t1 the rate is taken as piecewise linear between the samples (trapezoid; before the
// first and after the last sample in [t0, t1] it is held at that sample's rate), and the IMU's
// rotation is the ordered product R_imu0_imu1 = Π Exp((ω - b) Δt) over the pieces, b the bias
// estimate. In the camera frame: R_prev_curr = R_cam_imu · R_imu0_imu1 · R_imu_cam, the
// convention of T_prev_curr (p_prev = T_prev_curr · p_curr). Exact for a constant rate.
//
// Covariance (the noise model of sim/imu.h, Kalibr's four numbers): the white noise of density
// σ_c (rad/s/√Hz) integrates to a rotation error of variance σ_c² · Δt per axis over Δt; the
// bias estimate's error, of variance P (rad²/s²), to P · Δt². P starts at
// initial_bias_sigma_radps², grows by σ_bc² · dt for every second that passes (the random walk
// σ_bc, rad/s²/√Hz) and shrinks with each bias update. Σ = (σ_c² Δt + P Δt²) · I (rad²).
//
// Bias. The gyro's bias is estimated online from the VO's own rotations: over a stretch of
// consecutive well-tracked frames (bias_window_s of time), the rotation the gyro integrated
// (with the current estimate) is compared with the one the VO measured; their difference,
// divided by the stretch's time, is an observation of the estimate's error, taken in with the
// low gain bias_gain (the VO's rotation over a stretch of seconds is good to a fraction of a
// degree; a frame's to ~0.1°, which over 1/30 s would be a bias of degrees per second). A
// stretch whose observation is larger than max_bias_radps is the VO's error, not the gyro's,
// and is dropped. Before that, the standing start (ImuOptions::standing_start_s): the samples
// of the last second before the first frame, when they look still, give the bias as their
// mean (a real gyro's turn-on bias, too large for the online filter's bound, which then holds
// its corrections within max_bias_radps of that estimate). Without a standing start, the moving
// start: before any observation has been taken in, two stretches in a row whose observations
// are both beyond max_bias_radps (and at most max_standing_bias_radps) and agree within
// max_bias_radps give the bias their mean, as a standing start would (a turn-on bias repeats
// itself stretch after stretch; a VO's bad stretch does not). Until then the prior uses a bias
// of 0: a sequence that starts moving with a large turn-on bias is off by it for the first two
// stretches (results/gyro_prior/default_on.md).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "vo/ransac.h"

namespace vo {

// The `imu` group of vo_options.yaml.
struct ImuOptions {
  bool gyro_prior = true;  // when the caller gives gyro samples (StereoOdometry::SetGyro and
                           // AddGyroSamples), each frame's prior rotation is the gyro's (see the
                           // header comment); false = the constant velocity's, as without an IMU,
                           // bit for bit. On by default (issue #35): with the BA's rotation prior
                           // and the free platform's direct alignment, the 6-DoF mode loses no
                           // frame at strides 1 and 3 on l_hallway seeds 1-10 (113 / 50 without
                           // the gyro; results/gyro_prior/free_direct.md), and the ground
                           // vehicle's 40-run sweep ends closer on 38 runs
                           // (results/gyro_prior/vehicle_sweep.md). Without samples (no IMU, a
                           // bag) nothing changes
  bool few_point_motion = true;      // with the gyro's rotation, a frame RANSAC cannot measure
                                     // takes the few-point motion (motion.few_point_motion) on
                                     // any platform: its rotation is the gyro's (σ below), the
                                     // few matches measure the translation; off: as
                                     // motion.few_point_motion says
  bool few_point_after_loss = true;  // ... also after lost frames (the motion stage's own
                                     // few-point motion waits for a measured frame): the
                                     // rotation since the reference is the gyro's, the few
                                     // matches measure the translation the constant velocity
                                     // extrapolated
  bool ba_rotation_prior = true;     // the windowed bundle adjustment holds each pair of
                                     // consecutive window frames whose frames between were all
                                     // given the gyro's rotation to the gyro's rotation between
                                     // them (rotation_prior.h; σ as below, the frames' variances
                                     // summed); used only with gyro_prior on. It needs the
                                     // gyro's bias from the first frames: a real gyro's turn-on
                                     // bias (EuRoC V1_01's ADIS16448: 0.078 rad/s about z) comes
                                     // from the standing start (standing_start_s); without it
                                     // the prior turned the real standing clip's estimate 1.1°
                                     // in 0.95 s (0.08° with it; the images alone 0.09°)
  double max_weak_rotation_error_deg = 0.5;  // a weak RANSAC motion (fewer than
                                             // motion.reliable_min_inliers inliers) whose
                                             // rotation is farther than this from the gyro's
                                             // (degrees) is no consensus (the few-point motion
                                             // instead), > 0
  double min_rotation_sigma_deg = 0.05;      // σ of the gyro's rotation as a prior term (the
                                             // few-point motion's rotation prior, the direct
                                             // alignment's yaw prior, the bundle adjustment's
                                             // rotation prior): the gyro's own σ, at least
                                             // this (degrees; the IMU's mounting and time stamps
                                             // are not exact), > 0
  double initial_bias_sigma_radps = 0.005;   // σ of the bias before any estimate (rad/s), >= 0
  double bias_gain = 0.2;                    // each stretch's bias observation moves the
                                             // estimate this part of the way, in [0, 1]
                                             // (0: the bias stays 0)
  double bias_window_s = 2.0;    // a stretch of well-tracked frames this long (seconds) is
                                 // one observation of the bias, > 0
  double max_bias_radps = 0.02;  // an observation larger than this (rad/s) is dropped
                                 // (the VO's error), and the estimate is kept within it of the
                                 // standing start's (or of 0), > 0
  // The standing start: on the first frame, the gyro samples of the standing_start_s seconds
  // before it (they must span 90 % of that), when they look still (each axis' standard
  // deviation at most standing_max_std_radps: the sensor's noise and a standing platform's
  // vibration, not a turn) and their mean is at most max_standing_bias_radps, give the bias:
  // their mean, its variance the largest axis' variance over the number of samples. A real
  // gyro's turn-on bias (EuRoC V1_01's ADIS16448: 0.078 rad/s about z, std 0.013-0.021 rad/s
  // standing; 0.035-0.26 rad/s in flight) is then known from the first frame; the online
  // estimate corrects it from there (max_bias_radps about it). 0: off (the bias starts at 0).
  double standing_start_s = 1.0;         // >= 0
  double standing_max_std_radps = 0.03;  // > 0
  double max_standing_bias_radps = 0.2;  // > 0

  bool IsValid(std::string* error) const;
};

// One gyro sample: its time (seconds, the frames' clock) and rate (rad/s, IMU frame).
struct GyroSample {
  double time_s = 0.0;
  Eigen::Vector3d rate_radps = Eigen::Vector3d::Zero();
};

// The gyro's mounting and noise model.
struct GyroCalibration {
  Eigen::Matrix3d R_imu_cam = Eigen::Matrix3d::Identity();  // cam0's axes in the IMU frame
                                                            // (rotation of T_imu_cam0)
  double noise_density = 0.0;                               // σ_c, rad/s/√Hz, >= 0
  double random_walk = 0.0;                                 // σ_bc, rad/s²/√Hz, >= 0

  bool IsValid(std::string* error) const;
};

// A frame's rotation from the gyro.
struct GyroRotation {
  bool ok = false;  // samples covered the interval (at least one sample in or at its ends)
  double dt_s = 0.0;
  Eigen::Matrix3d R_prev_curr = Eigen::Matrix3d::Identity();  // camera frame
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();       // of its rotation vector (rad²)
  // σ of the rotation about any axis (radians): sqrt of the covariance's largest eigenvalue.
  double sigma_rad() const;
};

// The rotation R_a_b of the IMU from time t0 to t1 (> t0) integrated from `samples` (any
// order, sorted by time here; those outside [t0, t1] bound the pieces at the ends) with the
// bias subtracted; see the header comment. False when no sample lies in [t0 - 1 s, t1 + 1 s]
// (a gap), or t1 <= t0.
bool IntegrateGyro(const std::vector<GyroSample>& samples, double t0_s, double t1_s,
                   const Eigen::Vector3d& bias_radps, Eigen::Matrix3d* R_imu0_imu1);

// The gyro of one sequence: the samples given, the bias estimate and its variance.
class GyroPrior {
 public:
  GyroPrior(const ImuOptions& options, const GyroCalibration& calibration);

  // Samples (any number, stamps increasing; older ones than the previous frame are dropped).
  void AddSamples(const std::vector<GyroSample>& samples);

  // The rotation from the previous frame's time (the last call's t_s) to t_s; not ok for the
  // first call, a time that does not increase, or samples that do not cover the interval.
  // Each call starts the next interval at t_s and lets the bias's variance grow.
  GyroRotation Next(double t_s);

  // The VO measured this frame's rotation R_prev_curr (camera frame) on a well-tracked frame
  // (the last Next's interval): it extends the bias stretch; `measured` false (a lost or weak
  // frame) ends it without an observation.
  void Observe(bool measured, const Eigen::Matrix3d& R_prev_curr_vo);

  const Eigen::Vector3d& bias_radps() const { return bias_; }
  bool standing_start() const { return standing_start_; }  // the bias came from a standing start
  bool moving_start() const { return moving_start_; }      // ... from the moving start (Observe)
  double bias_variance() const { return bias_variance_; }
  int bias_updates() const { return bias_updates_; }
  void Reset();

 private:
  // The standing start before the first frame at t_s (see ImuOptions::standing_start_s).
  void EstimateStandingBias(double t_s);

  ImuOptions options_;
  GyroCalibration calibration_;
  std::vector<GyroSample> samples_;
  bool have_time_ = false;
  double last_time_s_ = 0.0;
  Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_origin_ = Eigen::Vector3d::Zero();  // the standing start's (or 0)
  bool standing_start_ = false;
  bool moving_start_ = false;  // the bias came from two large observations in a row (Observe)
  bool have_large_ = false;    // large_ holds the last large observation (none accepted yet)
  Eigen::Vector3d large_ = Eigen::Vector3d::Zero();
  double bias_variance_ = 0.0;
  int bias_updates_ = 0;
  // The last Next's result (the interval Observe speaks of).
  GyroRotation last_;
  // The stretch: its time, the gyro's and the VO's rotation over it (IMU frame).
  double stretch_s_ = 0.0;
  Eigen::Matrix3d stretch_gyro_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d stretch_vo_ = Eigen::Matrix3d::Identity();
};

// A weak RANSAC motion (ok, fewer than reliable_min_inliers inliers, finite) whose rotation is
// farther than options.max_weak_rotation_error_deg from the gyro's prior rotation R_prior
// (R_ref_curr) is a wrong consensus: it becomes one without a consensus (kNoConsensus, no
// inliers, the message says by how much), so the few-point motion with the gyro's rotation as
// its prior takes the frame. Anything else is left as it is.
void RejectWeakMotionAgainstGyro(const ImuOptions& options, int reliable_min_inliers,
                                 const Eigen::Matrix3d& R_prior, RansacResult* ransac);

}  // namespace vo
