// The initial orientation: the first frame's floor and wall planes (plane_orientation.h, paper
// section V) give the hallway frame the world is expressed in (x along the corridor, y left,
// z up, origin at the first camera centre). The points come from the first frame's dense
// disparity map (SampleDisparityPoints) or the seam's features; the floor (without one, the
// ceiling) is then refined on the images themselves (RefineInitialFloor, plane_refinement.h:
// the block matcher's map at a grazing floor is biased), and without floor or ceiling the up
// may come from the camera's mounting (up_from_mounting). The result also gives the σ the
// vehicle's up starts from (back_end.vehicle_planar). Its options are InitialOrientationOptions
// (the `initial_orientation` group of vo_options.yaml).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/plane_orientation.h"
#include "vo/plane_refinement.h"

namespace vo {

// The initial orientation's options (vo_options.yaml `initial_orientation`, key for key).
struct InitialOrientationOptions {
  bool enabled = true;             // hallway frame from the first frame's planes
                                   // (floor/walls); false = world is the first camera
  PlaneOrientationOptions planes;  // plane extraction for the initial orientation
  int sample_step_px = 4;  // the first frame's dense disparity map is sampled every this many
                           // pixels (both axes) for the plane extraction (pixels), >= 1.
                           // ProcessFeatures uses the features' 3D
  // The first frame's floor (when the plane extraction found one) refined on the images
  // themselves (plane_refinement.h) over the dense map's pixels on the geometric fit: the up and
  // the camera's height then come from it (the yaw stays the walls'). The block matcher's map
  // at a grazing floor is biased: the fit's pitch was off by +0.2..+0.8° on l_hallway texture
  // seeds 1-10 and +1.5° on plain_corridor. Needs the dense map (the first frame of Process;
  // ProcessFeatures has none and skips it).
  bool refine_floor = true;
  PlaneRefinementOptions floor_refinement;
  bool requires_wall = false;  // true: kNoWall (up known, yaw not) also counts as a failure
                               // (world = first camera); false: the yaw is then the camera's
                               // heading (zero)
  // When the first frame's planes give no up (neither floor nor ceiling: kNoFloor, e.g. a plain
  // floor without disparity and no ceiling in view), take planes.expected_up_cam0 as the up —
  // the camera's mounting on a vehicle standing on a level floor — and the camera's heading as
  // the yaw (as with kNoWall), instead of the first camera as the world, which leaves a ground
  // vehicle without its up (no planar motion, no planar BA prior). Off by default; on for a
  // ground vehicle whose rig's pitch is known (ResolvePlatform, which then also sets
  // expected_up_cam0 from that pitch). Measured on plain_corridor texture seeds 3 and 5 at
  // stride 1 (no floor or ceiling found in the first frame): end rotation error 5.1 / 13.9° ->
  // 2.2 / 2.7°, end-pose error 6.9 / 7.0 % -> 4.4 / 5.6 %.
  bool up_from_mounting = false;

  // planes and floor_refinement are checked when they are used (enabled, refine_floor).
  bool IsValid(std::string* error) const;
};

struct InitialOrientation {
  bool ok = false;  // the orientation defines the world frame (else: world = first camera)
  PlaneOrientationResult planes;  // the plane extraction (R_hall_cam0 refined when it was)
  Eigen::Matrix3d R_hall_cam0 = Eigen::Matrix3d::Identity();  // identity when not ok
  bool floor_refined = false;  // the floor (or the ceiling) was refined on the images
  std::string message;         // what the refinement did or why not, or where the up came from;
                               // empty when neither was tried
  double up_sigma_rad = 0.0;   // when ok: σ of the up as evidence of the vehicle's up (the
                               // refined floor's is smaller than the geometric fit's or a
                               // refined ceiling's)
};

// Plane-based orientation of the first frame from its 3D points (camera frame). With the
// images and the dense disparity map (empty for the seam) and refine_floor,
// the floor is refined photometrically.
InitialOrientation EstimateInitialOrientation(const StereoCamera& camera,
                                              const InitialOrientationOptions& options,
                                              const std::vector<Eigen::Vector3d>& points_cam0,
                                              const cv::Mat& left, const cv::Mat& right,
                                              const cv::Mat& disparity_px);

// Refines the floor of *planes (without one, its ceiling) on the images over the dense map's
// pixels on the geometric fit (within the plane extraction's inlier distance) and rebuilds its
// up, camera height and R_hall_cam0 from it (the yaw stays the walls'); false (unchanged) when
// refusing. *message says what it did or why not.
bool RefineInitialFloor(const StereoCamera& camera, const InitialOrientationOptions& options,
                        const cv::Mat& left, const cv::Mat& right, const cv::Mat& disparity_px,
                        PlaneOrientationResult* planes, std::string* message);

// The 3D points of a dense disparity map (CV_32F, > 0 valid) sampled every step_px pixels on
// both axes, those with min_depth_m <= z <= max_depth_m.
std::vector<Eigen::Vector3d> SampleDisparityPoints(const StereoCamera& camera,
                                                   const cv::Mat& disparity_px, int step_px,
                                                   double min_depth_m, double max_depth_m);

}  // namespace vo
