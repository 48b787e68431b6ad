#include "vo/bridge_alignment.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "vo/prior_motion.h"

namespace vo {
namespace {

bool Usable(const Feature& f) { return f.has_depth() && f.p_cam0.allFinite(); }

constexpr double kMinDepthM = 1e-3;  // a point nearer than this does not project

// The feature of `features` nearest to uv within gate_px (the first of equals), or null.
const Feature* Nearest(const std::vector<Feature>& features, const Eigen::Vector2d& uv,
                       double gate_px) {
  double best = gate_px;
  const Feature* nearest = nullptr;
  for (const Feature& f : features) {
    if (!Usable(f)) continue;
    const double d = (f.uv_px - uv).norm();
    if (d <= best) {
      best = d;
      nearest = &f;
    }
  }
  return nearest;
}

bool Valid(const StereoCamera& camera, const BridgeAlignmentOptions& options) {
  return options.IsValid(nullptr) && camera.IsValid(nullptr);
}

}  // namespace

bool BridgeAlignmentOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!(gate_px > 0.0) || !std::isfinite(gate_px)) {
    msg << "gate_px must be finite and > 0, got " << gate_px;
  } else if (min_pairs < 1) {
    msg << "min_pairs must be >= 1, got " << min_pairs;
  } else if (!(disparity_sigma_px > 0.0) || !std::isfinite(disparity_sigma_px)) {
    msg << "disparity_sigma_px must be finite and > 0, got " << disparity_sigma_px;
  } else if (!(step_sigma_m > 0.0) || !std::isfinite(step_sigma_m)) {
    msg << "step_sigma_m must be finite and > 0, got " << step_sigma_m;
  }
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

bool ForwardStepFromDepth(const StereoCamera& camera, const std::vector<Feature>& prev,
                          const std::vector<Feature>& curr, const Eigen::Isometry3d& T_prev_curr,
                          const BridgeAlignmentOptions& options, double* t_z, int* pairs) {
  if (!Valid(camera, options)) return false;
  const Eigen::Isometry3d& T = T_prev_curr;
  const double depth_sigma_per_z4 = options.disparity_sigma_px / (camera.fx_px * camera.baseline_m);
  std::vector<std::pair<double, double>> steps;  // t_z, σ
  for (const Feature& q : curr) {
    if (!Usable(q)) continue;
    Eigen::Vector2d uv;
    if (!camera.ProjectLeft(T * q.p_cam0, &uv, kMinDepthM)) continue;
    const Feature* p = Nearest(prev, uv, options.gate_px);
    if (p == nullptr) continue;
    const double z1 = p->p_cam0.z(), z2 = q.p_cam0.z();
    const double sigma = depth_sigma_per_z4 * std::sqrt(z1 * z1 * z1 * z1 + z2 * z2 * z2 * z2);
    steps.emplace_back(z1 - (T.linear() * q.p_cam0).z(), sigma);
  }
  const int n = static_cast<int>(steps.size());
  if (n < options.min_pairs) return false;
  std::vector<double> values;
  for (const auto& s : steps) values.push_back(s.first);
  std::nth_element(values.begin(), values.begin() + n / 2, values.end());
  const double median = values[n / 2];
  const double prior_variance = options.step_sigma_m * options.step_sigma_m;
  double weight_sum = 1.0 / prior_variance, sum = T.translation().z() / prior_variance;
  int used = 0;
  for (const auto& [step, sigma] : steps) {
    if (std::abs(step - median) > 3.0 * sigma) continue;
    weight_sum += 1.0 / (sigma * sigma);
    sum += step / (sigma * sigma);
    ++used;
  }
  const double fused = sum / weight_sum;
  if (used == 0 || !std::isfinite(fused)) return false;
  *t_z = fused;
  *pairs = used;
  return true;
}

bool AlignVehicleYaw(const StereoCamera& camera, const std::vector<Feature>& prev,
                     const std::vector<Feature>& curr, const Eigen::Vector3d& up,
                     double axle_behind_camera_m, double forward_m,
                     const BridgeAlignmentOptions& options, double* yaw_rad, int* pairs) {
  if (!Valid(camera, options) || !std::isfinite(*yaw_rad) || !std::isfinite(forward_m) ||
      !up.allFinite() || !(up.norm() > 0.0)) {
    return false;
  }
  const auto motion_inverse = [&](double yaw) {
    return VehicleMotion(up, axle_behind_camera_m, yaw, forward_m).inverse();
  };
  constexpr double kStep = 1e-6;  // numeric derivative (radians)
  double yaw = *yaw_rad;
  int n = 0;
  for (int iteration = 0; iteration < 10; ++iteration) {
    const Eigen::Isometry3d T_curr_prev = motion_inverse(yaw);
    const Eigen::Isometry3d T_curr_prev_d = motion_inverse(yaw + kStep);
    double jtj = 0.0, jtr = 0.0;
    n = 0;
    for (const Feature& f : prev) {
      if (!Usable(f)) continue;
      Eigen::Vector2d uv, uv_d;
      if (!camera.ProjectLeft(T_curr_prev * f.p_cam0, &uv, kMinDepthM)) continue;
      const Feature* target = Nearest(curr, uv, options.gate_px);
      if (target == nullptr) continue;
      if (!camera.ProjectLeft(T_curr_prev_d * f.p_cam0, &uv_d, kMinDepthM)) return false;
      ++n;
      const Eigen::Vector2d r = uv - target->uv_px;
      const Eigen::Vector2d J = (uv_d - uv) / kStep;
      const double w = r.norm() <= 1.0 ? 1.0 : 1.0 / r.norm();  // Huber at 1 px
      jtj += w * J.squaredNorm();
      jtr += w * J.dot(r);
    }
    if (n < options.min_pairs || !(jtj > 0.0)) return false;
    const double step = -jtr / jtj;
    if (!std::isfinite(step)) return false;
    yaw += step;
    if (std::abs(step) < 1e-9) break;
  }
  if (!std::isfinite(yaw)) return false;
  *yaw_rad = yaw;
  *pairs = n;
  return true;
}

}  // namespace vo
