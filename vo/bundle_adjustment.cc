#include "vo/bundle_adjustment.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <set>
#include <sstream>

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
  else if (!(min_depth_m > 0.0) || !std::isfinite(min_depth_m))
    msg << "min_depth_m must be finite and > 0, got " << min_depth_m;
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

namespace {

using PoseBlock = std::array<double, 7>;  // [qx qy qz qw tx ty tz] of T_world_cam0
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
  Eigen::Vector3d p;           // point in cam0
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
      2.0 * w * Skew(v) + 2.0 * (u.dot(v) * Eigen::Matrix3d::Identity() + u * v.transpose() -
                                 2.0 * v * u.transpose());
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

// Plain reprojection errors of one observation (pixels); false when behind the camera.
bool ObservationErrors(const StereoCamera& cam, const Eigen::Isometry3d& T_world_cam0,
                       const Eigen::Vector3d& p_world, const BaObservation& obs, double min_depth_m,
                       Eigen::Vector2d* e_left, Eigen::Vector2d* e_right) {
  const Eigen::Vector3d p_cam0 = T_world_cam0.inverse() * p_world;
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
  else if (num_frames < options.num_fixed_poses)
    msg << "need at least num_fixed_poses = " << options.num_fixed_poses << " poses, got "
        << num_frames;
  if (msg.tellp() != 0) return fail(Status::kInvalidInput);
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

  // --- linear solver choice ---
  ceres::Solver::Options solver_options;
  const bool has_suitesparse =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE);
  const bool has_eigen_sparse =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE);
  const bool has_sparse = has_suitesparse || has_eigen_sparse;
  if (options.linear_solver == BaLinearSolver::kSparseSchur && !has_sparse) {
    msg << "SPARSE_SCHUR asked for, but this Ceres has no sparse linear algebra library";
    return fail(Status::kInvalidInput);
  }
  if (options.linear_solver == BaLinearSolver::kDenseSchur || !has_sparse) {
    solver_options.linear_solver_type = ceres::DENSE_SCHUR;
    s.linear_solver = "DENSE_SCHUR";
  } else {
    solver_options.linear_solver_type = ceres::SPARSE_SCHUR;
    solver_options.sparse_linear_algebra_library_type =
        has_suitesparse ? ceres::SUITE_SPARSE : ceres::EIGEN_SPARSE;
    s.linear_solver =
        has_suitesparse ? "SPARSE_SCHUR (SUITE_SPARSE)" : "SPARSE_SCHUR (EIGEN_SPARSE)";
  }

  // --- which observations and points take part ---
  // An observation is used when its point lies in front of the camera initially; a point is
  // used when its used observations span at least min_frames_per_point frames.
  std::vector<bool> obs_used(input.observations.size(), false);
  std::vector<std::set<int>> point_frames(num_points);
  for (size_t k = 0; k < input.observations.size(); ++k) {
    const BaObservation& o = input.observations[k];
    Eigen::Vector2d e_l, e_r;
    if (!ObservationErrors(cam, input.T_world_cam0[o.frame_index],
                           input.points_world[o.point_index], o, options.min_depth_m, &e_l, &e_r)) {
      s.observation_is_outlier[k] = true;  // behind the camera: left out
      continue;
    }
    obs_used[k] = true;
    point_frames[o.point_index].insert(o.frame_index);
  }
  for (int j = 0; j < num_points; ++j) {
    s.point_optimized[j] = static_cast<int>(point_frames[j].size()) >= options.min_frames_per_point;
    if (s.point_optimized[j]) ++s.num_points_optimized;
  }
  for (size_t k = 0; k < input.observations.size(); ++k)
    if (obs_used[k] && !s.point_optimized[input.observations[k].point_index]) obs_used[k] = false;

  // --- plain rms of the used observations (before) ---
  auto rms = [&](const std::vector<Eigen::Isometry3d>& poses,
                 const std::vector<Eigen::Vector3d>& points, bool skip_outliers) {
    double sq = 0.0;
    int count = 0;
    for (size_t k = 0; k < input.observations.size(); ++k) {
      if (!obs_used[k] || (skip_outliers && s.observation_is_outlier[k])) continue;
      const BaObservation& o = input.observations[k];
      Eigen::Vector2d e_l, e_r;
      if (!ObservationErrors(cam, poses[o.frame_index], points[o.point_index], o, 0.0, &e_l, &e_r))
        continue;
      sq += e_l.squaredNorm() + e_r.squaredNorm();
      count += o.has_right ? 2 : 1;
    }
    return count > 0 ? std::sqrt(sq / count) : 0.0;
  };
  s.rms_reprojection_before_px = rms(input.T_world_cam0, input.points_world, false);

  // --- the Ceres problem ---
  std::vector<PoseBlock> poses(num_frames);
  for (int i = 0; i < num_frames; ++i) poses[i] = ToBlock(input.T_world_cam0[i]);
  std::vector<std::array<double, 3>> points(num_points);
  for (int j = 0; j < num_points; ++j)
    points[j] = {input.points_world[j].x(), input.points_world[j].y(), input.points_world[j].z()};

  ceres::Problem problem;
  ceres::LossFunction* loss = MakeLoss(options);  // shared; the problem deletes it once
  const Intrinsics intrinsics(cam);
  std::vector<bool> pose_in_problem(num_frames, false);
  for (size_t k = 0; k < input.observations.size(); ++k) {
    if (!obs_used[k]) continue;
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
    problem.AddResidualBlock(cost, loss, poses[o.frame_index].data(), points[o.point_index].data());
    pose_in_problem[o.frame_index] = true;
    ++s.num_residual_blocks;
  }
  if (s.num_residual_blocks == 0) {
    delete loss;  // never handed to the problem
    msg << "no usable observation";
    return fail(Status::kInvalidInput);
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (int i = 0; i < num_frames; ++i) {
    if (!pose_in_problem[i]) continue;
    problem.SetManifold(poses[i].data(), new PoseManifold());
    if (i < options.num_fixed_poses) problem.SetParameterBlockConstant(poses[i].data());
    ordering->AddElementToGroup(poses[i].data(), 1);
  }
  for (int j = 0; j < num_points; ++j)
    if (s.point_optimized[j]) ordering->AddElementToGroup(points[j].data(), 0);

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

  s.initial_cost = ceres_summary.initial_cost;
  s.num_iterations = ceres_summary.num_successful_steps + ceres_summary.num_unsuccessful_steps;
  if (!ceres_summary.IsSolutionUsable()) {
    msg << "ceres: " << ceres_summary.message;
    s.final_cost = ceres_summary.initial_cost;
    s.rms_reprojection_after_px = s.rms_reprojection_before_px;
    return fail(Status::kSolverFailed);
  }
  s.final_cost = ceres_summary.final_cost;
  s.converged = ceres_summary.termination_type == ceres::CONVERGENCE;

  // --- outputs: fixed poses copied bit for bit, the others from their blocks ---
  for (int i = options.num_fixed_poses; i < num_frames; ++i)
    if (pose_in_problem[i]) s.T_world_cam0[i] = FromBlock(poses[i]);
  for (int j = 0; j < num_points; ++j)
    if (s.point_optimized[j])
      s.points_world[j] = Eigen::Vector3d(points[j][0], points[j][1], points[j][2]);

  s.rms_reprojection_after_px = rms(s.T_world_cam0, s.points_world, false);
  for (size_t k = 0; k < input.observations.size(); ++k) {
    if (!obs_used[k]) continue;
    const BaObservation& o = input.observations[k];
    Eigen::Vector2d e_l, e_r;
    const bool in_front =
        ObservationErrors(cam, s.T_world_cam0[o.frame_index], s.points_world[o.point_index], o,
                          options.min_depth_m, &e_l, &e_r);
    s.observation_is_outlier[k] = !in_front || e_l.norm() > options.outlier_threshold_px ||
                                  e_r.norm() > options.outlier_threshold_px;
  }
  for (bool outlier : s.observation_is_outlier) s.num_outliers += outlier ? 1 : 0;
  s.rms_inlier_reprojection_after_px = rms(s.T_world_cam0, s.points_world, true);
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
