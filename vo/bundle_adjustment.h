// Windowed sparse bundle adjustment of a stereo head. Kwolek, docs/PAPER.md
// "refinement", section V: minimise the squared reprojection error, eq. (8),
//   min over poses P_i and points X_j of  Σ_i Σ_j d(P_i X_j, x_ij)²,
// over the last few frames (paper: 3–5, 10 wished for), pose as quaternion + translation
// (7 parameters). For a stereo head eq. (8) projects every point into BOTH the left and the
// right camera (cam1 = cam0 + baseline along x, camera.h).
//
// Parametrisation. Each frame i has ONE 7-double parameter block holding T_world_cam0 (the
// camera's pose in the world, p_world = T_world_cam0 * p_cam0): [qx qy qz qw tx ty tz], the
// unit quaternion q_world_cam0 in Eigen's order (x, y, z, w) and t_world_cam0 (metres), on
// ceres::ProductManifold<EigenQuaternionManifold, EuclideanManifold<3>> (6 tangent
// dimensions). Each point j has a 3-double block p_world (metres). A point is projected as
// p_cam0 = R_world_cam0ᵀ (p_world − t_world_cam0).
//
// Residuals. One residual block per observation (frame i, point j): 4 residuals
// [u_l, v_l, u_r, v_r] − observed (pixels) for a stereo observation, 2 for a left-only one,
// through a robust loss (Huber or Cauchy, scale loss_scale_px) applied to the whole block,
// so a stereo observation is down-weighted as one. Derivatives analytic (hand-derived, see
// bundle_adjustment.cc and schur_lm.h), or, for the Ceres backend, by
// ceres::AutoDiffCostFunction (analytic_jacobians = false).
//
// Ground vehicle (optional, BundleAdjustmentProblem::planar): residuals between consecutive
// poses that keep the camera's motion that of a wheeled vehicle on a floor (no roll or pitch
// change, no lift, no sideways slip of the axle; planar_motion_prior.h), without a robust
// loss. Both backends evaluate the same templated residual.
//
// Gyro (optional, BundleAdjustmentProblem::rotation_priors): residuals between two poses that
// hold their relative rotation to a gyro's (rotation_prior.h), without a robust loss. Both
// backends evaluate the same templated residual. None by default: the result is then bit for
// bit what it was without them.
//
// Gauge. The num_fixed_poses oldest poses (default 1: the oldest of the window) are held
// constant (Problem::SetParameterBlockConstant); the stereo baseline fixes the scale.
//
// Solver. Levenberg-Marquardt with the Schur complement (points eliminated first, the reduced
// camera system solved for the free poses), num_threads = 1 so the result is deterministic.
// Two backends (BundleAdjustmentOptions::solver) minimise the same cost from the same start
// with the same trust-region rules and stopping tests:
//  - kSchurLm (default): schur_lm.h, hand-written for this problem (fixed-size 3×3 point and
//    6×6 pose blocks built from each observation's 3×3 AᵀA, dense Cholesky of the reduced
//    system, no per-call set-up). At the pipeline's size (5 frames, <= 100 points, ~400
//    observations, ~8 iterations) it takes ~0.35 ms where Ceres takes ~2 ms: Ceres' fixed
//    cost (problem construction, preprocessing, first evaluation) is ~0.35 ms per call and its
//    block-size-generic Schur elimination and evaluation ~0.27 ms per iteration there.
//  - kCeres: the reference, ceres::Solve with ordering group 0 = points, group 1 = poses;
//    SPARSE_SCHUR when Ceres was built with a sparse library (Debian's Ceres 2.1 has
//    SuiteSparse and Eigen sparse), else DENSE_SCHUR (linear_solver). The two agree to
//    rounding (tests/vo/bundle_adjustment_test.cc).
//
// Points seen in a single frame are kept by default (min_frames_per_point = 1): one stereo
// observation gives 4 residuals for the point's 3 unknowns, so the point is well posed, but it
// carries no information about the poses (its cost is one small block of the Schur
// elimination). Set min_frames_per_point = 2 to leave such points out.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/planar_motion_prior.h"
#include "vo/tracks.h"

