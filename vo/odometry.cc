#include "vo/odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <utility>

#include "vo/initial_orientation.h"

namespace vo {
namespace {

using Clock = std::chrono::steady_clock;

// The vehicle's up in the camera frame (back_end.vehicle_planar): σ of a reliable tracked
// RANSAC motion's translation (metres) and rotation (degrees) as evidence of it (a translation
// across up, a rotation about it; the first frame's floor fit starts it, initial_orientation.h).
// The RANSAC motions (before the window BA) jitter by ~1 cm sideways and ~0.3° per frame; with
// σ 1 mm / 0.05° the estimate swung by 70° on the pitched camera's straight approach. A 4 cm
// step then gives its direction to ~14°, a 3° turn its axis to ~6°: the motions move the floor
// fit over tens of frames (seed 7: 0.77° -> 0.35° off).
constexpr double kVehicleUpTranslationSigmaM = 1e-2;
constexpr double kVehicleUpRotationSigmaDeg = 0.3;

}  // namespace

std::unique_ptr<StereoOdometry> StereoOdometry::Create(const StereoCamera& camera,
                                                       const OdometryOptions& options,
                                                       std::string* error) {
  std::string why;
  if (!camera.IsValid(&why)) {
    if (error) *error = "camera: " + why;
    return nullptr;
  }
  if (!options.IsValid(&why)) {
    if (error) *error = why;
    return nullptr;
  }
  return std::make_unique<StereoOdometry>(camera, options);
}

StereoOdometry::StereoOdometry(const StereoCamera& camera, const OdometryOptions& options)
    : camera_(camera),
      options_(EffectiveOdometryOptions(camera, options)),
      recovery_(camera, options_.recovery, options_.motion, options_.tracker),
      back_end_(options_.back_end) {
  std::string why;
  if (!camera_.IsValid(&why)) {
    std::fprintf(stderr, "vo::StereoOdometry: invalid camera: %s\n", why.c_str());
    std::abort();
  }
  if (!options_.IsValid(&why)) {
    std::fprintf(stderr, "vo::StereoOdometry: invalid options: %s\n", why.c_str());
    std::abort();
  }
  front_end_ = FrontEnd::Create(camera_, options_.front_end, &why);
  if (front_end_) tracker_ = Tracker::Create(camera_, options_.tracker, options_.motion, &why);
  if (!front_end_ || !tracker_) {
    std::fprintf(stderr, "vo::StereoOdometry: %s\n", why.c_str());
    std::abort();
  }
}

StereoOdometry::~StereoOdometry() = default;

void StereoOdometry::SetGyro(const GyroCalibration& calibration) {
  if (!options_.imu.gyro_prior || !calibration.IsValid(nullptr)) {
    gyro_.reset();
    return;
  }
  gyro_ = std::make_unique<GyroPrior>(options_.imu, calibration);
}

void StereoOdometry::AddGyroSamples(const std::vector<GyroSample>& samples) {
  if (gyro_) gyro_->AddSamples(samples);
}

bool StereoOdometry::GyroFewPointAfterLoss() const {
  return gyro_rotation_.ok && options_.imu.few_point_motion && options_.imu.few_point_after_loss;
}

void StereoOdometry::Reset() {
  back_end_.Reset();
  tracker_->Reset();
  recovery_.Reset();
  frame_index_ = 0;
  initialised_ = false;
  consecutive_lost_ = 0;
  previous_measured_ = false;
  reference_ = Reference();
  T_world_prev_ = Eigen::Isometry3d::Identity();
  velocity_.Reset();
  scene_num_disparities_ = 0;
  R_hall_cam0_initial_ = Eigen::Matrix3d::Identity();
  world_up_known_ = false;
  vehicle_up_ = VehicleUpEstimate();
  orientation_result_ = PlaneOrientationResult();
  last_features_.clear();
  last_matches_.clear();
  last_inlier_mask_.clear();
  last_reference_features_.clear();
  prev_call_index_map_.clear();
  current_left_ = cv::Mat();
  if (gyro_) gyro_->Reset();
  gyro_rotation_ = GyroRotation();
}

OdometryResult StereoOdometry::Finish(OdometryResult result, const Eigen::Isometry3d& T_world_cam0,
                                      TimePoint start) {
  // Never hand out a non-finite pose: fall back to the previous output. The rotation is
  // re-projected onto SO(3), so rounding in long chains of composed motions (a long bridge of
  // lost frames) cannot accumulate into a non-rigid transform.
  Eigen::Isometry3d T = IsFinitePose(T_world_cam0) ? T_world_cam0 : T_world_prev_;
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  result.T_world_cam0 = T;
  result.T_prev_curr = result.frame_index == 0 ? Eigen::Isometry3d::Identity()
                                               : Eigen::Isometry3d(T_world_prev_.inverse() * T);
  T_world_prev_ = T;
  previous_measured_ = result.motion_measured;
  if (gyro_) {
    // The gyro's rotation was this frame's only; a well-tracked frame's measured rotation is an
    // observation of the gyro's bias (gyro_prior.h).
    velocity_.ClearMeasuredRotation();
    const bool well_tracked = gyro_rotation_.ok && result.status == TrackingStatus::kTracking &&
                              result.motion_measured && !result.few_point_motion &&
                              !result.direct_motion &&
                              result.num_inliers >= options_.motion.reliable_min_inliers;
    gyro_->Observe(well_tracked, result.T_prev_curr.linear());
  }
  recovery_.EndFrame(last_features_, result.T_prev_curr, current_left_, gyro_ != nullptr);
  // Next frame's disparity search range from the depths of this one (full after a loss).
  scene_num_disparities_ = result.status != TrackingStatus::kLost
                               ? SceneNumDisparities(last_features_, options_.front_end)
                               : 0;
  current_left_ = cv::Mat();
  result.times.total_ms = ElapsedMs(start);
  return result;
}

BridgeContext StereoOdometry::Bridge(const MotionPrior* prior) {
  BridgeContext c;
  c.prior = prior;
  c.T_world_prev = T_world_prev_;
  c.world_up_known = world_up_known_;
  c.current_left = current_left_;
  c.features = &last_features_;
  c.after_loss = consecutive_lost_ > 0;
  c.velocity = &velocity_;
  if (gyro_rotation_.ok) {
    c.measured_rotation_sigma_rad =
        std::max(options_.imu.min_rotation_sigma_deg * M_PI / 180.0, gyro_rotation_.sigma_rad());
  }
  return c;
}

Eigen::Isometry3d StereoOdometry::PredictedPose(const MotionPrior* prior) const {
  return T_world_prev_ * velocity_.Prior(prior);
}

const Eigen::Vector3d* StereoOdometry::VehicleUpAtReference(Eigen::Vector3d* storage) const {
  const Eigen::Isometry3d* T_world_ref = back_end_.Pose(reference_.frame_index);
  if (!options_.motion.ground_vehicle || !world_up_known_ || T_world_ref == nullptr) {
    return nullptr;
  }
  *storage = WorldUpInCamera(*T_world_ref);
  return storage;
}

OdometryResult StereoOdometry::Lost(OdometryResult result, const std::string& message,
                                    TimePoint start, const MotionPrior* prior,
                                    const Eigen::Isometry3d* chained) {
  result.status = TrackingStatus::kLost;
  result.message = message;
  ++consecutive_lost_;
  // Frames are skipped from the matcher's point of view (the Kalman tracker keeps state).
  tracker_->Reset();
  const Eigen::Isometry3d T_world_cam0 = recovery_.BridgedPose(Bridge(prior), &result, chained);
  if (result.rotation_from_shift) result.message += "; pose: prior + rotation from the image shift";
  if (result.direct_motion) result.message += "; motion measured by direct image alignment";
  return Finish(std::move(result), T_world_cam0, start);
}

std::string StereoOdometry::OrientFirstFrame(const std::vector<Eigen::Vector3d>& points,
                                             const cv::Mat& left, const cv::Mat& right,
                                             const cv::Mat& disparity_px, OdometryResult* result) {
  const InitialOrientation orientation = EstimateInitialOrientation(
      camera_, options_.initial_orientation, points, left, right, disparity_px);
  orientation_result_ = orientation.planes;
  result->floor_refined = orientation.floor_refined;
  result->floor_refinement_message = orientation.message;
  R_hall_cam0_initial_ = orientation.R_hall_cam0;
  world_up_known_ = orientation.ok;
  if (orientation.ok) {
    vehicle_up_ = VehicleUpEstimate(R_hall_cam0_initial_.transpose() * Eigen::Vector3d::UnitZ(),
                                    orientation.up_sigma_rad);
  }
  result->initial_orientation_ok = orientation.ok;
  if (!orientation.ok) {
    return std::string("initial orientation failed (") + ToString(orientation_result_.status) +
           "): world = first camera frame";
  }
  return result->floor_refinement_message;
}

VehicleGeometry StereoOdometry::Geometry() const {
  VehicleGeometry g;
  g.vehicle = options_.motion.ground_vehicle;
  g.up_known = world_up_known_ && vehicle_up_.known();
  g.up_cam = vehicle_up_.up();
  g.R_world_cam0_initial = R_hall_cam0_initial_;
  g.floor_found = orientation_result_.floor_index >= 0;
  g.axle_behind_camera_m = options_.motion.few_point.axle_behind_camera_m;
  return g;
}

OdometryResult StereoOdometry::Initialise(OdometryResult result, MatchFrame frame,
                                          const std::string& reason, TimePoint start,
                                          const MotionPrior* prior,
                                          const Eigen::Isometry3d* chained) {
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();
  if (!initialised_) {
    // World = hallway frame with its origin at the first camera centre, or the first camera.
    T_world_cam0.linear() = R_hall_cam0_initial_;
    result.status = TrackingStatus::kInitializing;
    result.message = reason;
  } else {
    // Re-initialisation after a loss: keep the predicted pose and the constant velocity.
    T_world_cam0 = recovery_.BridgedPose(Bridge(prior), &result, chained);
    if (!IsFinitePose(T_world_cam0)) T_world_cam0 = T_world_prev_;
    result.status = TrackingStatus::kRecovered;
    result.reinitialised = true;
    result.message = reason.empty() ? "re-initialised at the predicted pose" : reason;
    if (result.direct_motion) result.message += "; motion measured by direct image alignment";
  }
  tracker_->Reset();
  const TrackUpdateResult update =
      back_end_.Start(result.frame_index, &frame.features, T_world_cam0);
  if (!update.ok()) {  // cannot happen on a new window; keep going without tracks
    result.message +=
        (result.message.empty() ? "" : "; ") + std::string("tracks: ") + update.message;
  }
  initialised_ = true;
  consecutive_lost_ = 0;
  recovery_.EndChain();
  last_features_ = frame.features;
  reference_.valid = true;
  reference_.frame_index = result.frame_index;
  reference_.frame = std::move(frame);
  return Finish(std::move(result), T_world_cam0, start);
}

OdometryResult StereoOdometry::Track(OdometryResult result, MatchFrame frame, MotionAttempt attempt,
                                     const Eigen::Isometry3d* T_ref_curr_prior,
                                     const MotionPrior* prior, TimePoint start) {
  const Clock::time_point motion_start = Clock::now();
  const std::vector<Feature>& ref_features = reference_.frame.features;
  result.reference_frame_index = static_cast<int>(reference_.frame_index);
  const std::vector<Match>& matches = attempt.matches;
  const std::vector<StereoCorrespondence>& correspondences = attempt.correspondences;
  const std::vector<int>& match_index = attempt.match_index;
  const RansacResult& ransac = attempt.ransac;
  result.num_matches = static_cast<int>(matches.size());
  result.prediction = attempt.source;

  // The frame's motion: RANSAC's, or the few-point motion with the prior (motion_estimation.h).
  const MotionOptions& motion_options = options_.motion;
  const Eigen::Isometry3d* T_world_ref = back_end_.Pose(reference_.frame_index);
  Eigen::Vector3d up_storage;
  // With the gyro's rotation in the prior, the few-point motion's rotation prior is the gyro's
  // (gyro_prior.h), not the constant velocity's.
  MotionOptions frame_motion_options = options_.motion;
  if (gyro_rotation_.ok) {
    frame_motion_options.few_point_motion =
        frame_motion_options.few_point_motion || options_.imu.few_point_motion;
    frame_motion_options.few_point.prior_rotation_sigma_deg =
        std::max(options_.imu.min_rotation_sigma_deg, gyro_rotation_.sigma_rad() * 180.0 / M_PI);
  }
  if (gyro_rotation_.ok && T_ref_curr_prior != nullptr)
    RejectWeakMotionAgainstGyro(options_.imu, options_.motion.reliable_min_inliers,
                                T_ref_curr_prior->linear(), &attempt.ransac);
  const FrameMotion motion = ResolveFrameMotion(
      camera_, frame_motion_options,
      static_cast<int>(frame.features.size()) < options_.front_end.min_features, ref_features,
      VehicleUpAtReference(&up_storage), T_ref_curr_prior,
      ((previous_measured_ && consecutive_lost_ == 0) || GyroFewPointAfterLoss()) && Predicted(),
      result.image_shift_ok, result.image_shift_px, &attempt);
  if (motion.few_point) {
    result.few_point_motion = true;
    result.message = motion.message;
  }

  last_matches_ = matches;
  last_inlier_mask_.assign(matches.size(), false);
  std::vector<Match> inlier_matches;
  for (size_t k = 0; k < correspondences.size() && k < ransac.inlier_mask.size(); ++k) {
    if (ransac.inlier_mask[k]) last_inlier_mask_[match_index[k]] = true;
  }
  for (size_t m = 0; m < matches.size(); ++m) {
    if (last_inlier_mask_[m]) inlier_matches.push_back(matches[m]);
  }
  last_reference_features_ = ref_features;
  last_features_ = frame.features;
  result.num_inliers = ransac.ok() ? ransac.num_inliers : 0;

  if (!motion.ok()) {
    std::ostringstream why;
    why << MotionFailureMessage(motion, attempt, options_.motion.min_inliers);
    result.times.motion_ms += ElapsedMs(motion_start);
    // The reference cannot measure this frame: the lost frames before it may (the pose and the
    // constant velocity from that chain; BridgedPose takes the pose).
    Eigen::Isometry3d T_world_chained;
    const bool chained =
        recovery_.ChainLostFrame(tracker_.get(), frame, Bridge(prior), &result, &T_world_chained);
    if (chained) {
      why << "; pose chained to lost frame " << result.chained_to_frame << " ("
          << result.chain_inliers << " inliers)";
    }
    // After a loss, a frame that has plenty of features but cannot be matched to the last good
    // one (even with the coarse-to-fine search) starts again at once: waiting longer would
    // only extrapolate further.
    const bool rich =
        static_cast<int>(frame.features.size()) >= 2 * options_.front_end.min_features;
    if (consecutive_lost_ >= options_.recovery.reinit_after_lost_frames ||
        (consecutive_lost_ > 0 && rich)) {
      // The reference is stale: start again from this frame at its predicted (or chained) pose.
      return Initialise(std::move(result), std::move(frame),
                        why.str() + "; re-initialised at the predicted pose", start, prior,
                        chained ? &T_world_chained : nullptr);
    }
    OdometryResult lost =
        Lost(std::move(result), why.str(), start, prior, chained ? &T_world_chained : nullptr);
    if (options_.recovery.chain_lost_frames &&
        static_cast<int>(frame.features.size()) >= options_.front_end.min_features) {
      recovery_.ContinueChain(lost.frame_index, std::move(frame), lost.T_world_cam0);
    }
    return lost;
  }

  // The back end (back_end.h): the initial pose (the measured motion blended with the prior's),
  // the tracks from the inlier matches, the windowed bundle adjustment.
  const int64_t gap = result.frame_index - reference_.frame_index;
  const double inlier_ratio =
      static_cast<double>(ransac.num_inliers) / std::max<size_t>(1, matches.size());
  const BackEndAdd add =
      back_end_.Add(result.frame_index, reference_.frame_index, &frame.features, inlier_matches,
                    ransac.T_prev_curr, T_ref_curr_prior, inlier_ratio, result.few_point_motion);
  if (!add.update.ok()) {
    result.times.motion_ms += ElapsedMs(motion_start);
    return Lost(std::move(result),
                T_world_ref == nullptr ? add.update.message : "tracks: " + add.update.message,
                start, prior);
  }
  Eigen::Isometry3d T_world_curr = add.T_world_curr;
  result.times.motion_ms += ElapsedMs(motion_start);
  result.rms_reprojection_px = ransac.rms_reprojection_px;

  // Windowed bundle adjustment, the oldest pose(s) fixed (sliding_window.h).
  const Clock::time_point ba_start = Clock::now();
  const WindowRefinement refinement =
      result.few_point_motion ? WindowRefinement()
                              : back_end_.Refine(camera_, result.frame_index, Geometry());
  if (refinement.attempted) result.times.ba_ms = ElapsedMs(ba_start);
  const bool ba_rejected = refinement.rejected;
  if (ba_rejected) result.message = refinement.message;
  if (refinement.ran) {
    T_world_curr = *back_end_.Pose(result.frame_index);
    result.ba_ran = true;
    result.ba_num_frames = refinement.num_frames;
    result.ba_num_points = refinement.num_points;
    result.rms_reprojection_px = refinement.rms_reprojection_px;
  }

  // Constant-velocity model: the (refined) motion from the reference, per frame, blended into
  // the prior by its support, so one weak estimate before a loss is not extrapolated over the
  // gap.
  const Eigen::Isometry3d T_ref_curr =
      back_end_.MotionFromReference(reference_.frame_index, T_world_curr, add.T_ref_curr_initial);
  const Eigen::Isometry3d per_frame = Root(T_ref_curr, gap);
  // Weight of this motion in the prior: 1 from reliable_min_inliers inliers up, less below
  // (a weak motion moves the prior only part of the way), 0 when the BA was rejected.
  const double weight = ba_rejected ? 0.0
                        : result.few_point_motion
                            ? motion_options.few_point_prior_update
                            : PriorUpdateWeight(ransac.num_inliers, motion_options);
  velocity_.Move(per_frame, weight);
  if (IsFinitePose(per_frame) && !ba_rejected)
    velocity_.SetLastMeasured(per_frame, result.frame_index);
  result.motion_measured = true;
  // A reliable measured motion refines the vehicle's up (not a few-point or bundle-adjusted
  // one: both are made planar about the current estimate).
  if (motion_options.ground_vehicle && options_.back_end.vehicle_planar.enabled &&
      !result.few_point_motion && !ba_rejected &&
      ransac.num_inliers >= motion_options.reliable_min_inliers)
    vehicle_up_.AddMotion(ransac.T_prev_curr, kVehicleUpTranslationSigmaM,
                          kVehicleUpRotationSigmaDeg * M_PI / 180.0);

  result.status = consecutive_lost_ > 0 ? TrackingStatus::kRecovered : TrackingStatus::kTracking;
  if (consecutive_lost_ > 0) {
    std::ostringstream msg;
    msg << "recovered against frame " << reference_.frame_index << " after " << consecutive_lost_
        << " lost frame(s)";
    result.message = msg.str();
  }
  consecutive_lost_ = 0;
  recovery_.EndChain();
  last_features_ = frame.features;
  reference_.frame_index = result.frame_index;
  reference_.frame = std::move(frame);
  reference_.valid = true;
  return Finish(std::move(result), T_world_curr, start);
}

OdometryResult StereoOdometry::Process(const cv::Mat& left, const cv::Mat& right, double time_s,
                                       const MotionPrior* prior) {
  const Clock::time_point start = Clock::now();
  OdometryResult result;
  result.frame_index = frame_index_++;
  result.time_s = time_s;
  last_features_.clear();
  last_matches_.clear();
  last_inlier_mask_.clear();
  last_reference_features_.clear();
  prev_call_index_map_.clear();
  // The gyro's rotation since the previous call: this frame's prior rotation (gyro_prior.h).
  gyro_rotation_ = GyroRotation();
  if (gyro_) {
    gyro_rotation_ = gyro_->Next(time_s);
    if (gyro_rotation_.ok) velocity_.SetMeasuredRotation(gyro_rotation_.R_prev_curr);
    if (options_.imu.ba_rotation_prior)  // the BA's rotation prior (back_end.h)
      back_end_.AddGyroRotation(result.frame_index, gyro_rotation_,
                                options_.imu.min_rotation_sigma_deg);
  }

  // Input checks: expected failures come back as kLost.
  const cv::Size camera_size(camera_.width, camera_.height);
  if (left.empty() || right.empty()) return Lost(std::move(result), "empty image", start, prior);
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1) {
    return Lost(std::move(result), "images must be 8-bit grayscale (CV_8UC1)", start, prior);
  }
  if (left.size() != right.size()) {
    return Lost(std::move(result), "left and right images differ in size", start, prior);
  }
  if (left.size() != camera_size) {
    std::ostringstream msg;
    msg << "image size " << left.cols << "x" << left.rows << " differs from the camera's "
        << camera_.width << "x" << camera_.height;
    return Lost(std::move(result), msg.str(), start, prior);
  }

