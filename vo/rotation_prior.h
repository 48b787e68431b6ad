// A relative-rotation prior of the windowed bundle adjustment (bundle_adjustment.h,
// BundleAdjustmentProblem::rotation_priors): a gyro measured the rotation R_a_b of camera b in
// camera a (gyro_prior.h, issue #35), σ sigma_rad about any axis. Residual of the two poses
// a, b (T_world_cam0 blocks [qx qy qz qw tx ty tz]):
//   r = Log(R_a_bᵀ · R_world_aᵀ R_world_b) / sigma_rad    (3 rows, the rotation vector),
// dimensionless, added to the reprojection cost (pixels²) as ½|r|² without a robust loss, so σ
// weighs the prior against one pixel of reprojection error (as the planar motion prior,
// planar_motion_prior.h). The translation does not enter.
//
// The residual is a template so that both backends evaluate the same function: the Ceres
// backend through ceres::AutoDiffCostFunction, schur_lm.cc through ceres::Jet and the pose
// manifold's Plus Jacobian. Log is ceres::QuaternionToAngleAxis (exact derivatives at 0).
// Only the backends include this header (it includes Ceres).
#pragma once

#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "vo/bundle_adjustment.h"

namespace vo {

// AutoDiffCostFunction<RotationPriorResidual, 3, 7, 7>.
class RotationPriorResidual {
 public:
  static constexpr int kNumResiduals = 3;

  explicit RotationPriorResidual(const RotationPrior& prior)
      : q_a_b_(Eigen::Quaterniond(prior.R_a_b).normalized()), weight_(1.0 / prior.sigma_rad) {}

  template <typename T>
  bool operator()(const T* pose_a, const T* pose_b, T* r) const {
    const Eigen::Quaternion<T> qa(pose_a[3], pose_a[0], pose_a[1], pose_a[2]);
    const Eigen::Quaternion<T> qb(pose_b[3], pose_b[0], pose_b[1], pose_b[2]);
    const Eigen::Quaternion<T> q_meas = q_a_b_.cast<T>();
    // R_a_bᵀ · R_world_aᵀ R_world_b as a quaternion; Log of it, (w, x, y, z) order for Ceres.
    const Eigen::Quaternion<T> e = q_meas.conjugate() * (qa.conjugate() * qb);
    const T wxyz[4] = {e.w(), e.x(), e.y(), e.z()};
    ceres::QuaternionToAngleAxis(wxyz, r);
    for (int k = 0; k < 3; ++k) r[k] *= T(weight_);
    return true;
  }

 private:
  Eigen::Quaterniond q_a_b_;
  double weight_;  // 1 / σ (1/rad)
};

}  // namespace vo
