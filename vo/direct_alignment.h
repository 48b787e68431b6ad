// A ground vehicle's motion measured by aligning two images directly (photometrically), for the
// frames that have too few features for any matcher: a robot turning in front of a plain wall.
//
// l_hallway texture seed 3, stride 1, frames 209-229: the view is the end wall, 1-14 features
// with depth a frame (too few for RANSAC and, after the first loss, for the few-point solver),
// yet the images hold the lower edge of a picture frame, a poster's corner, shadows, a socket and
// a few specks. The feature-based bridge (bridge_alignment.h) needs three features paired per
// frame; the prior carried the braking robot's cruise step (18 mm a frame for -2) and 0.6 deg a
// frame too much yaw through the gap. Every pixel with a gradient says something, though, once
// its depth is known: on a wall, the plane through the last features with depth gives it.
//
// The model. The previous left image's pixels x with a gradient lie on the scene's planes
// n·X = d (previous camera frame, |n| = 1, d > 0; the planes of the features, FitScenePlanes: a
// wall, the floor; carried through the frames with too few features by their motion); a pixel's
// point X(x) is where its ray meets the nearest of them (the surface seen from inside a convex
// room: a hallway's floor, walls and end wall). The vehicle's motion
// T = VehicleMotion(up, axle, yaw, forward) (prior_motion.h: a yaw about up and a forward step of
// the axle, no sideways slip) moves X into the current camera, where the current image should
// show the same grey level:
//     r(x) = I_curr(π(T⁻¹ · X(x))) − I_prev(x).
// (yaw, forward) minimise Σ ρ(r) by Gauss-Newton, coarse to fine on an image pyramid (pyrDown),
// from the caller's start (the bridged motion): Huber's ρ on every level (its scale from the
// residuals' median absolute deviation at the start), then on the finest level Tukey's biweight,
// so the pixels that lie on no fitted plane (an object in front of the wall) have no weight. This
// is a direct method (as in LSD-SLAM or DSO; here two parameters and a few planes) beyond the
// paper, which has no answer for a view without features.
//
// Whether the result is a measurement: it converged on the finest level, at least min_pixels
// pixels took part, the Gauss-Newton covariance (the robust residual variance times the inverse
// information) gives σ(yaw) <= max_yaw_sigma_deg and σ(forward) <= max_forward_sigma_m, and the
// result moved no further than max_yaw_change_deg / max_forward_change_m from the start (a
// wrong basin of a repeating texture). Deterministic; O(iterations · pixels).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/tracks.h"

namespace vo {

struct DirectAlignmentOptions {
  int pyramid_levels = 3;              // coarse-to-fine levels (1 = full resolution only), 1..6
  double min_gradient = 4.0;           // a pixel takes part when its grey-level gradient
                                       // (central differences, lightly smoothed) is at least
                                       // this (grey levels per pixel of its level), > 0
  int max_pixels = 6000;               // at most this many pixels per level (evenly thinned), > 0
  int max_iterations = 30;             // Gauss-Newton iterations per level, >= 1
  double huber_k = 1.345;              // Huber threshold in robust σ of the residuals, > 0
  double tukey_k = 4.685;              // the finest level is then refined with Tukey's
                                       // biweight at this many robust σ, >= 0 (0: Huber only)
  int min_pixels = 200;                // finest level: fewer pixels in view: no measurement, >= 1
  double max_yaw_sigma_deg = 0.05;     // finest level's σ(yaw) above this: no measurement, > 0
  double max_forward_sigma_m = 0.002;  // finest level's σ(forward) above this: none, > 0
  double max_yaw_change_deg = 3.0;     // a result further than this from the start: none, > 0
  double max_forward_change_m = 0.05;  // the same for the forward step (metres), > 0
  double min_depth_m = 0.1;            // pixels whose depth on the planes is outside [min, max]
  double max_depth_m = 20.0;           // are not used (metres), 0 < min < max

  bool IsValid(std::string* error) const;
};

// A plane n·X = d in a camera frame (|n| = 1, d > 0: the camera is on the side n points away
// from).
struct ScenePlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double distance_m = 0.0;
  int inliers = 0;  // features on it when fitted
};

struct DirectAlignmentResult {
  bool ok = false;       // a measurement (see the header comment)
  double yaw_rad = 0.0;  // the result (the start when not ok)
  double forward_m = 0.0;
  int pixels = 0;               // finest level's pixels in view
  int iterations = 0;           // over all levels
  double residual_sigma = 0.0;  // finest level's robust σ of the residuals (grey levels)
  double yaw_sigma_rad = 0.0;   // finest level's Gauss-Newton σ
  double forward_sigma_m = 0.0;
  std::string message;  // why not ok
};

