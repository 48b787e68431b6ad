// Recovery: the stage for a frame whose motion the reference cannot measure. It gives that
// frame a pose that is never NaN (the prior's bridge, its rotation corrected by the image
// shift), measures what it can of the gap instead (the lost-frame chain between the lost frames
// themselves; for a ground vehicle the bridge alignment on the previous frame's features and
// the direct alignment of the previous image), and keeps what the next frames need for that
// (the previous frame's features, image and planes, the chain). It receives the previous
// output, the prior, this frame and the constant velocity (BridgeContext), and the tracker for
// the chain's matching; the re-initialisation itself is StereoOdometry's. Its options are
// RecoveryOptions (the `recovery` group of vo_options.yaml); it also reads the motion stage's
// vehicle model and inlier thresholds (MotionOptions: ground_vehicle, few_point's axle,
// min_inliers, the prior's update) and the tracker's image shift and prediction mode
// (TrackerOptions). In detail:
//
// A lost frame's pose is the prior's prediction from the previous output, never NaN —
// corrected, when the image shift from the previous frame is found
// (rotation_from_shift), by the rotation that explains that shift (CorrectPriorWithImageShift;
// a ground vehicle's, VehicleMotionFromImageShift): a turn in front of a plain wall is
// followed, not extrapolated (ShiftCorrectedPose). A lost frame that the reference cannot
// measure is matched against the previous lost frame with features (chain_lost_frames,
// ChainLostFrame): a turn in front of a plain wall leaves the reference's view behind, but the
// frames of the gap overlap each other, so their motion is measured link by link (the frame
// stays lost, OdometryResult::chained_to_frame; chained to the frame just before it, its motion
// is measured and it is not a lost frame).
//
// Ground vehicle (MotionOptions::ground_vehicle; off on the free platform, on for a ground
// vehicle): where the images cannot measure the motion it is a wheeled vehicle's, planar about the
// world's up (PlanarBridge). A lost frame's forward step and yaw are then measured against the
// previous frame's features without matching them (vehicle_bridge_alignment,
// bridge_alignment.h), and then by aligning the previous left image with this one on the planes
// of the last features (vehicle_direct_alignment, direct_alignment.h): when that
// converges the frame's motion is measured (not a lost frame). Each measured bridge becomes the
// constant velocity (the braking and the turn go on through the next lost frames).
//
// The re-initialisation itself (after reinit_after_lost_frames lost frames, or a rich frame
// that cannot be matched after a loss) is StereoOdometry's: it restarts the window on the frame
// at the pose BridgedPose gives.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <opencv2/core.hpp>
#include <vector>

#include "vo/bridge_alignment.h"
#include "vo/camera.h"
#include "vo/direct_alignment.h"
#include "vo/matcher.h"
#include "vo/motion_estimation.h"
#include "vo/motion_model.h"
#include "vo/odometry_result.h"
#include "vo/tracker.h"
#include "vo/types.h"

