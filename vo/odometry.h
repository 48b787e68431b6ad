// The stereo visual-odometry pipeline: one call per stereo pair, the camera's pose back.
// Kwolek, docs/PAPER.md (the whole table), sections IV–V of the paper. StereoOdometry
// orchestrates the stages, each in its own unit that receives only the data it needs:
//
// Each stage takes its own part of OdometryOptions (FrontEndOptions, InitialOrientationOptions,
// TrackerOptions, MotionOptions, RecoveryOptions, BackEndOptions; the tracker and the recovery
// also read MotionOptions, the recovery the tracker's image shift):
//
//   front end     disparity prepared (area-based; search range from the scene)
//                 → features (Harris | SIFT, bucketed) → depth at the features'
//                 pixels, features without depth dropped                      front_end.h
//   frame 0       plane-based initial orientation (the hallway frame)         initial_orientation.h
//   frame k > 0   match to the reference frame with the prediction passes
//                 (motion prior, coarse-to-fine shift, last motion, guided)   tracker.h
//                 → RANSAC + Horn (T_ref_curr), seeded by track ages; the
//                 few-point motion with the prior where RANSAC has no
//                 consensus                                                   motion_estimation.h
//                 → initial pose = blend of that motion and the constant-velocity
//                 prediction (slerp on the rotation, linear on the translation)
//                 → tracks (inlier matches only), windowed bundle adjustment,
//                 oldest pose fixed, divergence guard          back_end.h (sliding_window.h)
//                 → T_world_cam0
//   no motion     the pose bridged (prior, image shift, lost-frame chain, a
//                 ground vehicle's bridge and direct alignment)               recovery.h
//   gyro          the prior's rotation integrated from the caller's gyro
//                 samples (SetGyro, AddGyroSamples; imu.gyro_prior)           gyro_prior.h
//   shared        the constant-velocity prior, predictions, pose algebra      motion_model.h
//   options       OdometryOptions (vo_options.yaml)                          odometry_options.h
//   result        OdometryResult, FrameDiagnostics, MotionPrior               odometry_result.h
//
// The reference frame is the last frame that was tracked (or initialised): normally the
// previous frame; after lost frames, the last good one.
//
// World frame. With initial_orientation.enabled (default) and a floor (or ceiling) found in
// the first frame: the hallway frame of plane_orientation.h (x along the corridor, y left,
// z up), with its origin at the first camera centre, i.e. T_world_cam0(frame 0) =
// [R_hall_cam0 | 0]. Otherwise the world is the first camera frame (T_world_cam0 = identity).
//
// Initial pose of the newest frame (paper, section V: "a linear combination of the pose
// estimated by the Horn method and the pose from the previous SBA"): with the RANSAC/Horn
// motion T_R and the constant-velocity prediction T_V (the last bundle-adjusted frame-to-
// frame motion, repeated once per frame since the reference), the initial T_ref_curr has
//   rotation    = slerp(q_R, q_V, w),   translation = (1 − w) t_R + w t_V,
//   w           = back_end.prior_weight · (1 − inlier_ratio),   inlier_ratio = inliers / matches
// So a motion supported by every match is taken as it is, and the prediction gains weight as
// the consensus weakens (w <= prior_weight). Without bundle adjustment this blend is the
// output; with it, the blend is where the solver starts.
//
// Lost tracking. A frame is "lost" (TrackingStatus::kLost, with a message) when its input is
// invalid (empty, not CV_8UC1, sizes differ from each other or from the camera), its disparity
// fails, it has fewer than front_end.min_features features with depth (black or textureless frame),
// or the motion fails (RANSAC without consensus, fewer than motion.min_inliers inliers; see "Few
// points" in motion_estimation.h). Its pose is bridged (recovery.h); the reference frame, the
// tracks and the window are kept, and the next frames are matched against that reference with
// the coarse-to-fine pass, so the motion across the gap is measured (kRecovered). When the
// motion still fails after recovery.reinit_after_lost_frames lost frames, or the current frame is
// rich (at least 2 · min_features features) yet cannot be matched after a loss, the pipeline
// re-initialises on the current frame at its bridged pose (kRecovered, reinitialised = true):
// tracks and window restart, the constant velocity is kept. Each measured motion moves the
// prior in proportion to its support (motion.reliable_min_inliers; not at all when the BA was
// rejected). Frames without a measured motion (lost and re-initialised ones, unless the direct
// image alignment measured them) are what IsLostFrame() counts. The frame after a kRecovered
// frame is kTracking again.
//
// Determinism: every random choice is seeded (RANSAC, plane extraction), the bundle
// adjustment is single-threaded; the same inputs give bit-identical outputs. Global OpenCV
// state (cv::setNumThreads) is left alone.
//
// Not thread-safe: one StereoOdometry per sequence and thread.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/back_end.h"
#include "vo/camera.h"
#include "vo/front_end.h"
#include "vo/gyro_prior.h"
#include "vo/matcher.h"
#include "vo/motion_estimation.h"
#include "vo/motion_model.h"
#include "vo/odometry_options.h"
#include "vo/odometry_result.h"
#include "vo/planar_motion_prior.h"
#include "vo/plane_orientation.h"
#include "vo/recovery.h"
#include "vo/sliding_window.h"
#include "vo/tracker.h"
#include "vo/tracks.h"
#include "vo/types.h"

