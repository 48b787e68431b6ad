// Levenberg-Marquardt with an explicit Schur complement for the windowed stereo bundle
// adjustment: the backend BaSolver::kSchurLm of bundle_adjustment.h. It solves the problem the
// Ceres backend solves — same residuals, robust loss, parametrisation, trust-region control and
// stopping rules (those of Ceres 2.1 with the options bundle_adjustment.cc sets) — without
// Ceres' per-call problem set-up and its block-size-generic Schur elimination, which at the
// pipeline's size (4 free poses, ~100 points, ~400 observations) cost ~0.35 ms per call plus
// ~0.27 ms per iteration.
//
// Problem. Pose blocks are 7 doubles [qx qy qz qw tx ty tz] of T_world_cam0 (unit quaternion
// q_world_cam0 in Eigen's order, t_world_cam0 in metres), each free or held constant. Points
// are p_world (metres); every point a residual refers to is free. One residual block per
// observation: [u_l, v_l, u_r, v_r] − observed (pixels) for a stereo one, [u_l, v_l] − observed
// for a left-only one, with p_cam0 = R_world_cam0ᵀ (p_world − t_world_cam0) (eq. (8) of
// docs/PAPER.md, both cameras). Cost = ½ Σ ρ(s), s = the block's squared norm, ρ the robust loss.
//
// Tangent space (ceres::EigenQuaternionManifold × EuclideanManifold<3>): a pose moves by
// δ = [δθ, δt] as q ← [cos|δθ|, sin|δθ| δθ/|δθ|] ⊗ q (a rotation by 2|δθ| applied on the
// world side) and t ← t + δt; a point by p ← p + δp. Hence, with v = p_world − t_world_cam0,
//   ∂p_cam0/∂δθ = 2 Rᵀ [v]×,  ∂p_cam0/∂δt = −Rᵀ,  ∂p_cam0/∂p_world = Rᵀ.
//
// Iteration (Ceres' TrustRegionMinimizer with LevenbergMarquardtStrategy, default settings):
//  - robust loss by iteratively reweighted least squares: each block's residual and Jacobian
//    scaled by √ρ'(s) (Ceres' Corrector, which adds no curvature term where ρ'' <= 0, i.e.
//    always for Huber and Cauchy; Triggs et al. 2000, "Bundle adjustment — a modern
//    synthesis", sec. 4.3);
//  - step: Ceres solves (J_sᵀJ_s + D_s/μ) y = J_sᵀr, step = −y, for the Jacobi-scaled J_s =
//    J diag(s), s = 1 / (1 + column norm of the first Jacobian), D_s = diag(J_sᵀJ_s) clamped to
//    [1e-6, 1e32] (recomputed after an accepted step only), μ the trust-region radius
//    (initially 1e4), δ = s ⊙ step. This solver solves the same system in the unscaled
//    unknowns, (JᵀJ + D_s/(s² μ)) x = Jᵀr, δ = −x: points eliminated first (3×3 blocks), the
//    reduced camera system (6 per free pose) by dense Cholesky, the points back-substituted
//    (Triggs et al. 2000, sec. 6.1). It uses the Jacobian's structure: with A = ∂r/∂p_world,
//    ∂r/∂[δθ δt] = A [2[v]×, −I], so every normal-equation block follows from AᵀA (3×3) and Aᵀr;
//  - step quality q = (cost − new cost) / model decrease; accepted when q > 1e-3, then
//    μ ← min(1e16, μ / max(1/3, 1 − (2q − 1)³)) and ν ← 2, else μ ← μ / ν and ν ← 2ν
//    (Nielsen 1999, "Damping parameter in Marquardt's method", IMM-REP-1999-05);
//  - converged: |cost change| <= function_tolerance · cost, or (after the first accepted step)
//    the ambient step norm <= parameter_tolerance · (‖x‖ + parameter_tolerance), or the
//    max-norm of x − Plus(x, −gradient) <= gradient_tolerance, or μ <= 1e-32; not converged:
//    max_num_iterations reached; failed: 5 consecutive invalid steps (Cholesky failure or no
//    model decrease) or a non-finite Jacobian. A step to a point with a depth (z in cam0)
//    <= 1e-9 counts as a step of infinite cost.
// The two backends differ by rounding only: on the 1133 window problems of three rendered
// hallway runs they took the same iterations, flagged the same outliers and agreed to 2e-14 m
// and 2e-14 rad in every pose and 1e-12 m in every point.
//
// Single-threaded, no data-dependent memory order: the same input gives the same output bit
// for bit.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "vo/bundle_adjustment.h"
#include "vo/camera.h"

