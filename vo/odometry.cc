#include "vo/odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <utility>

namespace vo {
namespace {

using Clock = std::chrono::steady_clock;

// The vehicle's up in the camera frame (tracking.vehicle_planar_ba): σ of the first frame's
// floor fit, and of a reliable tracked RANSAC motion's translation (metres) and rotation
// (degrees) as evidence of it (a translation across up, a rotation about it). Texture seed 7's
// floor fit is 0.77° off. The RANSAC motions (before the window BA) jitter by ~1 cm sideways
// and ~0.3° per frame; with σ 1 mm / 0.05° the estimate swung by 70° on the pitched camera's
// straight approach. A 4 cm step then gives its direction to ~14°, a 3° turn its axis to ~6°:
// the motions move the floor fit over tens of frames (seed 7: 0.77° -> 0.35° off).
constexpr double kVehicleUpPriorSigmaDeg = 1.0;
// ... when the floor was refined on the images (orientation_floor_refinement): its pitch error
// on l_hallway texture seeds 1-10 was within 0.17° (rms 0.10°). With 1° the reliable motions
// that refine the up carry its slow pitch drift into it (texture seed 5, stride 1: 1.2° off by
// the end, and the flat floor with it).
constexpr double kVehicleUpRefinedFloorSigmaDeg = 0.15;
constexpr double kVehicleUpTranslationSigmaM = 1e-2;
constexpr double kVehicleUpRotationSigmaDeg = 0.3;
// The planes of a frame's features for the direct alignment of the next lost frame
// (tracking.vehicle_direct_alignment): up to 3 (a wall, the floor, a side wall); a feature is on
// one within 1 px of disparity; each with at least 6 features spread at least 5 cm across (not
// all along one edge), 60 % of the features on them. Without such planes a frame carries the
// previous ones by its motion, for at most 30 frames.
constexpr double kScenePlaneTolerancePx = 1.0;
constexpr int kScenePlaneMinInliers = 6;
constexpr double kScenePlaneMinFraction = 0.6;
constexpr double kScenePlaneMinSpreadM = 0.05;
constexpr int kMaxScenePlanes = 3;
constexpr int kMaxScenePlaneAge = 30;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Prefixes the failing part's message with its name.
bool FailPart(const char* part, const std::string& part_error, std::string* error) {
  if (error) *error = std::string(part) + ": " + part_error;
  return false;
}

bool Fail(const std::ostringstream& msg, std::string* error) {
  if (error) *error = msg.str();
  return false;
}

bool IsFinite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

// The world's up (+z of the hallway frame) in the camera frame of T_world_cam.
Eigen::Vector3d WorldUpInCamera(const Eigen::Isometry3d& T_world_cam) {
  return T_world_cam.linear().transpose() * Eigen::Vector3d::UnitZ();
}

// Rotation and translation blend: slerp(q_a, q_b, w), (1 − w) t_a + w t_b.
Eigen::Isometry3d Blend(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b, double w) {
  if (w <= 0.0) return T_a;
  const Eigen::Quaterniond q_a(T_a.linear());
  const Eigen::Quaterniond q_b(T_b.linear());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q_a.slerp(w, q_b).normalized().toRotationMatrix();
  T.translation() = (1.0 - w) * T_a.translation() + w * T_b.translation();
  return T;
}

// The per-frame motion of a motion spanning n >= 1 frames: the rotation's n-th root (slerp from
// identity), the translation divided by n (exact for pure translations and pure rotations).
Eigen::Isometry3d Root(const Eigen::Isometry3d& T, int64_t n) {
  if (n <= 1) return T;
  const double f = 1.0 / static_cast<double>(n);
  Eigen::Isometry3d R = Eigen::Isometry3d::Identity();
  R.linear() = Eigen::Quaterniond::Identity()
                   .slerp(f, Eigen::Quaterniond(T.linear()))
                   .normalized()
                   .toRotationMatrix();
  R.translation() = f * T.translation();
  return R;
}

// Smallest multiple of 16 >= fx · b / min_depth, clamped (see OdometryOptions).
int DerivedNumDisparities(const StereoCamera& camera, const OdometryOptions& options) {
  const double needed = camera.fx_px * camera.baseline_m / options.disparity_min_depth_m;
  const int width_cap = std::max(16, (camera.width - 1) / 16 * 16);
  const int cap = std::min(options.max_num_disparities, width_cap);
  // Clamped in floating point first: an absurd camera (huge fx · baseline) must not overflow.
  const double blocks = std::ceil(std::min(needed, static_cast<double>(cap)) / 16.0);
  const int n = std::min(static_cast<int>(blocks) * 16, cap);
  return std::max(16, n);
}

// Options as the pipeline uses them: derived disparity range, RANSAC min_inliers raised.
OdometryOptions EffectiveOptions(const StereoCamera& camera, const OdometryOptions& options) {
  OdometryOptions effective = ResolvePlatform(options, -1.0);  // no rig known here
  if (options.derive_num_disparities) {
    effective.disparity.num_disparities = DerivedNumDisparities(camera, options);
  }
  effective.ransac.min_inliers = std::max(options.ransac.min_inliers, options.min_inliers);
  if (options.use_bundle_adjustment && !options.ransac_refine_with_ba) {
    effective.ransac.refine_nonlinear = false;
  }
  return effective;
}

// The back end's options from the pipeline's.
SlidingWindowOptions WindowOptions(const OdometryOptions& o) {
  SlidingWindowOptions w;
  w.window_frames = o.ba_window_frames;
  w.use_bundle_adjustment = o.use_bundle_adjustment;
  w.max_points = o.ba_max_points;
  w.max_correction_m = o.ba_max_correction_m;
  w.max_correction_deg = o.ba_max_correction_deg;
  w.ba = o.ba;
  return w;
}

}  // namespace

BundleAdjustmentOptions DefaultOdometryBundleAdjustmentOptions() {
  BundleAdjustmentOptions options;
  options.min_frames_per_point = 2;
  options.max_num_iterations = 10;
  options.solver = BaSolver::kSchurLm;
  options.linear_solver = BaLinearSolver::kDenseSchur;  // when solver = kCeres
  return options;
}

ImageShiftOptions DefaultTrackingImageShiftOptions() {
  ImageShiftOptions options;
  options.min_score = 0.1;
  return options;
}

DisparityOptions DefaultOdometryDisparityOptions() {
  DisparityOptions options;
  // The same correlation as cv::StereoBM, with the left-right check's right view taken from
  // the same cost volume instead of a second pass (vo/sad_block_matcher.h).
  options.algorithm = DisparityAlgorithm::kBlockMatchingOneVolume;
  return options;
}

DetectorOptions DefaultOdometryDetectorOptions() {
  DetectorOptions options;
  options.type = DetectorType::kHarris;
  options.max_features = 300;
  options.bucket_cols = 8;
  options.bucket_rows = 6;
  options.max_per_bucket = 10;
  // A lower relative threshold than the detector's 0.01: one bright ceiling light or door
  // edge otherwise sets the bar so high that a weakly textured wall in front of the camera
  // yields 10-15 corners and tracking is lost (seen on the L-hallway's corner approach).
  options.harris.quality_level = 0.001;
  return options;
}

bool RobustTrackingOptions::IsValid(std::string* error) const {
  std::string part_error;
  if (coarse_to_fine && !image_shift.IsValid(&part_error)) {
    return FailPart("image_shift", part_error, error);
  }
  if (few_point_motion && !few_point.IsValid(&part_error)) {
    return FailPart("few_point", part_error, error);
  }
  if (ground_vehicle && vehicle_bridge_alignment && !vehicle_bridge.IsValid(&part_error)) {
    return FailPart("vehicle_bridge", part_error, error);
  }
  if (ground_vehicle && vehicle_bridge_alignment && vehicle_direct_alignment &&
      !vehicle_direct.IsValid(&part_error)) {
    return FailPart("vehicle_direct", part_error, error);
  }
  std::ostringstream msg;
  if (!(prior_radius_scale >= 0.05 && prior_radius_scale <= 20.0)) {
    msg << "prior_radius_scale must be in [0.05, 20], got " << prior_radius_scale;
  } else if (!(shift_radius_scale >= 0.05 && shift_radius_scale <= 20.0)) {
    msg << "shift_radius_scale must be in [0.05, 20], got " << shift_radius_scale;
  } else if (confident_min_inliers < 0) {
    msg << "confident_min_inliers must be >= 0, got " << confident_min_inliers;
  } else if (!(confident_inlier_fraction >= 0.0 && confident_inlier_fraction <= 1.0)) {
    msg << "confident_inlier_fraction must be in [0, 1], got " << confident_inlier_fraction;
  } else if (!(guided_radius_scale >= 0.05 && guided_radius_scale <= 20.0)) {
    msg << "guided_radius_scale must be in [0.05, 20], got " << guided_radius_scale;
  } else if (!(rotation_min_shift_score >= -1.0 && rotation_min_shift_score <= 1.0)) {
    msg << "rotation_min_shift_score must be in [-1, 1], got " << rotation_min_shift_score;
  } else if (!(rotation_min_peak_ratio >= 1.0) || !std::isfinite(rotation_min_peak_ratio)) {
    msg << "rotation_min_peak_ratio must be finite and >= 1, got " << rotation_min_peak_ratio;
  } else if (!(rotation_min_residual_px >= 0.0) || !std::isfinite(rotation_min_residual_px)) {
    msg << "rotation_min_residual_px must be finite and >= 0, got " << rotation_min_residual_px;
  } else if (reliable_min_inliers < 3) {
    msg << "reliable_min_inliers must be >= 3, got " << reliable_min_inliers;
  } else if (!(prior_update_exponent >= 1.0) || !std::isfinite(prior_update_exponent)) {
    msg << "prior_update_exponent must be finite and >= 1, got " << prior_update_exponent;
  } else if (!(few_point_max_shift_disagreement_px >= 0.0) ||
             !std::isfinite(few_point_max_shift_disagreement_px)) {
    msg << "few_point_max_shift_disagreement_px must be finite and >= 0, got "
        << few_point_max_shift_disagreement_px;
  } else if (!(vehicle_max_weak_tilt_deg > 0.0) || !std::isfinite(vehicle_max_weak_tilt_deg)) {
    msg << "vehicle_max_weak_tilt_deg must be finite and > 0, got " << vehicle_max_weak_tilt_deg;
  } else if (!(vehicle_max_weak_lift_m > 0.0) || !std::isfinite(vehicle_max_weak_lift_m)) {
    msg << "vehicle_max_weak_lift_m must be finite and > 0, got " << vehicle_max_weak_lift_m;
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
  } else if (!(vehicle_ba_tilt_sigma_deg > 0.0) || !std::isfinite(vehicle_ba_tilt_sigma_deg) ||
             !(vehicle_ba_lift_sigma_m > 0.0) || !std::isfinite(vehicle_ba_lift_sigma_m) ||
             !(vehicle_ba_slip_sigma_m > 0.0) || !std::isfinite(vehicle_ba_slip_sigma_m)) {
    msg << "vehicle_ba_tilt_sigma_deg, vehicle_ba_lift_sigma_m and vehicle_ba_slip_sigma_m must "
           "be finite and > 0, got "
        << vehicle_ba_tilt_sigma_deg << ", " << vehicle_ba_lift_sigma_m << ", "
        << vehicle_ba_slip_sigma_m;
  } else if (!(vehicle_floor_tilt_sigma_deg > 0.0) ||
             !std::isfinite(vehicle_floor_tilt_sigma_deg) ||
             !(vehicle_floor_height_sigma_m > 0.0) ||
             !std::isfinite(vehicle_floor_height_sigma_m)) {
    msg << "vehicle_floor_tilt_sigma_deg and vehicle_floor_height_sigma_m must be finite and > 0, "
           "got "
        << vehicle_floor_tilt_sigma_deg << ", " << vehicle_floor_height_sigma_m;
  } else if (few_point_min_features < 1) {
    msg << "few_point_min_features must be >= 1, got " << few_point_min_features;
  } else if (!(few_point_prior_update >= 0.0 && few_point_prior_update <= 1.0)) {
    msg << "few_point_prior_update must be in [0, 1], got " << few_point_prior_update;
  }
  if (msg.tellp() != 0) return Fail(msg, error);
  return true;
}

bool OdometryOptions::IsValid(std::string* error) const {
  std::string part_error;
  if (!detector.IsValid(&part_error)) return FailPart("detector", part_error, error);
  DisparityOptions disparity_checked = disparity;
  if (derive_num_disparities) disparity_checked.num_disparities = 16;  // replaced later
  if (!disparity_checked.IsValid(&part_error)) return FailPart("disparity", part_error, error);
  if (!depth.IsValid(&part_error)) return FailPart("depth", part_error, error);
  if (!matcher.IsValid(&part_error)) return FailPart("matcher", part_error, error);
  if (!ransac.IsValid(&part_error)) return FailPart("ransac", part_error, error);
  if (!ba.IsValid(&part_error)) return FailPart("ba", part_error, error);
  if (!tracking.IsValid(&part_error)) return FailPart("tracking", part_error, error);
  if (estimate_initial_orientation && !orientation.IsValid(&part_error)) {
    return FailPart("orientation", part_error, error);
  }
  if (estimate_initial_orientation && orientation_floor_refinement &&
      !floor_refinement.IsValid(&part_error)) {
    return FailPart("floor_refinement", part_error, error);
  }
  std::ostringstream msg;
  if (matcher.type == MatcherType::kSiftRatio && detector.type != DetectorType::kSift) {
    msg << "matcher sift_ratio needs descriptors: detector.type must be kSift";
  } else if (!(disparity_min_depth_m > 0.0) || !std::isfinite(disparity_min_depth_m)) {
    msg << "disparity_min_depth_m must be finite and > 0, got " << disparity_min_depth_m;
  } else if (max_num_disparities < 16 || max_num_disparities % 16 != 0) {
    msg << "max_num_disparities must be a multiple of 16 and >= 16, got " << max_num_disparities;
  } else if (disparity_mode != DisparityMode::kDense &&
             disparity_mode != DisparityMode::kAtFeatures) {
    msg << "disparity_mode: unknown value " << static_cast<int>(disparity_mode);
  } else if (disparity_mode == DisparityMode::kAtFeatures &&
             disparity.algorithm != DisparityAlgorithm::kBlockMatchingOneVolume) {
    msg << "disparity_mode at_features needs disparity.algorithm "
        << ToString(DisparityAlgorithm::kBlockMatchingOneVolume) << " (got "
        << ToString(disparity.algorithm) << "); use disparity_mode dense with it";
  } else if (!(disparity_range_margin >= 0.0) || !std::isfinite(disparity_range_margin) ||
             !(disparity_range_margin_px >= 0.0) || !std::isfinite(disparity_range_margin_px)) {
    msg << "disparity_range_margin and disparity_range_margin_px must be finite and >= 0, got "
        << disparity_range_margin << " and " << disparity_range_margin_px;
  } else if (ba_window_frames < 3 || ba_window_frames > 10) {
    msg << "ba_window_frames must be in [3, 10], got " << ba_window_frames;
  } else if (ba.num_fixed_poses >= ba_window_frames) {
    msg << "ba.num_fixed_poses (" << ba.num_fixed_poses << ") must be < ba_window_frames ("
        << ba_window_frames << ")";
  } else if (!(prior_weight >= 0.0 && prior_weight <= 1.0)) {
    msg << "prior_weight must be in [0, 1], got " << prior_weight;
  } else if (!(ba_max_correction_m > 0.0) || !(ba_max_correction_deg > 0.0)) {
    msg << "ba_max_correction_m and ba_max_correction_deg must be > 0, got " << ba_max_correction_m
        << " and " << ba_max_correction_deg;
  } else if (ba_max_points < 0) {
    msg << "ba_max_points must be >= 0 (0 = no limit), got " << ba_max_points;
  } else if (orientation_sample_step_px < 1) {
    msg << "orientation_sample_step_px must be >= 1, got " << orientation_sample_step_px;
  } else if (adaptive_min_features < 0) {
    msg << "adaptive_min_features must be >= 0 (0 = off), got " << adaptive_min_features;
  } else if (!(adaptive_quality_level >= 0.0 && adaptive_quality_level < 1.0)) {
    msg << "adaptive_quality_level must be in [0, 1), got " << adaptive_quality_level;
  } else if (min_features < 3) {
    msg << "min_features must be >= 3, got " << min_features;
  } else if (min_inliers < 3) {
    msg << "min_inliers must be >= 3, got " << min_inliers;
  } else if (reinit_after_lost_frames < 1) {
    msg << "reinit_after_lost_frames must be >= 1, got " << reinit_after_lost_frames;
  }
  if (msg.tellp() != 0) return Fail(msg, error);
  return true;
}

const char* ToString(DisparityMode mode) {
  switch (mode) {
    case DisparityMode::kDense:
      return "dense";
    case DisparityMode::kAtFeatures:
      return "at_features";
  }
  return "unknown";
}

const char* ToString(Platform platform) {
  switch (platform) {
    case Platform::kAuto:
      return "auto";
    case Platform::kFree:
      return "free";
    case Platform::kGroundVehicle:
      return "ground_vehicle";
  }
  return "unknown";
}

OdometryOptions ResolvePlatform(const OdometryOptions& options, double rig_axle_behind_camera_m,
                                double rig_pitch_deg) {
  OdometryOptions o = options;
  if (o.platform == Platform::kAuto)
    o.platform = rig_axle_behind_camera_m >= 0.0 ? Platform::kGroundVehicle : Platform::kFree;
  if (o.platform == Platform::kGroundVehicle) {
    o.tracking.few_point_motion = true;
    o.tracking.ground_vehicle = true;
    o.tracking.vehicle_planar_ba = true;
    o.tracking.vehicle_flat_floor = true;
  }
  if (o.tracking.ground_vehicle && o.tracking.few_point.axle_behind_camera_m == 0.0 &&
      rig_axle_behind_camera_m >= 0.0)
    o.tracking.few_point.axle_behind_camera_m = rig_axle_behind_camera_m;
  if (o.platform == Platform::kGroundVehicle && std::isfinite(rig_pitch_deg)) {
    o.orientation_up_from_mounting = true;
    if (o.orientation.expected_up_cam0 == PlaneOrientationOptions().expected_up_cam0) {
      const double p = rig_pitch_deg * M_PI / 180.0;
      // (0 − sin p: a level camera writes 0, not −0, into vo_options.yaml)
      o.orientation.expected_up_cam0 = Eigen::Vector3d(0.0, -std::cos(p), 0.0 - std::sin(p));
    }
  }
  return o;
}

const char* ToString(PredictionSource source) {
  switch (source) {
    case PredictionSource::kNone:
      return "none";
    case PredictionSource::kMotionPrior:
      return "motion_prior";
    case PredictionSource::kImageShift:
      return "image_shift";
    case PredictionSource::kGuided:
      return "guided";
    case PredictionSource::kLastMotion:
      return "last_motion";
  }
  return "unknown";
}

const char* ToString(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::kInitializing:
      return "initializing";
    case TrackingStatus::kTracking:
      return "tracking";
    case TrackingStatus::kLost:
      return "lost";
    case TrackingStatus::kRecovered:
      return "recovered";
  }
  return "unknown";
}

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
      options_(EffectiveOptions(camera, options)),
      window_(WindowOptions(options_)) {
  std::string why;
  if (!camera_.IsValid(&why)) {
    std::fprintf(stderr, "vo::StereoOdometry: invalid camera: %s\n", why.c_str());
    std::abort();
  }
  if (!options_.IsValid(&why)) {
    std::fprintf(stderr, "vo::StereoOdometry: invalid options: %s\n", why.c_str());
    std::abort();
  }
  disparity_ = std::make_unique<DisparityEstimator>(options_.disparity);
  detector_ = CreateFeatureDetector(options_.detector, &why);
  if (options_.adaptive_min_features > 0 && options_.detector.type == DetectorType::kHarris) {
    DetectorOptions weak = options_.detector;
    weak.harris.quality_level =
        std::min(options_.detector.harris.quality_level, options_.adaptive_quality_level);
    weak_detector_ = CreateFeatureDetector(weak, &why);
  }
  matcher_ = CreateFrameMatcher(options_.matcher, &why);
  if (!detector_ || !matcher_) {
    std::fprintf(stderr, "vo::StereoOdometry: %s\n", why.c_str());
    std::abort();
  }
}

