#include "vo/ransac.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <ceres/tiny_solver.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>

namespace vo {

bool RansacOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!(inlier_threshold_px > 0.0) || !std::isfinite(inlier_threshold_px))
    msg << "inlier_threshold_px must be finite and > 0, got " << inlier_threshold_px;
  else if (!(confidence > 0.0 && confidence < 1.0))
    msg << "confidence must be in (0, 1), got " << confidence;
  else if (min_iterations < 1)
    msg << "min_iterations must be >= 1, got " << min_iterations;
  else if (max_iterations < min_iterations)
    msg << "max_iterations (" << max_iterations << ") must be >= min_iterations (" << min_iterations
        << ")";
  else if (min_inliers < 3)
    msg << "min_inliers must be >= 3, got " << min_inliers;
  else if (num_seeded_iterations < 0)
    msg << "num_seeded_iterations must be >= 0, got " << num_seeded_iterations;
  else if (!(stable_pool_fraction > 0.0 && stable_pool_fraction <= 1.0))
    msg << "stable_pool_fraction must be in (0, 1], got " << stable_pool_fraction;
  else if (min_stable_pool_size < 3)
    msg << "min_stable_pool_size must be >= 3, got " << min_stable_pool_size;
  else if (!(sample_collinear_tolerance >= 0.0 && sample_collinear_tolerance < 1.0))
    msg << "sample_collinear_tolerance must be in [0, 1), got " << sample_collinear_tolerance;
  else if (refit_iterations < 0)
    msg << "refit_iterations must be >= 0, got " << refit_iterations;
  else if (local_optimization_iterations < 0)
    msg << "local_optimization_iterations must be >= 0, got " << local_optimization_iterations;
  else if (refine_max_iterations < 1)
    msg << "refine_max_iterations must be >= 1, got " << refine_max_iterations;
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

const char* ToString(RansacResult::Status status) {
  switch (status) {
    case RansacResult::Status::kOk:
      return "ok";
    case RansacResult::Status::kTooFewMatches:
      return "too_few_matches";
    case RansacResult::Status::kNoConsensus:
      return "no_consensus";
    case RansacResult::Status::kInvalidInput:
      return "invalid_input";
  }
  return "unknown";
}

std::vector<StereoCorrespondence> MakeStereoCorrespondences(const std::vector<Feature>& prev,
                                                            const std::vector<Feature>& curr,
                                                            const std::vector<Match>& matches,
                                                            std::vector<int>* match_index) {
  std::vector<StereoCorrespondence> out;
  out.reserve(matches.size());
  if (match_index) match_index->clear();
  for (size_t k = 0; k < matches.size(); ++k) {
    const Match& m = matches[k];
    if (m.prev < 0 || m.curr < 0 || m.prev >= static_cast<int>(prev.size()) ||
        m.curr >= static_cast<int>(curr.size()))
      continue;
    const Feature& fp = prev[m.prev];
    const Feature& fc = curr[m.curr];
    if (!fp.has_depth() || !fc.has_depth() || !fp.p_cam0.allFinite()) continue;
    StereoCorrespondence c;
    c.p_prev_cam0 = fp.p_cam0;
    c.uv_curr_px = fc.uv_px;
    c.disparity_curr_px = fc.disparity_px;
    c.track_age = fp.track_age;
    c.uv_prev_px = fp.uv_px;
    c.disparity_prev_px = fp.disparity_px;
    out.push_back(c);
    if (match_index) match_index->push_back(static_cast<int>(k));
  }
  return out;
}

int RansacRequiredIterations(double inlier_ratio, int sample_size, double confidence) {
  if (inlier_ratio >= 1.0) return 0;
  if (!(inlier_ratio > 0.0)) return INT_MAX;
  const double p_good_sample = std::pow(inlier_ratio, sample_size);  // w^s
  const double log_miss = std::log1p(-p_good_sample);                // log(1 − w^s)
  if (!(log_miss < 0.0)) return INT_MAX;
  const double n = std::ceil(std::log1p(-confidence) / log_miss);
  if (!(n < static_cast<double>(INT_MAX))) return INT_MAX;
  return std::max(0, static_cast<int>(n));
}

