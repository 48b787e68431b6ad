#include "vo/prior_motion.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <sstream>

namespace vo {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNumericStep = 1e-6;     // central-difference step of the Jacobian (rad, m)
constexpr double kConvergedStep = 1e-10;  // stop when |δ|² falls below this

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// T_prior · [Exp(ω) | v] for x = (ω, v).
Eigen::Isometry3d Corrected(const Eigen::Isometry3d& T_prior, const Vector6d& x) {
  Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = x.head<3>();
  const double angle = w.norm();
  if (angle > 0.0) D.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  D.translation() = x.tail<3>();
  return T_prior * D;
}

// Inliers of T_prev_curr (both image errors <= threshold) and their squared-error sum.
int Classify(const StereoCamera& camera, const std::vector<StereoCorrespondence>& corr,
             const Eigen::Isometry3d& T_prev_curr, const PriorMotionOptions& o,
             std::vector<bool>* mask, double* sq_sum) {
  const Eigen::Isometry3d T_curr_prev = T_prev_curr.inverse();
  const double thr_sq = o.inlier_threshold_px * o.inlier_threshold_px;
  int n = 0;
  *sq_sum = 0.0;
  mask->assign(corr.size(), false);
  for (size_t i = 0; i < corr.size(); ++i) {
    Eigen::Vector2d el, er;
    if (!StereoReprojectionErrors(camera, T_curr_prev, corr[i], o.min_depth_m, &el, &er)) continue;
    if (el.squaredNorm() > thr_sq || er.squaredNorm() > thr_sq) continue;
    (*mask)[i] = true;
    ++n;
    *sq_sum += el.squaredNorm() + er.squaredNorm();
  }
  return n;
}

// Whitened residuals at x: per inlier (u_left, v_left, u_right) / σ_px, then ω / σ_rot, v / σ_t.
Eigen::VectorXd Residuals(const StereoCamera& camera, const std::vector<StereoCorrespondence>& corr,
                          const std::vector<int>& inliers, const Eigen::Isometry3d& T_prior,
                          const Vector6d& x, const PriorMotionOptions& o) {
  Eigen::VectorXd r(3 * inliers.size() + 6);
  const Eigen::Isometry3d T_curr_prev = Corrected(T_prior, x).inverse();
  const double inv_px = 1.0 / o.measurement_sigma_px;
  for (size_t k = 0; k < inliers.size(); ++k) {
    Eigen::Vector2d el, er;
    if (!StereoReprojectionErrors(camera, T_curr_prev, corr[inliers[k]], o.min_depth_m, &el, &er)) {
      // Behind the camera: a constant penalty of the inlier threshold (no gradient).
      el = Eigen::Vector2d::Constant(o.inlier_threshold_px);
      er = el;
    }
    r(3 * k) = el.x() * inv_px;
    r(3 * k + 1) = el.y() * inv_px;
    r(3 * k + 2) = er.x() * inv_px;
  }
  const size_t p = 3 * inliers.size();
  const double sigma_rot = o.prior_rotation_sigma_deg * kPi / 180.0;
  r.segment<3>(p) = x.head<3>() / sigma_rot;
  r.segment<3>(p + 3) = x.tail<3>() / o.prior_translation_sigma_m;
  return r;
}

// Gauss-Newton on x from x0 over the given inliers (a step that raises the cost is halved, at
// most a few times, then the iteration stops).
Vector6d Refine(const StereoCamera& camera, const std::vector<StereoCorrespondence>& corr,
                const std::vector<bool>& mask, const Eigen::Isometry3d& T_prior, const Vector6d& x0,
                const PriorMotionOptions& o) {
  std::vector<int> inliers;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (mask[i]) inliers.push_back(static_cast<int>(i));
  }
  Vector6d x = x0;
  Eigen::VectorXd r = Residuals(camera, corr, inliers, T_prior, x, o);
  double cost = r.squaredNorm();
  Eigen::MatrixXd J(r.size(), 6);
  for (int it = 0; it < o.max_iterations; ++it) {
    for (int j = 0; j < 6; ++j) {
      Vector6d xp = x, xm = x;
      xp(j) += kNumericStep;
      xm(j) -= kNumericStep;
      J.col(j) = (Residuals(camera, corr, inliers, T_prior, xp, o) -
                  Residuals(camera, corr, inliers, T_prior, xm, o)) /
                 (2.0 * kNumericStep);
    }
    const Matrix6d H = J.transpose() * J;
    const Vector6d g = J.transpose() * r;
    const Vector6d delta = -H.ldlt().solve(g);
    if (!delta.allFinite()) break;
    double step = 1.0;
    bool improved = false;
    for (int halving = 0; halving < 4; ++halving, step *= 0.5) {
      const Vector6d x_new = x + step * delta;
      const Eigen::VectorXd r_new = Residuals(camera, corr, inliers, T_prior, x_new, o);
      const double cost_new = r_new.squaredNorm();
      if (cost_new <= cost) {
        x = x_new;
        r = r_new;
        cost = cost_new;
        improved = true;
        break;
      }
    }
    if (!improved || (step * delta).squaredNorm() < kConvergedStep) break;
  }
  return x;
}

}  // namespace

