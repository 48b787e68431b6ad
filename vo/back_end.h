// The back end: what the pipeline remembers of its last few frames and how it refines them (the
// paper's refinement, section V; ORB-SLAM3's local mapping in small). A frame whose motion from
// the reference was measured enters with that motion; its initial pose blends it with the
// constant-velocity prediction by the matches' support (prior_weight · (1 − inlier ratio); no
// blend for a few-point motion, which already is the prior's fit to the matches), its inlier
// matches continue the feature tracks, and the windowed bundle adjustment (sliding_window.h,
// the oldest pose fixed) refines the window's poses unless the divergence guard rejects the
// result. For a ground vehicle the adjustment also links consecutive poses by the planar motion
// prior and keeps them on a flat floor (planar_motion_prior.h; the vehicle's up comes from the
// caller). The back end knows nothing of matching, RANSAC or recovery: it receives the frame's
// features, its inlier matches, its measured motion and the prior's, and gives back the poses
// and the refined motion from the reference, which the motion model (motion_model.h) takes in.
// With a gyro (imu.gyro_prior and imu.ba_rotation_prior), the adjustment also holds consecutive
// window frames to the gyro's rotation between them (AddGyroRotation, rotation_prior.h).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "vo/bundle_adjustment.h"
#include "vo/camera.h"
#include "vo/gyro_prior.h"
#include "vo/planar_motion_prior.h"
#include "vo/sliding_window.h"
#include "vo/tracks.h"
#include "vo/types.h"

namespace vo {

// Bundle-adjustment defaults for the pipeline: points seen in a single frame of the window
// carry no pose information, so they are left out (min_frames_per_point = 2); 10 LM
// iterations suffice from the blended initial pose; a window of 3–10 poses makes the reduced
// camera system tiny, so the hand-written Schur-complement solver (BaSolver::kSchurLm) is
// ~5× faster than Ceres there, and for the Ceres reference DENSE_SCHUR beats the sparse
// factorisation.
BundleAdjustmentOptions DefaultOdometryBundleAdjustmentOptions();

// A ground vehicle's planar motion prior in the window's bundle adjustment
// (back_end.vehicle_planar; with the vehicle model on, vehicle.enabled): consecutive poses keep
// their roll and pitch (σ tilt_sigma_deg), take no step along up (σ lift_sigma_m) and the axle
// does not slip sideways (σ slip_sigma_m), all > 0, each σ weighing the prior against one pixel
// of reprojection error. The up in the camera frame is the vehicle's: the first frame's floor
// fit refined by every reliable tracked motion. Off on the free platform; platform
// ground_vehicle switches it on. Measured with the few-point motion and the rig's axle (0.15 m)
// on l_hallway texture seeds 1-10 x strides 1/2/3/5 (40 runs): mean end-pose error 0.294 ->
// 0.270 m, camera.pitch_deg 10: 1.13 -> 0.33 % (README, "Planar bundle adjustment"). It needs
// the rig's axle: with 0 for a camera 0.15 m ahead of it the no-slip residual fights every
// turn's swing (texture seed 7, stride 1: 0.31 -> 4.3 %).
struct VehiclePlanarBaOptions {
  bool enabled = false;
  double tilt_sigma_deg = 0.1;
  double lift_sigma_m = 0.002;
  double slip_sigma_m = 0.002;
};

// With the planar prior: the floor is flat (one plane), so every pose of the window keeps the
// first pose's vehicle up (as refined so far; σ tilt_sigma_deg) and the first camera's height
// (σ height_sigma_m), both > 0 (planar_motion_prior.h, "Flat floor"; the σ are an indoor
// floor's and a vehicle's suspension's, not tuned). Only when the first frame found a floor (an
// up from a ceiling is 1-1.5° off). Off on the free platform (a library cannot assume a flat
// floor); platform ground_vehicle says so. Measured against the planar prior alone (40 runs):
// median end-pose error 0.108 -> 0.097 m, stride 1 median 0.108 -> 0.079 m (README, "Flat
// floor").
struct FlatFloorOptions {
  bool enabled = false;
  double tilt_sigma_deg = 0.3;
  double height_sigma_m = 0.01;
};

struct BackEndOptions {
  bool bundle_adjustment = true;  // refine with the windowed BA; false = the blended
                                  // RANSAC/Horn estimate is the output
  int window_frames = 5;          // frames in the BA window (and kept by the track manager),
                                  // 3..10 (paper: 3–5, 10 wished for)
  int max_points = 100;  // at most this many points in the BA (those seen in the most frames of
                         // the window, then the oldest tracks), >= 0; 0 = every point seen in at
                         // least ba.min_frames_per_point frames. 100 costs ~0.4 ms at 5 frames
                         // (~2 ms with ba.solver = ceres) and loses no accuracy on the
                         // synthetic corridor
  double max_correction_m = 0.25;   // a BA result that moves the newest pose farther than this
                                    // from its initial value (metres) is rejected (divergence
                                    // guard; the blend is kept), > 0
  double max_correction_deg = 5.0;  // the same for the rotation (degrees), > 0
  double prior_weight = 0.5;  // weight of the constant-velocity prediction in the initial pose
                              // is prior_weight · (1 − inlier_ratio), in [0, 1]; 0 = the
                              // RANSAC/Horn estimate alone
  BundleAdjustmentOptions ba = DefaultOdometryBundleAdjustmentOptions();  // the solver
  VehiclePlanarBaOptions vehicle_planar;
  FlatFloorOptions flat_floor;

