// Recovery: the stage for a frame whose motion the reference cannot measure. It gives that
// frame a pose that is never NaN (the prior's bridge, its rotation corrected by the image
// shift), measures what it can of the gap instead (the lost-frame chain between the lost frames
// themselves; for a ground vehicle the bridge alignment on the previous frame's features and
// the direct alignment of the previous image), and keeps what the next frames need for that
// (the previous frame's features, image and planes, the chain). It receives the previous
// output, the prior, this frame and the constant velocity (BridgeContext), and the tracker for
// the chain's matching; the re-initialisation itself is StereoOdometry's. Its options are the
// `recovery` group of vo_options.yaml. In detail:
//
// A lost frame's pose is the prior's prediction from the previous output, never NaN —
// corrected, when the image shift from the previous frame is found (tracking.
// rotation_from_shift), by the rotation that explains that shift (CorrectPriorWithImageShift;
// a ground vehicle's, VehicleMotionFromImageShift): a turn in front of a plain wall is
// followed, not extrapolated (ShiftCorrectedPose). A lost frame that the reference cannot
// measure is matched against the previous lost frame with features (tracking.chain_lost_frames,
// ChainLostFrame): a turn in front of a plain wall leaves the reference's view behind, but the
// frames of the gap overlap each other, so their motion is measured link by link (the frame
// stays lost; OdometryResult::chained_to_frame).
//
// Ground vehicle (tracking.ground_vehicle; off on the free platform, on for a ground vehicle):
// where the images cannot measure the motion it is a wheeled vehicle's, planar about the
// world's up (PlanarBridge). A lost frame's forward step and yaw are then measured against the
// previous frame's features without matching them (tracking.vehicle_bridge_alignment,
// bridge_alignment.h), and then by aligning the previous left image with this one on the planes
// of the last features (tracking.vehicle_direct_alignment, direct_alignment.h): when that
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
#include <opencv2/core.hpp>
#include <vector>

#include "vo/camera.h"
#include "vo/direct_alignment.h"
#include "vo/matcher.h"
#include "vo/motion_model.h"
#include "vo/odometry_options.h"
#include "vo/odometry_result.h"
#include "vo/tracker.h"
#include "vo/types.h"

namespace vo {

// What the recovery of one frame knows of the pipeline.
struct BridgeContext {
  const MotionPrior* prior = nullptr;  // the caller's prior (null: the constant velocity)
  Eigen::Isometry3d T_world_prev = Eigen::Isometry3d::Identity();  // the previous output
  bool world_up_known = false;  // the world's z is up (the first frame found the floor)
  cv::Mat current_left;         // this frame's left image (empty: none)
  const std::vector<Feature>* features = nullptr;  // this frame's features with depth
  bool after_loss = false;                         // frames were lost since the last tracked one
  ConstantVelocity* velocity = nullptr;            // the prior, moved by what the recovery measures
};

class Recovery {
 public:
  Recovery(const StereoCamera& camera, const OdometryOptions& options);

  // The pose of a frame without a measured motion: `chained` when ChainLostFrame measured one
  // (non-null), else the predicted pose corrected by the image shift from the previous frame
  // where it is found (sets result->rotation_from_shift), then for a ground vehicle with its
  // up known and no caller's prior the forward step and the yaw measured against the previous
  // frame's features (result->bridge_aligned) and by direct image alignment
  // (result->direct_motion, motion_measured).
  Eigen::Isometry3d BridgedPose(const BridgeContext& context, OdometryResult* result,
                                const Eigen::Isometry3d* chained = nullptr);

  // tracking.chain_lost_frames: `frame`, which the reference could not measure, against the
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
  void EndFrame(const std::vector<Feature>& features, const Eigen::Isometry3d& T_prev_curr,
                cv::Mat left);

  void Reset();

 private:
  // The prior's motion for a frame without a measured motion, made planar (PlanarPart about
  // the world's up) for a ground vehicle unless the caller gave the prior.
  Eigen::Isometry3d BridgeMotion(const BridgeContext& c) const;
  Eigen::Isometry3d ShiftCorrectedPose(const BridgeContext& c, OdometryResult* result);
  Eigen::Isometry3d AlignedBridgePose(const BridgeContext& c, const Eigen::Isometry3d& bridged,
                                      OdometryResult* result);
  Eigen::Isometry3d DirectAlignedPose(const BridgeContext& c, const Eigen::Isometry3d& bridged,
                                      OdometryResult* result);
  // The planes of `features`, else the previous ones moved by T_prev_curr (for at most 30
  // frames), for the next frame's direct alignment.
  void UpdateScenePlanes(const std::vector<Feature>& features,
                         const Eigen::Isometry3d& T_prev_curr);

  StereoCamera camera_;
  OdometryOptions options_;
  std::vector<Feature> previous_frame_features_;  // the previous call's features
  // The planes of the features in the previous output's camera frame
  // (vehicle_direct_alignment), carried for scene_planes_age_ frames since they were fitted.
  std::vector<ScenePlane> scene_planes_;
  int scene_planes_age_ = 0;
  cv::Mat previous_left_;     // the previous call's left image (empty after ProcessFeatures)
  bool chain_valid_ = false;  // the last lost frame with at least min_features features, since
  int64_t chain_frame_index_ = -1;  // the last tracked one, ...
  MatchFrame chain_frame_;
  Eigen::Isometry3d T_world_chain_ = Eigen::Isometry3d::Identity();  // ... and its output pose
};

}  // namespace vo