namespace vo {

// One observation of point `point` from pose `pose`.
struct SchurLmResidual {
  int pose = -1;                                          // index into the pose blocks
  int point = -1;                                         // index into the points
  Eigen::Vector2d uv_left_px = Eigen::Vector2d::Zero();   // left image (pixels)
  bool has_right = false;                                 // right observation present
  Eigen::Vector2d uv_right_px = Eigen::Vector2d::Zero();  // right image (pixels), if has_right
};

struct SchurLmSummary {
  enum class Termination {
    kConvergence,    // a tolerance was met
    kNoConvergence,  // max_num_iterations reached; the result is usable
    kFailure,        // see message; the parameters hold the last accepted values
  };
  Termination termination = Termination::kFailure;
  std::string message;             // why it stopped
  double initial_cost = 0.0;       // ½ Σ ρ(s) at the start (pixels², robustified)
  double final_cost = 0.0;         // the same at the returned parameters
  int num_successful_steps = 0;    // accepted steps, the start counted as one (as Ceres does)
  int num_unsuccessful_steps = 0;  // rejected and invalid steps

  bool usable() const { return termination != Termination::kFailure; }
};

using PoseBlock7 = std::array<double, 7>;  // [qx qy qz qw tx ty tz] of T_world_cam0

// Minimises the cost over the free poses (pose_is_free[i], among those a residual refers to)
// and the points residuals refer to; the others are left untouched. Uses max_num_iterations,
// the three tolerances, loss and loss_scale_px of `options` (its other fields are Ceres' or
// the caller's). The start must be evaluable (every depth > 1e-9), else kFailure. Indices
// must be in range and the sizes consistent (programmer errors: abort). `planar_links` (pose
// pairs, both referred to by a residual) add a PlanarMotionResidual of `planar` each
// (planar_motion_prior.h; plain squares, its Jacobian from ceres::Jet and the manifold's Plus
// Jacobian, as the Ceres backend's AutoDiffCostFunction): they enter the cost, the gradient,
// the Jacobi scaling and the reduced camera system (a pose–pose block couples the two poses).
// `rotation_priors` (frame_a, frame_b index the pose blocks, both referred to by a residual)
// add a RotationPriorResidual each (rotation_prior.h), the same way.
SchurLmSummary SolveSchurLm(const StereoCamera& cam, const BundleAdjustmentOptions& options,
                            const std::vector<SchurLmResidual>& residuals,
                            const std::vector<bool>& pose_is_free, std::vector<PoseBlock7>* poses,
                            std::vector<Eigen::Vector3d>* points,
                            const std::vector<std::pair<int, int>>& planar_links = {},
                            const PlanarMotionPrior& planar = PlanarMotionPrior(),
                            const std::vector<RotationPrior>& rotation_priors = {});

// One residual block and its Jacobians, unweighted: r = [u_l, v_l, u_r, v_r] − observed (rows
// 2, 3 and their Jacobian rows zero for a left-only observation), J_pose w.r.t. the pose's
// tangent [δθ δt] (see the header comment), J_point w.r.t. p_world. R_cam0_world = R_world_cam0ᵀ.
// False (outputs unspecified) when the depth z in cam0 is <= 1e-9. Jacobians may be null.
bool StereoResidualAndJacobians(const StereoCamera& cam, const Eigen::Matrix3d& R_cam0_world,
                                const Eigen::Vector3d& t_world_cam0, const Eigen::Vector3d& p_world,
                                const SchurLmResidual& obs, Eigen::Vector4d* r,
                                Eigen::Matrix<double, 4, 6>* J_pose,
                                Eigen::Matrix<double, 4, 3>* J_point);

}  // namespace vo
