#include "vo/bundle_adjustment.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <sstream>
#include <utility>

#include "vo/rotation_prior.h"
#include "vo/schur_lm.h"

namespace vo {

const char* ToString(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kNone:
      return "none";
    case RobustLoss::kHuber:
      return "huber";
    case RobustLoss::kCauchy:
      return "cauchy";
  }
  return "unknown";
}

const char* ToString(BaLinearSolver solver) {
  switch (solver) {
    case BaLinearSolver::kAuto:
      return "auto";
    case BaLinearSolver::kSparseSchur:
      return "sparse_schur";
    case BaLinearSolver::kDenseSchur:
      return "dense_schur";
  }
  return "unknown";
}

const char* ToString(BaSolver solver) {
  switch (solver) {
    case BaSolver::kCeres:
      return "ceres";
    case BaSolver::kSchurLm:
      return "schur_lm";
  }
  return "unknown";
}

const char* ToString(BundleAdjustmentSummary::Status status) {
  switch (status) {
    case BundleAdjustmentSummary::Status::kOk:
      return "ok";
    case BundleAdjustmentSummary::Status::kInvalidInput:
      return "invalid_input";
    case BundleAdjustmentSummary::Status::kSolverFailed:
      return "solver_failed";
  }
  return "unknown";
}

bool BundleAdjustmentOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (max_num_iterations < 1)
    msg << "max_num_iterations must be >= 1, got " << max_num_iterations;
  else if (!(function_tolerance >= 0.0))
    msg << "function_tolerance must be >= 0, got " << function_tolerance;
  else if (!(gradient_tolerance >= 0.0))
    msg << "gradient_tolerance must be >= 0, got " << gradient_tolerance;
  else if (!(parameter_tolerance >= 0.0))
    msg << "parameter_tolerance must be >= 0, got " << parameter_tolerance;
  else if (!(loss_scale_px > 0.0) || !std::isfinite(loss_scale_px))
    msg << "loss_scale_px must be finite and > 0, got " << loss_scale_px;
  else if (!(outlier_threshold_px > 0.0))
    msg << "outlier_threshold_px must be > 0, got " << outlier_threshold_px;
  else if (num_fixed_poses < 1)
    msg << "num_fixed_poses must be >= 1 (it fixes the gauge), got " << num_fixed_poses;
  else if (min_frames_per_point < 1)
    msg << "min_frames_per_point must be >= 1, got " << min_frames_per_point;
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

