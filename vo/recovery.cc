#include "vo/recovery.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "vo/bridge_alignment.h"
#include "vo/image_motion.h"
#include "vo/motion_estimation.h"
#include "vo/options_check.h"
#include "vo/prior_motion.h"

namespace vo {
namespace {

using Clock = std::chrono::steady_clock;

// The planes of a frame's features for the direct alignment of the next lost frame
// (vehicle_direct_alignment): up to 3 (a wall, the floor, a side wall); a feature is on
// one within 1 px of disparity; each with at least 6 features spread at least 5 cm across (not
// all along one edge), 60 % of the features on them. Without such planes a frame carries the
// previous ones by its motion, for at most 30 frames.
constexpr double kScenePlaneTolerancePx = 1.0;
constexpr int kScenePlaneMinInliers = 6;
constexpr double kScenePlaneMinFraction = 0.6;
constexpr double kScenePlaneMinSpreadM = 0.05;
constexpr int kMaxScenePlanes = 3;
constexpr int kMaxScenePlaneAge = 30;

}  // namespace

bool RecoveryOptions::IsValid(std::string* error) const {
  if (vehicle_bridge_alignment &&
      (!PartIsValid(vehicle_bridge, "vehicle_bridge", error) ||
       (vehicle_direct_alignment && !PartIsValid(vehicle_direct, "vehicle_direct", error)))) {
    return false;
  }
  if (free_direct_alignment && !PartIsValid(free_direct, "free_direct", error)) return false;
  std::ostringstream msg;
  if (!(rotation_min_shift_score >= -1.0 && rotation_min_shift_score <= 1.0)) {
    msg << "rotation_min_shift_score must be in [-1, 1], got " << rotation_min_shift_score;
  } else if (!(rotation_min_peak_ratio >= 1.0) || !std::isfinite(rotation_min_peak_ratio)) {
    msg << "rotation_min_peak_ratio must be finite and >= 1, got " << rotation_min_peak_ratio;
  } else if (!(rotation_min_residual_px >= 0.0) || !std::isfinite(rotation_min_residual_px)) {
    msg << "rotation_min_residual_px must be finite and >= 0, got " << rotation_min_residual_px;
  } else if (!(vehicle_rotation_min_shift_score >= -1.0 &&
               vehicle_rotation_min_shift_score <= 1.0)) {
    msg << "vehicle_rotation_min_shift_score must be in [-1, 1], got "
        << vehicle_rotation_min_shift_score;
  } else if (!(vehicle_rotation_min_peak_ratio >= 1.0) ||
             !std::isfinite(vehicle_rotation_min_peak_ratio)) {
    msg << "vehicle_rotation_min_peak_ratio must be finite and >= 1, got "
        << vehicle_rotation_min_peak_ratio;
  } else if (!(vehicle_max_vertical_shift_ratio >= 0.0) ||
             !std::isfinite(vehicle_max_vertical_shift_ratio)) {
    msg << "vehicle_max_vertical_shift_ratio must be finite and >= 0, got "
        << vehicle_max_vertical_shift_ratio;
  } else if (reinit_after_lost_frames < 1) {
    msg << "reinit_after_lost_frames must be >= 1, got " << reinit_after_lost_frames;
  }
  return NoBrokenRule(msg, error);
}

DirectAlignmentOptions RecoveryOptions::FreeDirectDefaults() {
  DirectAlignmentOptions o;
  o.max_forward_sigma_m = 0.003;  // the worst of three axes (a step along the view is the zoom)
  return o;
}

Recovery::Recovery(const StereoCamera& camera, const RecoveryOptions& options,
                   const MotionOptions& motion, const TrackerOptions& tracker)
    : camera_(camera),
      options_(options),
      motion_(motion),
      image_shift_(tracker.image_shift),
      predicted_(tracker.matcher.prediction != PredictionMode::kNone) {}

void Recovery::Reset() {
  previous_frame_features_.clear();
  scene_planes_.clear();
  scene_planes_age_ = 0;
  pending_planes_.clear();
  previous_left_ = cv::Mat();
  chain_valid_ = false;
  chain_frame_index_ = -1;
  chain_frame_ = MatchFrame();
}

void Recovery::EndFrame(const std::vector<Feature>& features, const Eigen::Isometry3d& T_prev_curr,
                        cv::Mat left, bool gyro) {
  // Only the bridge alignment reads the previous frame's features: no copy per frame otherwise.
  if (motion_.ground_vehicle && options_.vehicle_bridge_alignment) {
    previous_frame_features_ = features;
    if (options_.vehicle_direct_alignment) DeferScenePlanes(features, T_prev_curr);
  } else if (!motion_.ground_vehicle && options_.free_direct_alignment && gyro) {
    DeferScenePlanes(features, T_prev_curr);
  }
  previous_left_ = std::move(left);
}

void Recovery::ContinueChain(int64_t frame_index, MatchFrame frame,
                             const Eigen::Isometry3d& T_world) {
  chain_valid_ = true;  // the next lost frame is matched against this one
  chain_frame_index_ = frame_index;
  chain_frame_ = std::move(frame);
  T_world_chain_ = T_world;
}

Eigen::Isometry3d Recovery::BridgeMotion(const BridgeContext& c) const {
  const Eigen::Isometry3d T_prev_curr = c.velocity->Prior(c.prior);
  if (c.prior != nullptr || !motion_.ground_vehicle || !c.world_up_known) {
    return T_prev_curr;
  }
  return PlanarPart(T_prev_curr, WorldUpInCamera(c.T_world_prev));
}

Eigen::Isometry3d Recovery::BridgedPose(const BridgeContext& c, OdometryResult* result,
                                        const Eigen::Isometry3d* chained) {
  if (chained != nullptr) return *chained;  // measured against the lost-frame chain
  const Eigen::Isometry3d bridged = ShiftCorrectedPose(c, result);
  const RecoveryOptions& o = options_;
  if (!motion_.ground_vehicle) {
    const bool gyro = c.velocity->has_measured_rotation() && c.measured_rotation_sigma_rad > 0.0;
    return o.free_direct_alignment && gyro && c.prior == nullptr && predicted_
               ? FreeDirectAlignedPose(c, bridged, result)
               : bridged;
  }
  if (c.prior != nullptr || !o.vehicle_bridge_alignment || !c.world_up_known || !predicted_) {
    return bridged;
  }
  const Eigen::Isometry3d aligned = AlignedBridgePose(c, bridged, result);
  return o.vehicle_direct_alignment ? DirectAlignedPose(c, aligned, result) : aligned;
}

Eigen::Isometry3d Recovery::DirectAlignedPose(const BridgeContext& c,
                                              const Eigen::Isometry3d& bridged,
                                              OdometryResult* result) {
  if (previous_left_.empty() || c.current_left.empty() || ScenePlanes().empty()) return bridged;
  const RecoveryOptions& o = options_;
  const Clock::time_point t = Clock::now();
  const Eigen::Vector3d up = WorldUpInCamera(c.T_world_prev);
  const double axle = motion_.few_point.axle_behind_camera_m;
  const Eigen::Vector2d start =
      VehicleMotionParameters(c.T_world_prev.inverse() * bridged, up, axle);
  if (!start.allFinite()) return bridged;
  const DirectAlignmentResult direct = AlignVehicleDirect(
      camera_, previous_left_, c.current_left, scene_planes_, up, axle, start.x(), start.y(),
      o.vehicle_direct, c.velocity->has_measured_rotation() ? c.measured_rotation_sigma_rad : 0.0);
  result->times.predict_ms += ElapsedMs(t);
  if (!direct.ok) return bridged;
  const Eigen::Isometry3d T = VehicleMotion(up, axle, direct.yaw_rad, direct.forward_m);
  return IsFinitePose(T) ? DirectMotion(c, T, result) : bridged;
}

Eigen::Isometry3d Recovery::DirectMotion(const BridgeContext& c,
                                         const Eigen::Isometry3d& T_prev_curr,
                                         OdometryResult* result) {
  c.velocity->ReplaceIfKnown(T_prev_curr);
  result->direct_motion = true;
  result->motion_measured = true;
  return c.T_world_prev * T_prev_curr;
}

Eigen::Isometry3d Recovery::FreeDirectAlignedPose(const BridgeContext& c,
                                                  const Eigen::Isometry3d& bridged,
                                                  OdometryResult* result) {
  if (previous_left_.empty() || c.current_left.empty() || ScenePlanes().empty()) return bridged;
  const Clock::time_point t = Clock::now();
  const Eigen::Isometry3d start = c.T_world_prev.inverse() * bridged;
  const FreeDirectAlignmentResult direct =
      AlignFreeDirect(camera_, previous_left_, c.current_left, scene_planes_, start,
                      options_.free_direct, c.measured_rotation_sigma_rad);
  result->times.predict_ms += ElapsedMs(t);
  if (!direct.ok || !IsFinitePose(direct.T_prev_curr)) return bridged;
  return DirectMotion(c, direct.T_prev_curr, result);
}

void Recovery::DeferScenePlanes(const std::vector<Feature>& features,
                                const Eigen::Isometry3d& T_prev_curr) {
  // A plane is carried for kMaxScenePlaneAge frames after its fit: the planes after the last
  // kMaxScenePlaneAge + 1 frames depend on those frames only (none of them fits: none left).
  if (pending_planes_.size() > static_cast<size_t>(kMaxScenePlaneAge)) {
    pending_planes_.pop_front();
    scene_planes_.clear();
  }
  PendingPlaneFrame frame;
  frame.T_prev_curr = T_prev_curr;
  for (const Feature& f : features) {  // those FitScenePlanes reads, in order
    if (f.has_depth()) frame.features.push_back(f);
  }
  pending_planes_.push_back(std::move(frame));
}

const std::vector<ScenePlane>& Recovery::ScenePlanes() {
  if (pending_planes_.empty()) return scene_planes_;
  // The newest frame whose features fit planes sets them (age 0); the frames after it carry
  // them (or drop them, as the frame-by-frame update would); with no such frame, the planes
  // held before the pending frames are carried.
  size_t first = 0;
  for (size_t i = pending_planes_.size(); i-- > 0;) {
    std::vector<ScenePlane> fitted;
    if (FitScenePlanes(camera_, pending_planes_[i].features, kScenePlaneTolerancePx,
                       kScenePlaneMinInliers, kScenePlaneMinFraction, kScenePlaneMinSpreadM,
                       kMaxScenePlanes, &fitted)) {
      scene_planes_ = fitted;
      scene_planes_age_ = 0;
      first = i + 1;
      break;
    }
  }
  for (size_t i = first; i < pending_planes_.size(); ++i) {
    const Eigen::Isometry3d& T_prev_curr = pending_planes_[i].T_prev_curr;
    if (!scene_planes_.empty() && IsFinitePose(T_prev_curr) &&
        ++scene_planes_age_ <= kMaxScenePlaneAge) {
      std::vector<ScenePlane> moved;
      for (const ScenePlane& plane : scene_planes_) {
        const ScenePlane m = TransformPlane(plane, T_prev_curr);
        if (m.distance_m > 0.0) moved.push_back(m);  // the camera is still in front of it
      }
      scene_planes_.swap(moved);
    } else {
      scene_planes_.clear();
    }
  }
  pending_planes_.clear();
  return scene_planes_;
}

Eigen::Isometry3d Recovery::AlignedBridgePose(const BridgeContext& c,
                                              const Eigen::Isometry3d& bridged,
                                              OdometryResult* result) {
  const std::vector<Feature>& last_features = *c.features;
  const RecoveryOptions& o = options_;
  const Clock::time_point t = Clock::now();
  Eigen::Isometry3d T = c.T_world_prev.inverse() * bridged;
  int pairs = 0;
  double t_z = 0.0;
  if (ForwardStepFromDepth(camera_, previous_frame_features_, last_features, T, o.vehicle_bridge,
                           &t_z, &pairs)) {
    T.translation().z() = t_z;
    result->bridge_aligned = true;
  }
  const Eigen::Vector3d up = WorldUpInCamera(c.T_world_prev);
  const double axle = motion_.few_point.axle_behind_camera_m;
  const Eigen::Vector2d yaw_forward = VehicleMotionParameters(T, up, axle);
  double yaw = yaw_forward.x();
  // The gyro's yaw (a measured rotation in the prior) is not re-measured on the features.
  if (yaw_forward.allFinite() && !c.velocity->has_measured_rotation() &&
      AlignVehicleYaw(camera_, previous_frame_features_, last_features, up, axle, yaw_forward.y(),
                      o.vehicle_bridge, &yaw, &pairs)) {
    T = VehicleMotion(up, axle, yaw, yaw_forward.y());
    result->bridge_aligned = true;
  }
  result->times.predict_ms += ElapsedMs(t);
  if (!IsFinitePose(T)) return bridged;
  c.velocity->ReplaceIfKnown(T);
  return c.T_world_prev * T;
}

Eigen::Isometry3d Recovery::ShiftCorrectedPose(const BridgeContext& c, OdometryResult* result) {
  const MotionPrior* prior = c.prior;
  const std::vector<Feature>& last_features = *c.features;
  const Eigen::Isometry3d predicted = c.T_world_prev * BridgeMotion(c);
  const RecoveryOptions& o = options_;
  // A rotation measured by another sensor (the gyro, gyro_prior.h) is not corrected by the image
  // shift, which cannot tell a turn from parallax.
  if (!predicted_ || !o.rotation_from_shift || previous_left_.empty() || c.current_left.empty() ||
      previous_left_.size() != c.current_left.size() ||
      (prior == nullptr && c.velocity->has_measured_rotation())) {
    return predicted;
  }
  const Clock::time_point t = Clock::now();
  const ImageShiftResult shift = EstimateImageShift(previous_left_, c.current_left, image_shift_);
  result->times.predict_ms += ElapsedMs(t);
  // A ground vehicle (its motion a yaw and a forward step, the camera swinging about the axle)
  // reads the shift with that model: a sharp peak is trusted at a lower score, and a shift whose
  // vertical part (no pitch: zoom, parallax) is large against its horizontal part is no turn.
  const bool vehicle = prior == nullptr && motion_.ground_vehicle && c.world_up_known;
  const bool strong = shift.score >= o.rotation_min_shift_score &&
                      shift.second_best_ratio >= o.rotation_min_peak_ratio;
  const bool sharp = vehicle && shift.score >= o.vehicle_rotation_min_shift_score &&
                     shift.second_best_ratio >= o.vehicle_rotation_min_peak_ratio;
  if (!shift.ok || !(strong || sharp)) return predicted;
  // The prior's own frame-to-frame motion (not T_world_prev⁻¹ · predicted, which would feed
  // rounding in the composed poses back into the prior, frame after frame), corrected at the
  // median depth of this frame's features (last_features; none: far away).
  const Eigen::Isometry3d T_prev_curr_prior = BridgeMotion(c);
  double depth_m = -1.0;
  if (!last_features.empty()) {
    std::vector<double> z;
    for (const Feature& f : last_features) z.push_back(f.p_cam0.z());
    std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
    depth_m = z[z.size() / 2];
  }
  Eigen::Isometry3d T_prev_curr;
  if (vehicle) {
    const Eigen::Vector2d residual =
        shift.shift_px - PredictedCentreShift(camera_, T_prev_curr_prior, depth_m);
    if (!(std::abs(residual.y()) <=
          std::max(o.rotation_min_residual_px,
                   o.vehicle_max_vertical_shift_ratio * std::abs(residual.x())))) {
      return predicted;
    }
    T_prev_curr = VehicleMotionFromImageShift(camera_, WorldUpInCamera(c.T_world_prev),
                                              motion_.few_point.axle_behind_camera_m,
                                              T_prev_curr_prior, shift.shift_px, depth_m);
  } else {  // (not a ground vehicle whose up is known: PlanarBridge would change nothing)
    T_prev_curr = CorrectPriorWithImageShift(camera_, T_prev_curr_prior, shift.shift_px, depth_m);
  }
  if (!IsFinitePose(T_prev_curr)) return predicted;
  // The shift the prior itself predicts: the correction's rotation seen at the image centre.
  const double residual_px =
      camera_.fx_px *
      Eigen::AngleAxisd(T_prev_curr_prior.linear().transpose() * T_prev_curr.linear()).angle();
  if (residual_px <= o.rotation_min_residual_px) return predicted;
  // The measured rotation becomes the prior's rotation (a turn goes on through the next frames
  // that have no usable shift); the prior's translation stays.
  if (prior == nullptr) c.velocity->ReplaceRotationIfKnown(T_prev_curr.linear());
  result->rotation_from_shift = true;
  result->image_shift_ok = true;
  result->image_shift_px = shift.shift_px;
  return c.T_world_prev * T_prev_curr;
}

bool Recovery::ChainLostFrame(Tracker* tracker, const MatchFrame& frame, const BridgeContext& c,
                              OdometryResult* result, Eigen::Isometry3d* T_world_curr) {
  const MotionPrior* prior = c.prior;
  // A caller's prior (wheel odometry, a gyro) bridges a lost frame as given.
  if (!options_.chain_lost_frames || prior != nullptr || !chain_valid_ ||
      chain_frame_index_ >= result->frame_index || !predicted_ ||
      tracker->matcher_type() == MatcherType::kKalman) {
    return false;
  }
  const Eigen::Isometry3d T_chain_curr_prior =
      T_world_chain_.inverse() * (c.T_world_prev * c.velocity->Prior(prior));
  OdometryResult pass;  // the chain's prediction fields are not this frame's against the reference
  std::string matcher_error;
  TrackingContext context;
  context.T_ref_curr_prior = IsFinitePose(T_chain_curr_prior) ? &T_chain_curr_prior : nullptr;
  context.after_loss = c.after_loss;
  context.velocity = c.velocity;
  context.few_point_tie = false;
  const MotionAttempt attempt =
      tracker->MatchAndEstimate(chain_frame_, frame, context, &pass, &matcher_error);
  result->times.predict_ms += pass.times.predict_ms;
  result->times.match_ms += pass.times.match_ms;
  result->times.motion_ms += pass.times.motion_ms;
  result->times.guided_ms += pass.times.guided_ms;
  const RansacResult& ransac = attempt.ransac;
  if (!matcher_error.empty() || attempt.inliers() < motion_.min_inliers ||
      !IsFinitePose(ransac.T_prev_curr)) {
    return false;
  }
  *T_world_curr = T_world_chain_ * ransac.T_prev_curr;
  result->chained_to_frame = chain_frame_index_;
  result->chain_inliers = ransac.num_inliers;
  // Chained to the frame just before: its motion was measured by matching, as a tracked frame's
  // (not a lost frame); chained further back, the frames between were bridged.
  if (chain_frame_index_ == result->frame_index - 1) result->motion_measured = true;
  // The measured motion moves the constant velocity as a tracked one does (by its support).
  const Eigen::Isometry3d per_frame =
      Root(ransac.T_prev_curr, result->frame_index - chain_frame_index_);
  c.velocity->Move(per_frame, PriorUpdateWeight(ransac.num_inliers, motion_));
  return true;
}

}  // namespace vo
