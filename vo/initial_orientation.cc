#include "vo/initial_orientation.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "vo/options_check.h"
#include "vo/plane_refinement.h"

namespace vo {
namespace {

// The vehicle's up in the camera frame (back_end.vehicle_planar): σ of the first frame's
// floor fit as evidence of it. Texture seed 7's floor fit is 0.77° off; the reliable tracked
// motions move it over tens of frames (seed 7: 0.77° -> 0.35° off; odometry.cc).
constexpr double kVehicleUpPriorSigmaDeg = 1.0;
// ... when the floor was refined on the images (orientation_floor_refinement): its pitch error
// on l_hallway texture seeds 1-10 was within 0.17° (rms 0.10°). With 1° the reliable motions
// that refine the up carry its slow pitch drift into it (texture seed 5, stride 1: 1.2° off by
// the end, and the flat floor with it).
constexpr double kVehicleUpRefinedFloorSigmaDeg = 0.15;

}  // namespace

bool InitialOrientationOptions::IsValid(std::string* error) const {
  if (enabled && (!PartIsValid(planes, "planes", error) ||
                  (refine_floor && !PartIsValid(floor_refinement, "floor_refinement", error)))) {
    return false;
  }
  if (sample_step_px < 1) {
    if (error) *error = "sample_step_px must be >= 1, got " + std::to_string(sample_step_px);
    return false;
  }
  return true;
}

bool RefineInitialFloor(const StereoCamera& camera, const InitialOrientationOptions& options,
                        const cv::Mat& left, const cv::Mat& right, const cv::Mat& disparity_px,
                        PlaneOrientationResult* planes, std::string* message) {
  PlaneOrientationResult& o = *planes;
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
      const Eigen::Vector3d p = camera.Backproject(u, v, row[u]);
      if (std::abs(floor.normal_cam0.dot(p) + floor.offset_m) <=
          PlaneInlierDistance(p, options.planes)) {
        pixels.emplace_back(u, v);
      }
    }
  }
  const PlaneRefinementResult refined =
      RefinePlanePhotometric(left, right, camera, floor, pixels, options.floor_refinement);
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

InitialOrientation EstimateInitialOrientation(const StereoCamera& camera,
                                              const InitialOrientationOptions& options,
                                              const std::vector<Eigen::Vector3d>& points_cam0,
                                              const cv::Mat& left, const cv::Mat& right,
                                              const cv::Mat& disparity_px) {
  InitialOrientation out;
  PlaneOrientationResult& planes = out.planes;
  planes = EstimateHallwayOrientation(points_cam0, options.planes);
  if (options.refine_floor && !disparity_px.empty() &&
      (planes.floor_index >= 0 || planes.ceiling_index >= 0) &&
      (planes.ok() || planes.status == PlaneOrientationResult::Status::kNoWall)) {
    out.floor_refined =
        RefineInitialFloor(camera, options, left, right, disparity_px, &planes, &out.message);
  }
  bool ok = planes.ok() ||
            (planes.status == PlaneOrientationResult::Status::kNoWall && !options.requires_wall);
  if (!ok && options.up_from_mounting &&
      planes.status == PlaneOrientationResult::Status::kNoFloor) {
    // The mounting's up; x_hall the camera's forward axis made horizontal (zero yaw).
    const Eigen::Vector3d up = options.planes.expected_up_cam0.normalized();
    Eigen::Vector3d x_hall, y_hall;
    HorizontalBasis(up, &x_hall, &y_hall);
    planes.R_hall_cam0.row(0) = x_hall.transpose();
    planes.R_hall_cam0.row(1) = y_hall.transpose();
    planes.R_hall_cam0.row(2) = up.transpose();
    planes.up_cam0 = up;
    out.message =
        "no floor or ceiling in the first frame: the up from the camera's mounting "
        "(orientation.expected_up_cam0)";
    ok = x_hall.allFinite();
  }
  out.ok = ok;
  out.R_hall_cam0 = ok ? planes.R_hall_cam0 : Eigen::Matrix3d::Identity();
  if (ok) {
    // A refined ceiling is not as good (plain_corridor: 1.05° off): the floor's σ only for a
    // floor.
    const double sigma_deg = out.floor_refined && planes.floor_index >= 0
                                 ? kVehicleUpRefinedFloorSigmaDeg
                                 : kVehicleUpPriorSigmaDeg;
    out.up_sigma_rad = sigma_deg * M_PI / 180.0;
  }
  return out;
}

std::vector<Eigen::Vector3d> SampleDisparityPoints(const StereoCamera& camera,
                                                   const cv::Mat& disparity_px, int step_px,
                                                   double min_depth_m, double max_depth_m) {
  std::vector<Eigen::Vector3d> points;
  const cv::Mat& d = disparity_px;
  for (int v = 0; v < d.rows; v += step_px) {
    const float* row = d.ptr<float>(v);
    for (int u = 0; u < d.cols; u += step_px) {
      if (!(row[u] > 0.0f)) continue;
      const Eigen::Vector3d p = camera.Backproject(u, v, row[u]);
      if (p.z() >= min_depth_m && p.z() <= max_depth_m) points.push_back(p);
    }
  }
  return points;
}

}  // namespace vo