namespace {

using PoseBlock = PoseBlock7;  // [qx qy qz qw tx ty tz] of T_world_cam0
using PoseManifold =
    ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>;

PoseBlock ToBlock(const Eigen::Isometry3d& T_world_cam0) {
  Eigen::Quaterniond q(T_world_cam0.linear());
  q.normalize();
  const Eigen::Vector3d& t = T_world_cam0.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

Eigen::Isometry3d FromBlock(const PoseBlock& b) {
  const Eigen::Quaterniond q(b[3], b[0], b[1], b[2]);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(b[4], b[5], b[6]);
  return T;
}

// p_cam0 = R_world_cam0ᵀ (p_world − t_world_cam0), from a pose block.
template <typename T>
Eigen::Matrix<T, 3, 1> WorldToCam0(const T* pose, const T* point) {
  const Eigen::Map<const Eigen::Quaternion<T>> q_world_cam0(pose);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_world_cam0(pose + 4);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_world(point);
  return q_world_cam0.conjugate() * (p_world - t_world_cam0);
}

struct Intrinsics {
  double fx, fy, cx, cy, b;
  explicit Intrinsics(const StereoCamera& cam)
      : fx(cam.fx_px), fy(cam.fy_px), cx(cam.cx_px), cy(cam.cy_px), b(cam.baseline_m) {}
};

// eq. (8), stereo observation: left and right reprojection errors (4 residuals, pixels).
struct StereoCost {
  StereoCost(const Intrinsics& k, const Eigen::Vector2d& uv_l, const Eigen::Vector2d& uv_r)
      : k(k), uv_l(uv_l), uv_r(uv_r) {}
  template <typename T>
  bool operator()(const T* pose, const T* point, T* r) const {
    const Eigen::Matrix<T, 3, 1> p = WorldToCam0(pose, point);
    if (!(p.z() > T(1e-9))) return false;
    const T inv_z = T(1.0) / p.z();
    const T v = T(k.fy) * p.y() * inv_z + T(k.cy);
    r[0] = T(k.fx) * p.x() * inv_z + T(k.cx) - T(uv_l.x());
    r[1] = v - T(uv_l.y());
    r[2] = T(k.fx) * (p.x() - T(k.b)) * inv_z + T(k.cx) - T(uv_r.x());
    r[3] = v - T(uv_r.y());
    return true;
  }
  Intrinsics k;
  Eigen::Vector2d uv_l, uv_r;
};

// eq. (8), left-only observation (2 residuals, pixels).
struct MonoCost {
  MonoCost(const Intrinsics& k, const Eigen::Vector2d& uv_l) : k(k), uv_l(uv_l) {}
  template <typename T>
  bool operator()(const T* pose, const T* point, T* r) const {
    const Eigen::Matrix<T, 3, 1> p = WorldToCam0(pose, point);
    if (!(p.z() > T(1e-9))) return false;
    const T inv_z = T(1.0) / p.z();
    r[0] = T(k.fx) * p.x() * inv_z + T(k.cx) - T(uv_l.x());
    r[1] = T(k.fy) * p.y() * inv_z + T(k.cy) - T(uv_l.y());
    return true;
  }
  Intrinsics k;
  Eigen::Vector2d uv_l;
};

// The same residuals with analytic Jacobians (the default; autodiff is kept as the reference,
// BundleAdjustmentOptions::analytic_jacobians = false). p = q* (P − t) with Eigen's formula for
// a unit quaternion q = (w, u): p = v − 2w (u × v) + 2 u × (u × v), v = P − t, so
//   ∂p/∂w = −2 (u × v),  ∂p/∂u = 2w [v]× + 2 ((u·v) I + u vᵀ − 2 v uᵀ),
//   ∂p/∂v = I − 2w [u]× + 2 (u uᵀ − |u|² I)  (= Rᵀ for a unit q),  ∂p/∂P = ∂p/∂v = −∂p/∂t.
// These are the derivatives of exactly what the autodiff functors compute (tests compare them).
struct CameraPointJacobian {
  Eigen::Vector3d p;                     // point in cam0
  Eigen::Matrix<double, 3, 7> dp_dpose;  // columns: qx qy qz qw tx ty tz
  Eigen::Matrix3d dp_dpoint;
};

inline Eigen::Matrix3d Skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

void WorldToCam0WithJacobian(const double* pose, const double* point, CameraPointJacobian* j) {
  const Eigen::Vector3d u(pose[0], pose[1], pose[2]);
  const double w = pose[3];
  const Eigen::Vector3d v =
      Eigen::Vector3d(point[0], point[1], point[2]) - Eigen::Vector3d(pose[4], pose[5], pose[6]);
  const Eigen::Vector3d uxv = u.cross(v);
  j->p = v - 2.0 * w * uxv + 2.0 * u.cross(uxv);
  j->dp_dpose.block<3, 3>(0, 0) =
      2.0 * w * Skew(v) +
      2.0 * (u.dot(v) * Eigen::Matrix3d::Identity() + u * v.transpose() - 2.0 * v * u.transpose());
  j->dp_dpose.col(3) = -2.0 * uxv;
  j->dp_dpoint = Eigen::Matrix3d::Identity() - 2.0 * w * Skew(u) +
                 2.0 * (u * u.transpose() - u.squaredNorm() * Eigen::Matrix3d::Identity());
  j->dp_dpose.block<3, 3>(0, 4) = -j->dp_dpoint;
}

// kResiduals = 4: stereo observation [u_l, v_l, u_r, v_r]; 2: left-only [u_l, v_l].
template <int kResiduals>
class ReprojectionCostAnalytic : public ceres::SizedCostFunction<kResiduals, 7, 3> {
  static_assert(kResiduals == 2 || kResiduals == 4, "left-only or stereo");

 public:
  ReprojectionCostAnalytic(const Intrinsics& k, const Eigen::Vector2d& uv_l,
                           const Eigen::Vector2d& uv_r = Eigen::Vector2d::Zero())
      : k_(k), uv_l_(uv_l), uv_r_(uv_r) {}
  bool Evaluate(double const* const* parameters, double* r, double** jacobians) const override {
    CameraPointJacobian j;
    WorldToCam0WithJacobian(parameters[0], parameters[1], &j);
    const Eigen::Vector3d& p = j.p;
    if (!(p.z() > 1e-9)) return false;
    const double inv_z = 1.0 / p.z();
    const double inv_z2 = inv_z * inv_z;
    const double v = k_.fy * p.y() * inv_z + k_.cy;
    r[0] = k_.fx * p.x() * inv_z + k_.cx - uv_l_.x();
    r[1] = v - uv_l_.y();
    Eigen::Matrix<double, kResiduals, 3> dr_dp;
    dr_dp.template topRows<2>() << k_.fx * inv_z, 0, -k_.fx * p.x() * inv_z2,  //
        0, k_.fy * inv_z, -k_.fy * p.y() * inv_z2;
    if constexpr (kResiduals == 4) {
      r[2] = k_.fx * (p.x() - k_.b) * inv_z + k_.cx - uv_r_.x();
      r[3] = v - uv_r_.y();
      dr_dp.template bottomRows<2>() << k_.fx * inv_z, 0, -k_.fx * (p.x() - k_.b) * inv_z2,  //
          0, k_.fy * inv_z, -k_.fy * p.y() * inv_z2;
    }
    if (jacobians == nullptr) return true;
    if (jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, kResiduals, 7, Eigen::RowMajor>> J(jacobians[0]);
      J = dr_dp * j.dp_dpose;
    }
    if (jacobians[1]) {
      Eigen::Map<Eigen::Matrix<double, kResiduals, 3, Eigen::RowMajor>> J(jacobians[1]);
      J = dr_dp * j.dp_dpoint;
    }
    return true;
  }

 private:
  Intrinsics k_;
  Eigen::Vector2d uv_l_, uv_r_;
};

// Plain reprojection errors of one observation (pixels), the point mapped into cam0 by
// T_cam0_world; false when its depth is <= min_depth_m (metres). *depth_m (optional) receives
// the depth whenever the function returns.
bool ObservationErrors(const StereoCamera& cam, const Eigen::Isometry3d& T_cam0_world,
                       const Eigen::Vector3d& p_world, const BaObservation& obs, double min_depth_m,
                       Eigen::Vector2d* e_left, Eigen::Vector2d* e_right,
                       double* depth_m = nullptr) {
  const Eigen::Vector3d p_cam0 = T_cam0_world * p_world;
  if (depth_m) *depth_m = p_cam0.z();
  Eigen::Vector2d uv;
  if (!cam.ProjectLeft(p_cam0, &uv, min_depth_m)) return false;
  *e_left = uv - obs.uv_left_px;
  e_right->setZero();
  if (obs.has_right) {
    cam.ProjectRight(p_cam0, &uv, min_depth_m);
    *e_right = uv - obs.uv_right_px;
  }
  return true;
}

// T_cam0_world of every frame.
std::vector<Eigen::Isometry3d> Inverses(const std::vector<Eigen::Isometry3d>& T_world_cam0) {
  std::vector<Eigen::Isometry3d> inverses;
  inverses.reserve(T_world_cam0.size());
  for (const Eigen::Isometry3d& T : T_world_cam0) inverses.push_back(T.inverse());
  return inverses;
}

ceres::LossFunction* MakeLoss(const BundleAdjustmentOptions& options) {
  switch (options.loss) {
    case RobustLoss::kNone:
      return nullptr;
    case RobustLoss::kHuber:
      return new ceres::HuberLoss(options.loss_scale_px);
    case RobustLoss::kCauchy:
      return new ceres::CauchyLoss(options.loss_scale_px);
  }
  return nullptr;
}

// What a backend returns.
struct BackendResult {
  bool usable = false;     // a solution to use (converged or hit the iteration limit)
  bool converged = false;  // a tolerance was met
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int num_iterations = 0;  // successful + unsuccessful steps, the start counted as one
  std::string message;     // on failure
};

// The problem both backends solve: pose blocks (all frames), points (all, the optimised ones
// changed in place), the observations used, and which poses take part and are free.
struct BackendProblem {
  std::vector<PoseBlock7> poses;
  std::vector<Eigen::Vector3d> points;
  std::vector<int> observations;  // indices into the input's observations
  std::vector<bool> pose_in_problem;
  std::vector<std::pair<int, int>> planar_links;  // (earlier, later) pose of each planar block
  std::vector<RotationPrior> rotation_priors;     // the input's that take part
};

// Ceres' linear solver for BundleAdjustmentOptions::linear_solver (see BaLinearSolver).
struct CeresLinearSolver {
  ceres::LinearSolverType type = ceres::DENSE_SCHUR;
  ceres::SparseLinearAlgebraLibraryType library = ceres::SUITE_SPARSE;  // SPARSE_SCHUR only
  std::string name;  // for BundleAdjustmentSummary::linear_solver
};

// False when SPARSE_SCHUR is asked for and this Ceres has no sparse library.
bool ChooseCeresLinearSolver(BaLinearSolver wanted, CeresLinearSolver* choice) {
  const bool has_suitesparse =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE);
  const bool has_sparse =
      has_suitesparse || ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE);
  if (wanted == BaLinearSolver::kSparseSchur && !has_sparse) return false;
  if (wanted == BaLinearSolver::kDenseSchur || !has_sparse) {
    choice->type = ceres::DENSE_SCHUR;
    choice->name = "DENSE_SCHUR";
  } else {
    choice->type = ceres::SPARSE_SCHUR;
    choice->library = has_suitesparse ? ceres::SUITE_SPARSE : ceres::EIGEN_SPARSE;
    choice->name = has_suitesparse ? "SPARSE_SCHUR (SUITE_SPARSE)" : "SPARSE_SCHUR (EIGEN_SPARSE)";
  }
  return true;
}