namespace vo {

// The recovery's options (vo_options.yaml `recovery`): the bridge's rotation from the image
// shift, the lost-frame chain, the ground vehicle's bridge and direct alignment, and when the
// pipeline re-initialises.
struct RecoveryOptions {
  bool rotation_from_shift = true;  // a frame without a measured motion (too few features, no
                                    // consensus) takes the prior's motion corrected by the
                                    // image shift from the previous frame (the rotation that
                                    // explains the shift left after the prior, see
                                    // CorrectPriorWithImageShift), when that shift is found
                                    // (TrackerOptions::image_shift); the measured rotation then
                                    // becomes the prior's
  double rotation_min_shift_score = 0.85;  // ... with at least this ZNCC, in [-1, 1]: real
                                           // structure scores 0.9-0.99 between successive
                                           // frames, false peaks on plain, smoothly shaded
                                           // walls ~0.7 (measured on the plain corridor)
  double rotation_min_peak_ratio = 1.05;   // ... and an unambiguous peak: best / second-best
                                           // peak score (ImageShiftResult::second_best_ratio)
                                           // at least this, >= 1
  double rotation_min_residual_px = 3.0;   // ... and only when the shift differs from the one
                                           // the prior predicts by more than this (pixels),
                                           // >= 0: smaller residuals are within what a global
                                           // shift cannot tell from parallax and zoom (forward
                                           // motion past plain walls), so the prior stands
  // With MotionOptions::ground_vehicle, a lost frame's rotation from the image shift
  // (rotation_from_shift) is a vehicle's: the yaw whose motion, with the camera's swing about the
  // axle (few_point.axle_behind_camera_m), predicts the shift (VehicleMotionFromImageShift). A
  // peak with at least vehicle_rotation_min_shift_score ([-1, 1]) and a best / second-best ratio
  // of at least vehicle_rotation_min_peak_ratio (>= 1) is used too (a turn past a plain wall
  // scores low over the whole overlap but has one clear peak); a shift whose vertical residual
  // (after the prior) exceeds max(rotation_min_residual_px, vehicle_max_vertical_shift_ratio ·
  // its horizontal residual) (>= 0) is zoom and parallax of forward motion, not a turn (the
  // prior stands).
  double vehicle_rotation_min_shift_score = 0.7;
  double vehicle_rotation_min_peak_ratio = 3.0;
  double vehicle_max_vertical_shift_ratio = 0.25;
  // A lost frame with at least min_features features is matched against the previous lost
  // frame that had them (the chain), when matching against the reference failed: a turn in
  // front of a plain wall takes the camera past the reference's view, and the frames of the
  // gap, which do overlap each other, then measure the motion through it (rotation and
  // translation, RANSAC with at least min_inliers inliers) instead of extrapolating the prior.
  // The frame stays lost (no link to the window; it counts in lost_frames unless chained to the
  // frame just before it, whose motion to it is then measured), its pose is the
  // chain's pose times that motion, and the motion moves the constant-velocity prior as a
  // tracked one does. Not with matcher.prediction none (the paper's form), the Kalman matcher
  // (stateful), or a caller's MotionPrior (it bridges a lost frame as given). Measured on l_hallway
  // texture seeds 1-10 x strides 1/2/3/5 (40 runs, results/robustness/, linear prior update):
  // defaults' median end-pose error 0.206 -> 0.182 m, max 1.958 -> 1.663 m, mean 0.431 -> 0.442 m;
  // plain_corridor better at every stride (0.268-0.569 -> 0.222-0.492 m); with few_point_motion and
  // ground_vehicle mean 0.393 -> 0.328 m.
  bool chain_lost_frames = true;
  // With ground_vehicle (the up known, matcher.prediction motion_prior, no caller's prior), the
  // bridged motion of a lost frame (the prior, its rotation corrected by the image shift) is
  // measured against the previous frame's features without matching them (bridge_alignment.h):
  // the forward step from their depth change, then the yaw that lays the previous features onto
  // this frame's; each where at least vehicle_bridge.min_pairs features pair up. The result
  // becomes the constant velocity (the braking and the turn go on through the next lost frames).
  // The constant velocity otherwise keeps the cruise speed into a robot that stops and turns in
  // front of a plain end wall (texture seed 3, stride 1: 4.2 cm a frame where it moved 0.6 cm)
  // and reads the image shift of off-centre texture as too much yaw (2.8 deg a frame for 2.2).
  // Measured on l_hallway texture seeds 1-10 x strides 1/2/3/5 (40 runs) with few_point_motion,
  // vehicle_planar_ba and the rig's axle (0.15 m): mean end-pose error 0.270 -> 0.219 m, runs
  // <= 0.29 m 31 -> 35, stride 1 max 0.507 -> 0.267 m (every seed under the paper's 0.29 m);
  // without vehicle_planar_ba mean 0.294 -> 0.249 m; ground_vehicle and the axle alone 0.334 ->
  // 0.253 m. It needs the rig's axle: with axle_behind_camera_m 0 on that rig (0.15 m off) the
  // swing is misread and runs <= 0.29 m go 30 -> 26; and without vehicle_planar_ba the pitched
  // camera goes 0.85 -> 1.30 % (ground_vehicle and the axle). Not for the 6-DoF default: without
  // the axle's swing in the model a near wall's sideways flow reads as yaw (mean 0.375 -> 0.405 m).
  bool vehicle_bridge_alignment = true;
  BridgeAlignmentOptions vehicle_bridge;
  // With vehicle_bridge_alignment, a lost (or re-initialised) frame's bridged motion is then
  // measured by aligning the previous left image with this one directly (direct_alignment.h):
  // the previous image's pixels with a gradient on the planes of the features (fitted in each
  // frame with enough of them, carried by the measured or bridged motion through at most 30
  // frames without), the vehicle's yaw and forward step by robust
  // Gauss-Newton on the grey levels, coarse to fine. When it converges with enough pixels and a
  // small enough covariance (vehicle_direct), the frame's motion counts as measured
  // (motion_measured, direct_motion; it is not a lost frame) and becomes the constant velocity.
  // A turn in front of a plain wall whose features are too few for any matcher (texture seed 3,
  // stride 1: 1-14 a frame for 21 frames) is measured from its edges, shadows and specks.
  bool vehicle_direct_alignment = true;
  DirectAlignmentOptions vehicle_direct;
  // The free platform's (not ground_vehicle) direct alignment, with the gyro (issue #35): a lost
  // (or re-initialised) frame whose prior rotation is the gyro's (imu.gyro_prior) is measured
  // by aligning the previous left image with this one on the planes of the last features, as
  // the vehicle's, in 6 DoF (AlignFreeDirect): the rotation the gyro's, the translation from
  // the images (from the constant velocity's and from standing still, the better fit). When it
  // converges with enough pixels and a small enough covariance (free_direct; its forward bounds
  // read as the translation's along any axis, its yaw bounds are not used; direct_alignment.h)
  // the frame's motion counts as measured (motion_measured, direct_motion) and becomes the
  // constant velocity. Without a gyro nothing changes (a 6-DoF alignment in front of one plane
  // cannot tell a sideways step from a turn). Measured on l_hallway texture seeds 1-10, strides
  // 1 and 3, with imu.gyro_prior and imu.ba_rotation_prior (results/gyro_prior/free_direct.md):
  // lost frames 12 / 9 -> 2 / 1, worst end-pose error 0.392 / 0.840 -> 0.139 / 0.127 m.
  bool free_direct_alignment = true;
  DirectAlignmentOptions free_direct = FreeDirectDefaults();
  int reinit_after_lost_frames = 10;  // while this many consecutive frames (or more) have been
                                      // lost, a frame whose motion fails against the reference
                                      // re-initialises the pipeline on itself, >= 1. Before
                                      // that, each new frame is matched against the last good
                                      // frame (wide, coarse-to-fine search), so the motion
                                      // across the gap is measured, not extrapolated

