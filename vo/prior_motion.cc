#include "vo/prior_motion.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "vo/planar_motion_prior.h"

namespace vo {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNumericStep = 1e-6;     // central-difference step of the Jacobian (rad, m)
constexpr double kConvergedStep = 1e-10;  // stop when |δ|² falls below this

using Vector6d = Eigen::Matrix<double, 6, 1>;
// The parameters y and their map to x = (ω, v) = B · y: the identity (6 parameters), the
// planar basis (a rotation about up, two translations across it), or its first two columns
// (a vehicle's yaw and forward distance).
using Basis = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// The horizontal forward axis of a camera whose up direction is u (unit), as the BA's planar
// prior uses it.
Eigen::Vector3d HorizontalForward(const Eigen::Vector3d& u) { return HorizontalForwardAxis(u); }

// The rotation angle about u (unit) that turns the direction of b onto that of a, both seen
// across u (their components along u dropped; the callers check that neither vanishes).
double YawBetween(const Eigen::Vector3d& b, const Eigen::Vector3d& a, const Eigen::Vector3d& u) {
  const Eigen::Vector3d bh = b - b.dot(u) * u;
  const Eigen::Vector3d ah = a - a.dot(u) * u;
  return std::atan2(bh.cross(ah).dot(u), bh.dot(ah));
}

// Columns of B for a ground vehicle whose up direction in the current camera frame is `up`
// (unit): (up, 0), (0, e1), (0, e2) with e1, e2 spanning the plane perpendicular to up.
Basis PlanarBasis(const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d e1 = HorizontalForward(u);
  const Eigen::Vector3d e2 = u.cross(e1);
  Basis B = Basis::Zero(6, 3);
  B.block<3, 1>(0, 0) = u;
  B.block<3, 1>(3, 1) = e1;
  B.block<3, 1>(3, 2) = e2;
  return B;
}

// The motions searched, x = B · y. Without a vehicle: the prior corrected,
// T_prior · [Exp(ω) | v] (6-DoF, or planar with the planar basis). With one: the vehicle's
// motion of yaw yaw0 + u·ω and forward distance forward0 + e1·v (VehicleMotion), where
// (yaw0, forward0) are the prior's.
struct Model {
  Eigen::Isometry3d T_prior = Eigen::Isometry3d::Identity();
  Basis B;
  bool vehicle = false;
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  Eigen::Vector3d forward = Eigen::Vector3d::Zero();
  double axle_m = 0.0, yaw0 = 0.0, forward0 = 0.0;

  Eigen::Isometry3d At(const Vector6d& x) const {
    if (vehicle) {
      return VehicleMotion(up, axle_m, yaw0 + x.head<3>().dot(up),
                           forward0 + x.tail<3>().dot(forward));
    }
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d w = x.head<3>();
    const double angle = w.norm();
    if (angle > 0.0) D.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
    D.translation() = x.tail<3>();
    return T_prior * D;
  }
};

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
    if (!StereoReprojectionErrors(camera, T_curr_prev, corr[i], PriorMotionOptions::kMinDepthM, &el,
                                  &er))
      continue;
    if (el.squaredNorm() > thr_sq || er.squaredNorm() > thr_sq) continue;
    (*mask)[i] = true;
    ++n;
    *sq_sum += el.squaredNorm() + er.squaredNorm();
  }
  return n;
}