  current_left_ = left.clone();  // the caller may reuse its buffer

  // The front end: the disparity (the whole map in dense mode or for the first frame's
  // plane-based orientation, else prepared at the features' pixels), features, depth.
  const bool orientation_frame =
      !reference_.valid && !initialised_ && options_.initial_orientation.enabled;
  const bool dense =
      options_.front_end.disparity_mode == DisparityMode::kDense || orientation_frame;
  FrontEndFrame front =
      front_end_->Process(left, right,
                          scene_num_disparities_ > 0 ? scene_num_disparities_
                                                     : options_.front_end.disparity.num_disparities,
                          dense, &result);
  if (!front.ok) return Lost(std::move(result), front.message, start, prior);
  MatchFrame frame = std::move(front.frame);
  frame.frame_id = result.frame_index;
  last_features_ = frame.features;
  // Below min_features a frame is still matched when the few-point solver can use it (a
  // reference, a prior, at least few_point_min_features features).
  const bool few_point_possible =
      (options_.motion.few_point_motion || (gyro_rotation_.ok && options_.imu.few_point_motion)) &&
      Predicted() && reference_.valid && (prior != nullptr || velocity_.known()) &&
      ((previous_measured_ && consecutive_lost_ == 0) || GyroFewPointAfterLoss()) &&
      result.num_features_with_depth >= options_.motion.few_point_min_features;
  if (result.num_features_with_depth < options_.front_end.min_features && !few_point_possible) {
    std::ostringstream msg;
    msg << "too few features with depth (" << result.num_features_with_depth << " of "
        << result.num_features << " features; need " << options_.front_end.min_features
        << "): black, textureless or unmatched frame";
    return Lost(std::move(result), msg.str(), start, prior);
  }
  frame.image = current_left_;

