#include "sim/navigation.h"

#include <cmath>

namespace sim {

PlanarPose DeadReckon(const PlanarPose& pose, const DriveCommand& cmd, double dt_s) {
  PlanarPose next;
  const double mid_yaw = pose.yaw_rad + 0.5 * cmd.w_radps * dt_s;
  next.position =
      pose.position + cmd.v_mps * dt_s * Eigen::Vector2d(std::cos(mid_yaw), std::sin(mid_yaw));
  next.yaw_rad = pose.yaw_rad + cmd.w_radps * dt_s;
  return next;
}

PlanarPose PlanarPoseOf(const Eigen::Isometry3d& T_world_body) {
  PlanarPose p;
  p.position = T_world_body.translation().head<2>();
  const Eigen::Matrix3d& R = T_world_body.linear();
  p.yaw_rad = std::atan2(R(1, 0), R(0, 0));
  return p;
}

Eigen::Isometry3d BodyPoseOf(const PlanarPose& pose, double z_m) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(pose.yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(pose.position.x(), pose.position.y(), z_m);
  return T;
}

PlanarPose NavigationFixes::Fix(const Eigen::Isometry3d& T_vo_cam0, const PlanarPose& belief) {
  if (!anchored_) {
    T_world_vo_ = BodyPoseOf(belief, axle_height_m_) * T_body_cam0_ * T_vo_cam0.inverse();
    anchored_ = true;
  }
  return PlanarPoseOf(T_world_vo_ * T_vo_cam0 * T_body_cam0_.inverse());
}

}  // namespace sim
