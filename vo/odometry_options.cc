#include "vo/odometry_options.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace vo {
namespace {

// Prefixes the failing part's message with its name.
bool FailPart(const char* part, const std::string& part_error, std::string* error) {
  if (error) *error = std::string(part) + ": " + part_error;
  return false;
}

bool Fail(const std::ostringstream& msg, std::string* error) {
  if (error) *error = msg.str();
  return false;
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

}  // namespace

OdometryOptions EffectiveOdometryOptions(const StereoCamera& camera,
                                         const OdometryOptions& options) {
  OdometryOptions effective = ResolvePlatform(options, -1.0);  // no rig known here
  if (options.derive_num_disparities) {
    effective.disparity.num_disparities = DerivedNumDisparities(camera, options);
  }
  effective.ransac.min_inliers = std::max(options.ransac.min_inliers, options.min_inliers);
  if (options.back_end.bundle_adjustment && !options.ransac_refine_with_ba) {
    effective.ransac.refine_nonlinear = false;
  }
  return effective;
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
  if (!tracking.IsValid(&part_error)) return FailPart("tracking", part_error, error);
  if (!back_end.IsValid(&part_error)) return FailPart("back_end", part_error, error);
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
    o.back_end.vehicle_planar.enabled = true;
    o.back_end.flat_floor.enabled = true;
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

}  // namespace vo