bool StereoReprojectionErrors(const StereoCamera& cam, const Eigen::Isometry3d& T_curr_prev,
                              const StereoCorrespondence& c, double min_depth_m,
                              Eigen::Vector2d* err_left_px, Eigen::Vector2d* err_right_px) {
  const Eigen::Vector3d p_curr = T_curr_prev * c.p_prev_cam0;
  Eigen::Vector2d uv_left, uv_right;
  if (!cam.ProjectLeft(p_curr, &uv_left, min_depth_m)) return false;
  cam.ProjectRight(p_curr, &uv_right, min_depth_m);
  const Eigen::Vector2d obs_right(c.uv_curr_px.x() - c.disparity_curr_px, c.uv_curr_px.y());
  *err_left_px = uv_left - c.uv_curr_px;
  *err_right_px = uv_right - obs_right;
  return true;
}

namespace {

// Classification of all correspondences under one model.
struct Score {
  int num_inliers = 0;
  double sq_error_sum = 0.0;  // Σ over inliers of |e_left|² + |e_right|² (pixels²)
  bool BetterThan(const Score& other) const {
    if (num_inliers != other.num_inliers) return num_inliers > other.num_inliers;
    return sq_error_sum < other.sq_error_sum;
  }
};

Score Classify(const StereoCamera& cam, const std::vector<StereoCorrespondence>& corr,
               const Eigen::Isometry3d& T_curr_prev, const RansacOptions& options,
               std::vector<bool>* mask) {
  const double thr_sq = options.inlier_threshold_px * options.inlier_threshold_px;
  Score score;
  if (mask) mask->assign(corr.size(), false);
  Eigen::Vector2d e_left, e_right;
  for (size_t i = 0; i < corr.size(); ++i) {
    if (!StereoReprojectionErrors(cam, T_curr_prev, corr[i], RansacOptions::kMinDepthM, &e_left,
                                  &e_right))
      continue;
    const double sq_left = e_left.squaredNorm();
    const double sq_right = e_right.squaredNorm();
    if (sq_left > thr_sq || sq_right > thr_sq) continue;
    ++score.num_inliers;
    score.sq_error_sum += sq_left + sq_right;
    if (mask) (*mask)[i] = true;
  }
  return score;
}

// Horn fit of T_curr_prev (source p_prev, target p_curr) on the selected indices. With
// depth_weighted, pair i gets the weight 1 / (z_prev⁴ + z_curr⁴): stereo depth noise grows as
// z², so this is the inverse variance of the pair's 3D residual up to a common factor.
HornResult FitHorn(const std::vector<StereoCorrespondence>& corr,
                   const std::vector<Eigen::Vector3d>& p_curr, const std::vector<int>& indices,
                   const HornOptions& horn_options, bool depth_weighted) {
  Eigen::Matrix3Xd src(3, indices.size());
  Eigen::Matrix3Xd dst(3, indices.size());
  Eigen::VectorXd w(indices.size());
  for (size_t k = 0; k < indices.size(); ++k) {
    src.col(k) = corr[indices[k]].p_prev_cam0;
    dst.col(k) = p_curr[indices[k]];
    const double z_prev_sq = src(2, k) * src(2, k);
    const double z_curr_sq = dst(2, k) * dst(2, k);
    w[k] = 1.0 / (z_prev_sq * z_prev_sq + z_curr_sq * z_curr_sq);
  }
  if (!depth_weighted) return EstimateRigidMotionHorn(src, dst, horn_options);
  w /= w.maxCoeff();  // scale-free; keeps the numbers near 1
  return EstimateRigidMotionHorn(src, dst, w, horn_options);
}

std::vector<int> MaskToIndices(const std::vector<bool>& mask) {
  std::vector<int> idx;
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask[i]) idx.push_back(static_cast<int>(i));
  return idx;
}