BackendResult SolveWithCeres(const StereoCamera& cam, const BundleAdjustmentProblem& input,
                             const BundleAdjustmentOptions& options,
                             const CeresLinearSolver& linear_solver,
                             const std::vector<bool>& point_optimized, BackendProblem* bp) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = linear_solver.type;
  if (linear_solver.type == ceres::SPARSE_SCHUR)
    solver_options.sparse_linear_algebra_library_type = linear_solver.library;
  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);  // shared; the problem deletes it once
  const Intrinsics intrinsics(cam);
  for (int k : bp->observations) {
    const BaObservation& o = input.observations[k];
    ceres::CostFunction* cost = nullptr;
    if (options.analytic_jacobians) {
      cost = o.has_right ? static_cast<ceres::CostFunction*>(new ReprojectionCostAnalytic<4>(
                               intrinsics, o.uv_left_px, o.uv_right_px))
                         : new ReprojectionCostAnalytic<2>(intrinsics, o.uv_left_px);
    } else {
      cost = o.has_right ? static_cast<ceres::CostFunction*>(
                               new ceres::AutoDiffCostFunction<StereoCost, 4, 7, 3>(
                                   new StereoCost(intrinsics, o.uv_left_px, o.uv_right_px)))
                         : new ceres::AutoDiffCostFunction<MonoCost, 2, 7, 3>(
                               new MonoCost(intrinsics, o.uv_left_px));
    }
    problem.AddResidualBlock(cost, loss, bp->poses[o.frame_index].data(),
                             bp->points[o.point_index].data());
  }
  for (const auto& [a, b] : bp->planar_links) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PlanarMotionResidual, PlanarMotionResidual::kNumResiduals,
                                        7, 7>(new PlanarMotionResidual(input.planar)),
        nullptr, bp->poses[a].data(), bp->poses[b].data());
  }
  for (const RotationPrior& prior : bp->rotation_priors) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<RotationPriorResidual, RotationPriorResidual::kNumResiduals,
                                        7, 7>(new RotationPriorResidual(prior)),
        nullptr, bp->poses[prior.frame_a].data(), bp->poses[prior.frame_b].data());
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (size_t i = 0; i < bp->poses.size(); ++i) {
    if (!bp->pose_in_problem[i]) continue;
    problem.SetManifold(bp->poses[i].data(), new PoseManifold());
    if (static_cast<int>(i) < options.num_fixed_poses)
      problem.SetParameterBlockConstant(bp->poses[i].data());
    ordering->AddElementToGroup(bp->poses[i].data(), 1);
  }
  for (size_t j = 0; j < bp->points.size(); ++j)
    if (point_optimized[j]) ordering->AddElementToGroup(bp->points[j].data(), 0);

  solver_options.linear_solver_ordering = ordering;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver_options, &problem, &ceres_summary);

  BackendResult r;
  r.initial_cost = ceres_summary.initial_cost;
  r.num_iterations = ceres_summary.num_successful_steps + ceres_summary.num_unsuccessful_steps;
  r.usable = ceres_summary.IsSolutionUsable();
  r.final_cost = r.usable ? ceres_summary.final_cost : ceres_summary.initial_cost;
  r.converged = ceres_summary.termination_type == ceres::CONVERGENCE;
  if (!r.usable) r.message = "ceres: " + ceres_summary.message;
  return r;
}

