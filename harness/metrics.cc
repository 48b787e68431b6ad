#include "harness/metrics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace harness {

double RotationAngle(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  const Eigen::Matrix3d R = R_a.transpose() * R_b;
  const double c = (R.trace() - 1.0) / 2.0;
  const double s =
      0.5 * Eigen::Vector3d(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1)).norm();
  return std::atan2(s, c);
}

std::vector<Eigen::Isometry3d> RelativeToFirst(const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<Eigen::Isometry3d> out;
  if (poses.empty()) return out;
  const Eigen::Isometry3d inv0 = poses.front().inverse();
  for (const auto& T : poses) out.push_back(inv0 * T);
  return out;
}

std::vector<double> CumulativeDistance(const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<double> d(poses.size(), 0.0);
  for (size_t i = 1; i < poses.size(); ++i)
    d[i] = d[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  return d;
}

double Median(std::vector<double> v) { return Percentile(std::move(v), 50.0); }

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * v.size()));
  return v[std::clamp<size_t>(rank, 1, v.size()) - 1];
}

namespace {

// Error of the estimated motion from frame i to frame j against the ground truth's.
Eigen::Isometry3d RelativeError(const std::vector<Eigen::Isometry3d>& est,
                                const std::vector<Eigen::Isometry3d>& gt, size_t i, size_t j) {
  const Eigen::Isometry3d d_est = est[i].inverse() * est[j];
  const Eigen::Isometry3d d_gt = gt[i].inverse() * gt[j];
  return d_gt.inverse() * d_est;
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Metres(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.3f m", v);
  return buf;
}

}  // namespace

std::vector<std::pair<size_t, size_t>> RpeDistancePairs(const std::vector<double>& dist,
                                                        double delta) {
  std::vector<std::pair<size_t, size_t>> pairs;
  const double tol = 0.1 * delta;  // evo_rpe: --delta_tol 0.1 (relative), the default
  for (size_t i = 0; i + 1 < dist.size(); ++i) {
    // |(dist[j] - dist[i]) - delta| falls, then rises along j (dist does not decrease): the
    // first minimum is found before the distance passes delta by more than the best so far.
    size_t best = i + 1;
    double best_diff = std::fabs((dist[i + 1] - dist[i]) - delta);
    for (size_t j = i + 2; j < dist.size(); ++j) {
      const double diff = std::fabs((dist[j] - dist[i]) - delta);
      if (diff < best_diff) {
        best = j;
        best_diff = diff;
      } else if (dist[j] - dist[i] > delta) {
        break;
      }
    }
    if (best_diff <= tol) pairs.emplace_back(i, best);
  }
  return pairs;
}

std::vector<double> KittiSegmentLengths(double path_length_m) {
  const double unit = path_length_m >= 1000.0 ? 100.0 : path_length_m / 10.0;
  std::vector<double> lengths;
  for (int k = 1; k <= 8; ++k) lengths.push_back(k * unit);
  return lengths;
}

void KittiDrift(const std::vector<Eigen::Isometry3d>& est, const std::vector<Eigen::Isometry3d>& gt,
                const std::vector<double>& lengths, TrajectoryMetrics* m) {
  const size_t n = std::min(est.size(), gt.size());
  const std::vector<double> dist =
      CumulativeDistance(std::vector<Eigen::Isometry3d>(gt.begin(), gt.begin() + n));
  constexpr size_t kStepFrames = 10;  // the devkit's step_size
  double t_sum = 0.0, r_sum = 0.0;
  int count = 0;
  for (size_t first = 0; first < n; first += kStepFrames) {
    for (const double len : lengths) {
      size_t last = first;  // the devkit's lastFrameFromSegmentLength: first frame past len
      while (last < n && !(dist[last] > dist[first] + len)) ++last;
      if (last >= n) continue;
      const Eigen::Isometry3d d_gt = gt[first].inverse() * gt[last];
      const Eigen::Isometry3d d_est = est[first].inverse() * est[last];
      const Eigen::Isometry3d error = d_est.inverse() * d_gt;
      t_sum += error.translation().norm() / len;
      r_sum += RotationAngle(Eigen::Matrix3d::Identity(), error.linear()) / len;
      ++count;
    }
  }
  m->kitti_drift_segments = count;
  if (count == 0) {
    m->kitti_drift_pct = m->kitti_drift_deg_per_m = kNaN;
    m->kitti_drift_reason = "no segment of the KITTI lengths fits in the path";
    return;
  }
  m->kitti_drift_pct = 100.0 * t_sum / count;
  m->kitti_drift_deg_per_m = r_sum / count * 180.0 / M_PI;
  m->kitti_drift_reason.clear();
}

TrajectoryMetrics ComputeTrajectoryMetrics(const std::vector<Eigen::Isometry3d>& estimate,
                                           const std::vector<Eigen::Isometry3d>& ground_truth,
                                           double rpe_distance_step_m) {
  TrajectoryMetrics m;
  const size_t n = std::min(estimate.size(), ground_truth.size());
  m.frames = static_cast<int>(n);
  if (n < 2) return m;
  const std::vector<Eigen::Isometry3d> est =
      RelativeToFirst({estimate.begin(), estimate.begin() + n});
  const std::vector<Eigen::Isometry3d> gt =
      RelativeToFirst({ground_truth.begin(), ground_truth.begin() + n});
  const std::vector<double> dist = CumulativeDistance(gt);
  m.path_length_m = dist.back();

  // End pose.
  m.end_pose_error_m = (est.back().translation() - gt.back().translation()).norm();
  const bool short_path = !(m.path_length_m >= kMinPathForRatiosM);
  const std::string short_reason = "ground-truth path " + Metres(m.path_length_m) +
                                   " shorter than " + Metres(kMinPathForRatiosM) +
                                   ": no figures relative to the path length";
  if (short_path) {
    m.end_pose_error_pct = kNaN;
    m.end_pose_error_pct_reason = short_reason;
  } else {
    m.end_pose_error_pct = 100.0 * m.end_pose_error_m / m.path_length_m;
  }
  m.end_rotation_error_deg = RotationAngle(est.back().linear(), gt.back().linear()) * 180.0 / M_PI;

  // ATE: unaligned (common start) and after SE(3) Umeyama alignment of the positions.
  Eigen::Matrix3Xd P_est(3, n), P_gt(3, n);
  for (size_t i = 0; i < n; ++i) {
    P_est.col(i) = est[i].translation();
    P_gt.col(i) = gt[i].translation();
  }
  m.ate_rmse_unaligned_m = std::sqrt((P_est - P_gt).colwise().squaredNorm().mean());
  const Eigen::Matrix4d S = Eigen::umeyama(P_est, P_gt, false);
  const Eigen::Matrix3Xd aligned =
      (S.topLeftCorner<3, 3>() * P_est).colwise() + S.topRightCorner<3, 1>();
  m.ate_rmse_m = std::sqrt((aligned - P_gt).colwise().squaredNorm().mean());

  // RPE over one frame step.
  double st = 0.0, sr = 0.0;
  for (size_t i = 1; i < n; ++i) {
    const Eigen::Isometry3d e = RelativeError(est, gt, i - 1, i);
    st += e.translation().squaredNorm();
    const double r = RotationAngle(Eigen::Matrix3d::Identity(), e.linear());
    sr += r * r;
  }
  m.rpe_trans_rmse_m = std::sqrt(st / (n - 1));
  m.rpe_rot_rmse_deg = std::sqrt(sr / (n - 1)) * 180.0 / M_PI;

  // RPE over a distance step: evo_rpe's pairs (--delta step --delta_unit m --all_pairs).
  m.rpe_distance_step_m = rpe_distance_step_m;
  double dt = 0.0, dr = 0.0;
  if (rpe_distance_step_m > 0.0) {
    for (const auto& [i, j] : RpeDistancePairs(dist, rpe_distance_step_m)) {
      const Eigen::Isometry3d e = RelativeError(est, gt, i, j);
      dt += e.translation().squaredNorm();
      const double r = RotationAngle(Eigen::Matrix3d::Identity(), e.linear());
      dr += r * r;
      ++m.rpe_distance_pairs;
    }
  }
  if (m.rpe_distance_pairs > 0) {
    m.rpe_distance_trans_rmse_m = std::sqrt(dt / m.rpe_distance_pairs);
    m.rpe_distance_rot_rmse_deg = std::sqrt(dr / m.rpe_distance_pairs) * 180.0 / M_PI;
  } else {
    m.rpe_distance_trans_rmse_m = m.rpe_distance_rot_rmse_deg = kNaN;
    m.rpe_distance_reason = "no frame pair " + Metres(rpe_distance_step_m) +
                            " (+-10 %) apart along the ground-truth path of " +
                            Metres(m.path_length_m);
  }

  if (short_path) {
    m.drift_pct = m.drift_deg_per_m = kNaN;
    m.drift_reason = short_reason;
    m.kitti_drift_pct = m.kitti_drift_deg_per_m = kNaN;
    m.kitti_drift_reason = short_reason;
    return m;
  }

  // vobench's drift: for sub-path lengths L = k/8 of the path (k = 1..8), from every 10th
  // start frame, the relative pose error at the first frame at least L further along,
  // divided by the length of that sub-path.
  double t_sum = 0.0, r_sum = 0.0;
  int count = 0;
  for (int k = 1; k <= 8; ++k) {
    const double L = m.path_length_m * k / 8.0;
    for (size_t first = 0; first < n; first += 10) {
      size_t last = first;
      while (last < n && dist[last] - dist[first] < L) ++last;
      if (last >= n) break;
      const Eigen::Isometry3d e = RelativeError(est, gt, first, last);
      // Divided by the sub-path's actual length (>= L: frames are discrete).
      const double len = dist[last] - dist[first];
      t_sum += e.translation().norm() / len;
      r_sum += RotationAngle(Eigen::Matrix3d::Identity(), e.linear()) * 180.0 / M_PI / len;
      ++count;
    }
  }
  if (count > 0) {
    m.drift_pct = 100.0 * t_sum / count;
    m.drift_deg_per_m = r_sum / count;
  } else {
    m.drift_pct = m.drift_deg_per_m = kNaN;
    m.drift_reason = "no sub-path fits in the path";
  }

  // The KITTI devkit's drift.
  KittiDrift(est, gt, KittiSegmentLengths(m.path_length_m), &m);
  return m;
}

}  // namespace harness