// Left and right reprojection residuals (4, pixels) of a point p_cam0 in a rectified stereo
// pair, eq. (8) for a stereo head; the right v residual equals the left one because the
// observation is (u, v, disparity). False when the point is not in front of the camera.
template <typename T>
bool StereoResiduals(double fx, double fy, double cx, double cy, double b,
                     const Eigen::Matrix<T, 3, 1>& p, const Eigen::Vector2d& uv, double d,
                     T* residual) {
  // The constants enter as doubles, not as Jets with a zero derivative: the same values, fewer
  // operations on derivatives.
  if (!(p.z() > T(1e-9))) return false;
  const T inv_z = T(1.0) / p.z();
  residual[0] = fx * p.x() * inv_z + cx - uv.x();
  residual[1] = fy * p.y() * inv_z + cy - uv.y();
  residual[2] = fx * (p.x() - b) * inv_z + cx - (uv.x() - d);
  residual[3] = residual[1];
  return true;
}

// What each cost below holds: the camera and the correspondence it measures.
struct CorrespondenceCost {
  CorrespondenceCost(const StereoCamera& cam, const StereoCorrespondence& c) : cam(cam), c(c) {}
  // Current-frame residual of the previous-frame point p_prev moved by T_curr_prev = (q, t),
  // q_curr_prev in Eigen order x, y, z, w.
  template <typename T>
  bool CurrResiduals(const T* q_xyzw, const T* t, const Eigen::Matrix<T, 3, 1>& p_prev,
                     T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_xyzw);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tr(t);
    const Eigen::Matrix<T, 3, 1> p = q * p_prev + tr;  // p_curr
    return StereoResiduals(cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px, cam.baseline_m, p,
                           c.uv_curr_px, c.disparity_curr_px, residual);
  }
  StereoCamera cam;
  StereoCorrespondence c;
};

// Current-frame residual of a fixed previous-frame point under T_curr_prev.
// Parameters: q_curr_prev (Eigen order x, y, z, w), t_curr_prev.
struct FixedPointCost : CorrespondenceCost {
  using CorrespondenceCost::CorrespondenceCost;
  template <typename T>
  bool operator()(const T* q_xyzw, const T* t, T* residual) const {
    return CurrResiduals(q_xyzw, t, Eigen::Matrix<T, 3, 1>(c.p_prev_cam0.cast<T>()), residual);
  }
};

// Current-frame residual of a free previous-frame point: parameters q, t, p_prev.
struct FreePointCurrCost : CorrespondenceCost {
  using CorrespondenceCost::CorrespondenceCost;
  template <typename T>
  bool operator()(const T* q_xyzw, const T* t, const T* p_prev, T* residual) const {
    return CurrResiduals(q_xyzw, t, Eigen::Matrix<T, 3, 1>(p_prev), residual);
  }
};

// Previous-frame residual of a free point (its own observation): parameter p_prev.
struct FreePointPrevCost : CorrespondenceCost {
  using CorrespondenceCost::CorrespondenceCost;
  template <typename T>
  bool operator()(const T* p_prev, T* residual) const {
    const Eigen::Matrix<T, 3, 1> p = Eigen::Map<const Eigen::Matrix<T, 3, 1>>(p_prev);
    return StereoResiduals(cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px, cam.baseline_m, p,
                           c.uv_prev_px, c.disparity_prev_px, residual);
  }
};