namespace vo {

enum class RobustLoss {
  kNone,    // plain squared error
  kHuber,   // ceres::HuberLoss: quadratic up to the scale, linear beyond
  kCauchy,  // ceres::CauchyLoss: log(1 + s/scale²), stronger down-weighting of outliers
};

enum class BaSolver {
  kCeres,    // ceres::Solve (the reference; linear_solver and analytic_jacobians apply)
  kSchurLm,  // hand-written Levenberg-Marquardt with an explicit Schur complement (schur_lm.h)
};

enum class BaLinearSolver {
  kAuto,         // SPARSE_SCHUR when a sparse library is available, else DENSE_SCHUR
  kSparseSchur,  // ceres SPARSE_SCHUR (SuiteSparse, else Eigen sparse); kInvalidInput if none
  kDenseSchur,   // ceres DENSE_SCHUR
};

const char* ToString(RobustLoss loss);
const char* ToString(BaLinearSolver solver);
const char* ToString(BaSolver solver);

struct BundleAdjustmentOptions {
  int max_num_iterations = 20;           // Levenberg-Marquardt iteration limit, >= 1
  double function_tolerance = 1e-6;      // stop when the relative cost change is below (>= 0)
  double gradient_tolerance = 1e-10;     // stop when the max-norm of the gradient is below (>= 0)
  double parameter_tolerance = 1e-8;     // stop when the relative step is below (>= 0)
  RobustLoss loss = RobustLoss::kHuber;  // robust loss on each observation's residual block
  double loss_scale_px = 1.0;         // scale of the robust loss (pixels, residual-block norm), > 0
  double outlier_threshold_px = 3.0;  // after the solve, an observation whose left or right
                                      // reprojection error exceeds this (pixels) is flagged
                                      // as an outlier, > 0
  int num_fixed_poses = 1;            // the first (oldest) poses held constant, >= 1 (gauge)
  int min_frames_per_point = 1;       // points observed in fewer frames are left out (returned
                                      // unchanged, not optimised), >= 1
  BaSolver solver = BaSolver::kSchurLm;  // backend, see BaSolver and the header comment
  BaLinearSolver linear_solver = BaLinearSolver::kAuto;  // kCeres only: see BaLinearSolver
  bool analytic_jacobians = true;  // kCeres only: hand-derived Jacobians of the residuals
                                   // (faster); false = ceres::AutoDiffCostFunction (the
                                   // reference; same values)
  // Observations whose initial depth (z in cam0) is below this (metres) are left out and
  // flagged as outliers: a numerical guard, not a setting (it was the key ba.min_depth_m).
  static constexpr double kMinDepthM = 1e-3;

