// The pipeline's options (OdometryOptions: the platform and one options struct per stage, each
// declared and validated in its stage's header: FrontEndOptions in front_end.h, TrackerOptions in
// tracker.h, MotionOptions in motion_estimation.h, RecoveryOptions in recovery.h,
// InitialOrientationOptions in initial_orientation.h, BackEndOptions in back_end.h) and the
// platform's resolution (ResolvePlatform), the one place that configures the stages for a
// platform: what vo_options.yaml holds. StereoOdometry (odometry.h) holds the effective options
// (EffectiveOdometryOptions) and gives each stage its part.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

#include "vo/back_end.h"
#include "vo/camera.h"
#include "vo/front_end.h"
#include "vo/gyro_prior.h"
#include "vo/initial_orientation.h"
#include "vo/motion_estimation.h"
#include "vo/recovery.h"
#include "vo/tracker.h"

namespace vo {

// What the camera is mounted on (OdometryOptions::platform).
enum class Platform {
  kAuto,           // the caller's rig decides (ResolvePlatform): a rig known to be a ground
                   // vehicle (a wheeled robot on a floor, its axle known) is kGroundVehicle,
                   // anything else kFree. StereoOdometry alone knows no rig: kFree
  kFree,           // 6-DoF: the options as given (the paper's form; a drone, a hand-held rig)
  kGroundVehicle,  // a wheeled robot on one flat floor: the ground-vehicle options on
                   // (motion.few_point_motion, motion.ground_vehicle, back_end.vehicle_planar,
                   // back_end.flat_floor; the axle from the rig when the options leave it at 0)
};
// "auto", "free", "ground_vehicle".
const char* ToString(Platform platform);

// The pipeline's options, one part per stage (each with its own IsValid, in its stage's header)
// and the platform that configures them (ResolvePlatform): vo_options.yaml's groups, in the
// order a frame goes through them. The vehicle model (vo_options.yaml `vehicle`) is the motion
// stage's (MotionOptions::ground_vehicle, few_point.axle_behind_camera_m and
// few_point.no_sideways_slip); the recovery and the back end read it from there.
struct OdometryOptions {
  Platform platform = Platform::kAuto;  // see Platform and ResolvePlatform. Measured on the
                                        // simulated differential-drive robot (l_hallway texture
                                        // seeds 1-10 x strides 1/2/3/5, 40 runs): the ground
                                        // vehicle's median / mean end-pose error 0.097 / 0.211 m
                                        // against free's 0.136 / 0.375 m, stride 1 lost frames 31
                                        // against 113 (results/robustness/summary.md)
  FrontEndOptions front_end;            // front_end.h
  InitialOrientationOptions initial_orientation;  // initial_orientation.h
  TrackerOptions tracker;                         // tracker.h
  MotionOptions motion;                           // motion_estimation.h
  RecoveryOptions recovery;                       // recovery.h
  BackEndOptions back_end;                        // back_end.h
  ImuOptions imu;  // gyro_prior.h: the gyro's rotation as the prior's (when the caller gives
                   // gyro samples)

  // Each stage's IsValid (the message starts with the stage's name), then what spans two
  // stages (a sift_ratio matcher needs the SIFT detector's descriptors).
  bool IsValid(std::string* error) const;
};

// The options a run on a rig uses: `platform` resolved (never kAuto in the result). kAuto is
// kGroundVehicle when rig_axle_behind_camera_m >= 0 (the caller knows the rig is a ground
// vehicle and where its wheel axle is: a simulated robot, a dataset with the rig's
// description), kFree otherwise. kGroundVehicle switches motion.few_point_motion,
// motion.ground_vehicle, back_end.vehicle_planar and back_end.flat_floor on (so on that platform
// they cannot be switched off one by one: use kFree and set them). With motion.ground_vehicle on
// (either way), motion.few_point.axle_behind_camera_m left at 0 takes the rig's axle when it is
// known. On kGroundVehicle with the rig's camera pitch known (rig_pitch_deg finite: the optical
// axis's downward tilt, degrees), initial_orientation.up_from_mounting is switched on and
// initial_orientation.planes.expected_up_cam0, when left at its default (−y: an upright, level
// camera), becomes the up that pitch gives, (0, −cos p, −sin p).
OdometryOptions ResolvePlatform(const OdometryOptions& options, double rig_axle_behind_camera_m,
                                double rig_pitch_deg = std::numeric_limits<double>::quiet_NaN());

// The options as the pipeline uses them: the platform resolved without a rig (ResolvePlatform
// with no axle known), the disparity search range derived from the camera
// (front_end.derive_num_disparities), RANSAC's min_inliers raised to motion.min_inliers, and
// RANSAC's nonlinear refinement off when the bundle adjustment follows
// (motion.ransac_refine_with_ba false).
OdometryOptions EffectiveOdometryOptions(const StereoCamera& camera,
                                         const OdometryOptions& options);

}  // namespace vo
