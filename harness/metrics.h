// Trajectory metrics: estimate vs ground truth, both given per frame (same length, same times).
// Both trajectories are first expressed relative to their own first pose (T_first_k), so the
// VO's choice of world frame does not matter; ATE additionally aligns them (Umeyama, SE(3)).
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

namespace harness {

// Figures that do not apply to a run are NaN (metrics.json: null) with the reason in the
// matching *_reason string (empty when the figure applies).
struct TrajectoryMetrics {
  int frames = 0;
  double path_length_m = 0.0;              // ground-truth camera path length (m), 3-D
  double end_pose_error_m = 0.0;           // |t_est - t_gt| at the last frame, from the first (m)
  double end_pose_error_pct = 0.0;         // end_pose_error_m / path_length_m × 100; NaN when
                                           // the path is shorter than kMinPathForRatiosM
  std::string end_pose_error_pct_reason;   // why end_pose_error_pct is NaN ("" = it applies)
  double end_rotation_error_deg = 0.0;     // rotation error at the last frame (deg)
  double ate_rmse_m = 0.0;                 // RMSE of positions after SE(3) Umeyama alignment (m)
  double ate_rmse_unaligned_m = 0.0;       // RMSE of positions from the common start (m)
  double rpe_trans_rmse_m = 0.0;           // RPE over one frame step: translation RMSE (m)
  double rpe_rot_rmse_deg = 0.0;           // RPE over one frame step: rotation RMSE (deg)
  double rpe_distance_step_m = 0.0;        // distance step of the RPE below (m)
  double rpe_distance_trans_rmse_m = 0.0;  // RPE over a distance step, evo_rpe's pairs with
                                           // --delta <step> --delta_unit m --all_pairs
                                           // (RpeDistancePairs); translation RMSE (m)
  double rpe_distance_rot_rmse_deg = 0.0;  // the same, rotation RMSE (deg)
  int rpe_distance_pairs = 0;              // pairs evaluated; 0: the RMSEs are NaN
  std::string rpe_distance_reason;         // why the rpe_distance RMSEs are NaN ("" = apply)
  double drift_pct = 0.0;                  // vobench's drift (%): sub-paths of at least 1/8 …
                                           // 8/8 of the path, divided by their actual length
  double drift_deg_per_m = 0.0;            // the same, rotation (deg/m)
  std::string drift_reason;                // why drift_* are NaN ("" = they apply)
  double kitti_drift_pct = 0.0;            // the KITTI devkit's translation error (%):
                                           // KittiSegmentLengths, every 10th frame, the first
                                           // frame past L, divided by L (KittiDrift)
  double kitti_drift_deg_per_m = 0.0;      // the devkit's rotation error, in deg/m
  int kitti_drift_segments = 0;            // segments averaged; 0: kitti_drift_* are NaN
  std::string kitti_drift_reason;          // why kitti_drift_* are NaN ("" = they apply)
};

// Paths shorter than this (m; a standing-still clip) get no figures relative to the path
// length: end_pose_error_pct, drift_*, kitti_drift_* are NaN with the reason.
constexpr double kMinPathForRatiosM = 1.0;

// Rotation angle (radians) between two rotations, full precision near 0.
double RotationAngle(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

// Poses relative to the first one: T_first_k = T_0^-1 T_k.
std::vector<Eigen::Isometry3d> RelativeToFirst(const std::vector<Eigen::Isometry3d>& poses);

// Cumulative distance along the positions (m), one per pose, starting at 0.
std::vector<double> CumulativeDistance(const std::vector<Eigen::Isometry3d>& poses);

// Default distance step of the RPE over distance (m): a metre suits hallway paths of a few to
// a few tens of metres (KITTI's evaluation uses 100-800 m on road sequences).
constexpr double kDefaultRpeDistanceStepM = 1.0;

// The frame pairs (i, j) of the RPE over a distance step `delta` (m), as evo's
// filters.filter_pairs_by_path(..., all_pairs=True) picks them on the reference positions with
// evo_rpe's default tolerance tol = 0.1 × delta: for every i but the last, the j > i whose
// cumulative distance from i is closest to delta (the first such j on a tie), kept when
// |distance − delta| <= tol. `dist` is CumulativeDistance of the ground truth.
std::vector<std::pair<size_t, size_t>> RpeDistancePairs(const std::vector<double>& dist,
                                                        double delta);

// The KITTI odometry devkit's segment lengths (m) for a path of `path_length_m`: 100, 200, …,
// 800 m from 1000 m of path on; below, the same eight scaled to the path: k × path/10, k = 1..8
// (not rounded; continuous with the devkit's at 1000 m).
std::vector<double> KittiSegmentLengths(double path_length_m);

// The devkit's errors (evaluate_odometry.cpp, calcSequenceErrors) over `lengths`: from every
// 10th frame, for each length L the first frame whose ground-truth distance is more than L
// further (strictly), the error inv(Δest)·Δgt, its translation norm / L and rotation angle / L;
// the mean over every (frame, L) segment. Sets kitti_drift_pct (×100), kitti_drift_deg_per_m
// and kitti_drift_segments; both NaN (with kitti_drift_reason) when no segment fits. In double
// precision (the devkit: float), the angle by RotationAngle (the devkit: acos of the trace, the
// same angle without acos's loss near 0); rotation in deg/m (the devkit's stats: rad/m).
void KittiDrift(const std::vector<Eigen::Isometry3d>& est, const std::vector<Eigen::Isometry3d>& gt,
                const std::vector<double>& lengths, TrajectoryMetrics* m);

// Computes the metrics; `estimate` and `ground_truth` must have the same size (>= 2).
TrajectoryMetrics ComputeTrajectoryMetrics(const std::vector<Eigen::Isometry3d>& estimate,
                                           const std::vector<Eigen::Isometry3d>& ground_truth,
                                           double rpe_distance_step_m = kDefaultRpeDistanceStepM);

// Median and 95th percentile (nearest rank) of `values` (0 when empty).
double Median(std::vector<double> values);
double Percentile(std::vector<double> values, double p);

}  // namespace harness