  bool IsValid(std::string* error) const;
};

// One image observation of point `point_index` in frame `frame_index`.
struct BaObservation {
  int frame_index = -1;  // index into BundleAdjustmentProblem::T_world_cam0
  int point_index = -1;  // index into BundleAdjustmentProblem::points_world
  Eigen::Vector2d uv_left_px = Eigen::Vector2d::Zero();   // left image (pixels)
  bool has_right = false;                                 // right observation present
  Eigen::Vector2d uv_right_px = Eigen::Vector2d::Zero();  // right image (pixels), if has_right
};

// A relative-rotation prior between two poses (rotation_prior.h): the rotation of camera
// frame_b in camera frame_a measured by a gyro, R_a_b = R_world_aᵀ R_world_b ideally.
struct RotationPrior {
  int frame_a = -1;                                     // index into T_world_cam0
  int frame_b = -1;                                     // index into T_world_cam0, != frame_a
  Eigen::Matrix3d R_a_b = Eigen::Matrix3d::Identity();  // rotation of b in a (camera frames)
  double sigma_rad = 1.0;                               // σ about any axis (radians), > 0
};

// Initial values and measurements. Frames are ordered oldest first; the first
// num_fixed_poses frames are held constant.
struct BundleAdjustmentProblem {
  std::vector<Eigen::Isometry3d> T_world_cam0;  // per frame: p_world = T_world_cam0 * p_cam0
  std::vector<Eigen::Vector3d> points_world;    // per point (metres, world frame)
  std::vector<BaObservation> observations;
  // A ground vehicle's motion prior (planar_motion_prior.h), off by default: when enabled, one
  // 4-residual block links each pose that takes part to the previous one that does (in this
  // order), unless both are held constant.
  PlanarMotionPrior planar;
  // Relative-rotation priors (a gyro's), may be empty: one 3-residual block each, unless a
  // pose of it has no observation used or both are held constant.
  std::vector<RotationPrior> rotation_priors;
};

struct BundleAdjustmentSummary {
  enum class Status {
    kOk,            // the solver returned a usable solution (converged or hit the limit)
    kInvalidInput,  // bad options or camera, indices out of range, non-finite numbers, fewer
                    // poses than num_fixed_poses, no usable observation, no sparse library
    kSolverFailed,  // the backend reported a failure; the outputs hold the initial values
  };
  Status status = Status::kInvalidInput;
  std::string message;        // empty when kOk; the backend's message otherwise
  bool converged = false;     // a tolerance was met (Ceres: CONVERGENCE), not the iteration limit
  double initial_cost = 0.0;  // cost ½ Σ ρ(|r|²) at the start (pixels², robustified)
  double final_cost = 0.0;    // the same at the end
  double rms_reprojection_before_px = 0.0;        // sqrt(Σ|e|² / #image observations) over the
                                                  // observations used, left and right counted
                                                  // separately, plain (not robustified), initial
  double rms_reprojection_after_px = 0.0;         // the same for the refined values
  double rms_inlier_reprojection_after_px = 0.0;  // the same over non-outlier observations
  int num_iterations = 0;       // Levenberg-Marquardt iterations (successful + unsuccessful;
                                // the start counts as one successful, as in Ceres)
  int num_residual_blocks = 0;  // observations in the problem
  int num_planar_links = 0;     // planar motion prior blocks in the problem
  int num_rotation_priors = 0;  // relative-rotation prior blocks in the problem
  int num_points_optimized = 0;
  std::string linear_solver;  // linear solver used: Ceres', e.g. "SPARSE_SCHUR (SUITE_SPARSE)",
                              // or "SCHUR_LM (dense Cholesky)"
  std::vector<Eigen::Isometry3d> T_world_cam0;  // refined poses (the fixed ones are copied
                                                // from the input bit for bit)
  std::vector<Eigen::Vector3d> points_world;    // refined points (left-out ones unchanged)
  std::vector<bool> point_optimized;            // per point: was in the problem
  std::vector<bool> observation_is_outlier;     // per observation: left out, or a final left or
                                                // right error above outlier_threshold_px
  int num_outliers = 0;

  bool ok() const { return status == Status::kOk; }
};

const char* ToString(BundleAdjustmentSummary::Status status);

// Refines poses and points (see the header comment). Never throws.
BundleAdjustmentSummary RunBundleAdjustment(
    const StereoCamera& cam, const BundleAdjustmentProblem& problem,
    const BundleAdjustmentOptions& options = BundleAdjustmentOptions());

// Builds the window problem from a TrackManager: frames = the window's frames that have an
// entry in T_world_cam0_by_frame (oldest first), points = tracks with at least one
// observation with depth in those frames; each point starts at the observation with the
// largest disparity (the most precise depth) mapped to the world. Observations with depth are
// stereo (right = (u − d, v)), those without are left-only. frame_ids / track_ids (optional)
// receive the frame id of each pose and the track id of each point.
BundleAdjustmentProblem MakeWindowProblem(
    const TrackManager& tracks, const std::map<int64_t, Eigen::Isometry3d>& T_world_cam0_by_frame,
    std::vector<int64_t>* frame_ids = nullptr, std::vector<int64_t>* track_ids = nullptr);

}  // namespace vo