  // vehicle_bridge and vehicle_direct (free_direct) are checked when they are on (whatever the
  // platform).
  bool IsValid(std::string* error) const;
  // free_direct's defaults: the vehicle's, but for three translation axes.
  static DirectAlignmentOptions FreeDirectDefaults();
};

// What the recovery of one frame knows of the pipeline.
struct BridgeContext {
  const MotionPrior* prior = nullptr;  // the caller's prior (null: the constant velocity)
  Eigen::Isometry3d T_world_prev = Eigen::Isometry3d::Identity();  // the previous output
  bool world_up_known = false;  // the world's z is up (the first frame found the floor)
  cv::Mat current_left;         // this frame's left image (empty: none)
  const std::vector<Feature>* features = nullptr;  // this frame's features with depth
  bool after_loss = false;                         // frames were lost since the last tracked one
  ConstantVelocity* velocity = nullptr;            // the prior, moved by what the recovery measures
  double measured_rotation_sigma_rad = 0.0;  // > 0: the prior's rotation was measured (the gyro's,
                                             // ConstantVelocity::has_measured_rotation) with this
                                             // σ: a prior term of the direct alignment's yaw
};

class Recovery {
 public:
  // motion: the vehicle model (ground_vehicle, few_point.axle_behind_camera_m), the chain's
  // min_inliers and the prior's update; tracker: the image shift's options and whether the
  // matches are predicted (matcher.prediction; the paper's form bridges with the prior alone).
  Recovery(const StereoCamera& camera, const RecoveryOptions& options, const MotionOptions& motion,
           const TrackerOptions& tracker);

  // The pose of a frame without a measured motion: `chained` when ChainLostFrame measured one
  // (non-null), else the predicted pose corrected by the image shift from the previous frame
  // where it is found (sets result->rotation_from_shift), then for a ground vehicle with its
  // up known and no caller's prior the forward step and the yaw measured against the previous
  // frame's features (result->bridge_aligned) and by direct image alignment
  // (result->direct_motion, motion_measured).
  Eigen::Isometry3d BridgedPose(const BridgeContext& context, OdometryResult* result,
                                const Eigen::Isometry3d* chained = nullptr);

