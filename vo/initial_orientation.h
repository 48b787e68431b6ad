// The initial orientation: the first frame's floor and wall planes (plane_orientation.h, paper
// section V) give the hallway frame the world is expressed in (x along the corridor, y left,
// z up, origin at the first camera centre). The points come from the first frame's dense
// disparity map (SampleDisparityPoints) or the seam's features; the floor (without one, the
// ceiling) is then refined on the images themselves (RefineInitialFloor, plane_refinement.h:
// the block matcher's map at a grazing floor is biased), and without floor or ceiling the up
// may come from the camera's mounting (orientation_up_from_mounting). The result also gives
// the σ the vehicle's up starts from (tracking.vehicle_planar_ba).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/odometry_options.h"
#include "vo/plane_orientation.h"

namespace vo {

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
// images and the dense disparity map (empty for the seam) and orientation_floor_refinement,
// the floor is refined photometrically.
InitialOrientation EstimateInitialOrientation(const StereoCamera& camera,
                                              const OdometryOptions& options,
                                              const std::vector<Eigen::Vector3d>& points_cam0,
                                              const cv::Mat& left, const cv::Mat& right,
                                              const cv::Mat& disparity_px);

// Refines the floor of *planes (without one, its ceiling) on the images over the dense map's
// pixels on the geometric fit (within the plane extraction's inlier distance) and rebuilds its
// up, camera height and R_hall_cam0 from it (the yaw stays the walls'); false (unchanged) when
// refusing. *message says what it did or why not.
bool RefineInitialFloor(const StereoCamera& camera, const OdometryOptions& options,
                        const cv::Mat& left, const cv::Mat& right, const cv::Mat& disparity_px,
                        PlaneOrientationResult* planes, std::string* message);

// The 3D points of a dense disparity map (CV_32F, > 0 valid) sampled every step_px pixels on
// both axes, those with min_depth_m <= z <= max_depth_m.
std::vector<Eigen::Vector3d> SampleDisparityPoints(const StereoCamera& camera,
                                                   const cv::Mat& disparity_px, int step_px,
                                                   double min_depth_m, double max_depth_m);

}  // namespace vo