// ceres::AngleAxisRotatePoint split in two: the rotation's terms (angle, its sine and cosine,
// the axis), computed once for all points, and the part of each point. The same operations in
// the same order as Ceres', so the same values and, for Jets, the same derivatives (with a
// constant point given as doubles: equal, a zero's sign aside); what it saves is the square
// root, two divisions and four sines and cosines of every point.
template <typename T>
class AngleAxisRotation {
 public:
  explicit AngleAxisRotation(const T angle_axis[3]) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T theta2 = ceres::DotProduct(angle_axis, angle_axis);
    small_ = !(theta2 > T(std::numeric_limits<double>::epsilon()));
    if (small_) {  // first-order: R p = p + angle_axis × p
      for (int i = 0; i < 3; ++i) w_[i] = angle_axis[i];
      return;
    }
    const T theta = sqrt(theta2);
    cos_ = cos(theta);
    sin_ = sin(theta);
    const T theta_inverse = T(1.0) / theta;
    for (int i = 0; i < 3; ++i) w_[i] = angle_axis[i] * theta_inverse;
    one_minus_cos_ = T(1.0) - cos_;
  }

  // pt: T, or double for a constant point (its terms then have no derivative to carry).
  template <typename P>
  void Rotate(const P pt[3], T result[3]) const {
    const T w_cross_pt[3] = {w_[1] * pt[2] - w_[2] * pt[1], w_[2] * pt[0] - w_[0] * pt[2],
                             w_[0] * pt[1] - w_[1] * pt[0]};
    if (small_) {
      for (int i = 0; i < 3; ++i) result[i] = pt[i] + w_cross_pt[i];
      return;
    }
    const T tmp = (w_[0] * pt[0] + w_[1] * pt[1] + w_[2] * pt[2]) * one_minus_cos_;
    for (int i = 0; i < 3; ++i) result[i] = pt[i] * cos_ + w_cross_pt[i] * sin_ + w_[i] * tmp;
  }

 private:
  bool small_ = false;
  T w_[3];  // the unit axis (the angle-axis itself when small_)
  T cos_, sin_, one_minus_cos_;
};

// Reprojection residuals of fixed previous-frame points for ceres::TinySolver: 4 per
// correspondence, parameters x = [angle-axis of R_curr_prev (3), t_curr_prev (3)], the
// Jacobian by forward-mode automatic differentiation (ceres::Jet) as
// ceres::TinySolverAutoDiffFunction computes it (the same residuals and derivatives, a zero's
// sign aside; its failure behaviour too: residuals and Jacobian untouched when a point is not
// in front), with the rotation's terms computed once per evaluation rather than once per point
// and the points and intrinsics as doubles rather than Jets.
class FixedPointsFunction {
 public:
  using Scalar = double;
  enum { NUM_RESIDUALS = Eigen::Dynamic, NUM_PARAMETERS = 6 };

  FixedPointsFunction(const StereoCamera& cam, const std::vector<StereoCorrespondence>& corr,
                      const std::vector<int>& indices)
      : cam_(cam), corr_(corr), indices_(indices), jets_(NumResiduals()) {}

  int NumResiduals() const { return 4 * static_cast<int>(indices_.size()); }

  bool operator()(const double* x, double* residuals, double* jacobian) const {
    if (jacobian == nullptr) return Evaluate(x, residuals);
    Jet x_jet[6];
    for (int i = 0; i < 6; ++i) {
      x_jet[i].a = x[i];
      x_jet[i].v.setZero();
      x_jet[i].v[i] = 1.0;
    }
    if (!Evaluate(x_jet, jets_.data())) return false;
    const int n = NumResiduals();
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 6>> J(jacobian, n, 6);
    for (int r = 0; r < n; ++r) {
      residuals[r] = jets_[r].a;
      J.row(r) = jets_[r].v;
    }
    return true;
  }

 private:
  using Jet = ceres::Jet<double, 6>;

  template <typename T>
  bool Evaluate(const T* x, T* residuals) const {
    const AngleAxisRotation<T> rotation(x);
    for (size_t k = 0; k < indices_.size(); ++k) {
      const StereoCorrespondence& c = corr_[indices_[k]];
      T p[3];
      rotation.Rotate(c.p_prev_cam0.data(), p);
      const Eigen::Matrix<T, 3, 1> p_curr(p[0] + x[3], p[1] + x[4], p[2] + x[5]);
      if (!StereoResiduals(cam_.fx_px, cam_.fy_px, cam_.cx_px, cam_.cy_px, cam_.baseline_m, p_curr,
                           c.uv_curr_px, c.disparity_curr_px, residuals + 4 * k))
        return false;
    }
    return true;
  }

