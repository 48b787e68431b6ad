#include "vo/sliding_window.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace vo {
namespace {

bool IsFinitePose(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

}  // namespace

BundleAdjustmentProblem SelectBaPoints(BundleAdjustmentProblem problem, int max_points,
                                       int min_frames) {
  const int num_points = static_cast<int>(problem.points_world.size());
  std::vector<int> frames_seen(num_points, 0);
  for (const BaObservation& o : problem.observations) ++frames_seen[o.point_index];
  std::vector<int> order;
  for (int j = 0; j < num_points; ++j) {
    if (frames_seen[j] >= min_frames) order.push_back(j);
  }
  if (max_points <= 0 || static_cast<int>(order.size()) <= max_points) {
    if (static_cast<int>(order.size()) == num_points) return problem;
  } else {
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return frames_seen[a] > frames_seen[b]; });
    order.resize(max_points);
    std::sort(order.begin(), order.end());
  }
  std::vector<int> new_index(num_points, -1);
  BundleAdjustmentProblem selected;
  selected.T_world_cam0 = std::move(problem.T_world_cam0);
  selected.planar = problem.planar;
  selected.rotation_priors = problem.rotation_priors;
  for (int j : order) {
    new_index[j] = static_cast<int>(selected.points_world.size());
    selected.points_world.push_back(problem.points_world[j]);
  }
  for (BaObservation o : problem.observations) {
    if (new_index[o.point_index] < 0) continue;
    o.point_index = new_index[o.point_index];
    selected.observations.push_back(o);
  }
  return selected;
}

SlidingWindow::SlidingWindow(const SlidingWindowOptions& options)
    : options_(options), tracks_(TrackManagerOptions{options.window_frames}) {}

void SlidingWindow::Reset() {
  tracks_.Reset();
  T_world_cam0_by_frame_.clear();
}

TrackUpdateResult SlidingWindow::Start(int64_t frame_index, std::vector<Feature>* features,
                                       const Eigen::Isometry3d& T_world_cam0) {
  tracks_.Reset();
  const TrackUpdateResult update = tracks_.AddFrame(frame_index, features, {});
  T_world_cam0_by_frame_.clear();
  T_world_cam0_by_frame_[frame_index] = T_world_cam0;
  return update;
}

TrackUpdateResult SlidingWindow::Add(int64_t frame_index, std::vector<Feature>* features,
                                     const std::vector<Match>& inlier_matches,
                                     const Eigen::Isometry3d& T_world_cam0_initial) {
  const TrackUpdateResult update = tracks_.AddFrame(frame_index, features, inlier_matches);
  if (!update.ok()) return update;
  T_world_cam0_by_frame_[frame_index] = T_world_cam0_initial;
  // Keep the poses of the window's frames only.
  const auto& window = tracks_.window_frame_ids();
  for (auto it = T_world_cam0_by_frame_.begin(); it != T_world_cam0_by_frame_.end();) {
    if (std::find(window.begin(), window.end(), it->first) == window.end()) {
      it = T_world_cam0_by_frame_.erase(it);
    } else {
      ++it;
    }
  }
  return update;
}

WindowRefinement SlidingWindow::Refine(const StereoCamera& camera, int64_t newest_frame_index,
                                       const PlanarMotionPrior& planar,
                                       const std::vector<WindowRotationPrior>& rotations) {
  WindowRefinement r;
  const auto newest_pose = T_world_cam0_by_frame_.find(newest_frame_index);
  if (!options_.use_bundle_adjustment || T_world_cam0_by_frame_.size() < 2 ||
      newest_pose == T_world_cam0_by_frame_.end()) {
    return r;
  }
  r.attempted = true;
  const Eigen::Isometry3d T_initial = newest_pose->second;
  std::vector<int64_t> frame_ids;
  BundleAdjustmentProblem problem =
      SelectBaPoints(MakeWindowProblem(tracks_, T_world_cam0_by_frame_, &frame_ids),
                     options_.max_points, options_.ba.min_frames_per_point);
  problem.planar = planar;
  for (const WindowRotationPrior& w : rotations) {
    const auto a = std::find(frame_ids.begin(), frame_ids.end(), w.frame_a);
    const auto b = std::find(frame_ids.begin(), frame_ids.end(), w.frame_b);
    if (a == frame_ids.end() || b == frame_ids.end() || a == b) continue;
    RotationPrior prior;
    prior.frame_a = static_cast<int>(a - frame_ids.begin());
    prior.frame_b = static_cast<int>(b - frame_ids.begin());
    prior.R_a_b = w.R_a_b;
    prior.sigma_rad = w.sigma_rad;
    problem.rotation_priors.push_back(prior);
  }
  if (static_cast<int>(problem.T_world_cam0.size()) <= options_.ba.num_fixed_poses) return r;
  const BundleAdjustmentSummary ba = RunBundleAdjustment(camera, problem, options_.ba);
  bool usable = ba.ok() && ba.T_world_cam0.size() == frame_ids.size();
  for (size_t i = 0; usable && i < ba.T_world_cam0.size(); ++i) {
    usable = IsFinitePose(ba.T_world_cam0[i]);
  }
  // Divergence guard: the newest pose may move only so far from its initial value.
  const size_t newest = static_cast<size_t>(
      std::find(frame_ids.begin(), frame_ids.end(), newest_frame_index) - frame_ids.begin());
  usable = usable && newest < frame_ids.size();
  if (usable) {
    const Eigen::Isometry3d& T_new = ba.T_world_cam0[newest];
    const double moved_m = (T_new.translation() - T_initial.translation()).norm();
    const double turned_deg =
        Eigen::AngleAxisd(T_new.linear().transpose() * T_initial.linear()).angle() * 180.0 / M_PI;
    if (moved_m > options_.max_correction_m || turned_deg > options_.max_correction_deg) {
      std::ostringstream msg;
      msg << "bundle adjustment rejected: it moved the pose by " << moved_m << " m and "
          << turned_deg << " deg";
      r.message = msg.str();
      r.rejected = true;
      return r;
    }
  }
  if (!usable) return r;
  for (size_t i = 0; i < frame_ids.size(); ++i) {
    T_world_cam0_by_frame_[frame_ids[i]] = ba.T_world_cam0[i];
  }
  r.ran = true;
  r.num_frames = static_cast<int>(frame_ids.size());
  r.num_points = ba.num_points_optimized;
  r.rms_reprojection_px = ba.rms_inlier_reprojection_after_px;
  return r;
}

const Eigen::Isometry3d* SlidingWindow::Pose(int64_t frame_index) const {
  const auto it = T_world_cam0_by_frame_.find(frame_index);
  return it == T_world_cam0_by_frame_.end() ? nullptr : &it->second;
}

}  // namespace vo