  bool IsValid(std::string* error) const;
};

// The initial motion from the reference of a frame whose motion was measured: the measured
// motion blended with the prior's (Blend, motion_model.h) by prior_weight · (1 − inlier_ratio),
// the ratio clamped to 1; the measured motion alone without a prior or for a few-point motion.
Eigen::Isometry3d InitialMotion(const BackEndOptions& options,
                                const Eigen::Isometry3d& T_ref_curr_measured,
                                const Eigen::Isometry3d* T_ref_curr_prior, double inlier_ratio,
                                bool few_point);

// The ground vehicle's geometry the planar prior needs, from the pipeline.
struct VehicleGeometry {
  bool vehicle = false;   // the vehicle model is on (vehicle.enabled)
  bool up_known = false;  // the world's up and the vehicle's up in the camera are known
  Eigen::Vector3d up_cam = Eigen::Vector3d::Zero();  // the vehicle's up, camera frame (unit)
  Eigen::Matrix3d R_world_cam0_initial = Eigen::Matrix3d::Identity();  // the first pose
  bool floor_found = false;           // the first frame's orientation found a floor
  double axle_behind_camera_m = 0.0;  // vehicle.axle_behind_camera_m
};

// The window's planar motion prior for that geometry: off unless vehicle_planar is enabled,
// the vehicle model on and its up known; the flat floor only when the first frame found one,
// its up the vehicle's (as refined so far) at the first pose, its height 0.
PlanarMotionPrior WindowPlanarPrior(const BackEndOptions& options, const VehicleGeometry& geometry);

// What BackEnd::Add did.
struct BackEndAdd {
  TrackUpdateResult update;                                              // the tracks' update
  Eigen::Isometry3d T_ref_curr_initial = Eigen::Isometry3d::Identity();  // InitialMotion
  Eigen::Isometry3d T_world_curr = Eigen::Isometry3d::Identity();        // the initial pose
};

class BackEnd {
 public:
  explicit BackEnd(const BackEndOptions& options);

  void Reset();
  // A new window on `frame_index` at pose T_world_cam0 (tracks start on its features).
  TrackUpdateResult Start(int64_t frame_index, std::vector<Feature>* features,
                          const Eigen::Isometry3d& T_world_cam0);
  // A frame measured against the reference (`ref_frame_index`, in the window): its initial
  // pose (InitialMotion after the reference's pose) stored, its tracks continued by the inlier
  // matches (reference index → features index). The reference must be in the window
  // (update.status says otherwise).
  BackEndAdd Add(int64_t frame_index, int64_t ref_frame_index, std::vector<Feature>* features,
                 const std::vector<Match>& inlier_matches,
                 const Eigen::Isometry3d& T_ref_curr_measured,
                 const Eigen::Isometry3d* T_ref_curr_prior, double inlier_ratio, bool few_point);
  // The windowed bundle adjustment after Add (not for a few-point frame: a BA over a few points
  // has no prior and is weaker than the solver; the caller skips it).
  WindowRefinement Refine(const StereoCamera& camera, int64_t frame_index,
                          const VehicleGeometry& geometry);
  // The motion from the reference (as the window holds it now, after the refinement) to the
  // frame's pose T_world_curr; `fallback` when the reference has left the window.
  Eigen::Isometry3d MotionFromReference(int64_t ref_frame_index,
                                        const Eigen::Isometry3d& T_world_curr,
                                        const Eigen::Isometry3d& fallback) const;

  // Pose of a frame of the window (null when it is not in the window).
  const Eigen::Isometry3d* Pose(int64_t frame_index) const { return window_.Pose(frame_index); }
  const TrackManager& tracks() const { return window_.tracks(); }
  const BackEndOptions& options() const { return options_; }

  // The gyro's rotation of frame `frame_index` (every processed frame, indices consecutive):
  // R_prev_curr from the frame before, its σ max(min_rotation_sigma_deg, rotation.sigma_rad());
  // not ok breaks the chain there. Refine then holds each pair of consecutive window frames
  // whose chain is unbroken to the product of the rotations between them (σ² summed).
  void AddGyroRotation(int64_t frame_index, const GyroRotation& rotation,
                       double min_rotation_sigma_deg);
  // The priors Refine gives the window now (consecutive window frames, oldest first).
  std::vector<WindowRotationPrior> GyroRotationPriors() const;

 private:
  // A frame of the gyro's chain: the chain's first frame, the rotation R_first_frame and the
  // variance summed along it (rad²).
  struct GyroNode {
    int64_t first = -1;
    Eigen::Matrix3d R_first_frame = Eigen::Matrix3d::Identity();
    double variance_rad2 = 0.0;
  };

  BackEndOptions options_;
  SlidingWindow window_;                    // tracks, window poses and the bundle adjustment
  std::map<int64_t, GyroNode> gyro_chain_;  // by frame index, from the window's oldest frame
};

}  // namespace vo