  const StereoCamera& cam_;
  const std::vector<StereoCorrespondence>& corr_;
  const std::vector<int>& indices_;
  mutable std::vector<Jet> jets_;  // the residuals with their derivatives
};

// Nonlinear refinement of T_curr_prev on the inliers (see ransac.h). Returns false when
// Ceres fails.
bool RefineNonlinear(const StereoCamera& cam, const std::vector<StereoCorrespondence>& corr,
                     const std::vector<int>& inliers, const RansacOptions& options,
                     Eigen::Isometry3d* T_curr_prev) {
  Eigen::Quaterniond q(T_curr_prev->linear());
  q.normalize();
  double q_xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
  double t[3] = {T_curr_prev->translation().x(), T_curr_prev->translation().y(),
                 T_curr_prev->translation().z()};
  std::vector<Eigen::Vector3d> points;  // free points (stable addresses: reserved)
  points.reserve(inliers.size());
  ceres::Problem problem;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (int i : inliers) {
    const StereoCorrespondence& c = corr[i];
    if (options.refine_points && c.has_prev_observation()) {
      points.push_back(c.p_prev_cam0);
      double* p = points.back().data();
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<FreePointPrevCost, 4, 3>(new FreePointPrevCost(cam, c)),
          nullptr, p);
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FreePointCurrCost, 4, 4, 3, 3>(
                                   new FreePointCurrCost(cam, c)),
                               nullptr, q_xyzw, t, p);
      ordering->AddElementToGroup(p, 0);
    } else {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<FixedPointCost, 4, 4, 3>(new FixedPointCost(cam, c)),
          nullptr, q_xyzw, t);
    }
  }
  problem.SetManifold(q_xyzw, new ceres::EigenQuaternionManifold());
  ceres::Solver::Options solver_options;
  if (points.empty()) {
    solver_options.linear_solver_type = ceres::DENSE_QR;
  } else {
    ordering->AddElementToGroup(q_xyzw, 1);
    ordering->AddElementToGroup(t, 1);
    solver_options.linear_solver_type = ceres::DENSE_SCHUR;
    solver_options.linear_solver_ordering = ordering;
  }
  solver_options.max_num_iterations = options.refine_max_iterations;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return false;
  const Eigen::Quaterniond q_new(q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2]);
  T_curr_prev->setIdentity();
  T_curr_prev->linear() = q_new.normalized().toRotationMatrix();
  T_curr_prev->translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return true;
}

RansacResult Fail(RansacResult::Status status, const std::string& message, size_t n) {
  RansacResult r;
  r.status = status;
  r.message = message;
  r.inlier_mask.assign(n, false);
  return r;
}

}  // namespace

bool FitReprojectionFixedPoints(const StereoCamera& cam,
                                const std::vector<StereoCorrespondence>& corr,
                                const std::vector<int>& indices, int max_iterations,
                                Eigen::Isometry3d* T_curr_prev) {
  if (indices.size() < 3) return false;
  FixedPointsFunction function(cam, corr, indices);
  Eigen::Matrix<double, 6, 1> x;
  const Eigen::AngleAxisd aa(T_curr_prev->linear());
  x.head<3>() = aa.angle() * aa.axis();
  x.tail<3>() = T_curr_prev->translation();
  ceres::TinySolver<FixedPointsFunction> solver;
  solver.options.max_num_iterations = max_iterations;
  solver.Solve(function, &x);
  if (!x.allFinite()) return false;
  const double angle = x.head<3>().norm();
  T_curr_prev->setIdentity();
  if (angle > 0.0)
    T_curr_prev->linear() = Eigen::AngleAxisd(angle, x.head<3>() / angle).toRotationMatrix();
  T_curr_prev->translation() = x.tail<3>();
  return true;
}