  // chain_lost_frames: `frame`, which the reference could not measure, against the
  // chain (the last lost frame with features). True with *T_world_curr when RANSAC finds at
  // least min_inliers inliers; the motion then moves the constant velocity. Times go to
  // `result`.
  bool ChainLostFrame(Tracker* tracker, const MatchFrame& frame, const BridgeContext& context,
                      OdometryResult* result, Eigen::Isometry3d* T_world_curr);
  // The lost frame `frame` (index frame_index, output pose T_world) the next lost frame is
  // chained to; EndChain: none (a frame was tracked or the pipeline re-initialised).
  void ContinueChain(int64_t frame_index, MatchFrame frame, const Eigen::Isometry3d& T_world);
  void EndChain() { chain_valid_ = false; }

  // At the end of each call: this frame's features, its motion since the previous output and
  // its left image (empty for the seam) become the previous frame's for the next one (the
  // bridge alignment's features, the direct alignment's planes and image, the image shift).
  // gyro: a gyro gives the frames' rotations (the free platform's direct alignment keeps the
  // planes then).
  void EndFrame(const std::vector<Feature>& features, const Eigen::Isometry3d& T_prev_curr,
                cv::Mat left, bool gyro = false);

  void Reset();

  // The planes the direct alignment of the next frame starts from (previous camera frame): those
  // of the last frame given to EndFrame whose features fit planes (FitScenePlanes), moved by the
  // motions since, for at most 30 frames; none without. Computed when asked (a frame without
  // matches), not at every EndFrame: the frames' fits are tried newest first, so it usually
  // fits one frame rather than every frame, and gives what fitting every frame in turn gives,
  // bit for bit (RecoveryTest.ScenePlanesAreTheFrameByFrameUpdates).
  const std::vector<ScenePlane>& ScenePlanes();

 private:
  // The prior's motion for a frame without a measured motion, made planar (PlanarPart about
  // the world's up) for a ground vehicle unless the caller gave the prior.
  Eigen::Isometry3d BridgeMotion(const BridgeContext& c) const;
  Eigen::Isometry3d ShiftCorrectedPose(const BridgeContext& c, OdometryResult* result);
  Eigen::Isometry3d AlignedBridgePose(const BridgeContext& c, const Eigen::Isometry3d& bridged,
                                      OdometryResult* result);
  Eigen::Isometry3d DirectAlignedPose(const BridgeContext& c, const Eigen::Isometry3d& bridged,
                                      OdometryResult* result);
  Eigen::Isometry3d FreeDirectAlignedPose(const BridgeContext& c, const Eigen::Isometry3d& bridged,
                                          OdometryResult* result);
  // A lost frame's motion T_prev_curr measured by a direct alignment: it becomes the constant
  // velocity and the frame's motion (direct_motion, motion_measured); the frame's pose.
  Eigen::Isometry3d DirectMotion(const BridgeContext& c, const Eigen::Isometry3d& T_prev_curr,
                                 OdometryResult* result);
  // EndFrame's part for the planes: this frame's features with depth and its motion are kept
  // for ScenePlanes().
  void DeferScenePlanes(const std::vector<Feature>& features, const Eigen::Isometry3d& T_prev_curr);

  StereoCamera camera_;
  RecoveryOptions options_;
  MotionOptions motion_;
  ImageShiftOptions image_shift_;                 // the tracker's
  bool predicted_ = true;                         // the tracker's matcher.prediction is not kNone
  std::vector<Feature> previous_frame_features_;  // the previous call's features
  // The planes of the features in the previous output's camera frame
  // (vehicle_direct_alignment), carried for scene_planes_age_ frames since they were fitted:
  // as of the frame before the first of pending_planes_ (the frames not yet taken in, oldest
  // first, each its features with depth and its motion; at most 31: a plane is carried for 30).
  std::vector<ScenePlane> scene_planes_;
  int scene_planes_age_ = 0;
  struct PendingPlaneFrame {
    std::vector<Feature> features;
    Eigen::Isometry3d T_prev_curr;
  };
  std::deque<PendingPlaneFrame> pending_planes_;
  cv::Mat previous_left_;     // the previous call's left image (empty after ProcessFeatures)
  bool chain_valid_ = false;  // the last lost frame with at least min_features features, since
  int64_t chain_frame_index_ = -1;  // the last tracked one, ...
  MatchFrame chain_frame_;
  Eigen::Isometry3d T_world_chain_ = Eigen::Isometry3d::Identity();  // ... and its output pose
};

}  // namespace vo
