#include "vo/back_end.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <sstream>

#include "vo/motion_model.h"

namespace vo {
namespace {

SlidingWindowOptions WindowOptions(const BackEndOptions& o) {
  SlidingWindowOptions w;
  w.window_frames = o.window_frames;
  w.use_bundle_adjustment = o.bundle_adjustment;
  w.max_points = o.max_points;
  w.max_correction_m = o.max_correction_m;
  w.max_correction_deg = o.max_correction_deg;
  w.ba = o.ba;
  return w;
}

bool PositiveFinite(double x) { return x > 0.0 && std::isfinite(x); }

}  // namespace

BundleAdjustmentOptions DefaultOdometryBundleAdjustmentOptions() {
  BundleAdjustmentOptions options;
  options.min_frames_per_point = 2;
  // 10 before 2026-12-07: beyond 3 the accuracy does not change, the time does
  // (results/speed/ba_budget.md, 336 runs; the warm-started window is near its optimum).
  options.max_num_iterations = 3;
  options.solver = BaSolver::kSchurLm;
  options.linear_solver = BaLinearSolver::kDenseSchur;  // when solver = kCeres
  return options;
}

bool BackEndOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  std::string ba_error;
  if (!ba.IsValid(&ba_error)) {
    msg << "ba: " << ba_error;
  } else if (window_frames < 3 || window_frames > 10) {
    msg << "window_frames must be in [3, 10], got " << window_frames;
  } else if (ba.num_fixed_poses >= window_frames) {
    msg << "ba.num_fixed_poses (" << ba.num_fixed_poses << ") must be < window_frames ("
        << window_frames << ")";
  } else if (!(prior_weight >= 0.0 && prior_weight <= 1.0)) {
    msg << "prior_weight must be in [0, 1], got " << prior_weight;
  } else if (!(max_correction_m > 0.0) || !(max_correction_deg > 0.0)) {
    msg << "max_correction_m and max_correction_deg must be > 0, got " << max_correction_m
        << " and " << max_correction_deg;
  } else if (max_points < 0) {
    msg << "max_points must be >= 0 (0 = no limit), got " << max_points;
  } else if (!PositiveFinite(vehicle_planar.tilt_sigma_deg) ||
             !PositiveFinite(vehicle_planar.lift_sigma_m) ||
             !PositiveFinite(vehicle_planar.slip_sigma_m)) {
    msg << "vehicle_planar.tilt_sigma_deg, lift_sigma_m and slip_sigma_m must be finite and > 0, "
           "got "
        << vehicle_planar.tilt_sigma_deg << ", " << vehicle_planar.lift_sigma_m << ", "
        << vehicle_planar.slip_sigma_m;
  } else if (!PositiveFinite(flat_floor.tilt_sigma_deg) ||
             !PositiveFinite(flat_floor.height_sigma_m)) {
    msg << "flat_floor.tilt_sigma_deg and height_sigma_m must be finite and > 0, got "
        << flat_floor.tilt_sigma_deg << ", " << flat_floor.height_sigma_m;
  }
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

Eigen::Isometry3d InitialMotion(const BackEndOptions& options,
                                const Eigen::Isometry3d& T_ref_curr_measured,
                                const Eigen::Isometry3d* T_ref_curr_prior, double inlier_ratio,
                                bool few_point) {
  if (T_ref_curr_prior == nullptr) return T_ref_curr_measured;
  const double w = !few_point ? options.prior_weight * (1.0 - std::min(1.0, inlier_ratio)) : 0.0;
  return Blend(T_ref_curr_measured, *T_ref_curr_prior, w);
}

PlanarMotionPrior WindowPlanarPrior(const BackEndOptions& options,
                                    const VehicleGeometry& geometry) {
  PlanarMotionPrior prior;
  prior.enabled = geometry.vehicle && options.vehicle_planar.enabled && geometry.up_known;
  if (!prior.enabled) return prior;
  prior.up_cam = geometry.up_cam;
  prior.axle_behind_camera_m = geometry.axle_behind_camera_m;
  prior.tilt_sigma_rad = options.vehicle_planar.tilt_sigma_deg * M_PI / 180.0;
  prior.lift_sigma_m = options.vehicle_planar.lift_sigma_m;
  prior.slip_sigma_m = options.vehicle_planar.slip_sigma_m;
  // The floor's up is the vehicle's (as refined so far) at the first pose, so that a turn about
  // the refined up keeps it; the world's z (the first floor fit) would tilt every pose by what
  // the refinement has moved the up since. Only when the first frame found a floor: an up from
  // the ceiling is off by 1-1.5° (plain_corridor, where no floor is found: strides 1/2/3/5
  // 0.72/0.52/2.75/1.04 % without the flat floor, 2.10/1.56/2.01/1.44 % with it on the refined
  // ceiling's up).
  prior.flat_floor = options.flat_floor.enabled && geometry.floor_found;
  prior.floor_up_world = geometry.R_world_cam0_initial * geometry.up_cam;
  prior.floor_height_m = 0.0;
  prior.floor_tilt_sigma_rad = options.flat_floor.tilt_sigma_deg * M_PI / 180.0;
  prior.floor_height_sigma_m = options.flat_floor.height_sigma_m;
  return prior;
}

BackEnd::BackEnd(const BackEndOptions& options)
    : options_(options), window_(WindowOptions(options)) {}

void BackEnd::Reset() {
  window_.Reset();
  gyro_chain_.clear();
}

TrackUpdateResult BackEnd::Start(int64_t frame_index, std::vector<Feature>* features,
                                 const Eigen::Isometry3d& T_world_cam0) {
  return window_.Start(frame_index, features, T_world_cam0);
}

BackEndAdd BackEnd::Add(int64_t frame_index, int64_t ref_frame_index,
                        std::vector<Feature>* features, const std::vector<Match>& inlier_matches,
                        const Eigen::Isometry3d& T_ref_curr_measured,
                        const Eigen::Isometry3d* T_ref_curr_prior, double inlier_ratio,
                        bool few_point) {
  BackEndAdd add;
  add.T_ref_curr_initial =
      InitialMotion(options_, T_ref_curr_measured, T_ref_curr_prior, inlier_ratio, few_point);
  const Eigen::Isometry3d* T_world_ref = window_.Pose(ref_frame_index);
  if (T_world_ref == nullptr) {
    add.update.message = "the reference frame has no pose in the window";
    return add;
  }
  add.T_world_curr = *T_world_ref * add.T_ref_curr_initial;
  add.update = window_.Add(frame_index, features, inlier_matches, add.T_world_curr);
  return add;
}

WindowRefinement BackEnd::Refine(const StereoCamera& camera, int64_t frame_index,
                                 const VehicleGeometry& geometry) {
  return window_.Refine(camera, frame_index, WindowPlanarPrior(options_, geometry),
                        GyroRotationPriors());
}

void BackEnd::AddGyroRotation(int64_t frame_index, const GyroRotation& rotation,
                              double min_rotation_sigma_deg) {
  // Frames older than the window's oldest (and than the previous frame) are no longer needed.
  const std::deque<int64_t>& window = window_.tracks().window_frame_ids();
  const int64_t oldest =
      window.empty() ? frame_index - 1 : std::min(window.front(), frame_index - 1);
  gyro_chain_.erase(gyro_chain_.begin(), gyro_chain_.lower_bound(oldest));
  GyroNode node;
  node.first = frame_index;
  const auto prev = gyro_chain_.find(frame_index - 1);
  const double sigma_rad =
      std::max(min_rotation_sigma_deg * M_PI / 180.0, rotation.ok ? rotation.sigma_rad() : 0.0);
  if (rotation.ok && prev != gyro_chain_.end() && rotation.R_prev_curr.allFinite() &&
      std::isfinite(sigma_rad)) {
    node.first = prev->second.first;
    node.R_first_frame = prev->second.R_first_frame * rotation.R_prev_curr;
    node.variance_rad2 = prev->second.variance_rad2 + sigma_rad * sigma_rad;
  }
  gyro_chain_[frame_index] = node;
}

std::vector<WindowRotationPrior> BackEnd::GyroRotationPriors() const {
  std::vector<WindowRotationPrior> priors;
  const GyroNode* previous = nullptr;
  int64_t previous_frame = -1;
  for (int64_t frame : window_.tracks().window_frame_ids()) {
    const auto it = gyro_chain_.find(frame);
    const GyroNode* node =
        it != gyro_chain_.end() && Pose(frame) != nullptr ? &it->second : nullptr;
    if (node != nullptr && previous != nullptr && node->first == previous->first &&
        node->variance_rad2 > previous->variance_rad2) {
      WindowRotationPrior p;
      p.frame_a = previous_frame;
      p.frame_b = frame;
      p.R_a_b = previous->R_first_frame.transpose() * node->R_first_frame;
      p.sigma_rad = std::sqrt(node->variance_rad2 - previous->variance_rad2);
      priors.push_back(p);
    }
    previous = node;
    previous_frame = frame;
  }
  return priors;
}

Eigen::Isometry3d BackEnd::MotionFromReference(int64_t ref_frame_index,
                                               const Eigen::Isometry3d& T_world_curr,
                                               const Eigen::Isometry3d& fallback) const {
  const Eigen::Isometry3d* T_world_ref = window_.Pose(ref_frame_index);
  if (T_world_ref == nullptr) return fallback;
  return Eigen::Isometry3d(T_world_ref->inverse() * T_world_curr);
}

}  // namespace vo
