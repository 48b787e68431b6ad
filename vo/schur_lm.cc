#include "vo/schur_lm.h"

#include <ceres/jet.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include "vo/rotation_prior.h"

namespace vo {
namespace {

// Solver::Options defaults of Ceres 2.1 that the Ceres backend leaves untouched; the names are
// Ceres' option names.
constexpr double kInitialTrustRegionRadius = 1e4;  // initial_trust_region_radius
constexpr double kMaxTrustRegionRadius = 1e16;     // max_trust_region_radius
constexpr double kMinTrustRegionRadius = 1e-32;    // min_trust_region_radius
constexpr double kMinLmDiagonal = 1e-6;            // min_lm_diagonal
constexpr double kMaxLmDiagonal = 1e32;            // max_lm_diagonal
constexpr double kMinRelativeDecrease = 1e-3;      // min_relative_decrease
constexpr int kMaxConsecutiveInvalidSteps = 5;     // max_num_consecutive_invalid_steps
// A residual is not defined at or behind this depth (metres), as in the Ceres cost functions.
constexpr double kMinResidualDepthM = 1e-9;

using Matrix43 = Eigen::Matrix<double, 4, 3>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

[[noreturn]] void Abort(const std::string& what) {
  std::fprintf(stderr, "SolveSchurLm: %s\n", what.c_str());
  std::abort();
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

// m⁻¹ of a symmetric 3×3 matrix (cofactors); false unless positive definite (leading minors
// > 0, Sylvester's criterion) with a finite inverse.
bool InvertSymmetricPositiveDefinite3(const Eigen::Matrix3d& m, Eigen::Matrix3d* inv) {
  const double c00 = m(1, 1) * m(2, 2) - m(1, 2) * m(1, 2);
  const double c01 = m(0, 2) * m(1, 2) - m(0, 1) * m(2, 2);
  const double c02 = m(0, 1) * m(1, 2) - m(0, 2) * m(1, 1);
  const double det = m(0, 0) * c00 + m(0, 1) * c01 + m(0, 2) * c02;
  const double minor01 = m(0, 0) * m(1, 1) - m(0, 1) * m(0, 1);
  if (!(m(0, 0) > 0.0) || !(minor01 > 0.0) || !(det > 0.0)) return false;
  const double inv_det = 1.0 / det;
  const double c11 = m(0, 0) * m(2, 2) - m(0, 2) * m(0, 2);
  const double c12 = m(0, 1) * m(0, 2) - m(0, 0) * m(1, 2);
  const double c22 = minor01;
  *inv << c00, c01, c02, c01, c11, c12, c02, c12, c22;
  *inv *= inv_det;
  return inv->allFinite();
}

// ρ(s) and ρ'(s) exactly as ceres::HuberLoss / ceres::CauchyLoss with scale a; identity for
// kNone (no loss function in Ceres).
void Rho(RobustLoss loss, double a, double s, double* rho0, double* rho1) {
  switch (loss) {
    case RobustLoss::kNone:
      break;
    case RobustLoss::kHuber: {
      const double b = a * a;
      if (s > b) {
        const double r = std::sqrt(s);
        *rho0 = 2.0 * a * r - b;
        *rho1 = std::max(std::numeric_limits<double>::min(), a / r);
        return;
      }
      break;
    }
    case RobustLoss::kCauchy: {
      const double b = a * a;
      const double c = 1.0 / b;
      const double sum = 1.0 + s * c;
      const double inv = 1.0 / sum;
      *rho0 = b * std::log(sum);
      *rho1 = std::max(std::numeric_limits<double>::min(), inv);
      return;
    }
  }
  *rho0 = s;
  *rho1 = 1.0;
}

// ceres::EigenQuaternionManifold::Plus: out = [cos|δ|, sin|δ| δ/|δ|] ⊗ q.
void QuaternionPlus(const double* q, const double* delta, double* out) {
  const double norm_delta =
      std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
  const Eigen::Map<const Eigen::Quaterniond> x(q);
  Eigen::Map<Eigen::Quaterniond> x_plus_delta(out);
  if (norm_delta == 0.0) {
    x_plus_delta = x;
    return;
  }
  const double sin_by_norm = std::sin(norm_delta) / norm_delta;
  const Eigen::Quaterniond delta_q(std::cos(norm_delta), sin_by_norm * delta[0],
                                   sin_by_norm * delta[1], sin_by_norm * delta[2]);
  x_plus_delta = delta_q * x;
}

// ceres::EigenQuaternionManifold::PlusJacobian at q (4×3, rows x y z w).
Eigen::Matrix<double, 4, 3> QuaternionPlusJacobian(const double* q) {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  Eigen::Matrix<double, 4, 3> J;
  J << w, z, -y,  //
      -z, w, x,   //
      y, -x, w,   //
      -x, -y, -z;
  return J;
}

// A planar motion prior block (planar_motion_prior.h) of poses a and b: its residual and its
// Jacobians w.r.t. the two tangents [δθ δt], by ceres::Jet over the 14 ambient parameters
// times the manifold's Plus Jacobian (what ceres::AutoDiffCostFunction and the manifold give
// the Ceres backend).
constexpr int kLinkRows = PlanarMotionResidual::kNumResiduals;
using LinkVector = Eigen::Matrix<double, kLinkRows, 1>;
using LinkJacobian = Eigen::Matrix<double, kLinkRows, 6>;
void PlanarResidualAndJacobians(const PlanarMotionResidual& f, const PoseBlock7& a,
                                const PoseBlock7& b, LinkVector* r, LinkJacobian* J_a,
                                LinkJacobian* J_b) {
  using Jet = ceres::Jet<double, 14>;
  Jet pa[7], pb[7], out[kLinkRows];
  for (int c = 0; c < 7; ++c) {
    pa[c] = Jet(a[c], c);
    pb[c] = Jet(b[c], 7 + c);
  }
  f.EvaluateJets(pa, pb, out);
  Eigen::Matrix<double, kLinkRows, 14> J;
  for (int k = 0; k < kLinkRows; ++k) {
    (*r)(k) = out[k].a;
    J.row(k) = out[k].v.transpose();
  }
  J_a->leftCols<3>() = J.block<kLinkRows, 4>(0, 0) * QuaternionPlusJacobian(a.data());
  J_a->rightCols<3>() = J.block<kLinkRows, 3>(0, 4);
  J_b->leftCols<3>() = J.block<kLinkRows, 4>(0, 7) * QuaternionPlusJacobian(b.data());
  J_b->rightCols<3>() = J.block<kLinkRows, 3>(0, 11);
}

// Sums over a link's rows, the relative rows (4) and the flat floor's (3) apart, so that a
// prior without the flat floor (rows 4..6 zero) adds exactly what a 4-row block would.
double LinkSquaredNorm(const LinkVector& v) {
  return v.head<4>().squaredNorm() + v.tail<3>().squaredNorm();
}
double LinkDot(const LinkVector& a, const LinkVector& b) {
  return a.head<4>().dot(b.head<4>()) + a.tail<3>().dot(b.tail<3>());
}
// The squared norms of the columns of J (the Jacobi scaling's diagonal).
Vector6 LinkColumnSquaredNorms(const LinkJacobian& J) {
  return J.topRows<4>().colwise().squaredNorm().transpose() +
         J.bottomRows<3>().colwise().squaredNorm().transpose();
}
Vector6 LinkJtr(const LinkJacobian& J, const LinkVector& r) {
  return J.topRows<4>().transpose() * r.head<4>() + J.bottomRows<3>().transpose() * r.tail<3>();
}
Matrix6 LinkJtJ(const LinkJacobian& A, const LinkJacobian& B) {
  return A.topRows<4>().transpose() * B.topRows<4>() +
         A.bottomRows<3>().transpose() * B.bottomRows<3>();
}

// A rotation prior block (rotation_prior.h) of poses a and b: its residual and its Jacobians
// w.r.t. the two tangents [δθ δt] (zero for δt), by ceres::Jet over the two quaternions times
// the manifold's Plus Jacobian.
using RotationLinkJacobian = Eigen::Matrix<double, 3, 6>;
void RotationResidualAndJacobians(const RotationPriorResidual& f, const PoseBlock7& a,
                                  const PoseBlock7& b, Eigen::Vector3d* r,
                                  RotationLinkJacobian* J_a, RotationLinkJacobian* J_b) {
  using Jet = ceres::Jet<double, 8>;
  Jet pa[7], pb[7], out[3];
  for (int c = 0; c < 7; ++c) {
    pa[c] = c < 4 ? Jet(a[c], c) : Jet(a[c]);
    pb[c] = c < 4 ? Jet(b[c], 4 + c) : Jet(b[c]);
  }
  f(pa, pb, out);
  Eigen::Matrix<double, 3, 8> J;
  for (int k = 0; k < 3; ++k) {
    (*r)(k) = out[k].a;
    J.row(k) = out[k].v.transpose();
  }
  J_a->leftCols<3>() = J.leftCols<4>() * QuaternionPlusJacobian(a.data());
  J_a->rightCols<3>().setZero();
  J_b->leftCols<3>() = J.rightCols<4>() * QuaternionPlusJacobian(b.data());
  J_b->rightCols<3>().setZero();
}

// The residual block r = [u_l, v_l, u_r, v_r] − observed (rows 2, 3 zero for a left-only
// observation) of the point at v = p_world − t_world_cam0 and, optionally, the distinct rows of
// ∂r/∂p_world: a.row(0) of u_l, a.row(1) of v_l (and of v_r, the same), a.row(2) of u_r (zero
// for a left-only observation). False when the depth is <= 1e-9.
inline bool ResidualAndPointRows(const StereoCamera& cam, const Eigen::Matrix3d& R_cam0_world,
                                 const Eigen::Vector3d& v, const SchurLmResidual& obs,
                                 Eigen::Vector4d* r, Eigen::Matrix3d* a) {
  const Eigen::Vector3d p = R_cam0_world * v;
  if (!(p.z() > kMinResidualDepthM)) return false;
  const double inv_z = 1.0 / p.z();
  const double v_px = cam.fy_px * p.y() * inv_z + cam.cy_px;
  (*r)(0) = cam.fx_px * p.x() * inv_z + cam.cx_px - obs.uv_left_px.x();
  (*r)(1) = v_px - obs.uv_left_px.y();
  if (obs.has_right) {
    (*r)(2) = cam.fx_px * (p.x() - cam.baseline_m) * inv_z + cam.cx_px - obs.uv_right_px.x();
    (*r)(3) = v_px - obs.uv_right_px.y();
  } else {
    (*r)(2) = (*r)(3) = 0.0;
  }
  if (a == nullptr) return true;
  // ∂r/∂p_cam0 rows times ∂p_cam0/∂p_world = R_cam0_world.
  const double inv_z2 = inv_z * inv_z;
  const double fx_z = cam.fx_px * inv_z;
  a->row(0) = fx_z * R_cam0_world.row(0) - (cam.fx_px * p.x() * inv_z2) * R_cam0_world.row(2);
  a->row(1) = (cam.fy_px * inv_z) * R_cam0_world.row(1) -
              (cam.fy_px * p.y() * inv_z2) * R_cam0_world.row(2);
  if (obs.has_right) {
    a->row(2) = fx_z * R_cam0_world.row(0) -
                (cam.fx_px * (p.x() - cam.baseline_m) * inv_z2) * R_cam0_world.row(2);
  } else {
    a->row(2).setZero();
  }
  return true;
}

// S −= [−[a]× C [b]×, [a]× C; −C [b]×, C] (= B_aᵀ C B_b for B_x = [[x]×, −I]), by cross
// products: ([a]× C) column j = a × C_j, (M [b]×) row i = M_i × b.
void SubtractExpanded(const Eigen::Matrix3d& C, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      Matrix6* S) {
  Eigen::Matrix3d aC, Cb, aCb;
  for (int j = 0; j < 3; ++j) aC.col(j) = a.cross(C.col(j));
  for (int i = 0; i < 3; ++i) {
    Cb.row(i) = C.row(i).cross(b.transpose());
    aCb.row(i) = aC.row(i).cross(b.transpose());
  }
  S->topLeftCorner<3, 3>() += aCb;
  S->topRightCorner<3, 3>() -= aC;
  S->bottomLeftCorner<3, 3>() += Cb;
  S->bottomRightCorner<3, 3>() -= C;
}

// S += B_aᵀ D B_a = [−[a]× D [a]×, [a]× D; −D [a]×, D] for a symmetric D, lower triangle only
// (the top-right block is left alone; −D [a]× = ([a]× D)ᵀ).
void AddSymmetricExpandedLower(const Eigen::Matrix3d& D, const Eigen::Vector3d& a, Matrix6* S) {
  Eigen::Matrix3d aD, aDa;
  for (int j = 0; j < 3; ++j) aD.col(j) = a.cross(D.col(j));
  for (int i = 0; i < 3; ++i) aDa.row(i) = aD.row(i).cross(a.transpose());
  S->topLeftCorner<3, 3>() -= aDa;
  S->bottomLeftCorner<3, 3>() += aD.transpose();
  S->bottomRightCorner<3, 3>() += D;
}

class Solver {
 public:
  Solver(const StereoCamera& cam, const BundleAdjustmentOptions& options,
         const std::vector<SchurLmResidual>& residuals, const std::vector<bool>& pose_is_free,
         std::vector<PoseBlock7>* poses, std::vector<Eigen::Vector3d>* points,
         const std::vector<std::pair<int, int>>& planar_links, const PlanarMotionPrior& planar,
         const std::vector<RotationPrior>& rotation_priors);
  SchurLmSummary Run();

 private:
  // One residual block (observation) of the problem.
  struct Block {
    int residual = -1;   // index into residuals_
    int pose = -1;       // pose index
    int slot = -1;       // free-pose slot (6 unknowns of the reduced system), -1 = constant
    int point = -1;      // compact point index
    Eigen::Matrix3d HE;  // H (point block)⁻¹ of the current step (slot >= 0 only)
  };
  // A residual block linearised. With A = √ρ' ∂r/∂p_world (4×3) and B = [[v2]×, −I] (3×6),
  // the weighted Jacobian is [A B, A] (pose tangent, point), so the normal equations need only
  // H = AᵀA and g = Aᵀ √ρ' r: pose–pose BᵀHB, pose–point BᵀH, point–point H, gradient [Bᵀg, g].
  struct BlockLinearisation {
    Eigen::Matrix3d H;   // AᵀA
    Eigen::Vector3d g;   // Aᵀ √ρ' r
    Eigen::Vector3d v2;  // 2 (p_world − t_world_cam0)
  };
  // A planar prior block: its poses and their free-pose slots (-1 = constant).
  struct Link {
    int pose_a = -1, pose_b = -1, slot_a = -1, slot_b = -1;
  };
  // A planar prior block linearised: residual and Jacobians w.r.t. the two pose tangents.
  struct LinkLinearisation {
    LinkVector r;
    LinkJacobian J_a, J_b;
  };
  // A rotation prior block: its link and its residual.
  struct RotationLink {
    Link link;
    RotationPriorResidual f;
  };
  // A rotation prior block linearised.
  struct RotationLinkLinearisation {
    Eigen::Vector3d r;
    RotationLinkJacobian J_a, J_b;
  };
  // The linearisation at one point of parameter space: per block, and per slot (6) and per
  // point (3) the gradient Jᵀr and the squared Jacobian column norms diag(JᵀJ).
  struct Linearisation {
    std::vector<BlockLinearisation> blocks;
    std::vector<LinkLinearisation> links;
    std::vector<RotationLinkLinearisation> rotation_links;
    std::vector<Vector6> grad_pose, col_sq_pose;
    std::vector<Eigen::Vector3d> grad_point, col_sq_point;
  };

  // Cost ½ Σ ρ(s) of the given parameters and their linearisation. False when a depth is
  // <= 1e-9 or the cost is not finite.
  bool Evaluate(const std::vector<PoseBlock7>& poses, const std::vector<Eigen::Vector3d>& points,
                Linearisation* lin, double* cost);
  bool ComputeStep(double radius, bool reuse_diagonal, double* model_cost_change);
  void Plus();  // cand_ = Plus(x_, δ)
  double GradientMaxNorm() const;

  const StereoCamera& cam_;
  const BundleAdjustmentOptions& options_;
  const std::vector<SchurLmResidual>& residuals_;
  std::vector<PoseBlock7>* out_poses_;
  std::vector<Eigen::Vector3d>* out_points_;

  std::vector<int> used_poses_;   // poses a residual refers to, ascending
  std::vector<int> free_poses_;   // pose index of each slot
  std::vector<int> point_index_;  // caller's index of each compact point
  std::vector<int> point_begin_;  // blocks of compact point p: [point_begin_[p], [p + 1])
  std::vector<Block> blocks_;     // ordered by point, then by residual index
  std::vector<Link> links_;       // planar prior blocks
  std::unique_ptr<PlanarMotionResidual> planar_;  // their residual (when there are links)
  std::vector<RotationLink> rotation_links_;      // rotation prior blocks

  // Current parameters x and the candidate x ⊞ δ (compact points).
  std::vector<PoseBlock7> x_poses_, cand_poses_;
  std::vector<Eigen::Vector3d> x_points_, cand_points_;
  std::vector<Eigen::Matrix3d> R_cam0_world_;  // per pose, of the parameters evaluated last

  Linearisation lin_, cand_lin_;  // at x and at the candidate
  // Per slot (6) and per point (3): the Jacobi scaling of the first Jacobian, the LM diagonal,
  // the step δ.
  std::vector<Vector6> scale_pose_, lm_pose_, step_pose_;
  std::vector<Eigen::Vector3d> scale_point_, lm_point_, step_point_;
  std::vector<Eigen::Matrix3d> ete_inv_;  // per point (point block + D/μ)⁻¹
  std::vector<Eigen::Vector3d> ete_rhs_;  // per point Σ g
  std::vector<Matrix6> S_blocks_;  // reduced camera system, lower block triangle: (a, b), a >= b,
                                   // at a * #slots + b
  std::vector<Vector6> S_rhs_;     // its right-hand side per slot
  Eigen::MatrixXd S_;              // the same assembled, (6 · #slots)², lower triangle
  Eigen::VectorXd S_rhs_vec_, S_sol_;
  Eigen::LLT<Eigen::MatrixXd> S_llt_;
};

Solver::Solver(const StereoCamera& cam, const BundleAdjustmentOptions& options,
               const std::vector<SchurLmResidual>& residuals, const std::vector<bool>& pose_is_free,
               std::vector<PoseBlock7>* poses, std::vector<Eigen::Vector3d>* points,
               const std::vector<std::pair<int, int>>& planar_links,
               const PlanarMotionPrior& planar, const std::vector<RotationPrior>& rotation_priors)
    : cam_(cam), options_(options), residuals_(residuals), out_poses_(poses), out_points_(points) {
  const int num_poses = static_cast<int>(poses->size());
  const int num_points = static_cast<int>(points->size());
  if (static_cast<int>(pose_is_free.size()) != num_poses) Abort("pose_is_free.size() != #poses");
  std::vector<bool> pose_used(num_poses, false);
  std::vector<int> compact(num_points, -1);
  for (const SchurLmResidual& o : residuals) {
    if (o.pose < 0 || o.pose >= num_poses || o.point < 0 || o.point >= num_points) {
      std::ostringstream msg;
      msg << "residual refers to pose " << o.pose << " / point " << o.point << " (have "
          << num_poses << " poses, " << num_points << " points)";
      Abort(msg.str());
    }
    pose_used[o.pose] = true;
    compact[o.point] = 0;
  }
  std::vector<int> slot(num_poses, -1);
  for (int i = 0; i < num_poses; ++i) {
    if (!pose_used[i]) continue;
    used_poses_.push_back(i);
    if (pose_is_free[i]) {
      slot[i] = static_cast<int>(free_poses_.size());
      free_poses_.push_back(i);
    }
  }
  for (const auto& [a, b] : planar_links) {
    if (a < 0 || a >= num_poses || b < 0 || b >= num_poses || !pose_used[a] || !pose_used[b]) {
      std::ostringstream msg;
      msg << "planar link (" << a << ", " << b << ") refers to a pose no residual refers to";
      Abort(msg.str());
    }
    links_.push_back(Link{a, b, slot[a], slot[b]});
  }
  if (!links_.empty()) planar_ = std::make_unique<PlanarMotionResidual>(planar);
  for (const RotationPrior& prior : rotation_priors) {
    const int a = prior.frame_a, b = prior.frame_b;
    if (a < 0 || a >= num_poses || b < 0 || b >= num_poses || a == b || !pose_used[a] ||
        !pose_used[b]) {
      std::ostringstream msg;
      msg << "rotation prior (" << a << ", " << b
          << ") refers to the same pose twice or to one no residual refers to";
      Abort(msg.str());
    }
    rotation_links_.push_back(
        RotationLink{Link{a, b, slot[a], slot[b]}, RotationPriorResidual(prior)});
  }
  for (int j = 0; j < num_points; ++j) {
    if (compact[j] < 0) continue;
    compact[j] = static_cast<int>(point_index_.size());
    point_index_.push_back(j);
  }
  // Blocks grouped by point (counting sort, stable in the residual index).
  const int np = static_cast<int>(point_index_.size());
  point_begin_.assign(np + 1, 0);
  for (const SchurLmResidual& o : residuals) ++point_begin_[compact[o.point] + 1];
  for (int p = 0; p < np; ++p) point_begin_[p + 1] += point_begin_[p];
  blocks_.resize(residuals.size());
  std::vector<int> fill(point_begin_.begin(), point_begin_.end() - 1);
  for (size_t k = 0; k < residuals.size(); ++k) {
    const SchurLmResidual& o = residuals[k];
    Block& b = blocks_[fill[compact[o.point]]++];
    b.residual = static_cast<int>(k);
    b.pose = o.pose;
    b.slot = slot[o.pose];
    b.point = compact[o.point];
  }

  x_poses_ = *poses;
  cand_poses_ = *poses;
  x_points_.resize(np);
  for (int p = 0; p < np; ++p) x_points_[p] = (*points)[point_index_[p]];
  cand_points_ = x_points_;
  R_cam0_world_.resize(num_poses);
  const int nf = static_cast<int>(free_poses_.size());
  for (auto* v : {&scale_pose_, &lm_pose_, &step_pose_}) v->assign(nf, Vector6::Zero());
  for (auto* v : {&scale_point_, &lm_point_, &step_point_}) v->assign(np, Eigen::Vector3d::Zero());
  for (Linearisation* lin : {&lin_, &cand_lin_}) {
    lin->blocks.resize(blocks_.size());
    lin->links.resize(links_.size());
    lin->rotation_links.resize(rotation_links_.size());
    lin->grad_pose.resize(nf);
    lin->col_sq_pose.resize(nf);
    lin->grad_point.resize(np);
    lin->col_sq_point.resize(np);
  }
  ete_inv_.resize(np);
  ete_rhs_.resize(np);
  S_blocks_.resize(nf * nf);
  S_rhs_.resize(nf);
  S_.resize(6 * nf, 6 * nf);
  S_rhs_vec_.resize(6 * nf);
}

bool Solver::Evaluate(const std::vector<PoseBlock7>& poses,
                      const std::vector<Eigen::Vector3d>& points, Linearisation* lin,
                      double* cost) {
  for (int i : used_poses_) {
    const PoseBlock7& b = poses[i];
    R_cam0_world_[i] = Eigen::Quaterniond(b[3], b[0], b[1], b[2]).toRotationMatrix().transpose();
  }
  for (size_t a = 0; a < free_poses_.size(); ++a) {
    lin->grad_pose[a].setZero();
    lin->col_sq_pose[a].setZero();
  }
  for (size_t p = 0; p < x_points_.size(); ++p) {
    lin->grad_point[p].setZero();
    lin->col_sq_point[p].setZero();
  }
  double total = 0.0;
  Eigen::Vector4d r;
  Eigen::Matrix3d a;  // distinct rows of ∂r/∂p_world
  for (size_t k = 0; k < blocks_.size(); ++k) {
    const Block& b = blocks_[k];
    BlockLinearisation& l = lin->blocks[k];
    const PoseBlock7& pose = poses[b.pose];
    const Eigen::Vector3d t(pose[4], pose[5], pose[6]);
    const Eigen::Vector3d v = points[b.point] - t;
    const SchurLmResidual& obs = residuals_[b.residual];
    if (!ResidualAndPointRows(cam_, R_cam0_world_[b.pose], v, obs, &r, &a)) return false;
    double rho0 = 0.0, rho1 = 1.0;
    Rho(options_.loss, options_.loss_scale_px, r.squaredNorm(), &rho0, &rho1);
    total += 0.5 * rho0;
    // A = ∂r/∂p_world has rows a0, a1, a2, a1 (the v row twice for a stereo observation):
    // H = AᵀA = aᵀ diag(1, 1 or 2, 1) a, g = Aᵀr = aᵀ (r0, r1 + r3, r2). Ceres' Corrector
    // where ρ'' <= 0 scales residual and Jacobian by √ρ', so H and g by ρ'.
    Eigen::Matrix3d aw = a;
    if (obs.has_right) aw.row(1) *= 2.0;
    l.H.noalias() = a.transpose() * aw;
    l.g.noalias() = a.transpose() * Eigen::Vector3d(r(0), r(1) + r(3), r(2));
    if (rho1 != 1.0) {
      l.H *= rho1;
      l.g *= rho1;
    }
    l.v2 = 2.0 * v;
    lin->grad_point[b.point] += l.g;
    lin->col_sq_point[b.point] += l.H.diagonal();
    if (b.slot < 0) continue;
    // Pose gradient Bᵀg = [g × v2, −g]; diag(BᵀHB) = [diag(−[v2]× H [v2]×), diag(H)] with
    // diag(−[c]× H [c]×)_i = (c × e_i)ᵀ H (c × e_i).
    lin->grad_pose[b.slot].head<3>() += l.g.cross(l.v2);
    lin->grad_pose[b.slot].tail<3>() -= l.g;
    const Eigen::Vector3d& c = l.v2;
    const Eigen::Matrix3d& H = l.H;
    lin->col_sq_pose[b.slot].head<3>() += Eigen::Vector3d(
        c.z() * c.z() * H(1, 1) - 2.0 * c.y() * c.z() * H(1, 2) + c.y() * c.y() * H(2, 2),
        c.z() * c.z() * H(0, 0) - 2.0 * c.x() * c.z() * H(0, 2) + c.x() * c.x() * H(2, 2),
        c.y() * c.y() * H(0, 0) - 2.0 * c.x() * c.y() * H(0, 1) + c.x() * c.x() * H(1, 1));
    lin->col_sq_pose[b.slot].tail<3>() += H.diagonal();
  }
  for (size_t k = 0; k < links_.size(); ++k) {
    const Link& link = links_[k];
    LinkLinearisation& l = lin->links[k];
    PlanarResidualAndJacobians(*planar_, poses[link.pose_a], poses[link.pose_b], &l.r, &l.J_a,
                               &l.J_b);
    total += 0.5 * LinkSquaredNorm(l.r);
    for (const auto& [slot, J] :
         {std::make_pair(link.slot_a, &l.J_a), std::make_pair(link.slot_b, &l.J_b)}) {
      if (slot < 0) continue;
      lin->grad_pose[slot] += LinkJtr(*J, l.r);
      lin->col_sq_pose[slot] += LinkColumnSquaredNorms(*J);
    }
  }
  for (size_t k = 0; k < rotation_links_.size(); ++k) {
    const Link& link = rotation_links_[k].link;
    RotationLinkLinearisation& l = lin->rotation_links[k];
    RotationResidualAndJacobians(rotation_links_[k].f, poses[link.pose_a], poses[link.pose_b], &l.r,
                                 &l.J_a, &l.J_b);
    total += 0.5 * l.r.squaredNorm();
    for (const auto& [slot, J] :
         {std::make_pair(link.slot_a, &l.J_a), std::make_pair(link.slot_b, &l.J_b)}) {
      if (slot < 0) continue;
      lin->grad_pose[slot] += J->transpose() * l.r;
      lin->col_sq_pose[slot] += J->colwise().squaredNorm().transpose();
    }
  }
  if (!std::isfinite(total)) return false;
  *cost = total;
  return true;
}

// True when the gradient is finite (a non-finite Jacobian entry makes it non-finite).
bool GradientIsFinite(const std::vector<Vector6>& grad_pose,
                      const std::vector<Eigen::Vector3d>& grad_point) {
  for (const Vector6& g : grad_pose)
    if (!g.allFinite()) return false;
  for (const Eigen::Vector3d& g : grad_point)
    if (!g.allFinite()) return false;
  return true;
}

// Max-norm of x − Plus(x, −gradient) (Ceres' gradient_max_norm).
double Solver::GradientMaxNorm() const {
  double m = 0.0;
  for (size_t a = 0; a < free_poses_.size(); ++a) {
    const PoseBlock7& x = x_poses_[free_poses_[a]];
    const Vector6 minus_g = -lin_.grad_pose[a];
    PoseBlock7 y;
    QuaternionPlus(x.data(), minus_g.data(), y.data());
    for (int c = 0; c < 3; ++c) y[4 + c] = x[4 + c] + minus_g[3 + c];
    for (int c = 0; c < 7; ++c) m = std::max(m, std::abs(x[c] - y[c]));
  }
  for (size_t p = 0; p < x_points_.size(); ++p)
    m = std::max(m, (x_points_[p] - (x_points_[p] - lin_.grad_point[p])).lpNorm<Eigen::Infinity>());
  return m;
}

// Ceres solves (J_sᵀJ_s + D_s/μ) y = J_sᵀr for the Jacobi-scaled J_s = J diag(s) with
// D_s = clamp(diag(J_sᵀJ_s)); the same system in the unscaled unknowns x = diag(s) y is
// (JᵀJ + D/μ) x = Jᵀr with D = D_s / s², and δ = −x. Solved by eliminating the points; sets
// δ and the model cost decrease −(Jδ)ᵀ(r + Jδ/2). False: not positive definite, not finite, or
// no model decrease (an invalid step).
bool Solver::ComputeStep(double radius, bool reuse_diagonal, double* model_cost_change) {
  const int nf = static_cast<int>(free_poses_.size());
  const int np = static_cast<int>(x_points_.size());
  if (!reuse_diagonal) {
    for (int a = 0; a < nf; ++a) {
      const Vector6 s2 = scale_pose_[a].cwiseProduct(scale_pose_[a]);
      lm_pose_[a] =
          (s2.cwiseProduct(lin_.col_sq_pose[a]).cwiseMax(kMinLmDiagonal).cwiseMin(kMaxLmDiagonal))
              .cwiseQuotient(s2);
    }
    for (int p = 0; p < np; ++p) {
      const Eigen::Vector3d s2 = scale_point_[p].cwiseProduct(scale_point_[p]);
      lm_point_[p] =
          (s2.cwiseProduct(lin_.col_sq_point[p]).cwiseMax(kMinLmDiagonal).cwiseMin(kMaxLmDiagonal))
              .cwiseQuotient(s2);
    }
  }
  for (int a = 0; a < nf; ++a) {
    for (int b = 0; b <= a; ++b) S_blocks_[a * nf + b].setZero();
    S_blocks_[a * nf + a].diagonal() = lm_pose_[a] / radius;
    S_rhs_[a].setZero();
  }
  const std::vector<BlockLinearisation>& lin = lin_.blocks;
  // Eliminate each point: S −= W E⁻¹ Wᵀ, rhs −= W E⁻¹ Σg, with E the point block (+ D/μ) and
  // W = BᵀH per observation.
  for (int p = 0; p < np; ++p) {
    const int begin = point_begin_[p], end = point_begin_[p + 1];
    Eigen::Matrix3d ete = (lm_point_[p] / radius).asDiagonal();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (int k = begin; k < end; ++k) {
      const BlockLinearisation& l = lin[k];
      ete += l.H;
      g += l.g;
      const int a = blocks_[k].slot;
      if (a < 0) continue;
      S_rhs_[a].head<3>() += l.g.cross(l.v2);  // rhs_a += Bᵀg = [g × v2, −g]
      S_rhs_[a].tail<3>() -= l.g;
    }
    Eigen::Matrix3d ete_inv;
    if (!InvertSymmetricPositiveDefinite3(ete, &ete_inv)) return false;
    ete_inv_[p] = ete_inv;
    ete_rhs_[p] = g;
    // The lower block triangle of S only (the Cholesky reads no more). Diagonal block of an
    // observation: BᵀHB − BᵀH E⁻¹ HB = Bᵀ(H − H E⁻¹ H)B; rhs_a −= Bᵀ H E⁻¹ Σg.
    for (int k = begin; k < end; ++k) {
      Block& bk = blocks_[k];
      if (bk.slot < 0) continue;
      const BlockLinearisation& l = lin[k];
      bk.HE.noalias() = l.H * ete_inv;
      const Eigen::Vector3d q = bk.HE * g;
      S_rhs_[bk.slot].head<3>() -= q.cross(l.v2);
      S_rhs_[bk.slot].tail<3>() += q;
      const Eigen::Matrix3d D = l.H - bk.HE * l.H;
      AddSymmetricExpandedLower(D, l.v2, &S_blocks_[bk.slot * nf + bk.slot]);
    }
    // Two observations of the point: block (a, b) −= B_aᵀ (H_a E⁻¹ H_b) B_b.
    for (int k = begin; k < end; ++k) {
      const Block& bk = blocks_[k];
      if (bk.slot < 0) continue;
      for (int l = k + 1; l < end; ++l) {
        const Block& bl = blocks_[l];
        if (bl.slot < 0) continue;
        if (bk.slot >= bl.slot) {
          const Eigen::Matrix3d C = bk.HE * lin[l].H;
          SubtractExpanded(C, lin[k].v2, lin[l].v2, &S_blocks_[bk.slot * nf + bl.slot]);
          if (bk.slot == bl.slot) {  // the same pose twice: both products
            SubtractExpanded(C.transpose(), lin[l].v2, lin[k].v2,
                             &S_blocks_[bk.slot * nf + bk.slot]);
          }
        } else {
          const Eigen::Matrix3d C = bl.HE * lin[k].H;
          SubtractExpanded(C, lin[l].v2, lin[k].v2, &S_blocks_[bl.slot * nf + bk.slot]);
        }
      }
    }
  }
  // Planar prior blocks: pose terms only (JᵀJ, the pose–pose coupling, Jᵀr).
  for (size_t k = 0; k < links_.size(); ++k) {
    const Link& link = links_[k];
    const LinkLinearisation& l = lin_.links[k];
    if (link.slot_a >= 0) {
      S_blocks_[link.slot_a * nf + link.slot_a] += LinkJtJ(l.J_a, l.J_a);
      S_rhs_[link.slot_a] += LinkJtr(l.J_a, l.r);
    }
    if (link.slot_b >= 0) {
      S_blocks_[link.slot_b * nf + link.slot_b] += LinkJtJ(l.J_b, l.J_b);
      S_rhs_[link.slot_b] += LinkJtr(l.J_b, l.r);
    }
    if (link.slot_a >= 0 && link.slot_b >= 0) {
      if (link.slot_a > link.slot_b)
        S_blocks_[link.slot_a * nf + link.slot_b] += LinkJtJ(l.J_a, l.J_b);
      else
        S_blocks_[link.slot_b * nf + link.slot_a] += LinkJtJ(l.J_b, l.J_a);
    }
  }
  // Rotation prior blocks: the same pose terms.
  for (size_t k = 0; k < rotation_links_.size(); ++k) {
    const Link& link = rotation_links_[k].link;
    const RotationLinkLinearisation& l = lin_.rotation_links[k];
    if (link.slot_a >= 0) {
      S_blocks_[link.slot_a * nf + link.slot_a] += l.J_a.transpose() * l.J_a;
      S_rhs_[link.slot_a] += l.J_a.transpose() * l.r;
    }
    if (link.slot_b >= 0) {
      S_blocks_[link.slot_b * nf + link.slot_b] += l.J_b.transpose() * l.J_b;
      S_rhs_[link.slot_b] += l.J_b.transpose() * l.r;
    }
    if (link.slot_a >= 0 && link.slot_b >= 0) {
      if (link.slot_a > link.slot_b)
        S_blocks_[link.slot_a * nf + link.slot_b] += l.J_a.transpose() * l.J_b;
      else
        S_blocks_[link.slot_b * nf + link.slot_a] += l.J_b.transpose() * l.J_a;
    }
  }
  // Reduced camera system by dense Cholesky (lower triangle), then the points back-substituted.
  if (nf > 0) {
    for (int a = 0; a < nf; ++a) {
      for (int b = 0; b <= a; ++b) S_.block<6, 6>(6 * a, 6 * b) = S_blocks_[a * nf + b];
      S_rhs_vec_.segment<6>(6 * a) = S_rhs_[a];
    }
    S_llt_.compute(S_);
    if (S_llt_.info() != Eigen::Success) return false;
    S_sol_ = S_llt_.solve(S_rhs_vec_);
    if (!S_sol_.allFinite()) return false;
    for (int a = 0; a < nf; ++a) step_pose_[a] = -S_sol_.segment<6>(6 * a);
  }
  for (int p = 0; p < np; ++p) {
    // x_p = E⁻¹ (Σg − Σ H B x_a), δ_p = −x_p, where B x_a = −B δ_a = −(v2 × δθ − δt).
    Eigen::Vector3d g = ete_rhs_[p];
    for (int k = point_begin_[p]; k < point_begin_[p + 1]; ++k) {
      const int a = blocks_[k].slot;
      if (a < 0) continue;
      const Vector6& d = step_pose_[a];
      g.noalias() += lin[k].H * (lin[k].v2.cross(d.head<3>()) - d.tail<3>());
    }
    step_point_[p] = -(ete_inv_[p] * g);
    if (!step_point_[p].allFinite()) return false;
  }
  // Model decrease −Σ (uᵀg + ½ uᵀHu), u = B δ_a + δ_p the linearised change of p_cam0 in the
  // world frame (Jδ = A u).
  double change = 0.0;
  for (size_t k = 0; k < blocks_.size(); ++k) {
    const BlockLinearisation& l = lin[k];
    Eigen::Vector3d u = step_point_[blocks_[k].point];
    if (blocks_[k].slot >= 0) {
      const Vector6& d = step_pose_[blocks_[k].slot];
      u += l.v2.cross(d.head<3>()) - d.tail<3>();
    }
    change -= u.dot(l.g) + 0.5 * u.dot(l.H * u);
  }
  for (size_t k = 0; k < links_.size(); ++k) {
    const Link& link = links_[k];
    const LinkLinearisation& l = lin_.links[k];
    LinkVector jd = LinkVector::Zero();
    if (link.slot_a >= 0) jd += l.J_a * step_pose_[link.slot_a];
    if (link.slot_b >= 0) jd += l.J_b * step_pose_[link.slot_b];
    change -= LinkDot(jd, l.r) + 0.5 * LinkSquaredNorm(jd);
  }
  for (size_t k = 0; k < rotation_links_.size(); ++k) {
    const Link& link = rotation_links_[k].link;
    const RotationLinkLinearisation& l = lin_.rotation_links[k];
    Eigen::Vector3d jd = Eigen::Vector3d::Zero();
    if (link.slot_a >= 0) jd += l.J_a * step_pose_[link.slot_a];
    if (link.slot_b >= 0) jd += l.J_b * step_pose_[link.slot_b];
    change -= jd.dot(l.r) + 0.5 * jd.squaredNorm();
  }
  *model_cost_change = change;
  return change > 0.0;
}

void Solver::Plus() {
  for (size_t a = 0; a < free_poses_.size(); ++a) {
    const PoseBlock7& x = x_poses_[free_poses_[a]];
    PoseBlock7& y = cand_poses_[free_poses_[a]];
    QuaternionPlus(x.data(), step_pose_[a].data(), y.data());
    for (int c = 0; c < 3; ++c) y[4 + c] = x[4 + c] + step_pose_[a][3 + c];
  }
  for (size_t p = 0; p < x_points_.size(); ++p) cand_points_[p] = x_points_[p] + step_point_[p];
}

SchurLmSummary Solver::Run() {
  using Termination = SchurLmSummary::Termination;
  SchurLmSummary s;
  double x_cost = 0.0;
  if (!Evaluate(x_poses_, x_points_, &lin_, &x_cost) ||
      !GradientIsFinite(lin_.grad_pose, lin_.grad_point)) {
    s.message = "residual and Jacobian evaluation failed at the start";
    return s;
  }
  s.initial_cost = x_cost;
  // Jacobi scaling from the first Jacobian: 1 / (1 + column norm).
  for (size_t a = 0; a < free_poses_.size(); ++a)
    scale_pose_[a] = (1.0 + lin_.col_sq_pose[a].array().sqrt()).inverse().matrix();
  for (size_t p = 0; p < x_points_.size(); ++p)
    scale_point_[p] = (1.0 + lin_.col_sq_point[p].array().sqrt()).inverse().matrix();
  double gradient_max_norm = GradientMaxNorm();
  double radius = kInitialTrustRegionRadius;
  double decrease_factor = 2.0;
  bool reuse_diagonal = false;
  double x_norm = -1.0;  // ‖x‖ at the last accepted step; none before the first (as Ceres)
  int num_invalid = 0;
  int iteration = 0;
  bool step_successful = true;  // the start counts as a successful step
  std::ostringstream msg;

  // Ambient norms over the free poses and the points.
  auto ambient_norm = [&](const std::vector<PoseBlock7>* a, const std::vector<PoseBlock7>* b,
                          const std::vector<Eigen::Vector3d>* pa,
                          const std::vector<Eigen::Vector3d>* pb) {
    double sq = 0.0;
    for (int i : free_poses_)
      for (int c = 0; c < 7; ++c) {
        const double d = (*a)[i][c] - (b ? (*b)[i][c] : 0.0);
        sq += d * d;
      }
    for (size_t p = 0; p < pa->size(); ++p)
      sq += ((*pa)[p] - (pb ? (*pb)[p] : Eigen::Vector3d::Zero())).squaredNorm();
    return std::sqrt(sq);
  };

  while (true) {
    // End of an iteration: count it, then the checks Ceres makes between iterations.
    if (step_successful)
      ++s.num_successful_steps;
    else
      ++s.num_unsuccessful_steps;
    if (iteration >= options_.max_num_iterations) {
      s.termination = Termination::kNoConvergence;
      msg << "maximum number of iterations reached (" << iteration << ")";
      break;
    }
    if (step_successful && gradient_max_norm <= options_.gradient_tolerance) {
      s.termination = Termination::kConvergence;
      msg << "gradient tolerance reached: " << gradient_max_norm;
      break;
    }
    if (radius <= kMinTrustRegionRadius) {
      s.termination = Termination::kConvergence;
      msg << "minimum trust region radius reached: " << radius;
      break;
    }

    ++iteration;
    step_successful = false;
    double model_cost_change = 0.0;
    const bool valid = ComputeStep(radius, reuse_diagonal, &model_cost_change);
    reuse_diagonal = true;
    if (!valid) {
      if (++num_invalid >= kMaxConsecutiveInvalidSteps) {
        s.termination = Termination::kFailure;
        msg << num_invalid << " consecutive invalid steps";
        break;
      }
      radius /= decrease_factor;  // as a rejected step
      decrease_factor *= 2.0;
      continue;
    }
    num_invalid = 0;

    // The candidate's cost, and its linearisation for the case it is accepted.
    Plus();
    double candidate_cost = std::numeric_limits<double>::max();
    if (!Evaluate(cand_poses_, cand_points_, &cand_lin_, &candidate_cost))
      candidate_cost = std::numeric_limits<double>::max();

    if (x_norm >= 0.0) {
      const double step_norm = ambient_norm(&x_poses_, &cand_poses_, &x_points_, &cand_points_);
      if (step_norm <= options_.parameter_tolerance * (x_norm + options_.parameter_tolerance)) {
        s.termination = Termination::kConvergence;
        msg << "parameter tolerance reached: step norm " << step_norm;
        break;
      }
    }
    const double cost_change = x_cost - candidate_cost;
    if (std::abs(cost_change) <= options_.function_tolerance * x_cost) {
      s.termination = Termination::kConvergence;
      msg << "function tolerance reached: |cost change| / cost " << std::abs(cost_change) / x_cost;
      break;
    }
    const double quality = candidate_cost >= std::numeric_limits<double>::max()
                               ? std::numeric_limits<double>::lowest()
                               : cost_change / model_cost_change;
    if (quality > kMinRelativeDecrease) {
      if (!GradientIsFinite(cand_lin_.grad_pose, cand_lin_.grad_point)) {
        s.termination = Termination::kFailure;
        msg << "residual and Jacobian evaluation failed";
        break;
      }
      std::swap(x_poses_, cand_poses_);  // the constant poses are equal in both
      std::swap(x_points_, cand_points_);
      std::swap(lin_, cand_lin_);
      x_cost = candidate_cost;
      x_norm = ambient_norm(&x_poses_, nullptr, &x_points_, nullptr);
      gradient_max_norm = GradientMaxNorm();
      radius = std::min(kMaxTrustRegionRadius,
                        radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * quality - 1.0, 3)));
      decrease_factor = 2.0;
      reuse_diagonal = false;
      step_successful = true;
    } else {
      radius /= decrease_factor;
      decrease_factor *= 2.0;
    }
  }
  s.message = msg.str();
  s.final_cost = x_cost;
  // The free poses and the points back to the caller (the last accepted values).
  for (int i : free_poses_) (*out_poses_)[i] = x_poses_[i];
  for (size_t p = 0; p < x_points_.size(); ++p) (*out_points_)[point_index_[p]] = x_points_[p];
  return s;
}

}  // namespace

