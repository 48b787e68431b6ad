#include "vo/odometry_options.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "vo/options_check.h"

namespace vo {

OdometryOptions EffectiveOdometryOptions(const StereoCamera& camera,
                                         const OdometryOptions& options) {
  OdometryOptions effective = ResolvePlatform(options, -1.0);  // no rig known here
  if (options.front_end.derive_num_disparities) {
    effective.front_end.disparity.num_disparities =
        DerivedNumDisparities(camera, options.front_end);
  }
  effective.motion.ransac.min_inliers =
      std::max(options.motion.ransac.min_inliers, options.motion.min_inliers);
  if (options.back_end.bundle_adjustment && !options.motion.ransac_refine_with_ba) {
    effective.motion.ransac.refine_nonlinear = false;
  }
  return effective;
}

bool OdometryOptions::IsValid(std::string* error) const {
  if (!PartIsValid(front_end, "front_end", error) ||
      !PartIsValid(initial_orientation, "initial_orientation", error) ||
      !PartIsValid(tracker, "tracker", error) || !PartIsValid(motion, "motion", error) ||
      !PartIsValid(recovery, "recovery", error) || !PartIsValid(back_end, "back_end", error) ||
      !PartIsValid(imu, "imu", error)) {
    return false;
  }
  std::ostringstream msg;
  if (tracker.matcher.type == MatcherType::kSiftRatio &&
      front_end.detector.type != DetectorType::kSift) {
    msg << "matcher sift_ratio needs descriptors: detector.type must be kSift";
  }
  return NoBrokenRule(msg, error);
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
    o.motion.few_point_motion = true;
    o.motion.ground_vehicle = true;
    o.back_end.vehicle_planar.enabled = true;
    o.back_end.flat_floor.enabled = true;
  }
  if (o.motion.ground_vehicle && o.motion.few_point.axle_behind_camera_m == 0.0 &&
      rig_axle_behind_camera_m >= 0.0)
    o.motion.few_point.axle_behind_camera_m = rig_axle_behind_camera_m;
  if (o.platform == Platform::kGroundVehicle && std::isfinite(rig_pitch_deg)) {
    o.initial_orientation.up_from_mounting = true;
    if (o.initial_orientation.planes.expected_up_cam0 ==
        PlaneOrientationOptions().expected_up_cam0) {
      const double p = rig_pitch_deg * M_PI / 180.0;
      // (0 − sin p: a level camera writes 0, not −0, into vo_options.yaml)
      o.initial_orientation.planes.expected_up_cam0 =
          Eigen::Vector3d(0.0, -std::cos(p), 0.0 - std::sin(p));
    }
  }
  return o;
}

}  // namespace vo