// (yaw, forward) of the vehicle motion T_prev_curr = VehicleMotion(up_prev, axle_behind_camera_m,
// yaw, forward) that aligns `curr` with `prev` (8-bit grey left images of the same size as the
// camera's), the previous image's pixels on `planes` (previous camera frame), starting at
// (yaw0_rad, forward0_m). yaw_prior_sigma_rad > 0: yaw0_rad is a measurement of the yaw with
// this σ (a gyro's, gyro_prior.h), a prior term (yaw − yaw0)² / σ² beside the grey levels (in
// their units: times the level's robust residual variance), in the fit and its covariance.
DirectAlignmentResult AlignVehicleDirect(const StereoCamera& camera, const cv::Mat& prev,
                                         const cv::Mat& curr, const std::vector<ScenePlane>& planes,
                                         const Eigen::Vector3d& up_prev,
                                         double axle_behind_camera_m, double yaw0_rad,
                                         double forward0_m, const DirectAlignmentOptions& options,
                                         double yaw_prior_sigma_rad = 0.0);

// The same alignment for a 6-DoF motion (the free platform: a handheld rig, a drone, any
// sequence without a vehicle model), issue #35, with a gyro: T_prev_curr = [R_gyro | t], the
// rotation the start's (the gyro's, gyro_prior.h, of σ rotation_prior_sigma_rad > 0) and the
// translation t measured from the images (from the start's), with the same residuals, robust
// weights, pyramid and planes: the rotation from the gyro, the translation from the images.
// The residual also carries α, the log of the current image's gain over the previous image's
// (r = I_curr − e^α · I_prev, measured with t; log_gain): a camera's gain changes from frame to
// frame, and in front of a wall with one edge a wrong step explained a brighter image better
// than the true one (l_hallway texture seed 3, frame 212: 5 cm off with σ 1.3 mm without α).
// Two other forms were tried and are not offered. A prior term on the rotation (as the
// vehicle's yaw prior): the grey levels of thousands of pixels outweigh a gyro's σ of 0.05°
// by orders of magnitude, and planes that are not quite the scene's then turned the estimate
// 0.1-0.2° a frame away from a gyro that is right to 0.01° (l_hallway texture seed 3, frames
// 209-214). No gyro, all six parameters from the images: in front of one plane with a few
// marks a sideways step and a turn look alike, and the fit was confidently wrong (a 10 mm step
// read as 2.8 mm up). Without a gyro rotation (σ <= 0) the result is no measurement.
// The options are read for the translation: max_forward_sigma_m bounds its σ along its worst
// axis, max_forward_change_m its change |t − t_start| (the yaw bounds are not used).
// standing_start: a second alignment starts from the translation 0 (standing still); where
// both are measurements, the one whose grey levels fit better (the finest level's robust cost
// on the pixels in view of both, with one threshold) is the result. A robot that brakes in
// front of the wall leaves a constant velocity's start behind, outside the basin.
struct FreeDirectAlignmentResult {
  bool ok = false;  // a measurement (as AlignVehicleDirect's)
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();  // the start when not ok
  int pixels = 0;
  int iterations = 0;
  double residual_sigma = 0.0;
  double rotation_sigma_rad = 0.0;   // the gyro's σ (the rotation is its)
  double translation_sigma_m = 0.0;  // finest level's Gauss-Newton σ along the worst axis
  bool from_standing = false;        // the result of the second start (standing still)
  double log_gain = 0.0;             // α: the current image's gain over the previous's, e^α
  std::string message;               // why not ok
};

FreeDirectAlignmentResult AlignFreeDirect(const StereoCamera& camera, const cv::Mat& prev,
                                          const cv::Mat& curr,
                                          const std::vector<ScenePlane>& planes,
                                          const Eigen::Isometry3d& T_prev_curr0,
                                          const DirectAlignmentOptions& options,
                                          double rotation_prior_sigma_rad,
                                          bool standing_start = true);

// The plane that most features with depth lie on (camera frame): a feature is on it when its
// disparity is within tolerance_px of the plane's at its pixel. Deterministic RANSAC over
// triples, refined by least squares on the inliers. False when fewer than min_inliers features
// (>= 3) or fewer than min_fraction of them lie on the best plane, or when the inliers are all
// near one line (the plane would turn about it freely: their second principal spread below
// min_spread_m).
bool FitDominantPlane(const StereoCamera& camera, const std::vector<Feature>& features,
                      double tolerance_px, int min_inliers, double min_fraction,
                      double min_spread_m, ScenePlane* plane);

// Up to max_planes planes of the features, one after the other (FitDominantPlane's test on
// the features no earlier plane took): a hallway's floor, walls and end wall. False (planes
// unchanged) when none is found or fewer than min_fraction of the features lie on them.
bool FitScenePlanes(const StereoCamera& camera, const std::vector<Feature>& features,
                    double tolerance_px, int min_inliers, double min_fraction, double min_spread_m,
                    int max_planes, std::vector<ScenePlane>* planes);

// The plane of frame a (n·X_a = d) in frame b, for p_a = T_a_b · p_b.
ScenePlane TransformPlane(const ScenePlane& plane_a, const Eigen::Isometry3d& T_a_b);

}  // namespace vo
