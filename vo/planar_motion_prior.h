// A ground vehicle's motion prior for the windowed bundle adjustment (bundle_adjustment.h,
// BundleAdjustmentProblem::planar): the camera is mounted rigidly on a vehicle that drives on a
// floor, so between two poses of the window the camera turns about the vehicle's up only (no
// change of roll or pitch), does not move along up (no lift), and the axle's midpoint, the
// point axle_behind_camera_m behind the camera, moves along its heading (no sideways slip of a
// wheeled vehicle; the same model as VehicleMotion in prior_motion.h: the chord of a step
// points along the heading at half the turn).
//
// Residual of two poses a, b (T_world_cam0 blocks [qx qy qz qw tx ty tz], bundle_adjustment.h),
// with T_ab = T_world_aᵀ T_world_b = (R, t) and u the up in the camera frame (unit, the same in
// both cameras), e1 the horizontal forward axis (HorizontalForward(u)) and e2 = u × e1:
//   r0, r1 = e1·(R u), e2·(R u) / tilt_sigma_rad       (sines of the tilt; 0 for a yaw about u)
//   r2     = u·t / lift_sigma_m                        (the step along up)
//   r3     = l·(t − d (R e1 − e1)) / slip_sigma_m       (the axle's step across its heading),
// with d = axle_behind_camera_m, ψ = 2 atan2(q_vec·u, q_w) the yaw about u (q with q_w >= 0)
// and l = cos(ψ/2) e2 − sin(ψ/2) e1 the lateral axis at half the turn. Each residual is
// dimensionless; the cost ½|r|² is added to the reprojection cost (pixels²) without a robust
// loss, so σ weighs the prior against one pixel of reprojection error.
//
// Flat floor (optional, PlanarMotionPrior::flat_floor): the floor is one plane, so every pose
// keeps the first pose's tilt and height, not only its neighbour's. Three more residuals hold
// pose b against the floor (each free pose is the later pose of exactly one block), with w the
// floor's up in the world frame (floor_up_world, unit) and f1, f2 two axes across it:
//   r4, r5 = f1·(R_b u), f2·(R_b u) / floor_tilt_sigma_rad   (the vehicle's up against w)
//   r6     = (w·t_b − floor_height_m) / floor_height_sigma_m (the camera centre's height),
// with T_world_b = (R_b, t_b). Without it r4..r6 are 0. The relative residuals above let the
// tilt and the height wander by a little each step of the window (a pitch drift of ~1° over 200
// frames on l_hallway); these hold them to the floor given, so they are only as good as it.
//
// The residual is a template so that both backends evaluate the same function: the Ceres
// backend through ceres::AutoDiffCostFunction, schur_lm.cc through ceres::Jet and the pose
// manifold's Plus Jacobian (the same derivatives to rounding).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <string>

namespace vo {

struct PlanarMotionPrior {
  bool enabled = false;                              // false: no residuals are added
  Eigen::Vector3d up_cam = Eigen::Vector3d::Zero();  // the vehicle's up in the camera frame
                                                     // (normalised here; must not vanish)
  double axle_behind_camera_m = 0.0;  // the axle's midpoint behind the camera (metres, >= 0)
  double tilt_sigma_rad = 0.002;      // σ of a change of roll or pitch between two poses, > 0
  double lift_sigma_m = 0.002;        // σ of a step along up (metres), > 0
  double slip_sigma_m = 0.002;        // σ of the axle's sideways step (metres), > 0
  // Flat floor (see the header comment): off by default.
  bool flat_floor = false;
  Eigen::Vector3d floor_up_world = Eigen::Vector3d::UnitZ();  // the floor's up, world frame
                                                              // (normalised here; not zero)
  double floor_height_m = 0.0;          // w·t of a camera centre on the floor (metres)
  double floor_tilt_sigma_rad = 0.005;  // σ of the vehicle's up against the floor's, > 0
  double floor_height_sigma_m = 0.01;   // σ of the camera centre's height (metres), > 0