namespace vo {

class StereoOdometry {
 public:
  // Aborts with a message when the camera or the options are invalid (a programmer error);
  // use Create() to get the error instead.
  StereoOdometry(const StereoCamera& camera, const OdometryOptions& options);
  ~StereoOdometry();
  StereoOdometry(const StereoOdometry&) = delete;
  StereoOdometry& operator=(const StereoOdometry&) = delete;

  // nullptr (and *error filled, when given) for an invalid camera or options.
  static std::unique_ptr<StereoOdometry> Create(const StereoCamera& camera,
                                                const OdometryOptions& options,
                                                std::string* error = nullptr);

  // One rectified stereo pair: left/right CV_8UC1 of the camera's size. time_s: the frame's
  // time stamp (seconds), recorded only. Never throws; bad input gives kLost.
  // `prior` (optional): the camera motion since the previous call from another sensor; null =
  // the constant-velocity prediction.
  OdometryResult Process(const cv::Mat& left, const cv::Mat& right, double time_s,
                         const MotionPrior* prior = nullptr);

  // The gyro (gyro_prior.h), with options().imu.gyro_prior on (otherwise both are ignored):
  // its mounting and noise model once, then its samples in time order before the Process call
  // of the frame they lead up to (a skipped frame's too). Each frame's prior rotation is then
  // the gyro's since the previous call (its translation the constant velocity's); a frame the
  // samples do not cover keeps the constant velocity's. Not used by ProcessFeatures.
  void SetGyro(const GyroCalibration& calibration);
  void AddGyroSamples(const std::vector<GyroSample>& samples);

  // The seam (libviso2's process(matches)): runs the back end (RANSAC, tracks, blend, BA) on
  // externally supplied left-image features and matches, skipping disparity, detection and
  // matching. features: uv_px and disparity_px (> 0 for depth; p_cam0 is recomputed from
  // them with the camera); features without depth are dropped (matches re-indexed).
  // matches_to_prev: indices into the features of the PREVIOUS ProcessFeatures call (prev) and
  // into `features` (curr), one-to-one; ignored for the first frame. When the previous call
  // was lost, the matches cannot be used and the frame re-initialises (kRecovered).
  OdometryResult ProcessFeatures(std::vector<Feature> features,
                                 const std::vector<Match>& matches_to_prev, double time_s);

  // What the last Process/ProcessFeatures call matched (for matcher evaluation by a harness);
  // views into the VO, valid until the next call.
  FrameDiagnostics last_diagnostics() const {
    return {last_features_, last_reference_features_, last_matches_, last_inlier_mask_};
  }

  // R_hall_cam0 of the first frame from the plane orientation (identity when not estimated or
  // failed; see OdometryResult::initial_orientation_ok).
  const Eigen::Matrix3d& R_hall_cam0_initial() const { return R_hall_cam0_initial_; }
  // The whole plane-orientation result of the first frame (status kInvalidInput until then).
  const PlaneOrientationResult& initial_orientation() const { return orientation_result_; }

  const StereoCamera& camera() const { return camera_; }
  // The effective options (num_disparities as derived, RANSAC min_inliers raised).
  const OdometryOptions& options() const { return options_; }

  // Forgets the sequence: the next frame initialises again.
  void Reset();

 private:
  // The frame motion is estimated against.
  struct Reference {
    bool valid = false;
    int64_t frame_index = -1;
    MatchFrame frame;  // left image (Process only), features (with track ids), cue cache
  };

  using TimePoint = std::chrono::steady_clock::time_point;