StereoOdometry::~StereoOdometry() = default;

void StereoOdometry::Reset() {
  window_.Reset();
  matcher_->Reset();
  frame_index_ = 0;
  initialised_ = false;
  consecutive_lost_ = 0;
  previous_measured_ = false;
  reference_ = Reference();
  lost_chain_ = Reference();
  T_world_prev_ = Eigen::Isometry3d::Identity();
  velocity_ = Eigen::Isometry3d::Identity();
  has_velocity_ = false;
  last_motion_frame_ = -1;
  scene_num_disparities_ = 0;
  R_hall_cam0_initial_ = Eigen::Matrix3d::Identity();
  world_up_known_ = false;
  vehicle_up_ = VehicleUpEstimate();
  orientation_result_ = PlaneOrientationResult();
  last_features_.clear();
  previous_frame_features_.clear();
  scene_planes_.clear();
  scene_planes_age_ = 0;
  last_matches_.clear();
  last_inlier_mask_.clear();
  last_reference_features_.clear();
  prev_call_index_map_.clear();
  current_left_ = cv::Mat();
  previous_left_ = cv::Mat();
}

OdometryResult StereoOdometry::Finish(OdometryResult result, const Eigen::Isometry3d& T_world_cam0,
                                      TimePoint start) {
  // Never hand out a non-finite pose: fall back to the previous output. The rotation is
  // re-projected onto SO(3), so rounding in long chains of composed motions (a long bridge of
  // lost frames) cannot accumulate into a non-rigid transform.
  Eigen::Isometry3d T = IsFinite(T_world_cam0) ? T_world_cam0 : T_world_prev_;
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  result.T_world_cam0 = T;
  result.T_prev_curr = result.frame_index == 0 ? Eigen::Isometry3d::Identity()
                                               : Eigen::Isometry3d(T_world_prev_.inverse() * T);
  T_world_prev_ = T;
  previous_measured_ = result.motion_measured;
  // Only the bridge alignment reads the previous frame's features: no copy per frame otherwise.
  if (options_.tracking.ground_vehicle && options_.tracking.vehicle_bridge_alignment) {
    previous_frame_features_ = last_features_;
    if (options_.tracking.vehicle_direct_alignment) UpdateScenePlanes(result.T_prev_curr);
  }
  // Next frame's disparity search range from the depths of this one (full after a loss).
  scene_num_disparities_ = 0;
  if (options_.disparity_range_from_scene && result.status != TrackingStatus::kLost) {
    double max_disparity = 0.0;
    for (const Feature& f : last_features_) {
      if (f.has_depth()) max_disparity = std::max(max_disparity, f.disparity_px);
    }
    const double wanted = max_disparity * (1.0 + options_.disparity_range_margin) +
                          options_.disparity_range_margin_px;
    const int n = 16 * static_cast<int>(std::ceil(wanted / 16.0));
    if (max_disparity > 0.0 && n < options_.disparity.num_disparities) {
      scene_num_disparities_ = std::max(16, n);
    }
  }
  previous_left_ = current_left_;
  current_left_ = cv::Mat();
  result.times.total_ms = MsSince(start);
  return result;
}