  if (!reference_.valid) {
    std::string reason;
    if (!initialised_ && options_.initial_orientation.enabled) {
      // Initial orientation from the floor/wall planes of the dense disparity map.
      const Clock::time_point t = Clock::now();
      const std::vector<Eigen::Vector3d> points = SampleDisparityPoints(
          camera_, front.disparity_px, options_.initial_orientation.sample_step_px,
          options_.front_end.depth.min_depth_m, options_.front_end.depth.max_depth_m);
      reason = OrientFirstFrame(points, left, right, front.disparity_px, &result);
      result.times.orientation_ms = ElapsedMs(t);
    }
    return Initialise(std::move(result), std::move(frame), reason, start, prior);
  }

  // Match against the reference frame (its cues are cached in reference_.frame), with the
  // search predicted from the motion prior (tracker.h).
  const Eigen::Isometry3d* ref_pose = back_end_.Pose(reference_.frame_index);
  const Eigen::Isometry3d T_world_ref = ref_pose != nullptr ? *ref_pose : T_world_prev_;
  const Eigen::Isometry3d T_ref_curr_prior = T_world_ref.inverse() * PredictedPose(prior);
  const bool has_prior = (prior != nullptr || velocity_.known()) && IsFinitePose(T_ref_curr_prior);
  TrackingContext context;
  context.T_ref_curr_prior = has_prior ? &T_ref_curr_prior : nullptr;
  context.after_loss = consecutive_lost_ > 0;
  context.velocity = &velocity_;
  Eigen::Vector3d up_storage;
  context.up_ref = VehicleUpAtReference(&up_storage);
  std::string matcher_error;
  MotionAttempt attempt =
      tracker_->MatchAndEstimate(reference_.frame, frame, context, &result, &matcher_error);
  if (!matcher_error.empty()) {
    last_reference_features_ = reference_.frame.features;
    result.reference_frame_index = static_cast<int>(reference_.frame_index);
    return Lost(std::move(result), "matcher: " + matcher_error, start, prior);
  }
  return Track(std::move(result), std::move(frame), std::move(attempt),
               has_prior ? &T_ref_curr_prior : nullptr, prior, start);
}