bool StereoResidualAndJacobians(const StereoCamera& cam, const Eigen::Matrix3d& R_cam0_world,
                                const Eigen::Vector3d& t_world_cam0, const Eigen::Vector3d& p_world,
                                const SchurLmResidual& obs, Eigen::Vector4d* r,
                                Eigen::Matrix<double, 4, 6>* J_pose,
                                Eigen::Matrix<double, 4, 3>* J_point) {
  const Eigen::Vector3d v = p_world - t_world_cam0;
  Eigen::Matrix3d a;
  const bool jacobians = J_pose != nullptr || J_point != nullptr;
  if (!ResidualAndPointRows(cam, R_cam0_world, v, obs, r, jacobians ? &a : nullptr)) return false;
  if (!jacobians) return true;
  Matrix43 d_r_d_point;
  d_r_d_point.topRows<3>() = a;
  d_r_d_point.row(3) = obs.has_right ? Eigen::RowVector3d(a.row(1)) : Eigen::RowVector3d::Zero();
  if (J_point) *J_point = d_r_d_point;
  // ∂p_cam0/∂[δθ δt] = [2 Rᵀ[v]×, −Rᵀ] = ∂p_cam0/∂p_world · [2[v]×, −I].
  if (J_pose) {
    J_pose->leftCols<3>() = 2.0 * d_r_d_point * Skew(v);
    J_pose->rightCols<3>() = -d_r_d_point;
  }
  return true;
}

SchurLmSummary SolveSchurLm(const StereoCamera& cam, const BundleAdjustmentOptions& options,
                            const std::vector<SchurLmResidual>& residuals,
                            const std::vector<bool>& pose_is_free, std::vector<PoseBlock7>* poses,
                            std::vector<Eigen::Vector3d>* points,
                            const std::vector<std::pair<int, int>>& planar_links,
                            const PlanarMotionPrior& planar,
                            const std::vector<RotationPrior>& rotation_priors) {
  Solver solver(cam, options, residuals, pose_is_free, poses, points, planar_links, planar,
                rotation_priors);
  return solver.Run();
}

}  // namespace vo