RansacResult EstimateMotionRansac(const StereoCamera& cam,
                                  const std::vector<StereoCorrespondence>& corr,
                                  const RansacOptions& options) {
  const size_t n = corr.size();
  std::string error;
  if (!options.IsValid(&error)) return Fail(RansacResult::Status::kInvalidInput, error, n);
  if (!cam.IsValid(&error)) return Fail(RansacResult::Status::kInvalidInput, error, n);
  for (size_t i = 0; i < n; ++i) {
    const StereoCorrespondence& c = corr[i];
    if (!c.p_prev_cam0.allFinite() || !c.uv_curr_px.allFinite() ||
        !std::isfinite(c.disparity_curr_px) || !(c.disparity_curr_px > 0.0) ||
        (c.has_prev_observation() &&
         (!c.uv_prev_px.allFinite() || !std::isfinite(c.disparity_prev_px)))) {
      std::ostringstream msg;
      msg << "correspondence " << i << " has non-finite numbers or disparity <= 0";
      return Fail(RansacResult::Status::kInvalidInput, msg.str(), n);
    }
  }
  const size_t min_matches = static_cast<size_t>(std::max(3, options.min_inliers));
  if (n < min_matches) {
    std::ostringstream msg;
    msg << "need at least " << min_matches << " correspondences, got " << n;
    return Fail(RansacResult::Status::kTooFewMatches, msg.str(), n);
  }

  // Current-frame 3D points (Horn's target set).
  std::vector<Eigen::Vector3d> p_curr(n);
  for (size_t i = 0; i < n; ++i)
    p_curr[i] =
        cam.Backproject(corr[i].uv_curr_px.x(), corr[i].uv_curr_px.y(), corr[i].disparity_curr_px);

  // Stable pool: oldest tracks first (ties by index), closed under equal age.
  std::vector<int> by_age(n);
  std::iota(by_age.begin(), by_age.end(), 0);
  std::stable_sort(by_age.begin(), by_age.end(),
                   [&](int a, int b) { return corr[a].track_age > corr[b].track_age; });
  size_t pool_size = std::max<size_t>(
      static_cast<size_t>(options.min_stable_pool_size),
      static_cast<size_t>(std::ceil(options.stable_pool_fraction * static_cast<double>(n))));
  pool_size = std::min(pool_size, n);
  while (pool_size < n &&
         corr[by_age[pool_size]].track_age == corr[by_age[pool_size - 1]].track_age)
    ++pool_size;
  const bool seeding = options.num_seeded_iterations > 0 && pool_size < n;

  HornOptions sample_horn;
  sample_horn.collinear_tolerance = options.sample_collinear_tolerance;

  SplitMix64 rng(options.seed);
  RansacResult result;
  result.stable_pool_size = seeding ? static_cast<int>(pool_size) : 0;
  Score best;
  bool have_model = false;
  Eigen::Isometry3d best_T_curr_prev = Eigen::Isometry3d::Identity();
  int required = options.max_iterations;
  int it = 0;
  std::vector<int> sample(3);
  for (; it < options.max_iterations; ++it) {
    if (it >= options.min_iterations && it >= required) break;
    // Draw 3 distinct correspondences: from the stable pool during the seeded phase.
    const bool seeded = seeding && it < options.num_seeded_iterations;
    const uint64_t range = seeded ? pool_size : n;
    for (int k = 0; k < 3; ++k) {
      int idx;
      do {
        const uint64_t r = rng.UniformIndex(range);
        idx = seeded ? by_age[r] : static_cast<int>(r);
      } while (std::find(sample.begin(), sample.begin() + k, idx) != sample.begin() + k);
      sample[k] = idx;
    }
    if (seeded) ++result.num_seeded_iterations;

    const HornResult fit = FitHorn(corr, p_curr, sample, sample_horn, false);
    if (!fit.ok()) continue;  // degenerate sample
    std::vector<bool> sample_mask;
    const Score score = Classify(cam, corr, fit.T_dst_src, options, &sample_mask);
    if (!have_model || score.BetterThan(best)) {
      have_model = true;
      best = score;
      best_T_curr_prev = fit.T_dst_src;
      // Local optimisation (LO-RANSAC): fit the new best model to the reprojections of its
      // own inliers, re-classify, repeat while the score improves.
      for (int lo = 0; lo < options.local_optimization_iterations && best.num_inliers >= 3; ++lo) {
        Eigen::Isometry3d T_lo = best_T_curr_prev;
        if (!FitReprojectionFixedPoints(cam, corr, MaskToIndices(sample_mask),
                                        options.refine_max_iterations, &T_lo))
          break;
        std::vector<bool> lo_mask;
        const Score lo_score = Classify(cam, corr, T_lo, options, &lo_mask);
        if (!lo_score.BetterThan(best)) break;
        best = lo_score;
        best_T_curr_prev = T_lo;
        sample_mask.swap(lo_mask);
      }
      required = RansacRequiredIterations(
          static_cast<double>(best.num_inliers) / static_cast<double>(n), 3, options.confidence);
    }
  }
  result.num_iterations = it;

  if (!have_model || best.num_inliers < options.min_inliers) {
    std::ostringstream msg;
    msg << "best model has " << best.num_inliers << " inliers after " << it << " iterations, need "
        << options.min_inliers;
    RansacResult r = Fail(RansacResult::Status::kNoConsensus, msg.str(), n);
    r.num_iterations = result.num_iterations;
    r.num_seeded_iterations = result.num_seeded_iterations;
    r.stable_pool_size = result.stable_pool_size;
    if (have_model) {
      Classify(cam, corr, best_T_curr_prev, options, &r.inlier_mask);
      r.num_inliers = best.num_inliers;
      r.T_prev_curr = best_T_curr_prev.inverse();
    }
    return r;
  }

  // Horn refit on all inliers, re-classify; keep a refit only when it does not lose support.
  std::vector<bool> mask;
  Classify(cam, corr, best_T_curr_prev, options, &mask);
  for (int r = 0; r < options.refit_iterations; ++r) {
    const HornResult fit =
        FitHorn(corr, p_curr, MaskToIndices(mask), HornOptions(), options.refit_depth_weighted);
    if (!fit.ok()) break;
    std::vector<bool> new_mask;
    const Score score = Classify(cam, corr, fit.T_dst_src, options, &new_mask);
    if (score.num_inliers < best.num_inliers) break;
    best = score;
    best_T_curr_prev = fit.T_dst_src;
    const bool stable = new_mask == mask;
    mask.swap(new_mask);
    if (stable) break;
  }

  // Optional reprojection refinement on the inliers (at most two rounds: refine, re-classify,
  // refine again when the inlier set changed).
  if (options.refine_nonlinear) {
    for (int round = 0; round < 2; ++round) {
      Eigen::Isometry3d T_refined = best_T_curr_prev;
      if (!RefineNonlinear(cam, corr, MaskToIndices(mask), options, &T_refined)) break;
      std::vector<bool> new_mask;
      const Score score = Classify(cam, corr, T_refined, options, &new_mask);
      if (score.num_inliers < options.min_inliers) break;
      best = score;
      best_T_curr_prev = T_refined;
      result.refined = true;
      const bool stable = new_mask == mask;
      mask.swap(new_mask);
      if (stable) break;
    }
  }

  result.status = RansacResult::Status::kOk;
  result.T_prev_curr = best_T_curr_prev.inverse();
  result.inlier_mask = mask;
  result.num_inliers = best.num_inliers;
  result.rms_reprojection_px =
      best.num_inliers > 0 ? std::sqrt(best.sq_error_sum / (2.0 * best.num_inliers)) : 0.0;
  return result;
}

}  // namespace vo
