#include "vo/horn.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace vo {

bool HornOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!(collinear_tolerance >= 0.0 && collinear_tolerance < 1.0))
    msg << "collinear_tolerance must be in [0, 1), got " << collinear_tolerance;
  else if (!(min_spread_m >= 0.0) || !std::isfinite(min_spread_m))
    msg << "min_spread_m must be finite and >= 0, got " << min_spread_m;
  else if (!(min_eigengap_ratio >= 0.0) || !std::isfinite(min_eigengap_ratio))
    msg << "min_eigengap_ratio must be finite and >= 0, got " << min_eigengap_ratio;
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

const char* ToString(HornResult::Status status) {
  switch (status) {
    case HornResult::Status::kOk:
      return "ok";
    case HornResult::Status::kTooFewPoints:
      return "too_few_points";
    case HornResult::Status::kDegenerate:
      return "degenerate";
    case HornResult::Status::kInvalidInput:
      return "invalid_input";
  }
  return "unknown";
}

Eigen::Matrix3d RotationFromQuaternionEq7(const Eigen::Vector4d& q_wxyz) {
  const double q0 = q_wxyz[0], q1 = q_wxyz[1], q2 = q_wxyz[2], q3 = q_wxyz[3];
  Eigen::Matrix3d R;
  // eq. (7), row by row.
  // clang-format off
  R << q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, 2.0 * (q1 * q2 - q0 * q3), 2.0 * (q1 * q3 + q0 * q2),
      2.0 * (q2 * q1 + q0 * q3), q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3, 2.0 * (q2 * q3 - q0 * q1),
      2.0 * (q3 * q1 - q0 * q2), 2.0 * (q3 * q2 + q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3;
  // clang-format on
  return R;
}

namespace {

HornResult Fail(HornResult::Status status, const std::string& message) {
  HornResult r;
  r.status = status;
  r.message = message;
  return r;
}

// Degeneracy test of one centred, weighted point set. Returns an empty string when fine.
// scatter = Σ w_i p̃_i p̃_iᵀ; its eigenvalues are the squared singular values of the
// sqrt(w)-scaled centred 3×n matrix.
std::string CheckSpread(const Eigen::Matrix3d& scatter, double weight_sum, const char* name,
                        const HornOptions& options) {
  const double rms_spread_m = std::sqrt(std::max(scatter.trace(), 0.0) / weight_sum);
  std::ostringstream msg;
  if (!(rms_spread_m >= options.min_spread_m) || rms_spread_m == 0.0) {
    msg << name << " points coincide (rms spread " << rms_spread_m << " m)";
    return msg.str();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d lambda = eig.eigenvalues();                            // ascending
  const double sigma_ratio = std::sqrt(std::max(lambda[1], 0.0) / lambda[2]);  // σ₂/σ₁
  if (!(sigma_ratio >= options.collinear_tolerance) || sigma_ratio == 0.0) {
    msg << name << " points are collinear (sigma2/sigma1 = " << sigma_ratio << ")";
    return msg.str();
  }
  return std::string();
}

HornResult Estimate(const Eigen::Ref<const Eigen::Matrix3Xd>& src,
                    const Eigen::Ref<const Eigen::Matrix3Xd>& dst, const Eigen::VectorXd* weights,
                    const HornOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return Fail(HornResult::Status::kInvalidInput, error);
  const Eigen::Index n = src.cols();
  if (dst.cols() != n) {
    std::ostringstream msg;
    msg << "src has " << n << " points, dst has " << dst.cols();
    return Fail(HornResult::Status::kInvalidInput, msg.str());
  }
  if (weights && weights->size() != n) {
    std::ostringstream msg;
    msg << "weights has " << weights->size() << " entries for " << n << " points";
    return Fail(HornResult::Status::kInvalidInput, msg.str());
  }
  if (!src.allFinite() || !dst.allFinite())
    return Fail(HornResult::Status::kInvalidInput, "points must be finite");
  if (weights && (!weights->allFinite() || (weights->array() < 0.0).any()))
    return Fail(HornResult::Status::kInvalidInput, "weights must be finite and >= 0");

  auto weight = [&](Eigen::Index i) { return weights ? (*weights)[i] : 1.0; };
  int num_used = 0;
  double weight_sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (weight(i) > 0.0) {
      ++num_used;
      weight_sum += weight(i);
    }
  }
  if (num_used < 3) {
    std::ostringstream msg;
    msg << "need at least 3 points with positive weight, got " << num_used;
    HornResult r = Fail(HornResult::Status::kTooFewPoints, msg.str());
    r.num_points = num_used;
    return r;
  }

  // Step 1: centroids ū, v̄ of the raw points (the text's ũ = (1/n) Σ ũ_i is a typo).
  Eigen::Vector3d u_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_mean = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w = weight(i);
    if (w <= 0.0) continue;
    u_mean += w * src.col(i);
    v_mean += w * dst.col(i);
  }
  u_mean /= weight_sum;
  v_mean /= weight_sum;

  // Steps 2-3: eq. (6), M = Σ w_i Z_iᵀ Z_i with Z_i q = q ⊗ ũ_i − ṽ_i ⊗ q (see horn.h), and the
  // scatter matrices of both centred sets for the degeneracy tests.
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  Eigen::Matrix3d scatter_u = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d scatter_v = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w = weight(i);
    if (w <= 0.0) continue;
    const Eigen::Vector3d u = src.col(i) - u_mean;  // ũ_i
    const Eigen::Vector3d v = dst.col(i) - v_mean;  // ṽ_i
    const Eigen::Vector3d a = v - u;
    const Eigen::Vector3d s = v + u;
    Eigen::Matrix4d Z;
    // Row 0: scalar part a·q_v (omitted in the paper's 3×4 print); rows 1-3: the paper's
    // Z_i = [a | [s]×] (vector part q0 a + s × q_v).
    // clang-format off
    Z << 0.0, a.x(), a.y(), a.z(),
         a.x(), 0.0, -s.z(), s.y(),
         a.y(), s.z(), 0.0, -s.x(),
         a.z(), -s.y(), s.x(), 0.0;
    // clang-format on
    M.noalias() += w * (Z.transpose() * Z);
    scatter_u.noalias() += w * (u * u.transpose());
    scatter_v.noalias() += w * (v * v.transpose());
  }

  std::string degenerate = CheckSpread(scatter_u, weight_sum, "source", options);
  if (degenerate.empty()) degenerate = CheckSpread(scatter_v, weight_sum, "target", options);
  if (!degenerate.empty()) {
    HornResult r = Fail(HornResult::Status::kDegenerate, degenerate);
    r.num_points = num_used;
    return r;
  }

  // Step 4: q = eigenvector of the smallest eigenvalue of M (eigenvalues come ascending).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(M);
  if (eig.info() != Eigen::Success)
    return Fail(HornResult::Status::kDegenerate, "eigen decomposition of M failed");
  const Eigen::Vector4d lambda = eig.eigenvalues();
  if (lambda[1] - lambda[0] <= options.min_eigengap_ratio * std::abs(lambda[3])) {
    std::ostringstream msg;
    msg << "rotation is ambiguous: the two smallest eigenvalues of M are " << lambda[0] << " and "
        << lambda[1];
    HornResult r = Fail(HornResult::Status::kDegenerate, msg.str());
    r.num_points = num_used;
    return r;
  }
  Eigen::Vector4d q = eig.eigenvectors().col(0).normalized();
  if (q[0] < 0.0) q = -q;  // q and −q give the same rotation; keep q0 >= 0

  // eq. (7) and step 5: t = v̄ − R ū.
  const Eigen::Matrix3d R = RotationFromQuaternionEq7(q);
  const Eigen::Vector3d t = v_mean - R * u_mean;

  HornResult r;
  r.status = HornResult::Status::kOk;
  r.T_dst_src.setIdentity();
  r.T_dst_src.linear() = R;
  r.T_dst_src.translation() = t;
  r.q_wxyz = q;
  r.num_points = num_used;
  double sq_sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w = weight(i);
    if (w <= 0.0) continue;
    sq_sum += w * (dst.col(i) - (R * src.col(i) + t)).squaredNorm();
  }
  r.rms_residual_m = std::sqrt(sq_sum / weight_sum);
  return r;
}

}  // namespace

HornResult EstimateRigidMotionHorn(const Eigen::Ref<const Eigen::Matrix3Xd>& src,
                                   const Eigen::Ref<const Eigen::Matrix3Xd>& dst,
                                   const HornOptions& options) {
  return Estimate(src, dst, nullptr, options);
}

HornResult EstimateRigidMotionHorn(const Eigen::Ref<const Eigen::Matrix3Xd>& src,
                                   const Eigen::Ref<const Eigen::Matrix3Xd>& dst,
                                   const Eigen::Ref<const Eigen::VectorXd>& weights,
                                   const HornOptions& options) {
  const Eigen::VectorXd w = weights;
  return Estimate(src, dst, &w, options);
}

}  // namespace vo