bool IsVehicleLike(const Eigen::Isometry3d& T_a_b, const Eigen::Vector3d& up_a, double max_tilt_deg,
                   double max_lift_m) {
  const Eigen::Isometry3d planar = PlanarPart(T_a_b, up_a);
  const double tilt_rad = Eigen::AngleAxisd(planar.linear().transpose() * T_a_b.linear()).angle();
  const double lift_m = std::abs(up_a.normalized().dot(T_a_b.translation()));
  return tilt_rad <= max_tilt_deg * M_PI / 180.0 && lift_m <= max_lift_m;
}

Eigen::Vector2d PredictedCentreShift(const StereoCamera& camera,
                                     const Eigen::Isometry3d& T_ref_curr, double depth_m) {
  const Eigen::Vector2d centre(camera.cx_px, camera.cy_px);
  const bool near = std::isfinite(depth_m) && depth_m > 0.0;
  const Eigen::Isometry3d T_curr_ref = T_ref_curr.inverse();
  const Eigen::Vector3d ray(0.0, 0.0, 1.0);
  const Eigen::Vector3d p_curr = near ? Eigen::Vector3d(T_curr_ref * (depth_m * ray))
                                      : Eigen::Vector3d(T_curr_ref.linear() * ray);
  if (!(p_curr.z() > 1e-9)) {
    return Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  }
  return Eigen::Vector2d(camera.fx_px * p_curr.x() / p_curr.z(),
                         camera.fy_px * p_curr.y() / p_curr.z());
}

Eigen::Isometry3d CorrectPriorWithImageShift(const StereoCamera& camera,
                                             const Eigen::Isometry3d& T_prev_curr_prior,
                                             const Eigen::Vector2d& shift_px, double depth_m) {
  // Where the prior puts the point seen at the previous image centre (depth_m, or far away).
  const bool near = std::isfinite(depth_m) && depth_m > 0.0;
  const Eigen::Vector3d p_prev = Eigen::Vector3d(0.0, 0.0, near ? depth_m : 1.0);
  const Eigen::Isometry3d T_curr_prev = T_prev_curr_prior.inverse();
  const Eigen::Vector3d p_curr =
      near ? Eigen::Vector3d(T_curr_prev * p_prev) : Eigen::Vector3d(T_curr_prev.linear() * p_prev);
  if (!(p_curr.z() > 1e-9)) return T_prev_curr_prior;
  const Eigen::Vector2d predicted(camera.fx_px * p_curr.x() / p_curr.z(),
                                  camera.fy_px * p_curr.y() / p_curr.z());
  // The residual shift r: the prior-predicted camera c' sees along a ray that the true camera c
  // sees at (r_x / fx, r_y / fy, 1), i.e. R_c'c^T e_z ∝ d, and R_c'c = FromTwoVectors(d, e_z).
  const Eigen::Vector2d r = shift_px - predicted;
  const Eigen::Vector3d ray_c(p_curr.x() / p_curr.z() + r.x() / camera.fx_px,
                              p_curr.y() / p_curr.z() + r.y() / camera.fy_px, 1.0);
  const Eigen::Vector3d ray_c_prime(p_curr.x() / p_curr.z(), p_curr.y() / p_curr.z(), 1.0);
  // R_c'c maps directions in c to directions in c': the ray seen in c must map to the ray the
  // point has in c'.
  const Eigen::Matrix3d R_cprime_c =
      Eigen::Quaterniond::FromTwoVectors(ray_c, ray_c_prime).toRotationMatrix();
  Eigen::Isometry3d T_cprime_c = Eigen::Isometry3d::Identity();
  T_cprime_c.linear() = R_cprime_c;
  return T_prev_curr_prior * T_cprime_c;
}

Eigen::Isometry3d VehicleMotionFromImageShift(const StereoCamera& camera,
                                              const Eigen::Vector3d& up_prev,
                                              double axle_behind_camera_m,
                                              const Eigen::Isometry3d& T_prev_curr_prior,
                                              const Eigen::Vector2d& shift_px, double depth_m) {
  const Eigen::Vector2d yaw_forward =
      VehicleMotionParameters(T_prev_curr_prior, up_prev, axle_behind_camera_m);
  if (!yaw_forward.allFinite() || !shift_px.allFinite() || !up_prev.allFinite()) {
    return T_prev_curr_prior;
  }
  const double forward_m = yaw_forward.y();
  double yaw = yaw_forward.x();
  for (int i = 0; i < 100; ++i) {
    const Eigen::Isometry3d T = VehicleMotion(up_prev, axle_behind_camera_m, yaw, forward_m);
    const Eigen::Isometry3d corrected =
        PlanarPart(CorrectPriorWithImageShift(camera, T, shift_px, depth_m), up_prev);
    const double next = VehicleMotionParameters(corrected, up_prev, axle_behind_camera_m).x();
    if (!std::isfinite(next)) return T_prev_curr_prior;
    const bool converged = std::abs(next - yaw) <= 1e-12;
    yaw = next;
    if (converged) break;
  }
  return VehicleMotion(up_prev, axle_behind_camera_m, yaw, forward_m);
}

Eigen::Isometry3d StereoOdometry::BridgedPose(const MotionPrior* prior, OdometryResult* result,
                                              const Eigen::Isometry3d* chained) {
  if (chained != nullptr) return *chained;  // measured against the lost-frame chain
  const Eigen::Isometry3d bridged = ShiftCorrectedPose(prior, result);
  const RobustTrackingOptions& o = options_.tracking;
  if (prior != nullptr || !o.ground_vehicle || !o.vehicle_bridge_alignment || !world_up_known_ ||
      options_.matcher.prediction == PredictionMode::kNone) {
    return bridged;
  }
  const Eigen::Isometry3d aligned = AlignedBridgePose(bridged, result);
  return o.vehicle_direct_alignment ? DirectAlignedPose(aligned, result) : aligned;
}