BackendResult SolveWithSchurLm(const StereoCamera& cam, const BundleAdjustmentProblem& input,
                               const BundleAdjustmentOptions& options, BackendProblem* bp) {
  std::vector<SchurLmResidual> residuals;
  residuals.reserve(bp->observations.size());
  for (int k : bp->observations) {
    const BaObservation& o = input.observations[k];
    SchurLmResidual res;
    res.pose = o.frame_index;
    res.point = o.point_index;
    res.uv_left_px = o.uv_left_px;
    res.has_right = o.has_right;
    res.uv_right_px = o.uv_right_px;
    residuals.push_back(res);
  }
  std::vector<bool> pose_is_free(bp->poses.size(), false);
  for (size_t i = 0; i < bp->poses.size(); ++i)
    pose_is_free[i] = static_cast<int>(i) >= options.num_fixed_poses;
  const SchurLmSummary lm =
      SolveSchurLm(cam, options, residuals, pose_is_free, &bp->poses, &bp->points, bp->planar_links,
                   input.planar, bp->rotation_priors);
  BackendResult r;
  r.initial_cost = lm.initial_cost;
  r.num_iterations = lm.num_successful_steps + lm.num_unsuccessful_steps;
  r.usable = lm.usable();
  r.final_cost = r.usable ? lm.final_cost : lm.initial_cost;
  r.converged = lm.termination == SchurLmSummary::Termination::kConvergence;
  if (!r.usable) r.message = "schur_lm: " + lm.message;
  return r;
}

}  // namespace