  bool IsValid(std::string* error) const;
};

// The horizontal forward axis of a camera whose up is u (unit): its z axis made perpendicular
// to u (its x axis when they are parallel). prior_motion.cc's vehicle model uses the same.
Eigen::Vector3d HorizontalForwardAxis(const Eigen::Vector3d& u);

// The up of a camera mounted on a wheeled vehicle, in the camera's own frame, from a prior
// direction (a floor fit) and the camera's rigid motions: the vehicle moves across its up and
// turns about it. Each motion T_ref_curr = (R, t), ω the rotation vector of R, adds
// t tᵀ / σ_t² + (|ω|² I − ω ωᵀ) / σ_ω² to an information matrix that starts at
// (I − u₀ u₀ᵀ) / σ₀²; the estimate is the eigenvector of its smallest eigenvalue, on u₀'s side.
// Straight driving fixes the up's tilt along the heading only; a turn fixes the rest.
class VehicleUpEstimate {
 public:
  VehicleUpEstimate() = default;  // unknown
  VehicleUpEstimate(const Eigen::Vector3d& prior_up, double prior_sigma_rad);

  // Adds a motion (ignored when not finite or while unknown).
  void AddMotion(const Eigen::Isometry3d& T_ref_curr, double translation_sigma_m,
                 double rotation_sigma_rad);
  bool known() const { return up_.norm() > 0.5; }
  const Eigen::Vector3d& up() const { return up_; }  // unit; zero while unknown

 private:
  Eigen::Vector3d up_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d information_ = Eigen::Matrix3d::Zero();
};

// The residual above as a functor (AutoDiffCostFunction<PlanarMotionResidual, kNumResiduals,
// 7, 7>).
class PlanarMotionResidual {
 public:
  static constexpr int kNumResiduals = 7;  // 4 relative + 3 flat floor (0 without it)

  explicit PlanarMotionResidual(const PlanarMotionPrior& prior)
      : u_(prior.up_cam.normalized()),
        e1_(HorizontalForwardAxis(u_)),
        e2_(u_.cross(e1_)),
        w_(prior.floor_up_world.normalized()),
        f1_(HorizontalForwardAxis(w_)),
        f2_(w_.cross(f1_)),
        axle_(prior.axle_behind_camera_m),
        w_tilt_(1.0 / prior.tilt_sigma_rad),
        w_lift_(1.0 / prior.lift_sigma_m),
        w_slip_(1.0 / prior.slip_sigma_m),
        floor_(prior.flat_floor),
        floor_height_(prior.floor_height_m),
        w_floor_tilt_(1.0 / prior.floor_tilt_sigma_rad),
        w_floor_height_(1.0 / prior.floor_height_sigma_m) {}

  template <typename T>
  bool operator()(const T* pose_a, const T* pose_b, T* r) const {
    using Vec3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Quaternion<T> qa(pose_a[3], pose_a[0], pose_a[1], pose_a[2]);
    const Eigen::Quaternion<T> qb(pose_b[3], pose_b[0], pose_b[1], pose_b[2]);
    const Vec3 ta(pose_a[4], pose_a[5], pose_a[6]);
    const Vec3 tb(pose_b[4], pose_b[5], pose_b[6]);
    Eigen::Quaternion<T> q = qa.conjugate() * qb;
    if (q.w() < T(0)) q.coeffs() = -q.coeffs();
    const Vec3 t = qa.conjugate() * (tb - ta);
    const Vec3 u = u_.cast<T>(), e1 = e1_.cast<T>(), e2 = e2_.cast<T>();
    const Vec3 Ru = q * u;
    r[0] = e1.dot(Ru) * T(w_tilt_);
    r[1] = e2.dot(Ru) * T(w_tilt_);
    r[2] = u.dot(t) * T(w_lift_);
    using std::atan2;
    using std::cos;
    using std::sin;
    const T half_yaw = atan2(q.vec().dot(u), q.w());
    const Vec3 lateral = cos(half_yaw) * e2 - sin(half_yaw) * e1;
    const Vec3 axle_step = t - T(axle_) * (q * e1 - e1);
    r[3] = lateral.dot(axle_step) * T(w_slip_);
    if (!floor_) {
      r[4] = r[5] = r[6] = T(0);
      return true;
    }
    const Vec3 up_world = qb * u;
    r[4] = f1_.cast<T>().dot(up_world) * T(w_floor_tilt_);
    r[5] = f2_.cast<T>().dot(up_world) * T(w_floor_tilt_);
    r[6] = (w_.cast<T>().dot(tb) - T(floor_height_)) * T(w_floor_height_);
    return true;
  }

