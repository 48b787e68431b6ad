// A lost frame's ground-vehicle motion measured against the previous frame's features without
// matching them: what a turn in front of a plain wall leaves (1–14 features a frame, too few for
// the matchers and RANSAC; l_hallway texture seed 3: the top edge of the end wall, at one depth,
// and a few corners that move 9–12 px a frame). The prior (the constant velocity, its rotation
// corrected by the image shift) carries the cruise speed into a robot that brakes and turns in
// place, and reads the shift of off-centre texture as too much yaw; both then run on through the
// gap. Two measurements correct it (odometry.h, "Ground vehicle"):
//
// 1. The forward step from the depth change. Each current feature q is moved into the previous
//    image by the prior's motion T_prev_curr (p_prev = T · q) and paired with the nearest previous
//    feature within gate_px (no descriptor: on a fronto-parallel wall every feature has the same
//    depth, so even a neighbour along the same edge is the right depth). A pair says
//        t_z = z(previous feature) − z(R · q),
//    with σ = disparity_sigma_px / (f·b) · sqrt(z_prev⁴ + z_curr⁴) (the disparity's depth noise
//    of both points). Pairs more than 3σ from the median are dropped; the rest are fused with the
//    prior's t_z (σ step_sigma_m) by inverse variance, so far points (a long corridor, σ of
//    decimetres) leave the prior as it was and near ones (a wall at 1 m, σ ~3 mm) decide.
// 2. The yaw by aligning the features. The yaw of VehicleMotion(up, axle, yaw, forward) (a
//    wheeled vehicle's motion: prior_motion.h) is refined by Gauss-Newton so that the previous
//    features with depth, moved into the current image, land on their nearest current features
//    (gate_px; Huber weights at 1 px; pairs found again each iteration). The camera's swing about
//    the axle is part of the model, so a near wall's flow is not all read as yaw.
//
// Both need at least min_pairs pairs, else they report no measurement. Deterministic; O(n·m) for
// n and m features.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/tracks.h"

namespace vo {

struct BridgeAlignmentOptions {
  double gate_px = 6.0;             // a feature pairs with its nearest neighbour within this
                                    // distance (pixels), > 0
  int min_pairs = 3;                // fewer pairs than this: no measurement, >= 1
  double disparity_sigma_px = 0.3;  // σ of a feature's disparity (pixels), > 0
  double step_sigma_m = 0.01;       // σ of the prior's forward step (metres), > 0

  bool IsValid(std::string* error) const;
};

// The forward step t_z of T_prev_curr (p_prev = T_prev_curr · p_curr, cam0 frames) from the
// depth change of paired features (1. above), fused with T_prev_curr's own t_z. False (outputs
// unchanged) with fewer than min_pairs pairs, invalid options or camera.
bool ForwardStepFromDepth(const StereoCamera& camera, const std::vector<Feature>& prev,
                          const std::vector<Feature>& curr, const Eigen::Isometry3d& T_prev_curr,
                          const BridgeAlignmentOptions& options, double* t_z, int* pairs);

// The yaw (radians) of VehicleMotion(up, axle_behind_camera_m, yaw, forward_m) that aligns the
// previous frame's features with the current frame's (2. above), starting at *yaw_rad. False
// (outputs unchanged) with fewer than min_pairs pairs in any iteration, a non-finite result,
// invalid options or camera.
bool AlignVehicleYaw(const StereoCamera& camera, const std::vector<Feature>& prev,
                     const std::vector<Feature>& curr, const Eigen::Vector3d& up,
                     double axle_behind_camera_m, double forward_m,
                     const BridgeAlignmentOptions& options, double* yaw_rad, int* pairs);

}  // namespace vo