  // What the recovery needs of this call (the previous output, the prior, this frame).
  BridgeContext Bridge(const MotionPrior* prior);
  // The predicted T_world_cam0 of the newest frame: the previous output moved by the prior.
  Eigen::Isometry3d PredictedPose(const MotionPrior* prior) const;
  // The world's up in the reference camera frame for a ground vehicle whose up is known (the
  // few-point motion and the weak-motion check are planar about it); null otherwise.
  const Eigen::Vector3d* VehicleUpAtReference(Eigen::Vector3d* storage) const;
  // With the gyro's rotation for this frame, the few-point motion is used after lost frames too
  // (imu.few_point_motion and imu.few_point_after_loss).
  bool GyroFewPointAfterLoss() const;
  // The tracker predicts its matches (matcher.prediction is not kNone).
  bool Predicted() const { return options_.tracker.matcher.prediction != PredictionMode::kNone; }
  // A lost frame: pose bridged (or `chained`, see Recovery::BridgedPose), reference and
  // tracks kept.
  OdometryResult Lost(OdometryResult result, const std::string& message, TimePoint start,
                      const MotionPrior* prior = nullptr,
                      const Eigen::Isometry3d* chained = nullptr);
  // (Re-)initialises on `frame`: first time at the initial orientation, later at the bridged
  // (or chained) pose (kRecovered). `reason` goes into the message.
  OdometryResult Initialise(OdometryResult result, MatchFrame frame, const std::string& reason,
                            TimePoint start, const MotionPrior* prior = nullptr,
                            const Eigen::Isometry3d* chained = nullptr);
  // The first frame's orientation (initial_orientation.h) from its points; sets the world
  // frame and the vehicle's up. The message for Initialise.
  std::string OrientFirstFrame(const std::vector<Eigen::Vector3d>& points, const cv::Mat& left,
                               const cv::Mat& right, const cv::Mat& disparity_px,
                               OdometryResult* result);
  // The vehicle's geometry for the back end's planar prior (back_end.h): the vehicle model,
  // its up, the first pose, the floor, the axle.
  VehicleGeometry Geometry() const;
  // Everything after matching: the frame's motion, tracks, blend, BA. `result` carries the
  // counts so far. T_ref_curr_prior: the prior's motion from the reference to this frame (null
  // = none), the blend's partner; `prior`: the caller's prior (for a lost frame), may be null.
  OdometryResult Track(OdometryResult result, MatchFrame frame, MotionAttempt attempt,
                       const Eigen::Isometry3d* T_ref_curr_prior, const MotionPrior* prior,
                       TimePoint start);
  // Sets the output pose (finite), T_prev_curr and the total time.
  OdometryResult Finish(OdometryResult result, const Eigen::Isometry3d& T_world_cam0,
                        TimePoint start);

  StereoCamera camera_;
  OdometryOptions options_;
  std::unique_ptr<FrontEnd> front_end_;  // disparity, features, depth
  std::unique_ptr<Tracker> tracker_;     // the matcher and its prediction passes
  Recovery recovery_;                    // bridges, the lost-frame chain
  BackEnd back_end_;                     // the window, the blend, the BA (back_end.h)

  int64_t frame_index_ = 0;      // index of the next call
  bool initialised_ = false;     // a reference was set at least once since Reset
  bool world_up_known_ = false;  // the world's z is up (the first frame's orientation found
                                 // the floor or a ceiling)
  // The vehicle's up in the camera frame (back_end.vehicle_planar): the floor fit refined
  // by the reliable tracked motions.
  VehicleUpEstimate vehicle_up_;
  int consecutive_lost_ = 0;        // lost frames since the last good one
  bool previous_measured_ = false;  // the previous call's motion was measured (the prior is
                                    // a measured motion, not a bridge: few_point_motion)
  Reference reference_;
  Eigen::Isometry3d T_world_prev_ = Eigen::Isometry3d::Identity();  // previous call's output
  ConstantVelocity velocity_;      // the prior, and the last motion as measured
  int scene_num_disparities_ = 0;  // next frame's search range from the scene; 0 = full

  Eigen::Matrix3d R_hall_cam0_initial_ = Eigen::Matrix3d::Identity();
  PlaneOrientationResult orientation_result_;
  std::vector<Feature> last_features_;
  std::vector<Match> last_matches_;
  std::vector<bool> last_inlier_mask_;
  std::vector<Feature> last_reference_features_;
  std::unique_ptr<GyroPrior> gyro_;       // SetGyro with imu.gyro_prior on; null otherwise
  GyroRotation gyro_rotation_;            // this call's rotation from the gyro (when ok)
  cv::Mat current_left_;                  // this call's left image
  std::vector<int> prev_call_index_map_;  // ProcessFeatures: given index → kept index of the
                                          // previous call's features (empty when unusable)
};

}  // namespace vo