  // operator() for ceres::Jet, with the constant vectors and weights entering as doubles
  // rather than as Jets with a zero derivative: the same operations on the values in the same
  // order (Eigen's for a cross product, a quaternion rotating a vector and a 3-vector dot
  // product), so the same residuals and derivatives (up to the sign of a zero), with about
  // half the operations on derivatives. The Schur bundle adjustment's linearisation
  // (schur_lm.cc); PlanarMotionPriorTest compares the two.
  template <typename J>
  bool EvaluateJets(const J* pose_a, const J* pose_b, J* r) const {
    using Vec3 = Eigen::Matrix<J, 3, 1>;
    const Eigen::Quaternion<J> qa(pose_a[3], pose_a[0], pose_a[1], pose_a[2]);
    const Eigen::Quaternion<J> qb(pose_b[3], pose_b[0], pose_b[1], pose_b[2]);
    const Vec3 ta(pose_a[4], pose_a[5], pose_a[6]);
    const Vec3 tb(pose_b[4], pose_b[5], pose_b[6]);
    Eigen::Quaternion<J> q = qa.conjugate() * qb;
    if (q.w() < J(0)) q.coeffs() = -q.coeffs();
    const Vec3 t = qa.conjugate() * (tb - ta);
    const Vec3 Ru = Rotate(q, u_);
    r[0] = Dot(e1_, Ru) * w_tilt_;
    r[1] = Dot(e2_, Ru) * w_tilt_;
    r[2] = Dot(u_, t) * w_lift_;
    using std::atan2;
    using std::cos;
    using std::sin;
    const J half_yaw = atan2(Dot(u_, q.vec()), q.w());
    const J c = cos(half_yaw), s = sin(half_yaw);
    const Vec3 lateral(c * e2_[0] - s * e1_[0], c * e2_[1] - s * e1_[1], c * e2_[2] - s * e1_[2]);
    const Vec3 Re1 = Rotate(q, e1_);
    const Vec3 axle_step(t[0] - axle_ * (Re1[0] - e1_[0]), t[1] - axle_ * (Re1[1] - e1_[1]),
                         t[2] - axle_ * (Re1[2] - e1_[2]));
    r[3] = lateral.dot(axle_step) * w_slip_;
    if (!floor_) {
      r[4] = r[5] = r[6] = J(0);
      return true;
    }
    const Vec3 up_world = Rotate(qb, u_);
    r[4] = Dot(f1_, up_world) * w_floor_tilt_;
    r[5] = Dot(f2_, up_world) * w_floor_tilt_;
    r[6] = (Dot(w_, tb) - floor_height_) * w_floor_height_;
    return true;
  }

 private:
  // c · v in Eigen's order for a 3-vector of Jets (c₀v₀ + (c₁v₁ + c₂v₂)).
  template <typename V>
  static typename V::Scalar Dot(const Eigen::Vector3d& c, const V& v) {
    return c[0] * v[0] + (c[1] * v[1] + c[2] * v[2]);
  }
  // q v for a constant v, as Eigen's QuaternionBase::_transformVector: uv = 2 q_v × v,
  // v + w uv + q_v × uv.
  template <typename J>
  static Eigen::Matrix<J, 3, 1> Rotate(const Eigen::Quaternion<J>& q, const Eigen::Vector3d& v) {
    const J x = q.x(), y = q.y(), z = q.z();
    Eigen::Matrix<J, 3, 1> uv(y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]);
    uv += uv;
    return Eigen::Matrix<J, 3, 1>(v[0] + q.w() * uv[0] + (y * uv[2] - z * uv[1]),
                                  v[1] + q.w() * uv[1] + (z * uv[0] - x * uv[2]),
                                  v[2] + q.w() * uv[2] + (x * uv[1] - y * uv[0]));
  }

  Eigen::Vector3d u_, e1_, e2_, w_, f1_, f2_;
  double axle_, w_tilt_, w_lift_, w_slip_;
  bool floor_;
  double floor_height_, w_floor_tilt_, w_floor_height_;
};

}  // namespace vo
