// What one StereoOdometry call gives back (OdometryResult: status, pose, counts, stage times,
// what the recovery did) and what it matched (FrameDiagnostics), and the caller's motion prior
// (MotionPrior). The stages fill their parts of an OdometryResult; odometry.h returns it.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "vo/types.h"

namespace vo {

// An external motion prior for one frame (wheel odometry, a gyro, an IMU preintegration): the
// camera's motion since the previous Process call, p_prev = T_prev_curr * p_curr (cam0 frames).
// It replaces the constant-velocity prediction for that frame: it centres the matcher's search,
// it is the pose of a lost frame, and it is what the RANSAC motion is blended with.
struct MotionPrior {
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();
};

enum class TrackingStatus {
  kInitializing,  // first frame (or a frame before the first usable one): pose = initial
  kTracking,      // motion estimated against the previous frame
  kLost,          // not tracked: pose = constant-velocity prediction, or the direct image
                  // alignment's measurement (OdometryResult::direct_motion); see `message`
  kRecovered,     // first frame estimated (or re-initialised) after one or more lost frames
};

// "initializing", "tracking", "lost", "recovered".
const char* ToString(TrackingStatus status);

// Wall-clock time of each stage of one frame (milliseconds, std::chrono::steady_clock);
// 0 for stages that did not run.
struct StageTimes {
  double disparity_ms = 0.0;    // disparity (dense map, or the features' pixels)
  double detect_ms = 0.0;       // feature detection
  double depth_ms = 0.0;        // AttachDepth + dropping features without depth
  double match_ms = 0.0;        // inter-frame matching (cue computation included)
  double motion_ms = 0.0;       // correspondences + RANSAC + tracks + initial-pose blend
  double ba_ms = 0.0;           // window problem + bundle adjustment
  double orientation_ms = 0.0;  // first frame only: plane-based initial orientation
  double predict_ms = 0.0;      // predicted positions + coarse-to-fine image shift (when run);
                                // a lost frame: its bridge and direct image alignment
  double guided_ms = 0.0;       // guided second pass: re-match + RANSAC
  double total_ms = 0.0;        // the whole Process / ProcessFeatures call
};

// Milliseconds on std::chrono::steady_clock since `start`: how the stages time themselves.
inline double ElapsedMs(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// What centred the matcher's search for the matches that were used.
enum class PredictionSource {
  kNone,         // previous positions (matcher.prediction: none, or no motion known yet)
  kMotionPrior,  // the motion prior (constant velocity or the caller's MotionPrior)
  kImageShift,   // previous positions + the coarse-to-fine image shift
  kGuided,       // the estimated motion of this frame (guided second pass)
  kLastMotion,   // the previous frame's own measured motion (not blended into the prior)
};
// "none", "motion_prior", "image_shift", "guided", "last_motion".
const char* ToString(PredictionSource source);

struct OdometryResult {
  TrackingStatus status = TrackingStatus::kLost;
  std::string message;       // empty when tracking normally; says why when lost or re-initialised
  int64_t frame_index = -1;  // 0-based count of Process/ProcessFeatures calls since Reset
  double time_s = 0.0;       // the time stamp given (seconds)
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();  // p_world = T * p_cam0;
                                                                   // always finite
  Eigen::Isometry3d T_prev_curr =
      Eigen::Isometry3d::Identity();  // motion since the previous
                                      // call's output pose: p_prev = T_prev_curr * p_curr, i.e.
                                      // T_world_cam0(prev)⁻¹ · T_world_cam0(curr); identity for the
                                      // first frame
  int num_features = 0;              // features detected (or given) in the left image
  int num_features_with_depth = 0;   // of those, with a valid disparity (kept)
  int num_matches = 0;               // matches to the reference frame
  int num_inliers = 0;               // RANSAC inliers among them
  double rms_reprojection_px = 0.0;  // BA inlier rms when BA ran, else RANSAC's rms (pixels)
  bool ba_ran = false;               // the bundle adjustment ran and its result was used
  int ba_num_frames = 0;             // poses in the BA window (when ba_ran)
  int ba_num_points = 0;             // points optimised (when ba_ran)
  int reference_frame_index = -1;    // frame_index of the frame matched against; -1 = none
  bool motion_measured = false;      // T_prev_curr was measured by matching (kTracking or a
                                     // kRecovered frame matched across the gap); false for the
                                     // first frame, lost frames and re-initialisations (their
                                     // pose is the prior's prediction) unless the direct image
                                     // alignment measured them (direct_motion) or they were
                                     // chained to the lost frame just before (chained_to_frame)
  bool reinitialised = false;        // the pipeline restarted on this frame after a loss
  bool few_point_motion = false;     // the motion came from the few-point solver with the
                                     // prior (MotionOptions::few_point_motion)
  bool rotation_from_shift = false;  // lost or re-initialised, its pose is the prior corrected
                                     // by the image shift from the previous frame
  bool bridge_aligned = false;       // lost or re-initialised, its forward step or yaw was
                                     // measured against the previous frame's features
                                     // (RecoveryOptions::vehicle_bridge_alignment)
  bool direct_motion = false;        // lost or re-initialised, its motion was measured by
                                     // direct image alignment (motion_measured;
                                     // RecoveryOptions::vehicle_direct_alignment)
  int64_t chained_to_frame = -1;     // lost or re-initialised, its pose was measured against
                                     // this earlier lost frame (RecoveryOptions::chain_lost_frames;
                                     // -1: not chained) ...
  int chain_inliers = 0;             // ... with this many RANSAC inliers
  PredictionSource prediction = PredictionSource::kNone;  // centre of the used matches' search
  bool image_shift_ok = false;  // the coarse-to-fine image shift ran and found a shift
  Eigen::Vector2d image_shift_px = Eigen::Vector2d::Zero();  // that shift (pixels), when ok
  int num_first_pass_inliers = 0;  // inliers of the first (prior-centred) pass, before the
                                   // coarse-to-fine and guided passes
  int num_disparities = 0;         // the disparity search range of this frame (pixels)
  int disparity_pixels = 0;        // pixels whose disparity was evaluated (the whole image
                                   // with disparity_mode dense; left + right-view pixels
                                   // with at_features)
  StageTimes times;
  bool initial_orientation_ok = false;   // first frame only: the hallway orientation was found
  bool floor_refined = false;            // first frame only: its floor (without one, its
                                         // ceiling) was refined on the images
                                         // (orientation_floor_refinement)
  std::string floor_refinement_message;  // first frame: what the refinement did, or why not
                                         // and defines the world frame
};

// A frame without a measured motion: lost, or re-initialised at the predicted pose (what
// `lost_frames` counts). The first frame (kInitializing) has nothing to measure and is not.
inline bool IsLostFrame(const OdometryResult& r) {
  return !r.motion_measured && r.status != TrackingStatus::kInitializing;
}

// What one StereoOdometry call matched, beside its OdometryResult: the frame's features (with
// depth, track ids set when tracked), the reference frame's features, the matches between
// them (prev = index into reference_features, curr = index into features) and per match
// whether it is a RANSAC inlier. Empty for a frame that matched nothing (first, lost).
struct FrameDiagnostics {
  const std::vector<Feature>& features;
  const std::vector<Feature>& reference_features;
  const std::vector<Match>& matches;
  const std::vector<bool>& inlier_mask;
};

}  // namespace vo