// Whitened residuals at x: per inlier (u_left, v_left, u_right) / σ_px, then ω / σ_rot, v / σ_t
// (the basis is orthonormal within ω and within v, so these are the parameters' own priors).
Eigen::VectorXd Residuals(const StereoCamera& camera, const std::vector<StereoCorrespondence>& corr,
                          const std::vector<int>& inliers, const Model& model, const Vector6d& x,
                          const PriorMotionOptions& o) {
  Eigen::VectorXd r(3 * inliers.size() + 6);
  const Eigen::Isometry3d T_curr_prev = model.At(x).inverse();
  const double inv_px = 1.0 / o.measurement_sigma_px;
  for (size_t k = 0; k < inliers.size(); ++k) {
    Eigen::Vector2d el, er;
    if (!StereoReprojectionErrors(camera, T_curr_prev, corr[inliers[k]],
                                  PriorMotionOptions::kMinDepthM, &el, &er)) {
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

// A wheeled vehicle's yaw and forward distance (x = B · y, from y0) that fit correspondence c
// alone: its left image position and its right image column (three residuals, two unknowns; no
// prior). One stereo point tells both, the bearing the yaw and the depth change the forward
// distance. False when the fit leaves the camera's view or does not stay finite.
bool FitVehicleToOnePoint(const StereoCamera& camera, const StereoCorrespondence& c,
                          const Model& model, const Eigen::Vector2d& y0,
                          const PriorMotionOptions& o, Vector6d* x) {
  const Basis& B = model.B;
  auto residual = [&](const Eigen::Vector2d& y, Eigen::Vector3d* r) {
    Eigen::Vector2d el, er;
    if (!StereoReprojectionErrors(camera, model.At(B * y).inverse(), c,
                                  PriorMotionOptions::kMinDepthM, &el, &er))
      return false;
    *r << el.x(), el.y(), er.x();
    return true;
  };
  Eigen::Vector2d y = y0;
  Eigen::Vector3d r;
  if (!residual(y, &r)) return false;
  for (int it = 0; it < o.max_iterations; ++it) {
    Eigen::Matrix<double, 3, 2> J;
    for (int j = 0; j < 2; ++j) {
      Eigen::Vector2d yp = y, ym = y;
      yp(j) += kNumericStep;
      ym(j) -= kNumericStep;
      Eigen::Vector3d rp, rm;
      if (!residual(yp, &rp) || !residual(ym, &rm)) return false;
      J.col(j) = (rp - rm) / (2.0 * kNumericStep);
    }
    const Eigen::Vector2d delta = -(J.transpose() * J).ldlt().solve(J.transpose() * r);
    if (!delta.allFinite()) return false;
    y += delta;
    if (!residual(y, &r)) return false;
    if (delta.squaredNorm() < kConvergedStep) break;
  }
  *x = B * y;
  return x->allFinite();
}

// Gauss-Newton on y (x = B · y) from y0 over the given inliers (a step that raises the cost is
// halved, at most a few times, then the iteration stops). Returns x.
Vector6d Refine(const StereoCamera& camera, const std::vector<StereoCorrespondence>& corr,
                const std::vector<bool>& mask, const Model& model, const Eigen::VectorXd& y0,
                const PriorMotionOptions& o) {
  const Basis& B = model.B;
  std::vector<int> inliers;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (mask[i]) inliers.push_back(static_cast<int>(i));
  }
  const int k = static_cast<int>(B.cols());
  Eigen::VectorXd y = y0;
  Eigen::VectorXd r = Residuals(camera, corr, inliers, model, B * y, o);
  double cost = r.squaredNorm();
  Eigen::MatrixXd J(r.size(), k);
  for (int it = 0; it < o.max_iterations; ++it) {
    for (int j = 0; j < k; ++j) {
      Eigen::VectorXd yp = y, ym = y;
      yp(j) += kNumericStep;
      ym(j) -= kNumericStep;
      J.col(j) = (Residuals(camera, corr, inliers, model, B * yp, o) -
                  Residuals(camera, corr, inliers, model, B * ym, o)) /
                 (2.0 * kNumericStep);
    }
    const Eigen::MatrixXd H = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    const Eigen::VectorXd delta = -H.ldlt().solve(g);
    if (!delta.allFinite()) break;
    double step = 1.0;
    bool improved = false;
    for (int halving = 0; halving < 4; ++halving, step *= 0.5) {
      const Eigen::VectorXd y_new = y + step * delta;
      const Eigen::VectorXd r_new = Residuals(camera, corr, inliers, model, B * y_new, o);
      const double cost_new = r_new.squaredNorm();
      if (cost_new <= cost) {
        y = y_new;
        r = r_new;
        cost = cost_new;
        improved = true;
        break;
      }
    }
    if (!improved || (step * delta).squaredNorm() < kConvergedStep) break;
  }
  return B * y;
}

// The parameters y of x in the basis B (B's columns are orthonormal: y = Bᵀ x).
Eigen::VectorXd Coordinates(const Basis& B, const Vector6d& x) { return B.transpose() * x; }

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
  } else if (!std::isfinite(axle_behind_camera_m)) {
    msg << "axle_behind_camera_m must be finite, got " << axle_behind_camera_m;
  }
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

// A rotation prior at least this tight (degrees) is a measurement (a gyro's, gyro_prior.h), not
// an extrapolation: the 1-point translation hypotheses below.
constexpr double kMeasuredRotationSigmaDeg = 0.5;

PriorMotionResult EstimateMotionWithPrior(const StereoCamera& camera,
                                          const std::vector<StereoCorrespondence>& corr,
                                          const Eigen::Isometry3d& T_prior,
                                          const PriorMotionOptions& o,
                                          const Eigen::Vector3d* up_curr) {
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
  if (up_curr != nullptr && (!up_curr->allFinite() || !(up_curr->norm() > 0.0))) {
    result.message = "invalid input: up direction must be finite and non-zero";
    return result;
  }
  Model model;
  model.T_prior = T_prior;
  model.B = up_curr != nullptr ? PlanarBasis(*up_curr) : Basis(Basis::Identity(6, 6));
  if (up_curr != nullptr && o.no_sideways_slip) {
    // A wheeled vehicle: yaw and forward distance only, from the prior's.
    model.vehicle = true;
    model.up = up_curr->normalized();
    model.forward = HorizontalForward(model.up);
    model.axle_m = o.axle_behind_camera_m;
    const Eigen::Vector2d yaw_forward = VehicleMotionParameters(T_prior, model.up, model.axle_m);
    model.yaw0 = yaw_forward(0);
    model.forward0 = yaw_forward(1);
    model.B = Basis(model.B.leftCols(2));
  }
  const Basis& B = model.B;
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
  int best_n = Classify(camera, corr, model.At(Vector6d::Zero()), o, &best_mask, &best_sq);
  // A hypothesis x is kept when more correspondences agree with it (ties: the smaller sum of
  // squared errors; the earlier one).
  auto consider = [&](const Vector6d& x) {
    if (!x.allFinite()) return;
    std::vector<bool> mask;
    double sq = 0.0;
    const int n = Classify(camera, corr, model.At(x), o, &mask, &sq);
    if (n > best_n || (n == best_n && sq < best_sq)) {
      best_n = n;
      best_sq = sq;
      best_x = x;
      best_mask = std::move(mask);
    }
  };
  const Eigen::Matrix3d R_prior = T_prior.linear();
  // A vehicle's 1-point yaw correction per correspondence (NaN: none).
  std::vector<double> point_yaw(corr.size(), std::numeric_limits<double>::quiet_NaN());
  for (size_t i = 0; i < corr.size(); ++i) {
    // The observed bearing b in the current camera; the point's direction a' seen from the
    // prior's camera centre, in the prior's rotated frame. Q b = a' (smallest rotation).
    const Eigen::Vector3d b((corr[i].uv_curr_px.x() - camera.cx_px) / camera.fx_px,
                            (corr[i].uv_curr_px.y() - camera.cy_px) / camera.fy_px, 1.0);
    const Eigen::Vector3d a = R_prior.transpose() * (corr[i].p_prev_cam0 - T_prior.translation());
    if (!(a.norm() > 0.0) || a.normalized().dot(b.normalized()) <= 0.0) continue;
    Vector6d x = Vector6d::Zero();
    if (model.vehicle) {
      // The vehicle's yaw that puts the point on its bearing: the yaw moves the camera about
      // the axle too, so the rotation about up that turns b's horizontal direction onto the
      // point's (seen from the moved camera) is repeated until it settles.
      const Eigen::Vector3d& u = model.up;
      double yaw = 0.0;
      bool settled = (b - b.dot(u) * u).norm() > 0.0;
      for (int it = 0; settled && it < 5; ++it) {
        x.head<3>() = yaw * u;
        const Eigen::Isometry3d T = model.At(x);
        const Eigen::Vector3d p = T.linear().transpose() * (corr[i].p_prev_cam0 - T.translation());
        if (!((p - p.dot(u) * u).norm() > 0.0) || p.dot(b) <= 0.0) {
          settled = false;
          break;
        }
        const double step = YawBetween(b, p, u);
        yaw += step;
        if (std::abs(step) < 1e-12) break;
      }
      if (!settled) continue;
      x.head<3>() = yaw * u;
      point_yaw[i] = yaw;
    } else if (up_curr != nullptr) {
      // Planar: the rotation about up that turns b's horizontal direction onto a's.
      const Eigen::Vector3d u = B.block<3, 1>(0, 0);
      if (!((b - b.dot(u) * u).norm() > 0.0) || !((a - a.dot(u) * u).norm() > 0.0)) continue;
      x.head<3>() = YawBetween(b, a, u) * u;
    } else {
      const Eigen::AngleAxisd Q(Eigen::Quaterniond::FromTwoVectors(b, a));
      x.head<3>() = Q.angle() * Q.axis();
    }
    consider(x);
  }
  // The support an ok result needs (checked at the end): min_inliers and min_inlier_fraction.
  const double needed =
      std::max(static_cast<double>(o.min_inliers), o.min_inlier_fraction * corr.size());
  // A vehicle whose prior's forward distance is far off (a robot that brakes and then turns in
  // place: l_hallway with the camera pitched 20°, stride 3, the first frame of the turn, where
  // the prior kept 8.6 cm of the braking steps and no yaw alone put any of 10 correct matches
  // within 2 px): when no hypothesis above has the support the result needs, each point's own
  // forward distance as well (FitVehicleToOnePoint, from its yaw).
  if (model.vehicle && best_n < needed) {
    for (size_t i = 0; i < corr.size(); ++i) {
      Vector6d x_fit;
      if (std::isfinite(point_yaw[i]) &&
          FitVehicleToOnePoint(camera, corr[i], model, Eigen::Vector2d(point_yaw[i], 0.0), o,
                               &x_fit))
        consider(x_fit);
    }
  }
  // A 6-DoF prior whose rotation is measured (a gyro's: prior_rotation_sigma_deg at most
  // kMeasuredRotationSigmaDeg) and whose translation is far off (the constant velocity carried
  // into a robot that stops to turn): when no hypothesis above has the support the result
  // needs, each point's own translation with the prior's rotation (p_prev = R p_curr + t for
  // that point, its current position from its disparity) as well.
  if (!model.vehicle && up_curr == nullptr && best_n < needed &&
      o.prior_rotation_sigma_deg <= kMeasuredRotationSigmaDeg) {
    for (size_t i = 0; i < corr.size(); ++i) {
      if (!(corr[i].disparity_curr_px > 0.0)) continue;
      const Eigen::Vector3d p_curr = camera.Backproject(
          corr[i].uv_curr_px.x(), corr[i].uv_curr_px.y(), corr[i].disparity_curr_px);
      Vector6d x = Vector6d::Zero();
      x.tail<3>() = R_prior.transpose() * (corr[i].p_prev_cam0 - T_prior.translation()) - p_curr;
      consider(x);
    }
  }
  if (best_n == 0) {
    result.message = "no correspondence agrees with the prior";
    return result;
  }

  // Refine on the inliers, re-classify, refine again.
  Vector6d x = Refine(camera, corr, best_mask, model, Coordinates(B, best_x), o);
  std::vector<bool> mask;
  double sq = 0.0;
  int n = Classify(camera, corr, model.At(x), o, &mask, &sq);
  if (n >= best_n && mask != best_mask) {
    x = Refine(camera, corr, mask, model, Coordinates(B, x), o);
    n = Classify(camera, corr, model.At(x), o, &mask, &sq);
  }
  if (n < best_n) {  // the refinement lost support: keep the hypothesis
    x = best_x;
    mask = best_mask;
    n = best_n;
    sq = best_sq;
  }
  const Eigen::Isometry3d T = model.At(x);
  if (!T.matrix().allFinite()) {
    result.message = "refinement diverged";
    return result;
  }
  result.T_prev_curr = T;
  result.inlier_mask = mask;
  result.num_inliers = n;
  result.rms_reprojection_px = n > 0 ? std::sqrt(sq / (2.0 * n)) : 0.0;
  if (n < needed) {
    std::ostringstream msg;
    msg << "too few inliers (" << n << " of " << corr.size() << "; need " << o.min_inliers
        << " and a fraction " << o.min_inlier_fraction << ")";
    result.message = msg.str();
    return result;
  }
  result.ok = true;
  return result;
}

Eigen::Isometry3d PlanarPart(const Eigen::Isometry3d& T_a_b, const Eigen::Vector3d& up_a) {
  if (!T_a_b.matrix().allFinite() || !up_a.allFinite() || !(up_a.norm() > 0.0)) return T_a_b;
  const Eigen::Vector3d u = up_a.normalized();
  // Swing-twist: the twist is the quaternion's vector part projected onto the axis.
  const Eigen::Quaterniond q(T_a_b.linear());
  Eigen::Quaterniond twist(q.w(), 0.0, 0.0, 0.0);
  twist.vec() = q.vec().dot(u) * u;
  Eigen::Isometry3d P = Eigen::Isometry3d::Identity();
  if (twist.norm() > 1e-12) P.linear() = twist.normalized().toRotationMatrix();
  const Eigen::Vector3d t = T_a_b.translation();
  P.translation() = t - t.dot(u) * u;
  return P;
}

Eigen::Isometry3d VehicleMotion(const Eigen::Vector3d& up, double axle_behind_camera_m,
                                double yaw_rad, double forward_m) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d e1 = HorizontalForward(u);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw_rad, u).toRotationMatrix();
  // The axle point a = −d·e1 (each camera's own coordinates) moves by forward_m along the
  // heading at half the turn: R·a + t = a + forward_m · Rot(yaw/2)·e1.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() =
      axle_behind_camera_m * (R * e1 - e1) + forward_m * (Eigen::AngleAxisd(0.5 * yaw_rad, u) * e1);
  return T;
}

Eigen::Vector2d VehicleMotionParameters(const Eigen::Isometry3d& T, const Eigen::Vector3d& up,
                                        double axle_behind_camera_m) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d e1 = HorizontalForward(u);
  const Eigen::Quaterniond q(T.linear());
  const double yaw = 2.0 * std::atan2(q.vec().dot(u), q.w());
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, u).toRotationMatrix();
  const Eigen::Vector3d axle_step = T.translation() - axle_behind_camera_m * (R * e1 - e1);
  const double forward = axle_step.dot(Eigen::AngleAxisd(0.5 * yaw, u) * e1);
  return Eigen::Vector2d(std::remainder(yaw, 2.0 * kPi), forward);
}

}  // namespace vo
