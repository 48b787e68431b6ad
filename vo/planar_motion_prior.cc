#include "vo/planar_motion_prior.h"

#include <Eigen/Eigenvalues>
#include <sstream>

namespace vo {

bool PlanarMotionPrior::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!up_cam.allFinite() || up_cam.norm() < 1e-9)
    msg << "planar motion prior: up_cam must be finite and non-zero";
  else if (!(axle_behind_camera_m >= 0.0) || !std::isfinite(axle_behind_camera_m))
    msg << "planar motion prior: axle_behind_camera_m must be finite and >= 0";
  else if (!(tilt_sigma_rad > 0.0) || !(lift_sigma_m > 0.0) || !(slip_sigma_m > 0.0) ||
           !std::isfinite(tilt_sigma_rad) || !std::isfinite(lift_sigma_m) ||
           !std::isfinite(slip_sigma_m))
    msg << "planar motion prior: the sigmas must be finite and > 0";
  else if (flat_floor && (!floor_up_world.allFinite() || floor_up_world.norm() < 1e-9 ||
                          !std::isfinite(floor_height_m) || !(floor_tilt_sigma_rad > 0.0) ||
                          !(floor_height_sigma_m > 0.0) || !std::isfinite(floor_tilt_sigma_rad) ||
                          !std::isfinite(floor_height_sigma_m)))
    msg << "planar motion prior: the flat floor needs a finite, non-zero floor_up_world, a "
           "finite floor_height_m and finite sigmas > 0";
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

Eigen::Vector3d HorizontalForwardAxis(const Eigen::Vector3d& u) {
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitZ() - u.z() * u;
  if (e1.norm() < 1e-6) e1 = Eigen::Vector3d::UnitX() - u.x() * u;
  return e1.normalized();
}

VehicleUpEstimate::VehicleUpEstimate(const Eigen::Vector3d& prior_up, double prior_sigma_rad) {
  if (!prior_up.allFinite() || prior_up.norm() < 1e-9 || !(prior_sigma_rad > 0.0)) return;
  up_ = prior_up.normalized();
  information_ =
      (Eigen::Matrix3d::Identity() - up_ * up_.transpose()) / (prior_sigma_rad * prior_sigma_rad);
}

void VehicleUpEstimate::AddMotion(const Eigen::Isometry3d& T_ref_curr, double translation_sigma_m,
                                  double rotation_sigma_rad) {
  if (!known() || !T_ref_curr.matrix().allFinite()) return;
  const Eigen::Vector3d t = T_ref_curr.translation();
  const Eigen::AngleAxisd aa(T_ref_curr.linear());
  const Eigen::Vector3d w = aa.angle() * aa.axis();
  information_ += t * t.transpose() / (translation_sigma_m * translation_sigma_m) +
                  (w.squaredNorm() * Eigen::Matrix3d::Identity() - w * w.transpose()) /
                      (rotation_sigma_rad * rotation_sigma_rad);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(information_);
  if (eig.info() != Eigen::Success) return;
  Eigen::Vector3d up = eig.eigenvectors().col(0);  // the smallest eigenvalue's
  if (up.dot(up_) < 0.0) up = -up;
  if (up.allFinite()) up_ = up.normalized();
}

}  // namespace vo
