// Trajectory metrics: estimate vs ground truth, both given per frame (same length, same times).
// Both trajectories are first expressed relative to their own first pose (T_first_k), so the
// VO's choice of world frame does not matter; ATE additionally aligns them (Umeyama, SE(3)).
#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace harness {

struct TrajectoryMetrics {
  int frames = 0;
  double path_length_m = 0.0;              // ground-truth camera path length (m)
  double end_pose_error_m = 0.0;           // |t_est - t_gt| at the last frame, from the first (m)
  double end_pose_error_pct = 0.0;         // end_pose_error_m / path_length_m × 100
  double end_rotation_error_deg = 0.0;     // rotation error at the last frame (deg)
  double ate_rmse_m = 0.0;                 // RMSE of positions after SE(3) Umeyama alignment (m)
  double ate_rmse_unaligned_m = 0.0;       // RMSE of positions from the common start (m)
  double rpe_trans_rmse_m = 0.0;           // RPE over one frame step: translation RMSE (m)
  double rpe_rot_rmse_deg = 0.0;           // RPE over one frame step: rotation RMSE (deg)
  double rpe_distance_step_m = 0.0;        // distance step of the RPE below (m)
  double rpe_distance_trans_rmse_m = 0.0;  // RPE over a distance step: from every frame to
                                           // the first frame at least the step further along
                                           // the ground-truth path; translation RMSE (m)
  double rpe_distance_rot_rmse_deg = 0.0;  // the same, rotation RMSE (deg)
  int rpe_distance_pairs = 0;              // pairs evaluated (0 when the path is shorter)
  double drift_pct = 0.0;                  // KITTI-style translation drift (%), sub-paths of
                                           // 1/8 … 8/8 of the path length, averaged
  double drift_deg_per_m = 0.0;            // KITTI-style rotation drift (deg/m), same sub-paths
};

// Rotation angle (radians) between two rotations, full precision near 0.
double RotationAngle(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

// Poses relative to the first one: T_first_k = T_0^-1 T_k.
std::vector<Eigen::Isometry3d> RelativeToFirst(const std::vector<Eigen::Isometry3d>& poses);

// Cumulative distance along the positions (m), one per pose, starting at 0.
std::vector<double> CumulativeDistance(const std::vector<Eigen::Isometry3d>& poses);

// Default distance step of the RPE over distance (m): a metre suits hallway paths of a few to
// a few tens of metres (KITTI's evaluation uses 100-800 m on road sequences).
constexpr double kDefaultRpeDistanceStepM = 1.0;

// Computes the metrics; `estimate` and `ground_truth` must have the same size (>= 2).
TrajectoryMetrics ComputeTrajectoryMetrics(const std::vector<Eigen::Isometry3d>& estimate,
                                           const std::vector<Eigen::Isometry3d>& ground_truth,
                                           double rpe_distance_step_m = kDefaultRpeDistanceStepM);

// Median and 95th percentile (nearest rank) of `values` (0 when empty).
double Median(std::vector<double> values);
double Percentile(std::vector<double> values, double p);

}  // namespace harness
