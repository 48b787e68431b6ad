#include "vo/planar_motion_prior.h"

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
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

Eigen::Vector3d HorizontalForwardAxis(const Eigen::Vector3d& u) {
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitZ() - u.z() * u;
  if (e1.norm() < 1e-6) e1 = Eigen::Vector3d::UnitX() - u.x() * u;
  return e1.normalized();
}

}  // namespace vo
