#include "vo/motion_model.h"

#include <cmath>
#include <limits>

#include "vo/prior_motion.h"

namespace vo {

Eigen::Vector3d WorldUpInCamera(const Eigen::Isometry3d& T_world_cam) {
  return T_world_cam.linear().transpose() * Eigen::Vector3d::UnitZ();
}

Eigen::Isometry3d Blend(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b, double w) {
  if (w <= 0.0) return T_a;
  const Eigen::Quaterniond q_a(T_a.linear());
  const Eigen::Quaterniond q_b(T_b.linear());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q_a.slerp(w, q_b).normalized().toRotationMatrix();
  T.translation() = (1.0 - w) * T_a.translation() + w * T_b.translation();
  return T;
}

Eigen::Isometry3d Root(const Eigen::Isometry3d& T, int64_t n) {
  if (n <= 1) return T;
  const double f = 1.0 / static_cast<double>(n);
  Eigen::Isometry3d R = Eigen::Isometry3d::Identity();
  R.linear() = Eigen::Quaterniond::Identity()
                   .slerp(f, Eigen::Quaterniond(T.linear()))
                   .normalized()
                   .toRotationMatrix();
  R.translation() = f * T.translation();
  return R;
}

bool IsVehicleLike(const Eigen::Isometry3d& T_a_b, const Eigen::Vector3d& up_a, double max_tilt_deg,
                   double max_lift_m) {
  const Eigen::Isometry3d planar = PlanarPart(T_a_b, up_a);
  const double tilt_rad = Eigen::AngleAxisd(planar.linear().transpose() * T_a_b.linear()).angle();
  const double lift_m = std::abs(up_a.normalized().dot(T_a_b.translation()));
  return tilt_rad <= max_tilt_deg * M_PI / 180.0 && lift_m <= max_lift_m;
}

Eigen::Vector2d PredictedCentreShift(const StereoCamera& camera,
                                     const Eigen::Isometry3d& T_ref_curr, double depth_m) {
  const Eigen::Vector2d centre(camera.cx_px, camera.cy_px);
  const bool near = std::isfinite(depth_m) && depth_m > 0.0;
  const Eigen::Isometry3d T_curr_ref = T_ref_curr.inverse();
  const Eigen::Vector3d ray(0.0, 0.0, 1.0);
  const Eigen::Vector3d p_curr = near ? Eigen::Vector3d(T_curr_ref * (depth_m * ray))
                                      : Eigen::Vector3d(T_curr_ref.linear() * ray);
  if (!(p_curr.z() > 1e-9)) {
    return Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  }
  return Eigen::Vector2d(camera.fx_px * p_curr.x() / p_curr.z(),
                         camera.fy_px * p_curr.y() / p_curr.z());
}

Eigen::Isometry3d CorrectPriorWithImageShift(const StereoCamera& camera,
                                             const Eigen::Isometry3d& T_prev_curr_prior,
                                             const Eigen::Vector2d& shift_px, double depth_m) {
  // Where the prior puts the point seen at the previous image centre (depth_m, or far away).
  const bool near = std::isfinite(depth_m) && depth_m > 0.0;
  const Eigen::Vector3d p_prev = Eigen::Vector3d(0.0, 0.0, near ? depth_m : 1.0);
  const Eigen::Isometry3d T_curr_prev = T_prev_curr_prior.inverse();
  const Eigen::Vector3d p_curr =
      near ? Eigen::Vector3d(T_curr_prev * p_prev) : Eigen::Vector3d(T_curr_prev.linear() * p_prev);
  if (!(p_curr.z() > 1e-9)) return T_prev_curr_prior;
  const Eigen::Vector2d predicted(camera.fx_px * p_curr.x() / p_curr.z(),
                                  camera.fy_px * p_curr.y() / p_curr.z());
  // The residual shift r: the prior-predicted camera c' sees along a ray that the true camera c
  // sees at (r_x / fx, r_y / fy, 1), i.e. R_c'c^T e_z ∝ d, and R_c'c = FromTwoVectors(d, e_z).
  const Eigen::Vector2d r = shift_px - predicted;
  const Eigen::Vector3d ray_c(p_curr.x() / p_curr.z() + r.x() / camera.fx_px,
                              p_curr.y() / p_curr.z() + r.y() / camera.fy_px, 1.0);
  const Eigen::Vector3d ray_c_prime(p_curr.x() / p_curr.z(), p_curr.y() / p_curr.z(), 1.0);
  // R_c'c maps directions in c to directions in c': the ray seen in c must map to the ray the
  // point has in c'.
  const Eigen::Matrix3d R_cprime_c =
      Eigen::Quaterniond::FromTwoVectors(ray_c, ray_c_prime).toRotationMatrix();
  Eigen::Isometry3d T_cprime_c = Eigen::Isometry3d::Identity();
  T_cprime_c.linear() = R_cprime_c;
  return T_prev_curr_prior * T_cprime_c;
}

Eigen::Isometry3d VehicleMotionFromImageShift(const StereoCamera& camera,
                                              const Eigen::Vector3d& up_prev,
                                              double axle_behind_camera_m,
                                              const Eigen::Isometry3d& T_prev_curr_prior,
                                              const Eigen::Vector2d& shift_px, double depth_m) {
  const Eigen::Vector2d yaw_forward =
      VehicleMotionParameters(T_prev_curr_prior, up_prev, axle_behind_camera_m);
  if (!yaw_forward.allFinite() || !shift_px.allFinite() || !up_prev.allFinite()) {
    return T_prev_curr_prior;
  }
  const double forward_m = yaw_forward.y();
  double yaw = yaw_forward.x();
  for (int i = 0; i < 100; ++i) {
    const Eigen::Isometry3d T = VehicleMotion(up_prev, axle_behind_camera_m, yaw, forward_m);
    const Eigen::Isometry3d corrected =
        PlanarPart(CorrectPriorWithImageShift(camera, T, shift_px, depth_m), up_prev);
    const double next = VehicleMotionParameters(corrected, up_prev, axle_behind_camera_m).x();
    if (!std::isfinite(next)) return T_prev_curr_prior;
    const bool converged = std::abs(next - yaw) <= 1e-12;
    yaw = next;
    if (converged) break;
  }
  return VehicleMotion(up_prev, axle_behind_camera_m, yaw, forward_m);
}

std::vector<Eigen::Vector2d> PredictFeaturePositions(const StereoCamera& camera,
                                                     const std::vector<Feature>& features,
                                                     const Eigen::Isometry3d& T_ref_curr,
                                                     double min_depth_m) {
  const Eigen::Isometry3d T_curr_ref = T_ref_curr.inverse();
  const Eigen::Vector2d none = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<Eigen::Vector2d> uv(features.size(), none);
  for (size_t i = 0; i < features.size(); ++i) {
    const Feature& f = features[i];
    if (!f.has_depth() || !f.p_cam0.allFinite()) continue;
    Eigen::Vector2d p;
    if (camera.ProjectLeft(T_curr_ref * f.p_cam0, &p, min_depth_m)) uv[i] = p;
  }
  return uv;
}

Eigen::Isometry3d ConstantVelocity::Prior(const MotionPrior* prior) const {
  if (prior != nullptr && IsFinitePose(prior->T_prev_curr)) return prior->T_prev_curr;
  if (has_measured_rotation_) {
    Eigen::Isometry3d T = known_ ? velocity_ : Eigen::Isometry3d::Identity();
    T.linear() = measured_rotation_;
    return T;
  }
  return known_ ? velocity_ : Eigen::Isometry3d::Identity();
}

void ConstantVelocity::Move(const Eigen::Isometry3d& per_frame, double weight) {
  if (IsFinitePose(per_frame) && (weight > 0.0 || !known_)) {
    velocity_ = known_ ? Blend(velocity_, per_frame, weight) : per_frame;
    known_ = true;
  }
}

}  // namespace vo