bool PriorMotionOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (min_inliers < 1) {
    msg << "min_inliers must be >= 1, got " << min_inliers;
  } else if (!(min_inlier_fraction >= 0.0 && min_inlier_fraction <= 1.0)) {
    msg << "min_inlier_fraction must be in [0, 1], got " << min_inlier_fraction;
  } else if (!(inlier_threshold_px > 0.0) || !std::isfinite(inlier_threshold_px)) {
    msg << "inlier_threshold_px must be finite and > 0, got " << inlier_threshold_px;
  } else if (!(measurement_sigma_px > 0.0) || !std::isfinite(measurement_sigma_px)) {
    msg << "measurement_sigma_px must be finite and > 0, got " << measurement_sigma_px;
  } else if (!(prior_rotation_sigma_deg > 0.0) || !std::isfinite(prior_rotation_sigma_deg)) {
    msg << "prior_rotation_sigma_deg must be finite and > 0, got " << prior_rotation_sigma_deg;
  } else if (!(prior_translation_sigma_m > 0.0) || !std::isfinite(prior_translation_sigma_m)) {
    msg << "prior_translation_sigma_m must be finite and > 0, got " << prior_translation_sigma_m;
  } else if (max_iterations < 1) {
    msg << "max_iterations must be >= 1, got " << max_iterations;
  } else if (!(min_depth_m > 0.0) || !std::isfinite(min_depth_m)) {
    msg << "min_depth_m must be finite and > 0, got " << min_depth_m;
  }
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

PriorMotionResult EstimateMotionWithPrior(const StereoCamera& camera,
                                          const std::vector<StereoCorrespondence>& corr,
                                          const Eigen::Isometry3d& T_prior,
                                          const PriorMotionOptions& o) {
  PriorMotionResult result;
  result.T_prev_curr = T_prior;
  result.inlier_mask.assign(corr.size(), false);
  std::string why;
  if (!o.IsValid(&why) || !camera.IsValid(&why)) {
    result.message = "invalid input: " + why;
    return result;
  }
  if (!T_prior.matrix().allFinite()) {
    result.message = "invalid input: non-finite prior";
    return result;
  }
  for (const StereoCorrespondence& c : corr) {
    if (!c.p_prev_cam0.allFinite() || !c.uv_curr_px.allFinite() ||
        !std::isfinite(c.disparity_curr_px)) {
      result.message = "invalid input: non-finite correspondence";
      return result;
    }
  }

  // Hypotheses: the prior (x = 0), then one 1-point rotation correction per correspondence.
  Vector6d best_x = Vector6d::Zero();
  std::vector<bool> best_mask;
  double best_sq = 0.0;
  int best_n = Classify(camera, corr, T_prior, o, &best_mask, &best_sq);
  const Eigen::Matrix3d R_prior = T_prior.linear();
  for (size_t i = 0; i < corr.size(); ++i) {
    // The observed bearing b in the current camera; the point's direction a' seen from the
    // prior's camera centre, in the prior's rotated frame. Q b = a' (smallest rotation).
    const Eigen::Vector3d b((corr[i].uv_curr_px.x() - camera.cx_px) / camera.fx_px,
                            (corr[i].uv_curr_px.y() - camera.cy_px) / camera.fy_px, 1.0);
    const Eigen::Vector3d a = R_prior.transpose() * (corr[i].p_prev_cam0 - T_prior.translation());
    if (!(a.norm() > 0.0) || a.normalized().dot(b.normalized()) <= 0.0) continue;
    const Eigen::AngleAxisd Q(Eigen::Quaterniond::FromTwoVectors(b, a));
    Vector6d x = Vector6d::Zero();
    x.head<3>() = Q.angle() * Q.axis();
    if (!x.allFinite()) continue;
    std::vector<bool> mask;
    double sq = 0.0;
    const int n = Classify(camera, corr, Corrected(T_prior, x), o, &mask, &sq);
    if (n > best_n || (n == best_n && sq < best_sq)) {
      best_n = n;
      best_sq = sq;
      best_x = x;
      best_mask = std::move(mask);
    }
  }
  if (best_n == 0) {
    result.message = "no correspondence agrees with the prior";
    return result;
  }

  // Refine on the inliers, re-classify, refine again.
  Vector6d x = Refine(camera, corr, best_mask, T_prior, best_x, o);
  std::vector<bool> mask;
  double sq = 0.0;
  int n = Classify(camera, corr, Corrected(T_prior, x), o, &mask, &sq);
  if (n >= best_n && mask != best_mask) {
    x = Refine(camera, corr, mask, T_prior, x, o);
    n = Classify(camera, corr, Corrected(T_prior, x), o, &mask, &sq);
  }
  if (n < best_n) {  // the refinement lost support: keep the hypothesis
    x = best_x;
    mask = best_mask;
    n = best_n;
    sq = best_sq;
  }
  const Eigen::Isometry3d T = Corrected(T_prior, x);
  if (!T.matrix().allFinite()) {
    result.message = "refinement diverged";
    return result;
  }
  result.T_prev_curr = T;
  result.inlier_mask = mask;
  result.num_inliers = n;
  result.rms_reprojection_px = n > 0 ? std::sqrt(sq / (2.0 * n)) : 0.0;
  if (n < o.min_inliers || n < o.min_inlier_fraction * static_cast<double>(corr.size())) {
    std::ostringstream msg;
    msg << "too few inliers (" << n << " of " << corr.size() << "; need " << o.min_inliers
        << " and a fraction " << o.min_inlier_fraction << ")";
    result.message = msg.str();
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace vo
