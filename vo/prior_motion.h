// Frame-to-frame motion from FEW stereo correspondences and a motion prior: what the pipeline
// does when RANSAC has too few matches for a consensus (a plain wall in front of the camera:
// 2–12 features), instead of calling the frame lost and extrapolating the prior.
//
// Model (maximum a posteriori, Gaussian): the motion is the prior moved by a small correction,
//   T_prev_curr = T_prior · [Exp(ω) | v],   ω, v ∈ R³ (rotation vector, radians; metres),
// and it minimises
//   Σ_inliers |e_left|² / σ_px² + e_right,u² / σ_px²  +  |ω|² / σ_rot²  +  |v|² / σ_t²,
// e = the stereo reprojection errors of p_prev in the current left and right images (as in the
// RANSAC inlier test, ransac.h). With many points the data decide; with one or two the bearing
// fixes the rotation (pan and tilt), and what the points cannot tell apart (roll about a single
// bearing, translation against rotation for points at one depth) comes from the prior.
//
// Hypotheses (deterministic, exhaustive, no random sampling): the prior itself, and for every
// correspondence i the prior's translation with the smallest rotation correction that puts
// p_prev(i) exactly on its observed bearing (a 1-point rotation solver). Each is scored by its
// inliers (left and right errors <= inlier_threshold_px; ties: the smaller sum of squared
// errors, then the lower index). The best one's inliers are refined (Gauss-Newton on (ω, v),
// numeric Jacobians), re-classified, and refined once more.
//
// Ground vehicle (up_curr given): the motion is planar, and the 1-point hypotheses are rotations
// about up. With no_sideways_slip (the default) it is a wheeled vehicle's VehicleMotion: a yaw
// and a forward distance, both regularised towards the prior's (σ_rot, σ_t); otherwise the
// prior corrected by a yaw and a translation across up (3 parameters). A wheeled robot neither
// rolls nor pitches nor lifts off the floor by itself, and the few points left in front of a plain
// wall cannot tell those motions from yaw and sideways translation: unconstrained, the fit turns
// part of a turn into roll and pitch (measured on l_hallway texture seed 2: 18° of roll after the
// end wall). Nor can they tell a yaw from a sideways step: a free fit slid the camera 3.4 cm
// sideways per frame where it moved 1.2 cm and under-stated the turn by 40 % (seed 2, stride 2); a
// wheel does not slide.
//
// Cost: O(n²) reprojections for n correspondences (n is small where it is used: RANSAC failed)
// plus a few 6×6 solves. Deterministic: the same input gives bit-identical output.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/ransac.h"

namespace vo {

struct PriorMotionOptions {
  int min_inliers = 2;                      // fewer inliers than this: not ok, >= 1
  double min_inlier_fraction = 0.5;         // and fewer than this fraction of the
                                            // correspondences: not ok, in [0, 1] (two points
                                            // that agree among five matches are more likely a
                                            // coincidence of wrong matches than the motion)
  double inlier_threshold_px = 2.0;         // max reprojection error (pixels) in EACH of the
                                            // current left and right images, > 0
  double measurement_sigma_px = 1.0;        // σ_px of the image observations (pixels), > 0
  double prior_rotation_sigma_deg = 2.0;    // σ_rot of the prior's rotation (degrees), > 0
  double prior_translation_sigma_m = 0.01;  // σ_t of the prior's translation (metres), > 0
  int max_iterations = 10;                  // Gauss-Newton iterations per refinement, >= 1
  // Transformed points closer than this (z, metres) are outliers: a numerical guard, not a
  // setting (it was the key tracking.few_point.min_depth_m).
  static constexpr double kMinDepthM = 1e-3;
  bool no_sideways_slip = true;       // with an up direction (ground vehicle): the vehicle's wheels
                                      // do not slide sideways, the motion is a yaw and a forward
                                      // distance (VehicleMotion, 2 parameters) instead of a yaw and
                                      // a free translation across up (3); false = the latter
  double axle_behind_camera_m = 0.0;  // where the vehicle turns: its axle's distance behind
                                      // the camera along the horizontal forward axis (metres,
                                      // finite); 0 = the camera above the axle. The rig's
                                      // calibration, not a tuning knob; vobench's simulated
                                      // runs and tune put the rig's camera.forward_m here when
                                      // ground_vehicle is on and this is left at 0
                                      // (vo::ResolvePlatform)

  bool IsValid(std::string* error) const;
};

struct PriorMotionResult {
  bool ok = false;      // at least min_inliers inliers support T_prev_curr
  std::string message;  // why not ok (empty when ok)
  Eigen::Isometry3d T_prev_curr = Eigen::Isometry3d::Identity();  // p_prev = T * p_curr (cam0);
                                                                  // the prior when not ok
  std::vector<bool> inlier_mask;                                  // one per correspondence
  int num_inliers = 0;
  double rms_reprojection_px = 0.0;  // sqrt(mean over inliers and both images of |e|²) (pixels)
};

// T_prev_curr from `correspondences` (any number, 0 allowed) and the prior T_prev_curr_prior
// (see the header comment). up_curr (optional): the world's up direction in the current
// camera frame (any length > 0); given, the correction is planar (see "Ground vehicle").
// Invalid options or camera, a non-finite prior or up: not ok.
PriorMotionResult EstimateMotionWithPrior(const StereoCamera& camera,
                                          const std::vector<StereoCorrespondence>& correspondences,
                                          const Eigen::Isometry3d& T_prev_curr_prior,
                                          const PriorMotionOptions& options = PriorMotionOptions(),
                                          const Eigen::Vector3d* up_curr = nullptr);

// A wheeled ground vehicle's camera motion p_prev = T · p_curr (camera frames): a yaw yaw_rad
// about `up` (the world's up in the camera frame, any length > 0) and forward_m of travel of
// the axle point, axle_behind_camera_m behind the camera on its horizontal forward axis, along
// the chord of the turn (the heading at half the yaw): a unicycle without sideways slip.
Eigen::Isometry3d VehicleMotion(const Eigen::Vector3d& up, double axle_behind_camera_m,
                                double yaw_rad, double forward_m);
// The (yaw_rad, forward_m) of VehicleMotion closest to T: the twist of T's rotation about up,
// and the axle's step projected on the chord's direction. Exact for a VehicleMotion.
Eigen::Vector2d VehicleMotionParameters(const Eigen::Isometry3d& T, const Eigen::Vector3d& up,
                                        double axle_behind_camera_m);

// The planar part of a motion T_a_b (p_a = T_a_b · p_b) of a ground vehicle whose up direction
// in frame a is up_a (any length > 0): the rotation's twist about up (its swing, roll and
// pitch, removed) and the translation without its component along up. A motion that is
// already planar comes back unchanged; a non-finite input or up comes back as it is.
Eigen::Isometry3d PlanarPart(const Eigen::Isometry3d& T_a_b, const Eigen::Vector3d& up_a);

}  // namespace vo