OdometryResult StereoOdometry::ProcessFeatures(std::vector<Feature> features,
                                               const std::vector<Match>& matches_to_prev,
                                               double time_s) {
  const Clock::time_point start = Clock::now();
  OdometryResult result;
  result.frame_index = frame_index_++;
  result.time_s = time_s;
  result.num_features = static_cast<int>(features.size());
  gyro_rotation_ = GyroRotation();  // the seam has no gyro
  last_features_.clear();
  last_matches_.clear();
  last_inlier_mask_.clear();
  last_reference_features_.clear();

  // Keep the features with depth; p_cam0 from the camera, track fields reset.
  const Clock::time_point t = Clock::now();
  std::vector<int> index_map;  // given index → kept index
  MatchFrame frame;
  frame.frame_id = result.frame_index;
  frame.features = KeepFeaturesWithDepth(camera_, features, &index_map);
  result.times.depth_ms = ElapsedMs(t);
  result.num_features_with_depth = static_cast<int>(frame.features.size());
  last_features_ = frame.features;

  // The matches refer to the previous call's features; usable only when that call became the
  // reference.
  const bool prev_is_reference = reference_.valid &&
                                 reference_.frame_index == result.frame_index - 1 &&
                                 !prev_call_index_map_.empty();
  std::vector<Match> matches;
  if (prev_is_reference) {
    matches = ReindexMatches(matches_to_prev, prev_call_index_map_, index_map,
                             reference_.frame.features.size(), frame.features.size());
  }
  prev_call_index_map_.clear();

  const bool few_point_possible =
      options_.motion.few_point_motion && Predicted() && prev_is_reference && velocity_.known() &&
      previous_measured_ &&
      result.num_features_with_depth >= options_.motion.few_point_min_features;
  if (result.num_features_with_depth < options_.front_end.min_features && !few_point_possible) {
    std::ostringstream msg;
    msg << "too few features with depth (" << result.num_features_with_depth << " of "
        << result.num_features << "; need " << options_.front_end.min_features << ")";
    return Lost(std::move(result), msg.str(), start);
  }
  prev_call_index_map_ = index_map;
  if (!prev_is_reference) {
    std::string reason;
    if (!initialised_ && options_.initial_orientation.enabled) {
      const Clock::time_point to = Clock::now();
      std::vector<Eigen::Vector3d> points;
      for (const Feature& f : frame.features) points.push_back(f.p_cam0);
      reason = OrientFirstFrame(points, cv::Mat(), cv::Mat(), cv::Mat(), &result);
      result.times.orientation_ms = ElapsedMs(to);
    } else if (initialised_) {
      reason =
          "the previous frame was lost, its matches cannot be used: re-initialised at the "
          "predicted pose";
    }
    return Initialise(std::move(result), std::move(frame), reason, start);
  }
  // The constant-velocity prediction from the reference (the previous call) to this frame.
  const Eigen::Isometry3d T_ref_curr_prior = velocity_.per_frame();
  MotionAttempt attempt = tracker_->Estimate(reference_.frame.features, frame.features, matches,
                                             PredictionSource::kNone);
  result.num_first_pass_inliers = attempt.inliers();
  return Track(std::move(result), std::move(frame), std::move(attempt),
               velocity_.known() ? &T_ref_curr_prior : nullptr, nullptr, start);
}

}  // namespace vo