Eigen::Isometry3d StereoOdometry::DirectAlignedPose(const Eigen::Isometry3d& bridged,
                                                    OdometryResult* result) {
  if (scene_planes_.empty() || previous_left_.empty() || current_left_.empty()) return bridged;
  const RobustTrackingOptions& o = options_.tracking;
  const Clock::time_point t = Clock::now();
  const Eigen::Vector3d up = WorldUpInCamera(T_world_prev_);
  const double axle = o.few_point.axle_behind_camera_m;
  const Eigen::Vector2d start =
      VehicleMotionParameters(T_world_prev_.inverse() * bridged, up, axle);
  if (!start.allFinite()) return bridged;
  const DirectAlignmentResult direct =
      AlignVehicleDirect(camera_, previous_left_, current_left_, scene_planes_, up, axle, start.x(),
                         start.y(), o.vehicle_direct);
  result->times.predict_ms += MsSince(t);
  if (!direct.ok) return bridged;
  const Eigen::Isometry3d T = VehicleMotion(up, axle, direct.yaw_rad, direct.forward_m);
  if (!IsFinite(T)) return bridged;
  if (has_velocity_) velocity_ = T;
  result->direct_motion = true;
  result->motion_measured = true;
  return T_world_prev_ * T;
}

void StereoOdometry::UpdateScenePlanes(const Eigen::Isometry3d& T_prev_curr) {
  std::vector<ScenePlane> fitted;
  if (FitScenePlanes(camera_, last_features_, kScenePlaneTolerancePx, kScenePlaneMinInliers,
                     kScenePlaneMinFraction, kScenePlaneMinSpreadM, kMaxScenePlanes, &fitted)) {
    scene_planes_ = fitted;
    scene_planes_age_ = 0;
  } else if (!scene_planes_.empty() && IsFinite(T_prev_curr) &&
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

Eigen::Isometry3d StereoOdometry::AlignedBridgePose(const Eigen::Isometry3d& bridged,
                                                    OdometryResult* result) {
  const RobustTrackingOptions& o = options_.tracking;
  const Clock::time_point t = Clock::now();
  Eigen::Isometry3d T = T_world_prev_.inverse() * bridged;
  int pairs = 0;
  double t_z = 0.0;
  if (ForwardStepFromDepth(camera_, previous_frame_features_, last_features_, T, o.vehicle_bridge,
                           &t_z, &pairs)) {
    T.translation().z() = t_z;
    result->bridge_aligned = true;
  }
  const Eigen::Vector3d up = WorldUpInCamera(T_world_prev_);
  const double axle = o.few_point.axle_behind_camera_m;
  const Eigen::Vector2d yaw_forward = VehicleMotionParameters(T, up, axle);
  double yaw = yaw_forward.x();
  if (yaw_forward.allFinite() &&
      AlignVehicleYaw(camera_, previous_frame_features_, last_features_, up, axle, yaw_forward.y(),
                      o.vehicle_bridge, &yaw, &pairs)) {
    T = VehicleMotion(up, axle, yaw, yaw_forward.y());
    result->bridge_aligned = true;
  }
  result->times.predict_ms += MsSince(t);
  if (!IsFinite(T)) return bridged;
  if (has_velocity_) velocity_ = T;
  return T_world_prev_ * T;
}

Eigen::Isometry3d StereoOdometry::ShiftCorrectedPose(const MotionPrior* prior,
                                                     OdometryResult* result) {
  const Eigen::Isometry3d predicted = T_world_prev_ * BridgeMotion(prior);
  const RobustTrackingOptions& o = options_.tracking;
  if (options_.matcher.prediction == PredictionMode::kNone || !o.rotation_from_shift ||
      previous_left_.empty() || current_left_.empty() ||
      previous_left_.size() != current_left_.size()) {
    return predicted;
  }
  const Clock::time_point t = Clock::now();
  const ImageShiftResult shift = EstimateImageShift(previous_left_, current_left_, o.image_shift);
  result->times.predict_ms += MsSince(t);
  // A ground vehicle (its motion a yaw and a forward step, the camera swinging about the axle)
  // reads the shift with that model: a sharp peak is trusted at a lower score, and a shift whose
  // vertical part (no pitch: zoom, parallax) is large against its horizontal part is no turn.
  const bool vehicle = prior == nullptr && o.ground_vehicle && world_up_known_;
  const bool strong = shift.score >= o.rotation_min_shift_score &&
                      shift.second_best_ratio >= o.rotation_min_peak_ratio;
  const bool sharp = vehicle && shift.score >= o.vehicle_rotation_min_shift_score &&
                     shift.second_best_ratio >= o.vehicle_rotation_min_peak_ratio;
  if (!shift.ok || !(strong || sharp)) return predicted;
  // The prior's own frame-to-frame motion (not T_world_prev⁻¹ · predicted, which would feed
  // rounding in the composed poses back into the prior, frame after frame), corrected at the
  // median depth of this frame's features (last_features_; none: far away).
  const Eigen::Isometry3d T_prev_curr_prior = BridgeMotion(prior);
  double depth_m = -1.0;
  if (!last_features_.empty()) {
    std::vector<double> z;
    for (const Feature& f : last_features_) z.push_back(f.p_cam0.z());
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
    T_prev_curr = VehicleMotionFromImageShift(camera_, WorldUpInCamera(T_world_prev_),
                                              o.few_point.axle_behind_camera_m, T_prev_curr_prior,
                                              shift.shift_px, depth_m);
  } else {  // (not a ground vehicle whose up is known: PlanarBridge would change nothing)
    T_prev_curr = CorrectPriorWithImageShift(camera_, T_prev_curr_prior, shift.shift_px, depth_m);
  }
  if (!IsFinite(T_prev_curr)) return predicted;
  // The shift the prior itself predicts: the correction's rotation seen at the image centre.
  const double residual_px =
      camera_.fx_px *
      Eigen::AngleAxisd(T_prev_curr_prior.linear().transpose() * T_prev_curr.linear()).angle();
  if (residual_px <= o.rotation_min_residual_px) return predicted;
  // The measured rotation becomes the prior's rotation (a turn goes on through the next frames
  // that have no usable shift); the prior's translation stays.
  if (prior == nullptr && has_velocity_) velocity_.linear() = T_prev_curr.linear();
  result->rotation_from_shift = true;
  result->image_shift_ok = true;
  result->image_shift_px = shift.shift_px;
  return T_world_prev_ * T_prev_curr;
}

Eigen::Isometry3d StereoOdometry::PriorMotion(const MotionPrior* prior) const {
  if (prior != nullptr && IsFinite(prior->T_prev_curr)) return prior->T_prev_curr;
  return has_velocity_ ? velocity_ : Eigen::Isometry3d::Identity();
}

Eigen::Isometry3d StereoOdometry::PlanarBridge(const Eigen::Isometry3d& T_prev_curr,
                                               const MotionPrior* prior) const {
  if (prior != nullptr || !options_.tracking.ground_vehicle || !world_up_known_) {
    return T_prev_curr;
  }
  return PlanarPart(T_prev_curr, WorldUpInCamera(T_world_prev_));
}

Eigen::Isometry3d StereoOdometry::BridgeMotion(const MotionPrior* prior) const {
  return PlanarBridge(PriorMotion(prior), prior);
}

Eigen::Isometry3d StereoOdometry::PredictedPose(const MotionPrior* prior) const {
  return T_world_prev_ * PriorMotion(prior);
}

OdometryResult StereoOdometry::Lost(OdometryResult result, const std::string& message,
                                    TimePoint start, const MotionPrior* prior,
                                    const Eigen::Isometry3d* chained) {
  result.status = TrackingStatus::kLost;
  result.message = message;
  ++consecutive_lost_;
  // Frames are skipped from the matcher's point of view (the Kalman tracker keeps state).
  matcher_->Reset();
  const Eigen::Isometry3d T_world_cam0 = BridgedPose(prior, &result, chained);
  if (result.rotation_from_shift) result.message += "; pose: prior + rotation from the image shift";
  if (result.direct_motion) result.message += "; motion measured by direct image alignment";
  return Finish(std::move(result), T_world_cam0, start);
}

bool StereoOdometry::RefineInitialFloor(const cv::Mat& left, const cv::Mat& right,
                                        const cv::Mat& disparity_px, std::string* message) {
  PlaneOrientationResult& o = orientation_result_;
  // The floor, or without one the ceiling (its normal is then the down direction).
  const bool has_floor = o.floor_index >= 0;
  Plane& floor = o.planes[has_floor ? o.floor_index : o.ceiling_index];
  const double up_sign = has_floor ? 1.0 : -1.0;
  // The floor's pixels: those whose point of the dense map lies on the geometric fit (within
  // the plane extraction's inlier distance).
  std::vector<cv::Point> pixels;
  for (int v = 0; v < disparity_px.rows; ++v) {
    const float* row = disparity_px.ptr<float>(v);
    for (int u = 0; u < disparity_px.cols; ++u) {
      if (!(row[u] > 0.0f)) continue;
      const Eigen::Vector3d p = camera_.Backproject(u, v, row[u]);
      if (std::abs(floor.normal_cam0.dot(p) + floor.offset_m) <=
          PlaneInlierDistance(p, options_.orientation)) {
        pixels.emplace_back(u, v);
      }
    }
  }
  const PlaneRefinementResult refined =
      RefinePlanePhotometric(left, right, camera_, floor, pixels, options_.floor_refinement);
  if (!refined.ok) {
    *message = "floor not refined: " + refined.message;
    return false;
  }
  const double start_offset = floor.offset_m;
  floor = refined.plane;
  // The floor fixes the pitch: the rotation about the hallway's y axis. With walls found, that
  // axis (their normal) stays, so the roll and the yaw stay the walls' (a side wall seen face
  // on measures the roll better than a floor seen at a grazing angle); the up is the refined
  // normal without its part along y_hall. Without walls, the up is the refined normal.
  Eigen::Vector3d up = up_sign * floor.normal_cam0;
  if (o.ok()) {
    const Eigen::Vector3d y_old = o.R_hall_cam0.row(1).transpose();
    up = (up - up.dot(y_old) * y_old).normalized();
  }
  const Eigen::Vector3d x_old = o.R_hall_cam0.row(0).transpose();
  const Eigen::Vector3d x_hall = (x_old - x_old.dot(up) * up).normalized();
  o.R_hall_cam0.row(0) = x_hall.transpose();
  o.R_hall_cam0.row(1) = up.cross(x_hall).transpose();
  o.R_hall_cam0.row(2) = up.transpose();
  std::ostringstream msg;
  msg << (has_floor ? "floor" : "ceiling") << " refined on the images (" << refined.pixels
      << " pixels, " << refined.iterations << " iterations): up moved by "
      << std::acos(std::clamp(up.dot(o.up_cam0), -1.0, 1.0)) * 180.0 / M_PI << " deg, distance "
      << start_offset << " -> " << floor.offset_m << " m";
  *message = msg.str();
  o.up_cam0 = up;
  if (has_floor) o.camera_height_m = floor.offset_m;
  return true;
}

bool StereoOdometry::EstimateInitialOrientation(const std::vector<Eigen::Vector3d>& points_cam0,
                                                const cv::Mat& left, const cv::Mat& right,
                                                const cv::Mat& disparity_px,
                                                OdometryResult* result) {
  orientation_result_ = EstimateHallwayOrientation(points_cam0, options_.orientation);
  if (options_.orientation_floor_refinement && !disparity_px.empty() &&
      (orientation_result_.floor_index >= 0 || orientation_result_.ceiling_index >= 0) &&
      (orientation_result_.ok() ||
       orientation_result_.status == PlaneOrientationResult::Status::kNoWall)) {
    result->floor_refined =
        RefineInitialFloor(left, right, disparity_px, &result->floor_refinement_message);
  }
  bool ok = orientation_result_.ok() ||
            (orientation_result_.status == PlaneOrientationResult::Status::kNoWall &&
             !options_.orientation_requires_wall);
  if (!ok && options_.orientation_up_from_mounting &&
      orientation_result_.status == PlaneOrientationResult::Status::kNoFloor) {
    // The mounting's up; x_hall the camera's forward axis made horizontal (zero yaw).
    const Eigen::Vector3d up = options_.orientation.expected_up_cam0.normalized();
    Eigen::Vector3d x_hall, y_hall;
    HorizontalBasis(up, &x_hall, &y_hall);
    orientation_result_.R_hall_cam0.row(0) = x_hall.transpose();
    orientation_result_.R_hall_cam0.row(1) = y_hall.transpose();
    orientation_result_.R_hall_cam0.row(2) = up.transpose();
    orientation_result_.up_cam0 = up;
    result->floor_refinement_message =
        "no floor or ceiling in the first frame: the up from the camera's mounting "
        "(orientation.expected_up_cam0)";
    ok = x_hall.allFinite();
  }
  R_hall_cam0_initial_ = ok ? orientation_result_.R_hall_cam0 : Eigen::Matrix3d::Identity();
  world_up_known_ = ok;
  if (ok) {
    // A refined ceiling is not as good (plain_corridor: 1.05° off): the floor's σ only for a
    // floor.
    const double sigma_deg = result->floor_refined && orientation_result_.floor_index >= 0
                                 ? kVehicleUpRefinedFloorSigmaDeg
                                 : kVehicleUpPriorSigmaDeg;
    vehicle_up_ = VehicleUpEstimate(R_hall_cam0_initial_.transpose() * Eigen::Vector3d::UnitZ(),
                                    sigma_deg * M_PI / 180.0);
  }
  return ok;
}

PlanarMotionPrior StereoOdometry::WindowPlanarPrior() const {
  const RobustTrackingOptions& o = options_.tracking;
  PlanarMotionPrior prior;
  prior.enabled = o.ground_vehicle && o.vehicle_planar_ba && world_up_known_ && vehicle_up_.known();
  if (!prior.enabled) return prior;
  prior.up_cam = vehicle_up_.up();
  prior.axle_behind_camera_m = o.few_point.axle_behind_camera_m;
  prior.tilt_sigma_rad = o.vehicle_ba_tilt_sigma_deg * M_PI / 180.0;
  prior.lift_sigma_m = o.vehicle_ba_lift_sigma_m;
  prior.slip_sigma_m = o.vehicle_ba_slip_sigma_m;
  // The floor's up is the vehicle's (as refined so far) at the first pose, (R_hall_cam0_initial_,
  // 0) (Initialise), so that a turn about the refined up keeps it; the world's z (the first
  // floor fit) would tilt every pose by what the refinement has moved the up since.
  // Only when the first frame found a floor: an up from the ceiling is off by 1-1.5°
  // (plain_corridor, where no floor is found: strides 1/2/3/5 0.72/0.52/2.75/1.04 % without the
  // flat floor, 2.10/1.56/2.01/1.44 % with it on the refined ceiling's up).
  prior.flat_floor = o.vehicle_flat_floor && orientation_result_.floor_index >= 0;
  prior.floor_up_world = R_hall_cam0_initial_ * vehicle_up_.up();
  prior.floor_height_m = 0.0;
  prior.floor_tilt_sigma_rad = o.vehicle_floor_tilt_sigma_deg * M_PI / 180.0;
  prior.floor_height_sigma_m = o.vehicle_floor_height_sigma_m;
  return prior;
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
    T_world_cam0 = BridgedPose(prior, &result, chained);
    if (!IsFinite(T_world_cam0)) T_world_cam0 = T_world_prev_;
    result.status = TrackingStatus::kRecovered;
    result.reinitialised = true;
    result.message = reason.empty() ? "re-initialised at the predicted pose" : reason;
    if (result.direct_motion) result.message += "; motion measured by direct image alignment";
  }
  matcher_->Reset();
  const TrackUpdateResult update = window_.Start(result.frame_index, &frame.features, T_world_cam0);
  if (!update.ok()) {  // cannot happen on a new window; keep going without tracks
    result.message +=
        (result.message.empty() ? "" : "; ") + std::string("tracks: ") + update.message;
  }
  initialised_ = true;
  consecutive_lost_ = 0;
  lost_chain_.valid = false;
  last_features_ = frame.features;
  reference_.valid = true;
  reference_.frame_index = result.frame_index;
  reference_.frame = std::move(frame);
  return Finish(std::move(result), T_world_cam0, start);
}

std::vector<Eigen::Vector2d> PredictFeaturePositions(const StereoCamera& camera,
                                                     const std::vector<Feature>& features,
                                                     const Eigen::Isometry3d& T_ref_curr,
                                                     double min_depth_m) {
  const Eigen::Isometry3d T_curr_ref = T_ref_curr.inverse();
  const Eigen::Vector2d none = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<Eigen::Vector2d> uv(features.size(), none);
  for (size_t i = 0; i < features.size(); ++i) {
    const Feature& f = features[i];
    if (!f.has_depth() || !f.p_cam0.allFinite()) continue;
    Eigen::Vector2d p;
    if (camera.ProjectLeft(T_curr_ref * f.p_cam0, &p, min_depth_m)) uv[i] = p;
  }
  return uv;
}

std::vector<Eigen::Vector2d> StereoOdometry::PredictPositions(
    const std::vector<Feature>& ref_features, const Eigen::Isometry3d& T_ref_curr) const {
  return PredictFeaturePositions(camera_, ref_features, T_ref_curr, options_.ransac.min_depth_m);
}

StereoOdometry::MotionAttempt StereoOdometry::EstimateMotion(
    const std::vector<Feature>& ref_features, const std::vector<Feature>& curr_features,
    std::vector<Match> matches, PredictionSource source) const {
  MotionAttempt a;
  a.matches = std::move(matches);
  a.source = source;
  a.correspondences =
      MakeStereoCorrespondences(ref_features, curr_features, a.matches, &a.match_index);
  a.ransac = EstimateMotionRansac(camera_, a.correspondences, options_.ransac);
  return a;
}

PriorMotionResult StereoOdometry::FewPointMotion(
    const std::vector<StereoCorrespondence>& correspondences,
    const Eigen::Isometry3d& T_ref_curr_prior, Eigen::Isometry3d* few_prior) const {
  // A ground vehicle's motion is planar: the prior without roll, pitch and lift, and the
  // correction about the world's up (known when the first frame's orientation found the
  // floor), as the reference's pose puts it.
  const Eigen::Isometry3d* T_world_ref = window_.Pose(reference_.frame_index);
  const bool planar = options_.tracking.ground_vehicle && world_up_known_ && T_world_ref != nullptr;
  const Eigen::Vector3d up_ref = planar ? WorldUpInCamera(*T_world_ref) : Eigen::Vector3d::UnitZ();
  *few_prior = planar ? PlanarPart(T_ref_curr_prior, up_ref) : T_ref_curr_prior;
  const Eigen::Vector3d up_curr = few_prior->linear().transpose() * up_ref;
  return EstimateMotionWithPrior(camera_, correspondences, *few_prior, options_.tracking.few_point,
                                 planar ? &up_curr : nullptr);
}

StereoOdometry::MotionAttempt StereoOdometry::MatchAndEstimate(
    const MatchFrame& ref, const MatchFrame& frame, const Eigen::Isometry3d* T_ref_curr_prior,
    OdometryResult* result, std::string* matcher_error, bool few_point_tie) {
  const RobustTrackingOptions& o = options_.tracking;
  // One pass: match around `prediction`, then RANSAC. Times go to `match_ms` / `motion_ms`.
  auto pass = [&](const MatchPrediction& prediction, PredictionSource source, double* match_ms,
                  double* motion_ms, MotionAttempt* attempt) {
    Clock::time_point t = Clock::now();
    MatcherSummary summary;
    std::vector<Match> matches = matcher_->MatchFrames(ref, frame, prediction, &summary);
    *match_ms += MsSince(t);
    if (!summary.ok) {
      *matcher_error = summary.message;
      return false;
    }
    t = Clock::now();
    *attempt = EstimateMotion(ref.features, frame.features, std::move(matches), source);
    *motion_ms += MsSince(t);
    return true;
  };
  MotionAttempt best;
  StageTimes& times = result->times;
  if (options_.matcher.prediction == PredictionMode::kNone) {  // the paper's form
    pass(MatchPrediction(), PredictionSource::kNone, &times.match_ms, &times.motion_ms, &best);
    result->num_first_pass_inliers = best.inliers();
    return best;
  }

  // 1. Centred on the motion prior's prediction (previous positions without a prior).
  Clock::time_point t = Clock::now();
  MatchPrediction prediction;
  PredictionSource source = PredictionSource::kNone;
  if (T_ref_curr_prior != nullptr) {
    prediction.uv_px = PredictPositions(ref.features, *T_ref_curr_prior);
    prediction.radius_scale = o.prior_radius_scale;
    source = PredictionSource::kMotionPrior;
  }
  times.predict_ms += MsSince(t);
  if (!pass(prediction, source, &times.match_ms, &times.motion_ms, &best)) return best;
  result->num_first_pass_inliers = best.inliers();
  // The stateful Kalman tracker sees each frame pair once.
  if (matcher_->type() == MatcherType::kKalman) return best;

  // 2. Weak (no reliable motion yet, or after a loss) or contradicted prior: the dominant image
  //    shift, coarse-to-fine, and a wider search around it; the pass with more inliers wins.
  const double smaller = static_cast<double>(std::min(ref.features.size(), frame.features.size()));
  const bool weak = T_ref_curr_prior == nullptr || consecutive_lost_ > 0;
  auto confident = [&](const MotionAttempt& a) {
    return a.inliers() >= std::max(options_.min_inliers, o.confident_min_inliers) &&
           a.inliers() >= o.confident_inlier_fraction * smaller;
  };
  if (o.coarse_to_fine && (weak || !confident(best))) {
    t = Clock::now();
    const ImageShiftResult shift = EstimateImageShift(ref.image, frame.image, o.image_shift);
    result->image_shift_ok = shift.ok;
    if (shift.ok) result->image_shift_px = shift.shift_px;
    times.predict_ms += MsSince(t);
    if (shift.ok) {
      MatchPrediction shifted;
      shifted.radius_scale = o.shift_radius_scale;
      shifted.uv_px.reserve(ref.features.size());
      for (const Feature& f : ref.features) shifted.uv_px.push_back(f.uv_px + shift.shift_px);
      MotionAttempt attempt;
      if (!pass(shifted, PredictionSource::kImageShift, &times.match_ms, &times.motion_ms,
                &attempt)) {
        return best;
      }
      if (attempt.inliers() > best.inliers()) {
        best = std::move(attempt);
      } else if (best.inliers() == 0 && attempt.inliers() == 0 && o.few_point_motion &&
                 few_point_tie && T_ref_curr_prior != nullptr) {
        // Neither pass has a RANSAC consensus (too few features: the few-point solver will
        // decide). The prior's pass must not win by default: a prior that lags a turn centres
        // its gates where the features are not and picks up neighbours that agree with it.
        // The pass whose matches support more of the few-point motion is kept.
        Eigen::Isometry3d unused;
        const PriorMotionResult few_best =
            FewPointMotion(best.correspondences, *T_ref_curr_prior, &unused);
        const PriorMotionResult few_shift =
            FewPointMotion(attempt.correspondences, *T_ref_curr_prior, &unused);
        if (few_shift.ok && (!few_best.ok || few_shift.num_inliers > few_best.num_inliers)) {
          best = std::move(attempt);
        }
      }
    }
  }

  // 2b. Still not confident, and the previous frame (the reference) measured its own motion: a
  //     pass around that motion as measured. The prior took a weak motion in only in part, so
  //     where a turn starts it lags (l_hallway, camera pitched 20°, stride 2: 12 px behind at the
  //     radiator whose fins repeat every 12 px, where the image shift, 65 px, was ambiguous too).
  //     Skipped when both predict the same (within a pixel at the image centre).
  if (o.last_motion_pass && !confident(best) && T_ref_curr_prior != nullptr &&
      last_motion_frame_ >= 0 && ref.frame_id == last_motion_frame_ &&
      frame.frame_id == ref.frame_id + 1 &&
      (PredictedCentreShift(camera_, last_motion_, -1.0) -
       PredictedCentreShift(camera_, *T_ref_curr_prior, -1.0))
              .norm() > 1.0) {
    t = Clock::now();
    MatchPrediction measured;
    measured.uv_px = PredictPositions(ref.features, last_motion_);
    measured.radius_scale = o.prior_radius_scale;
    times.predict_ms += MsSince(t);
    MotionAttempt attempt;
    if (!pass(measured, PredictionSource::kLastMotion, &times.match_ms, &times.motion_ms,
              &attempt)) {
      return best;
    }
    if (attempt.inliers() > best.inliers()) best = std::move(attempt);
  }

  // 3. Guided second pass: every reference feature predicted with the estimated motion, matched
  //    in a tight window, so more correct matches reach the bundle adjustment.
  if (o.guided_rematch && best.ransac.ok() && IsFinite(best.ransac.T_prev_curr)) {
    t = Clock::now();
    MatchPrediction guided;
    guided.uv_px = PredictPositions(ref.features, best.ransac.T_prev_curr);
    guided.radius_scale = o.guided_radius_scale;
    guided.coherence_test = false;
    double match_ms = 0.0, motion_ms = 0.0;
    MotionAttempt attempt;
    const bool ok = pass(guided, PredictionSource::kGuided, &match_ms, &motion_ms, &attempt);
    times.guided_ms += MsSince(t);
    if (!ok) return best;
    if (attempt.inliers() >= best.inliers()) best = std::move(attempt);
  }
  return best;
}

bool StereoOdometry::AgreesWithImageShift(const std::vector<Feature>& ref_features,
                                          const Eigen::Isometry3d& T_ref_curr,
                                          const Eigen::Isometry3d& T_ref_curr_prior, bool shift_ok,
                                          const Eigen::Vector2d& shift_px) const {
  if (!shift_ok) return true;
  // The image shift the motions predict at the image centre (the reference's median depth)
  // against the measured one.
  std::vector<double> z;
  for (const Feature& f : ref_features) {
    if (f.has_depth() && f.p_cam0.allFinite()) z.push_back(f.p_cam0.z());
  }
  double depth_m = -1.0;
  if (!z.empty()) {
    std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
    depth_m = z[z.size() / 2];
  }
  const double motion_px = (PredictedCentreShift(camera_, T_ref_curr, depth_m) - shift_px).norm();
  const double prior_px =
      (PredictedCentreShift(camera_, T_ref_curr_prior, depth_m) - shift_px).norm();
  return motion_px <= prior_px + options_.tracking.few_point_max_shift_disagreement_px;
}

double StereoOdometry::PriorUpdateWeight(int num_inliers) const {
  const RobustTrackingOptions& o = options_.tracking;
  return std::pow(std::min(1.0, static_cast<double>(num_inliers) / o.reliable_min_inliers),
                  o.prior_update_exponent);
}

bool StereoOdometry::ChainLostFrame(const MatchFrame& frame, const MotionPrior* prior,
                                    OdometryResult* result, Eigen::Isometry3d* T_world_curr) {
  // A caller's prior (wheel odometry, a gyro) bridges a lost frame as given.
  if (!options_.tracking.chain_lost_frames || prior != nullptr || !lost_chain_.valid ||
      lost_chain_.frame_index >= result->frame_index ||
      options_.matcher.prediction == PredictionMode::kNone ||
      matcher_->type() == MatcherType::kKalman) {
    return false;
  }
  const Eigen::Isometry3d T_chain_curr_prior = T_world_chain_.inverse() * PredictedPose(prior);
  OdometryResult pass;  // the chain's prediction fields are not this frame's against the reference
  std::string matcher_error;
  const MotionAttempt attempt = MatchAndEstimate(
      lost_chain_.frame, frame, IsFinite(T_chain_curr_prior) ? &T_chain_curr_prior : nullptr, &pass,
      &matcher_error, /*few_point_tie=*/false);
  result->times.predict_ms += pass.times.predict_ms;
  result->times.match_ms += pass.times.match_ms;
  result->times.motion_ms += pass.times.motion_ms;
  result->times.guided_ms += pass.times.guided_ms;
  const RansacResult& ransac = attempt.ransac;
  if (!matcher_error.empty() || attempt.inliers() < options_.min_inliers ||
      !IsFinite(ransac.T_prev_curr)) {
    return false;
  }
  *T_world_curr = T_world_chain_ * ransac.T_prev_curr;
  result->chained_to_frame = lost_chain_.frame_index;
  result->chain_inliers = ransac.num_inliers;
  // The measured motion moves the constant velocity as a tracked one does (by its support).
  const Eigen::Isometry3d per_frame =
      Root(ransac.T_prev_curr, result->frame_index - lost_chain_.frame_index);
  MoveVelocity(per_frame, PriorUpdateWeight(ransac.num_inliers));
  return true;
}

void StereoOdometry::MoveVelocity(const Eigen::Isometry3d& per_frame, double weight) {
  if (IsFinite(per_frame) && (weight > 0.0 || !has_velocity_)) {
    velocity_ = has_velocity_ ? Blend(velocity_, per_frame, weight) : per_frame;
    has_velocity_ = true;
  }
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
  RansacResult& ransac = attempt.ransac;
  result.num_matches = static_cast<int>(matches.size());
  result.prediction = attempt.source;

  // No consensus (too few matches, or fewer than min_inliers of them agree), or a frame with
  // fewer than min_features features (matched only for this): the few-point solver with the
  // prior. Such a frame takes no RANSAC motion. (Until 2026-12-03 a frame with min_inliers
  // matches or more but fewer inliers was left lost: texture seed 10, stride 1, frame 204, 11
  // of 13.) So does a ground vehicle's frame whose weak RANSAC motion tilts or lifts it: until
  // 2026-12-04 it was left lost when that motion had min_inliers inliers or more (9 of the 31
  // lost frames of texture seeds 1-10 at stride 1, 12-27 inliers each).
  const RobustTrackingOptions& tracking = options_.tracking;
  const bool few_features = static_cast<int>(frame.features.size()) < options_.min_features;
  bool ransac_failed = few_features || !ransac.ok() || ransac.num_inliers < options_.min_inliers ||
                       !IsFinite(ransac.T_prev_curr);
  // A ground vehicle neither tilts nor lifts: a weak motion that does is a wrong consensus.
  const Eigen::Isometry3d* T_world_ref = window_.Pose(reference_.frame_index);
  const bool not_vehicle_like =
      !ransac_failed && tracking.ground_vehicle && world_up_known_ && T_world_ref != nullptr &&
      ransac.num_inliers < tracking.reliable_min_inliers &&
      !IsVehicleLike(ransac.T_prev_curr, WorldUpInCamera(*T_world_ref),
                     tracking.vehicle_max_weak_tilt_deg, tracking.vehicle_max_weak_lift_m);
  if (not_vehicle_like) ransac_failed = true;
  if (ransac_failed && tracking.few_point_motion && T_ref_curr_prior != nullptr &&
      previous_measured_ && consecutive_lost_ == 0 &&
      options_.matcher.prediction != PredictionMode::kNone && !correspondences.empty() &&
      (few_features || not_vehicle_like || ransac.num_inliers < options_.min_inliers)) {
    Eigen::Isometry3d few_prior;
    const PriorMotionResult few = FewPointMotion(correspondences, *T_ref_curr_prior, &few_prior);
    const bool agrees =
        few.ok && AgreesWithImageShift(ref_features, few.T_prev_curr, few_prior,
                                       result.image_shift_ok, result.image_shift_px);
    if (agrees) {
      ransac.status = RansacResult::Status::kOk;
      ransac.message.clear();
      ransac.T_prev_curr = few.T_prev_curr;
      ransac.inlier_mask = few.inlier_mask;
      ransac.num_inliers = few.num_inliers;
      ransac.rms_reprojection_px = few.rms_reprojection_px;
      result.few_point_motion = true;
      std::ostringstream msg;
      msg << "few-point motion with the prior (" << few.num_inliers << " inliers of "
          << correspondences.size() << " correspondences)";
      result.message = msg.str();
    }
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

  if (!result.few_point_motion && ransac_failed) {
    std::ostringstream why;
    why << "motion failed: "
        << (few_features       ? "too few features for RANSAC, no few-point motion"
            : not_vehicle_like ? "a weak motion tilts or lifts the ground vehicle (more than "
                                 "tracking.vehicle_max_weak_tilt_deg / _lift_m)"
            : ransac.ok()      ? "too few inliers"
                               : ToString(ransac.status))
        << " (" << ransac.num_inliers << " inliers of " << correspondences.size()
        << " correspondences, " << matches.size() << " matches; need " << options_.min_inliers
        << (not_vehicle_like ? ", and tracking.reliable_min_inliers to pass without the check" : "")
        << ")";
    if (!ransac.message.empty()) why << ": " << ransac.message;
    result.times.motion_ms += MsSince(motion_start);
    // The reference cannot measure this frame: the lost frames before it may (the pose and the
    // constant velocity from that chain; BridgedPose takes the pose).
    Eigen::Isometry3d T_world_chained;
    const bool chained = ChainLostFrame(frame, prior, &result, &T_world_chained);
    if (chained) {
      why << "; pose chained to lost frame " << result.chained_to_frame << " ("
          << result.chain_inliers << " inliers)";
    }
    // After a loss, a frame that has plenty of features but cannot be matched to the last good
    // one (even with the coarse-to-fine search) starts again at once: waiting longer would
    // only extrapolate further.
    const bool rich = static_cast<int>(frame.features.size()) >= 2 * options_.min_features;
    if (consecutive_lost_ >= options_.reinit_after_lost_frames || (consecutive_lost_ > 0 && rich)) {
      // The reference is stale: start again from this frame at its predicted (or chained) pose.
      return Initialise(std::move(result), std::move(frame),
                        why.str() + "; re-initialised at the predicted pose", start, prior,
                        chained ? &T_world_chained : nullptr);
    }
    OdometryResult lost =
        Lost(std::move(result), why.str(), start, prior, chained ? &T_world_chained : nullptr);
    if (options_.tracking.chain_lost_frames &&
        static_cast<int>(frame.features.size()) >= options_.min_features) {
      lost_chain_.valid = true;  // the next lost frame is matched against this one
      lost_chain_.frame_index = lost.frame_index;
      lost_chain_.frame = std::move(frame);
      T_world_chain_ = lost.T_world_cam0;
    }
    return lost;
  }

  // Initial pose: blend of the RANSAC/Horn motion and the constant-velocity prediction.
  const int64_t gap = result.frame_index - reference_.frame_index;
  const double inlier_ratio =
      static_cast<double>(ransac.num_inliers) / std::max<size_t>(1, matches.size());
  // (A few-point motion already is the prior's fit to the matches: no second blend.)
  const double w = T_ref_curr_prior != nullptr && !result.few_point_motion
                       ? options_.prior_weight * (1.0 - std::min(1.0, inlier_ratio))
                       : 0.0;
  const Eigen::Isometry3d T_ref_curr_initial = T_ref_curr_prior != nullptr
                                                   ? Blend(ransac.T_prev_curr, *T_ref_curr_prior, w)
                                                   : ransac.T_prev_curr;

  // Tracks from the inlier matches (track ids and ages written into the features), the
  // frame's initial pose into the window.
  if (T_world_ref == nullptr) {  // cannot happen: the reference is the window's newest frame
    result.times.motion_ms += MsSince(motion_start);
    return Lost(std::move(result), "the reference frame has no pose in the window", start, prior);
  }
  Eigen::Isometry3d T_world_curr = *T_world_ref * T_ref_curr_initial;
  const TrackUpdateResult update =
      window_.Add(result.frame_index, &frame.features, inlier_matches, T_world_curr);
  if (!update.ok()) {
    result.times.motion_ms += MsSince(motion_start);
    return Lost(std::move(result), "tracks: " + update.message, start, prior);
  }
  result.times.motion_ms += MsSince(motion_start);
  result.rms_reprojection_px = ransac.rms_reprojection_px;

  // Windowed bundle adjustment, the oldest pose(s) fixed (sliding_window.h).
  const Clock::time_point ba_start = Clock::now();
  const WindowRefinement refinement =
      result.few_point_motion ? WindowRefinement()
                              : window_.Refine(camera_, result.frame_index, WindowPlanarPrior());
  if (refinement.attempted) result.times.ba_ms = MsSince(ba_start);
  const bool ba_rejected = refinement.rejected;
  if (ba_rejected) result.message = refinement.message;
  if (refinement.ran) {
    T_world_curr = *window_.Pose(result.frame_index);
    result.ba_ran = true;
    result.ba_num_frames = refinement.num_frames;
    result.ba_num_points = refinement.num_points;
    result.rms_reprojection_px = refinement.rms_reprojection_px;
  }

  // Constant-velocity model: the (refined) motion from the reference, per frame, blended into
  // the prior by its support, so one weak estimate before a loss is not extrapolated over the
  // gap.
  const Eigen::Isometry3d* T_world_ref_now = window_.Pose(reference_.frame_index);
  const Eigen::Isometry3d T_ref_curr =
      T_world_ref_now != nullptr ? Eigen::Isometry3d(T_world_ref_now->inverse() * T_world_curr)
                                 : T_ref_curr_initial;
  const Eigen::Isometry3d per_frame = Root(T_ref_curr, gap);
  // Weight of this motion in the prior: 1 from reliable_min_inliers inliers up, less below
  // (a weak motion moves the prior only part of the way), 0 when the BA was rejected.
  const double weight = ba_rejected               ? 0.0
                        : result.few_point_motion ? tracking.few_point_prior_update
                                                  : PriorUpdateWeight(ransac.num_inliers);
  MoveVelocity(per_frame, weight);
  if (IsFinite(per_frame) && !ba_rejected) {
    last_motion_ = per_frame;
    last_motion_frame_ = result.frame_index;
  }
  result.motion_measured = true;
  // A reliable measured motion refines the vehicle's up (not a few-point or bundle-adjusted
  // one: both are made planar about the current estimate).
  if (tracking.ground_vehicle && tracking.vehicle_planar_ba && !result.few_point_motion &&
      !ba_rejected && ransac.num_inliers >= tracking.reliable_min_inliers)
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
  lost_chain_.valid = false;
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

  // Disparity: the whole map (dense mode, or the first frame's plane-based orientation), or
  // its pixels prepared for evaluation where the features read them.
  const bool orientation_frame =
      !reference_.valid && !initialised_ && options_.estimate_initial_orientation;
  const bool dense = options_.disparity_mode == DisparityMode::kDense || orientation_frame;
  result.num_disparities =
      scene_num_disparities_ > 0 ? scene_num_disparities_ : options_.disparity.num_disparities;
  Clock::time_point t = Clock::now();
  const DisparityResult disparity =
      dense ? disparity_->Compute(left, right, result.num_disparities)
            : disparity_->PrepareAtPixels(left, right, result.num_disparities);
  result.times.disparity_ms = MsSince(t);
  if (!disparity.ok)
    return Lost(std::move(result), "disparity: " + disparity.message, start, prior);

  // Features in the left image.
  t = Clock::now();
  FeatureSet set = detector_->DetectWithDescriptors(left);
  if (weak_detector_ && static_cast<int>(set.features.size()) < options_.adaptive_min_features) {
    // A weakly textured view: detect again with the lower relative threshold.
    FeatureSet more = weak_detector_->DetectWithDescriptors(left);
    if (more.features.size() > set.features.size()) set = std::move(more);
  }
  result.times.detect_ms = MsSince(t);
  result.num_features = static_cast<int>(set.features.size());

  // Depth from the disparity map; features without depth are dropped (with their descriptors).
  t = Clock::now();
  if (dense) {
    AttachDepth(disparity.disparity_px, camera_, &set.features, options_.depth);
    result.disparity_pixels = camera_.width * camera_.height;
  } else {
    AttachDepth(disparity_.get(), camera_, &set.features, options_.depth);
    const DisparityEstimator::PixelCounts counts = disparity_->pixel_counts();
    result.disparity_pixels = counts.left + counts.right;
    result.times.disparity_ms += MsSince(t);  // the evaluation is the disparity stage's work
    t = Clock::now();
  }
  MatchFrame frame;
  frame.frame_id = result.frame_index;
  std::vector<int> kept;
  for (size_t i = 0; i < set.features.size(); ++i) {
    if (set.features[i].has_depth() && set.features[i].p_cam0.allFinite()) {
      kept.push_back(static_cast<int>(i));
    }
  }
  frame.features.reserve(kept.size());
  for (int i : kept) frame.features.push_back(set.features[i]);
  if (!set.descriptors.empty()) {
    frame.descriptors.create(static_cast<int>(kept.size()), set.descriptors.cols,
                             set.descriptors.type());
    for (size_t k = 0; k < kept.size(); ++k) {
      set.descriptors.row(kept[k]).copyTo(frame.descriptors.row(static_cast<int>(k)));
    }
  }
  result.times.depth_ms = MsSince(t);
  result.num_features_with_depth = static_cast<int>(frame.features.size());
  last_features_ = frame.features;
  // Below min_features a frame is still matched when the few-point solver can use it (a
  // reference, a prior, at least few_point_min_features features).
  const bool few_point_possible =
      options_.tracking.few_point_motion && options_.matcher.prediction != PredictionMode::kNone &&
      reference_.valid && (prior != nullptr || has_velocity_) && previous_measured_ &&
      consecutive_lost_ == 0 &&
      result.num_features_with_depth >= options_.tracking.few_point_min_features;
  if (result.num_features_with_depth < options_.min_features && !few_point_possible) {
    std::ostringstream msg;
    msg << "too few features with depth (" << result.num_features_with_depth << " of "
        << result.num_features << " features; need " << options_.min_features
        << "): black, textureless or unmatched frame";
    return Lost(std::move(result), msg.str(), start, prior);
  }
  frame.image = current_left_;

  if (!reference_.valid) {
    std::string reason;
    if (!initialised_ && options_.estimate_initial_orientation) {
      // Initial orientation from the floor/wall planes of the dense disparity map.
      t = Clock::now();
      std::vector<Eigen::Vector3d> points;
      const int step = options_.orientation_sample_step_px;
      const cv::Mat& d = disparity.disparity_px;
      for (int v = 0; v < d.rows; v += step) {
        const float* row = d.ptr<float>(v);
        for (int u = 0; u < d.cols; u += step) {
          if (!(row[u] > 0.0f)) continue;
          const Eigen::Vector3d p = camera_.Backproject(u, v, row[u]);
          if (p.z() >= options_.depth.min_depth_m && p.z() <= options_.depth.max_depth_m) {
            points.push_back(p);
          }
        }
      }
      result.initial_orientation_ok = EstimateInitialOrientation(points, left, right, d, &result);
      if (!result.initial_orientation_ok) {
        reason = std::string("initial orientation failed (") +
                 ToString(orientation_result_.status) + "): world = first camera frame";
      } else {
        reason = result.floor_refinement_message;
      }
      result.times.orientation_ms = MsSince(t);
    }
    return Initialise(std::move(result), std::move(frame), reason, start, prior);
  }

  // Match against the reference frame (its cues are cached in reference_.frame), with the
  // search predicted from the motion prior (see the header comment).
  const Eigen::Isometry3d* ref_pose = window_.Pose(reference_.frame_index);
  const Eigen::Isometry3d T_world_ref = ref_pose != nullptr ? *ref_pose : T_world_prev_;
  const Eigen::Isometry3d T_ref_curr_prior = T_world_ref.inverse() * PredictedPose(prior);
  const bool has_prior = (prior != nullptr || has_velocity_) && IsFinite(T_ref_curr_prior);
  std::string matcher_error;
  MotionAttempt attempt = MatchAndEstimate(
      reference_.frame, frame, has_prior ? &T_ref_curr_prior : nullptr, &result, &matcher_error);
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
  last_features_.clear();
  last_matches_.clear();
  last_inlier_mask_.clear();
  last_reference_features_.clear();

  // Keep the features with depth; p_cam0 from the camera, track fields reset.
  const Clock::time_point t = Clock::now();
  std::vector<int> index_map(features.size(), -1);  // given index → kept index
  MatchFrame frame;
  frame.frame_id = result.frame_index;
  for (size_t i = 0; i < features.size(); ++i) {
    Feature f = features[i];
    if (!f.uv_px.allFinite() || !std::isfinite(f.disparity_px) || !f.has_depth()) continue;
    f.p_cam0 = camera_.Backproject(f.uv_px.x(), f.uv_px.y(), f.disparity_px);
    if (!f.p_cam0.allFinite()) continue;
    f.track_id = -1;
    f.track_age = 0;
    index_map[i] = static_cast<int>(frame.features.size());
    frame.features.push_back(f);
  }
  result.times.depth_ms = MsSince(t);
  result.num_features_with_depth = static_cast<int>(frame.features.size());
  last_features_ = frame.features;

  // The matches refer to the previous call's features; usable only when that call became the
  // reference. Re-index, skipping dropped or out-of-range features and repeated indices.
  const bool prev_is_reference = reference_.valid &&
                                 reference_.frame_index == result.frame_index - 1 &&
                                 !prev_call_index_map_.empty();
  std::vector<Match> matches;
  if (prev_is_reference) {
    std::vector<bool> prev_used(reference_.frame.features.size(), false);
    std::vector<bool> curr_used(frame.features.size(), false);
    for (const Match& m : matches_to_prev) {
      if (m.prev < 0 || m.prev >= static_cast<int>(prev_call_index_map_.size()) || m.curr < 0 ||
          m.curr >= static_cast<int>(index_map.size())) {
        continue;
      }
      const int p = prev_call_index_map_[m.prev];
      const int c = index_map[m.curr];
      if (p < 0 || c < 0 || prev_used[p] || curr_used[c]) continue;
      prev_used[p] = curr_used[c] = true;
      matches.push_back(Match{p, c, m.score});
    }
    std::sort(matches.begin(), matches.end(),
              [](const Match& a, const Match& b) { return a.prev < b.prev; });
  }
  prev_call_index_map_.clear();

  const bool few_point_possible =
      options_.tracking.few_point_motion && options_.matcher.prediction != PredictionMode::kNone &&
      prev_is_reference && has_velocity_ && previous_measured_ &&
      result.num_features_with_depth >= options_.tracking.few_point_min_features;
  if (result.num_features_with_depth < options_.min_features && !few_point_possible) {
    std::ostringstream msg;
    msg << "too few features with depth (" << result.num_features_with_depth << " of "
        << result.num_features << "; need " << options_.min_features << ")";
    return Lost(std::move(result), msg.str(), start);
  }
  prev_call_index_map_ = index_map;
  if (!prev_is_reference) {
    std::string reason;
    if (!initialised_ && options_.estimate_initial_orientation) {
      const Clock::time_point to = Clock::now();
      std::vector<Eigen::Vector3d> points;
      for (const Feature& f : frame.features) points.push_back(f.p_cam0);
      result.initial_orientation_ok =
          EstimateInitialOrientation(points, cv::Mat(), cv::Mat(), cv::Mat(), &result);
      if (!result.initial_orientation_ok) {
        reason = std::string("initial orientation failed (") +
                 ToString(orientation_result_.status) + "): world = first camera frame";
      } else {
        reason = result.floor_refinement_message;
      }
      result.times.orientation_ms = MsSince(to);
    } else if (initialised_) {
      reason =
          "the previous frame was lost, its matches cannot be used: re-initialised at the "
          "predicted pose";
    }
    return Initialise(std::move(result), std::move(frame), reason, start);
  }
  // The constant-velocity prediction from the reference (the previous call) to this frame.
  const Eigen::Isometry3d T_ref_curr_prior = velocity_;
  MotionAttempt attempt =
      EstimateMotion(reference_.frame.features, frame.features, matches, PredictionSource::kNone);
  result.num_first_pass_inliers = attempt.inliers();
  return Track(std::move(result), std::move(frame), std::move(attempt),
               has_velocity_ ? &T_ref_curr_prior : nullptr, nullptr, start);
}

}  // namespace vo
