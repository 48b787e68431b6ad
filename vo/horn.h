// Closed-form rigid motion between two matched 3D point sets with unit quaternions:
// Kwolek, docs/PAPER.md "pose, rough", eq. (6)-(7), after Horn (1987), "Closed-form solution of
// absolute orientation using unit quaternions", JOSA A 4(4).
//
// Given matched points u_i (source) and v_i (target) with v_i ≈ R u_i + t, the estimate
// minimises the (weighted) least-squares error  Σ w_i |v_i − (R u_i + t)|²:
//   1. centre both sets on their (weighted) means ū, v̄ (the paper's centroid line writes
//      ũ = (1/n) Σ ũ_i; it means the mean of the raw points u_i, which is what is used);
//   2. per pair build Z_i from a_i = ṽ_i − ũ_i and s_i = ṽ_i + ũ_i, eq. (6), so that
//      Z_i q = q ⊗ ũ_i − ṽ_i ⊗ q (quaternion products, ũ, ṽ as pure quaternions);
//   3. M = Σ w_i Z_iᵀ Z_i (4×4, symmetric, positive semi-definite), eq. (6);
//   4. q = unit eigenvector of M's smallest eigenvalue; R from q by eq. (7);
//   5. t = v̄ − R ū.
//
// Which Z_i: the paper prints Z_i as the 3×4 matrix [a_i | [s_i]×] (the vector part of
// q ⊗ ũ − ṽ ⊗ q; its row 3 carries a sign typo, −ṽ₁+ũ₁ where ṽ₁+ũ₁ is meant). We use the full
// 4×4 Z_i = [0 a_iᵀ; a_i [s_i]×], i.e. we add the scalar row a_i·q_v of the same product.
// With it, |Z_i q|² = |R ũ_i − ṽ_i|² exactly for a unit q, so qᵀMq IS the least-squares
// cost, and M = Σ w_i (|ũ_i|² + |ṽ_i|²) I₄ − 2N, where N is Horn's (1987) 4×4 matrix built
// from the cross-covariance Σ w_i ũ_i ṽ_iᵀ: the smallest eigenvector of M is the largest
// eigenvector of Horn's N, the same estimate as Horn's and Umeyama's (1991) methods. The
// paper's 3×4 version drops the scalar rows; it agrees on noise-free data but is not the
// least-squares estimate under noise.
//
// Degenerate inputs (kDegenerate): all points (nearly) coincident, or (nearly) collinear in
// either set (the rotation about the line is then free), detected from the singular values
// σ₁ ≥ σ₂ ≥ σ₃ of the centred 3×n point matrices: σ₂/σ₁ below collinear_tolerance, or the rms
// distance from the centroid below min_spread_m. Coplanar sets (e.g. three points) are fine.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace vo {

struct HornOptions {
  double collinear_tolerance = 1e-6;  // the set is collinear when σ₂/σ₁ of its centred point
                                      // matrix is below this (dimensionless), in [0, 1)
  double min_spread_m = 1e-9;         // the set is coincident when the rms distance of its points
                                      // from their centroid is below this (metres), >= 0
  double min_eigengap_ratio = 1e-12;  // the rotation is ambiguous when the two smallest
                                      // eigenvalues of M differ by less than this times its
                                      // largest eigenvalue (dimensionless), >= 0

  bool IsValid(std::string* error) const;
};

struct HornResult {
  enum class Status {
    kOk,            // T_dst_src holds the least-squares rigid motion
    kTooFewPoints,  // fewer than 3 points (or fewer than 3 with positive weight)
    kDegenerate,    // coincident or collinear points, or an ambiguous rotation
    kInvalidInput,  // size mismatch, non-finite numbers, negative weights, invalid options
  };
  Status status = Status::kInvalidInput;
  std::string message;  // empty when kOk; otherwise says what was wrong
  Eigen::Isometry3d T_dst_src = Eigen::Isometry3d::Identity();  // v ≈ T_dst_src * u, i.e.
                                                                // v ≈ R u + t; identity unless kOk
  Eigen::Vector4d q_wxyz =
      Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);  // the rotation as the unit
                                            // quaternion [q0 q1 q2 q3] of eq. (7), q0 >= 0
  double rms_residual_m = 0.0;  // sqrt(Σ w_i |v_i − T u_i|² / Σ w_i) (metres); 0 unless kOk
  int num_points = 0;           // points used (positive weight)

  bool ok() const { return status == Status::kOk; }
};

// "ok", "too_few_points", "degenerate", "invalid_input".
const char* ToString(HornResult::Status status);

// Rotation matrix of the unit quaternion q = [q0 q1 q2 q3] (q0 = scalar part), eq. (7).
Eigen::Matrix3d RotationFromQuaternionEq7(const Eigen::Vector4d& q_wxyz);

// The rigid motion T with dst_i ≈ T * src_i (least squares, all weights 1). src, dst: 3×n,
// column i of each is one matched pair (metres, any common frame convention). Never throws.
HornResult EstimateRigidMotionHorn(const Eigen::Ref<const Eigen::Matrix3Xd>& src,
                                   const Eigen::Ref<const Eigen::Matrix3Xd>& dst,
                                   const HornOptions& options = HornOptions());

// Weighted version: minimises Σ w_i |dst_i − T src_i|². weights: n finite values >= 0 with a
// positive sum; zero-weight pairs are ignored (also by the degeneracy tests).
HornResult EstimateRigidMotionHorn(const Eigen::Ref<const Eigen::Matrix3Xd>& src,
                                   const Eigen::Ref<const Eigen::Matrix3Xd>& dst,
                                   const Eigen::Ref<const Eigen::VectorXd>& weights,
                                   const HornOptions& options = HornOptions());

}  // namespace vo
