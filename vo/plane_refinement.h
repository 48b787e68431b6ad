// Direct (photometric) refinement of a plane seen by the rectified stereo pair: the floor's
// normal and height read off the images themselves, not off the block matcher's disparities.
//
// Why: the first frame's floor fit (plane_orientation.h) fits a plane to the block matcher's
// disparity map. A 9×9 window that assumes a fronto-parallel patch, on a floor seen at a grazing
// angle (a level camera 1 m up sees the floor from 1.9 m on), is biased: on l_hallway the fit's
// pitch is off by +0.2…+0.8° on texture seeds 1–10 and by +1.5° on plain_corridor, and that is
// what the vehicle's up (and a flat floor) starts from. Aligning the images on the plane itself
// takes the slant into account exactly.
//
// Model. On a plane n·p + o = 0 (cam0, n unit, o > 0 the camera's distance; plane_orientation.h's
// Plane) the disparity of a left pixel (u, v) is exactly affine:
//     d(u, v) = a·(u − cx) + b·(v − cy) + c,   a = −B·m_x,  b = −(fx/fy)·B·m_y,  c = −fx·B·m_z,
// with m = n / o and B the baseline (from p = z·((u−cx)/fx, (v−cy)/fy, 1) and d = fx·B / z). The
// three coefficients are estimated by Gauss-Newton on the photometric residual over the plane's
// pixels (given by the caller, e.g. those whose block-matching disparity lies on the geometric
// fit):
//     r(u, v) = (1 + g)·R(u − d(u, v), v) + β − L(u, v),
// with R sampled bilinearly and its horizontal gradient by central differences, and a gain g and
// bias β for the two cameras' exposure (5 unknowns). Iteratively reweighted with the robust σ
// (1.4826·median |r − median r|, at least min_sigma_grey): Huber weights for the first
// huber_iterations (the start may be off by a degree: every residual is large), then Tukey's
// biweight, so pixels that do not lie on the plane (a wall that covers part of the region, an
// object on the floor) stop counting, and pixels whose neighbourhood fits the plane much worse
// than the region's median are left out (a wall's texture seen through the plane's disparity is
// wrong over a whole patch, noise is not): a side wall over 30 % of the region tilted the result
// by 0.7° with Huber alone, 0.3° with Tukey's weights, 0.005° with the neighbourhoods. Stops when a
// Tukey update moves no pixel's disparity by more than converged_px. Deterministic; O(pixels) per
// iteration.
//
// Measured in the odometry's first frame (orientation_floor_refinement; pixels: the dense map's
// on the geometric fit): pitch error against the ground truth on l_hallway texture seeds 1–10
// −0.05…+0.17° (the block matcher's fit: −0.36…+0.82°); README, "Robust tracking".
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/plane_orientation.h"

namespace vo {

struct PlaneRefinementOptions {
  int max_iterations = 30;            // Gauss-Newton iterations at most, >= 1
  double converged_px = 1e-3;         // stop when no pixel's disparity moves more (pixels), > 0
  int huber_iterations = 3;           // the first iterations weigh by Huber, in [0, max_iterations)
  double huber_sigmas = 2.0;          // Huber threshold in robust σ of the residual, > 0
  double tukey_sigmas = 4.685;        // later ones by Tukey's biweight, zero beyond this many
                                      // robust σ (95 % efficiency on Gaussian noise), > 0
  int region_radius_px = 3;           // Tukey phase: a pixel whose (2·radius+1)² neighbourhood in
  double region_outlier_ratio = 2.0;  // the region has a mean |r| above this many times the
                                      // region's median of it is left out; radius in [1, 50],
                                      // ratio > 1
  double min_sigma_grey = 0.5;  // floor of the robust σ (grey levels; a noiseless render), > 0
  int min_pixels = 200;         // fewer usable pixels (disparity > 0, inside the right image)
                                // in any iteration: no result, >= 5
  double max_tilt_change_deg = 5.0;  // a refined normal further than this from the initial one,
                                     // or a distance changed by more than max_offset_change of
                                     // it, is rejected (the alignment slid off the plane), > 0
  double max_offset_change = 0.2;    // (fraction of the initial distance), > 0

  bool IsValid(std::string* error) const;
};

struct PlaneRefinementResult {
  bool ok = false;
  std::string message;  // why not, when !ok
  Plane plane;          // the refined plane (kind copied from the initial one)
  Eigen::Vector3d disparity_coefficients = Eigen::Vector3d::Zero();  // (a, b, c) above
  double gain = 0.0;                                                 // g above
  double bias = 0.0;                                                 // β above (grey levels)
  double residual_sigma = 0;  // robust σ of the last iteration's residual (grey levels)
  int pixels = 0;             // pixels used in the last iteration
  int iterations = 0;
};

// (a, b, c) of the affine disparity of `plane` (header comment). Needs offset_m > 0.
Eigen::Vector3d PlaneDisparityCoefficients(const StereoCamera& camera, const Plane& plane);
// The plane of disparity coefficients (a, b, c) (normal towards the camera, offset > 0); false
// when they describe no plane in front of the camera (all zero or non-finite).
bool PlaneFromDisparityCoefficients(const StereoCamera& camera, const Eigen::Vector3d& abc,
                                    Plane* plane);

// Refines `initial` on the rectified 8-bit grey images (CV_8UC1, the camera's size) over the
// left-image `pixels`. Never throws; !ok with a message on invalid input, too few pixels, a
// diverged or implausible result.
PlaneRefinementResult RefinePlanePhotometric(const cv::Mat& left, const cv::Mat& right,
                                             const StereoCamera& camera, const Plane& initial,
                                             const std::vector<cv::Point>& pixels,
                                             const PlaneRefinementOptions& options = {});

}  // namespace vo