BundleAdjustmentSummary RunBundleAdjustment(const StereoCamera& cam,
                                            const BundleAdjustmentProblem& input,
                                            const BundleAdjustmentOptions& options) {
  using Status = BundleAdjustmentSummary::Status;
  BundleAdjustmentSummary s;
  s.T_world_cam0 = input.T_world_cam0;
  s.points_world = input.points_world;
  s.point_optimized.assign(input.points_world.size(), false);
  s.observation_is_outlier.assign(input.observations.size(), false);
  const int num_frames = static_cast<int>(input.T_world_cam0.size());
  const int num_points = static_cast<int>(input.points_world.size());
  std::ostringstream msg;
  std::string error;
  auto fail = [&](Status status) {
    s.status = status;
    s.message = msg.str();
    return s;
  };

  // --- validation ---
  if (!options.IsValid(&error))
    msg << error;
  else if (!cam.IsValid(&error))
    msg << error;
  else if (input.planar.enabled && !input.planar.IsValid(&error))
    msg << error;
  else if (num_frames < options.num_fixed_poses)
    msg << "need at least num_fixed_poses = " << options.num_fixed_poses << " poses, got "
        << num_frames;
  if (msg.tellp() != 0) return fail(Status::kInvalidInput);
  for (size_t k = 0; k < input.rotation_priors.size(); ++k) {
    const RotationPrior& p = input.rotation_priors[k];
    if (p.frame_a < 0 || p.frame_a >= num_frames || p.frame_b < 0 || p.frame_b >= num_frames ||
        p.frame_a == p.frame_b || !p.R_a_b.allFinite() ||
        !(p.R_a_b * p.R_a_b.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
        !(p.R_a_b.determinant() > 0.0) || !(p.sigma_rad > 0.0) || !std::isfinite(p.sigma_rad)) {
      msg << "rotation prior " << k << " refers to frames " << p.frame_a << " / " << p.frame_b
          << " (have " << num_frames << ", they must differ) or has no rotation or no finite "
          << "sigma_rad > 0";
      return fail(Status::kInvalidInput);
    }
  }
  for (int i = 0; i < num_frames; ++i) {
    if (!input.T_world_cam0[i].matrix().allFinite()) {
      msg << "pose " << i << " is not finite";
      return fail(Status::kInvalidInput);
    }
  }
  for (int j = 0; j < num_points; ++j) {
    if (!input.points_world[j].allFinite()) {
      msg << "point " << j << " is not finite";
      return fail(Status::kInvalidInput);
    }
  }
  for (size_t k = 0; k < input.observations.size(); ++k) {
    const BaObservation& o = input.observations[k];
    if (o.frame_index < 0 || o.frame_index >= num_frames || o.point_index < 0 ||
        o.point_index >= num_points) {
      msg << "observation " << k << " refers to frame " << o.frame_index << " / point "
          << o.point_index << " (have " << num_frames << " frames, " << num_points << " points)";
      return fail(Status::kInvalidInput);
    }
    if (!o.uv_left_px.allFinite() || (o.has_right && !o.uv_right_px.allFinite())) {
      msg << "observation " << k << " is not finite";
      return fail(Status::kInvalidInput);
    }
  }

  // --- backend and (Ceres) linear solver ---
  CeresLinearSolver ceres_linear_solver;
  if (options.solver == BaSolver::kCeres) {
    if (!ChooseCeresLinearSolver(options.linear_solver, &ceres_linear_solver)) {
      msg << "SPARSE_SCHUR asked for, but this Ceres has no sparse linear algebra library";
      return fail(Status::kInvalidInput);
    }
    s.linear_solver = ceres_linear_solver.name;
  } else {
    s.linear_solver = "SCHUR_LM (dense Cholesky)";
  }

  // --- which observations and points take part ---
  // An observation is used when its point lies in front of the camera initially; a point is
  // used when its used observations span at least min_frames_per_point frames.
  std::vector<bool> obs_used(input.observations.size(), false);
  std::vector<double> sq_error(input.observations.size(), 0.0);  // |e_l|² + |e_r|² (pixels²)
  std::vector<std::pair<int, int>> point_frame;  // (point, frame) of each used observation
  point_frame.reserve(input.observations.size());
  {
    const std::vector<Eigen::Isometry3d> T_cam0_world = Inverses(input.T_world_cam0);
    for (size_t k = 0; k < input.observations.size(); ++k) {
      const BaObservation& o = input.observations[k];
      Eigen::Vector2d e_l, e_r;
      if (!ObservationErrors(cam, T_cam0_world[o.frame_index], input.points_world[o.point_index], o,
                             BundleAdjustmentOptions::kMinDepthM, &e_l, &e_r)) {
        s.observation_is_outlier[k] = true;  // behind the camera: left out
        continue;
      }
      obs_used[k] = true;
      sq_error[k] = e_l.squaredNorm() + e_r.squaredNorm();
      point_frame.emplace_back(o.point_index, o.frame_index);
    }
  }
  // Distinct frames per point.
  std::sort(point_frame.begin(), point_frame.end());
  std::vector<int> num_point_frames(num_points, 0);
  for (size_t n = 0; n < point_frame.size(); ++n)
    if (n == 0 || point_frame[n] != point_frame[n - 1]) ++num_point_frames[point_frame[n].first];
  for (int j = 0; j < num_points; ++j) {
    s.point_optimized[j] = num_point_frames[j] >= options.min_frames_per_point;
    if (s.point_optimized[j]) ++s.num_points_optimized;
  }
  BackendProblem bp;
  bp.pose_in_problem.assign(num_frames, false);
  for (size_t k = 0; k < input.observations.size(); ++k) {
    if (obs_used[k] && !s.point_optimized[input.observations[k].point_index]) obs_used[k] = false;
    if (!obs_used[k]) continue;
    bp.observations.push_back(static_cast<int>(k));
    bp.pose_in_problem[input.observations[k].frame_index] = true;
  }
  s.num_residual_blocks = static_cast<int>(bp.observations.size());
  if (input.planar.enabled) {
    int previous = -1;
    for (int i = 0; i < num_frames; ++i) {
      if (!bp.pose_in_problem[i]) continue;
      if (previous >= 0 && i >= options.num_fixed_poses) bp.planar_links.emplace_back(previous, i);
      previous = i;
    }
    s.num_planar_links = static_cast<int>(bp.planar_links.size());
  }
  for (const RotationPrior& prior : input.rotation_priors) {
    if (!bp.pose_in_problem[prior.frame_a] || !bp.pose_in_problem[prior.frame_b]) continue;
    if (prior.frame_a < options.num_fixed_poses && prior.frame_b < options.num_fixed_poses)
      continue;
    bp.rotation_priors.push_back(prior);
  }
  s.num_rotation_priors = static_cast<int>(bp.rotation_priors.size());

  // --- plain rms of the used observations (before) ---
  // sqrt(Σ |e|² / #image observations) over the used observations (and, with
  // skip_outliers, not flagged), from the squared errors of the pass that computed them.
  auto rms = [&](bool skip_outliers) {
    double sq = 0.0;
    int count = 0;
    for (size_t k = 0; k < input.observations.size(); ++k) {
      if (!obs_used[k] || (skip_outliers && s.observation_is_outlier[k])) continue;
      sq += sq_error[k];
      count += input.observations[k].has_right ? 2 : 1;
    }
    return count > 0 ? std::sqrt(sq / count) : 0.0;
  };
  s.rms_reprojection_before_px = rms(false);

  if (s.num_residual_blocks == 0) {
    msg << "no usable observation";
    return fail(Status::kInvalidInput);
  }

  // --- the solve ---
  bp.poses.resize(num_frames);
  for (int i = 0; i < num_frames; ++i) bp.poses[i] = ToBlock(input.T_world_cam0[i]);
  bp.points = input.points_world;
  BackendResult result;
  switch (options.solver) {
    case BaSolver::kCeres:
      result = SolveWithCeres(cam, input, options, ceres_linear_solver, s.point_optimized, &bp);
      break;
    case BaSolver::kSchurLm:
      result = SolveWithSchurLm(cam, input, options, &bp);
      break;
  }
  s.initial_cost = result.initial_cost;
  s.num_iterations = result.num_iterations;
  if (!result.usable) {
    msg << result.message;
    s.final_cost = result.initial_cost;
    s.rms_reprojection_after_px = s.rms_reprojection_before_px;
    return fail(Status::kSolverFailed);
  }
  s.final_cost = result.final_cost;
  s.converged = result.converged;

  // --- outputs: fixed poses copied bit for bit, the others from their blocks ---
  for (int i = options.num_fixed_poses; i < num_frames; ++i)
    if (bp.pose_in_problem[i]) s.T_world_cam0[i] = FromBlock(bp.poses[i]);
  for (int j = 0; j < num_points; ++j)
    if (s.point_optimized[j]) s.points_world[j] = bp.points[j];

  // Errors at the refined values: rms over the points in front of the camera; an observation
  // is an outlier when its depth is <= min_depth_m or its left or right error is too large.
  double sq_after = 0.0;
  int count_after = 0;
  {
    const std::vector<Eigen::Isometry3d> T_cam0_world = Inverses(s.T_world_cam0);
    for (size_t k = 0; k < input.observations.size(); ++k) {
      if (!obs_used[k]) continue;
      const BaObservation& o = input.observations[k];
      Eigen::Vector2d e_l, e_r;
      double depth_m = 0.0;
      const bool in_front =
          ObservationErrors(cam, T_cam0_world[o.frame_index], s.points_world[o.point_index], o, 0.0,
                            &e_l, &e_r, &depth_m);
      sq_error[k] = in_front ? e_l.squaredNorm() + e_r.squaredNorm() : 0.0;
      if (in_front) {
        sq_after += sq_error[k];
        count_after += o.has_right ? 2 : 1;
      }
      s.observation_is_outlier[k] = !(depth_m > BundleAdjustmentOptions::kMinDepthM) ||
                                    e_l.norm() > options.outlier_threshold_px ||
                                    e_r.norm() > options.outlier_threshold_px;
    }
  }
  s.rms_reprojection_after_px = count_after > 0 ? std::sqrt(sq_after / count_after) : 0.0;
  for (bool outlier : s.observation_is_outlier) s.num_outliers += outlier ? 1 : 0;
  s.rms_inlier_reprojection_after_px = rms(true);
  s.status = Status::kOk;
  return s;
}

BundleAdjustmentProblem MakeWindowProblem(
    const TrackManager& tracks, const std::map<int64_t, Eigen::Isometry3d>& T_world_cam0_by_frame,
    std::vector<int64_t>* frame_ids, std::vector<int64_t>* track_ids) {
  BundleAdjustmentProblem problem;
  std::map<int64_t, int> frame_index;
  if (frame_ids) frame_ids->clear();
  if (track_ids) track_ids->clear();
  for (int64_t id : tracks.window_frame_ids()) {
    const auto it = T_world_cam0_by_frame.find(id);
    if (it == T_world_cam0_by_frame.end()) continue;
    frame_index[id] = static_cast<int>(problem.T_world_cam0.size());
    problem.T_world_cam0.push_back(it->second);
    if (frame_ids) frame_ids->push_back(id);
  }
  for (const auto& [track_id, track] : tracks.tracks()) {
    // Initial point: the observation with the largest disparity, mapped to the world.
    const TrackObservation* best = nullptr;
    for (const TrackObservation& o : track.observations) {
      if (!o.has_depth() || !o.p_cam0.allFinite() || frame_index.count(o.frame_id) == 0) continue;
      if (best == nullptr || o.disparity_px > best->disparity_px) best = &o;
    }
    if (best == nullptr) continue;
    const int point_index = static_cast<int>(problem.points_world.size());
    problem.points_world.push_back(problem.T_world_cam0[frame_index[best->frame_id]] *
                                   best->p_cam0);
    if (track_ids) track_ids->push_back(track_id);
    for (const TrackObservation& o : track.observations) {
      const auto fi = frame_index.find(o.frame_id);
      if (fi == frame_index.end()) continue;
      BaObservation obs;
      obs.frame_index = fi->second;
      obs.point_index = point_index;
      obs.uv_left_px = o.uv_left_px;
      obs.has_right = o.has_depth();
      if (obs.has_right) obs.uv_right_px = o.uv_right_px();
      problem.observations.push_back(obs);
    }
  }
  return problem;
}

}  // namespace vo
