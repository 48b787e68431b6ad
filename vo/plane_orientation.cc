#include "vo/plane_orientation.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "vo/horn.h"
#include "vo/ransac.h"  // SplitMix64

namespace vo {

const char* ToString(Plane::Kind kind) {
  switch (kind) {
    case Plane::Kind::kUnknown:
      return "unknown";
    case Plane::Kind::kFloor:
      return "floor";
    case Plane::Kind::kCeiling:
      return "ceiling";
    case Plane::Kind::kWall:
      return "wall";
  }
  return "unknown";
}

const char* ToString(PlaneOrientationResult::Status status) {
  switch (status) {
    case PlaneOrientationResult::Status::kOk:
      return "ok";
    case PlaneOrientationResult::Status::kNoFloor:
      return "no_floor";
    case PlaneOrientationResult::Status::kNoWall:
      return "no_wall";
    case PlaneOrientationResult::Status::kInvalidInput:
      return "invalid_input";
  }
  return "unknown";
}

bool PlaneOrientationOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (max_planes < 1)
    msg << "max_planes must be >= 1, got " << max_planes;
  else if (min_plane_inliers < 3)
    msg << "min_plane_inliers must be >= 3, got " << min_plane_inliers;
  else if (!(distance_threshold_m > 0.0) || !std::isfinite(distance_threshold_m))
    msg << "distance_threshold_m must be finite and > 0, got " << distance_threshold_m;
  else if (!(distance_threshold_per_m >= 0.0) || !std::isfinite(distance_threshold_per_m))
    msg << "distance_threshold_per_m must be finite and >= 0, got " << distance_threshold_per_m;
  else if (ransac_iterations < 1)
    msg << "ransac_iterations must be >= 1, got " << ransac_iterations;
  else if (!expected_up_cam0.allFinite() || !(expected_up_cam0.norm() > 0.0))
    msg << "expected_up_cam0 must be finite and non-zero";
  else if (!(max_normal_deviation_deg > 0.0 && max_normal_deviation_deg <= 45.0))
    msg << "max_normal_deviation_deg must be in (0, 45], got " << max_normal_deviation_deg;
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

// Grows with depth (stereo depth error grows with z).
double PlaneInlierDistance(const Eigen::Vector3d& p, const PlaneOrientationOptions& options) {
  return options.distance_threshold_m + options.distance_threshold_per_m * std::max(p.z(), 0.0);
}

void HorizontalBasis(const Eigen::Vector3d& up, Eigen::Vector3d* e1, Eigen::Vector3d* e2) {
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ() - up.z() * up;
  constexpr double kMinProjectedNorm = 1e-6;  // forward (almost) parallel to up
  if (forward.norm() < kMinProjectedNorm) forward = Eigen::Vector3d::UnitX() - up.x() * up;
  *e1 = forward.normalized();
  *e2 = up.cross(*e1);
}

namespace {

// Weighted least-squares plane through the points (smallest eigenvector of the weighted,
// centred scatter). Weights 1 / PlaneInlierDistance(p)²: the threshold models the point's noise,
// which grows with depth, so far (noisy) points count less.
bool FitPlaneLeastSquares(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& idx,
                          const PlaneOrientationOptions& options, Eigen::Vector3d* normal,
                          double* offset) {
  if (idx.size() < 3) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double weight_sum = 0.0;
  for (int i : idx) {
    const double w = 1.0 / std::pow(PlaneInlierDistance(points[i], options), 2);
    mean += w * points[i];
    weight_sum += w;
  }
  mean /= weight_sum;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i : idx) {
    const double w = 1.0 / std::pow(PlaneInlierDistance(points[i], options), 2);
    const Eigen::Vector3d q = points[i] - mean;
    scatter.noalias() += w * (q * q.transpose());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  if (eig.info() != Eigen::Success) return false;
  *normal = eig.eigenvectors().col(0).normalized();
  *offset = -normal->dot(mean);
  return true;
}

std::vector<int> Inliers(const std::vector<Eigen::Vector3d>& points,
                         const std::vector<int>& candidates, const Eigen::Vector3d& n, double d,
                         const PlaneOrientationOptions& options) {
  std::vector<int> in;
  for (int i : candidates)
    if (std::abs(n.dot(points[i]) + d) <= PlaneInlierDistance(points[i], options)) in.push_back(i);
  return in;
}

// Sequential RANSAC plane extraction (header, step 1).
std::vector<Plane> ExtractPlanes(const std::vector<Eigen::Vector3d>& points,
                                 const PlaneOrientationOptions& options) {
  std::vector<Plane> planes;
  std::vector<int> remaining(points.size());
  for (size_t i = 0; i < points.size(); ++i) remaining[i] = static_cast<int>(i);
  SplitMix64 rng(options.seed);
  constexpr double kMinSampleArea = 1e-12;  // |(b−a)×(c−a)| below: collinear sample (m²)
  for (int p = 0; p < options.max_planes; ++p) {
    if (static_cast<int>(remaining.size()) < options.min_plane_inliers) break;
    int best_count = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    Eigen::Vector3d best_n = Eigen::Vector3d::UnitZ();
    double best_d = 0.0;
    const uint64_t m = remaining.size();
    for (int it = 0; it < options.ransac_iterations; ++it) {
      const uint64_t i0 = rng.UniformIndex(m);
      uint64_t i1 = rng.UniformIndex(m);
      while (i1 == i0) i1 = rng.UniformIndex(m);
      uint64_t i2 = rng.UniformIndex(m);
      while (i2 == i0 || i2 == i1) i2 = rng.UniformIndex(m);
      const Eigen::Vector3d& a = points[remaining[i0]];
      const Eigen::Vector3d& b = points[remaining[i1]];
      const Eigen::Vector3d& c = points[remaining[i2]];
      Eigen::Vector3d n = (b - a).cross(c - a);
      if (!(n.norm() > kMinSampleArea)) continue;
      n.normalize();
      const double d = -n.dot(a);
      // MSAC score (Torr & Zisserman 2000): Σ min(r², thr²), in units of each point's own
      // threshold. Unlike the inlier count, it prefers the plane that fits its inliers
      // tightly, not one tilted to also graze the foot of a wall.
      int count = 0;
      double cost = 0.0;
      for (int i : remaining) {
        const double r = std::abs(n.dot(points[i]) + d) / PlaneInlierDistance(points[i], options);
        if (r <= 1.0) {
          ++count;
          cost += r * r;
        } else {
          cost += 1.0;
        }
      }
      if (cost < best_cost) {
        best_cost = cost;
        best_count = count;
        best_n = n;
        best_d = d;
      }
    }
    if (best_count < options.min_plane_inliers) break;
    // Least-squares refit on the inliers, twice (the refit may gain a few inliers).
    std::vector<int> inliers = Inliers(points, remaining, best_n, best_d, options);
    for (int r = 0; r < 2; ++r) {
      Eigen::Vector3d n;
      double d;
      if (!FitPlaneLeastSquares(points, inliers, options, &n, &d)) break;
      std::vector<int> refit = Inliers(points, remaining, n, d, options);
      if (refit.size() < inliers.size()) break;
      best_n = n;
      best_d = d;
      inliers.swap(refit);
    }
    if (static_cast<int>(inliers.size()) < options.min_plane_inliers) break;
    Plane plane;
    // (num_inliers and rms are final after the corner pass below.)
    // Orient the normal to the camera's side: d >= 0 is then the origin's distance.
    if (best_d < 0.0) {
      best_n = -best_n;
      best_d = -best_d;
    }
    plane.normal_cam0 = best_n;
    plane.offset_m = best_d;
    plane.num_inliers = static_cast<int>(inliers.size());
    double sq = 0.0;
    for (int i : inliers) sq += std::pow(best_n.dot(points[i]) + best_d, 2);
    plane.rms_distance_m = std::sqrt(sq / static_cast<double>(inliers.size()));
    planes.push_back(plane);
    // Remove the inliers (both lists are ascending).
    std::vector<int> rest;
    rest.reserve(remaining.size() - inliers.size());
    std::set_difference(remaining.begin(), remaining.end(), inliers.begin(), inliers.end(),
                        std::back_inserter(rest));
    remaining.swap(rest);
  }

  // Corner pass: a plane extracted early also took the points of its neighbours that lie
  // near the common edge (the foot of a wall for the floor), which tilt its least-squares
  // fit towards them. Refit every plane on its exclusive inliers: points within the
  // threshold of this plane and of no other one.
  for (int pass = 0; pass < 2 && planes.size() > 1; ++pass) {
    std::vector<std::vector<int>> exclusive(planes.size());
    for (size_t i = 0; i < points.size(); ++i) {
      const double thr = PlaneInlierDistance(points[i], options);
      int owner = -1, count = 0;
      for (size_t k = 0; k < planes.size(); ++k) {
        if (std::abs(planes[k].normal_cam0.dot(points[i]) + planes[k].offset_m) <= thr) {
          owner = static_cast<int>(k);
          ++count;
        }
      }
      if (count == 1) exclusive[owner].push_back(static_cast<int>(i));
    }
    for (size_t k = 0; k < planes.size(); ++k) {
      Eigen::Vector3d n;
      double d;
      if (static_cast<int>(exclusive[k].size()) < options.min_plane_inliers ||
          !FitPlaneLeastSquares(points, exclusive[k], options, &n, &d))
        continue;
      if (n.dot(planes[k].normal_cam0) < 0.0) {  // keep the camera-side orientation
        n = -n;
        d = -d;
      }
      planes[k].normal_cam0 = n;
      planes[k].offset_m = d;
      planes[k].num_inliers = static_cast<int>(exclusive[k].size());
      double sq = 0.0;
      for (int i : exclusive[k]) sq += std::pow(n.dot(points[i]) + d, 2);
      planes[k].rms_distance_m = std::sqrt(sq / static_cast<double>(exclusive[k].size()));
    }
  }
  return planes;
}

}  // namespace

PlaneOrientationResult EstimateHallwayOrientation(const std::vector<Eigen::Vector3d>& points,
                                                  const PlaneOrientationOptions& options) {
  using Status = PlaneOrientationResult::Status;
  PlaneOrientationResult result;
  std::string error;
  if (!options.IsValid(&error)) {
    result.message = error;
    return result;
  }
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      result.message = "point " + std::to_string(i) + " is not finite";
      return result;
    }
  }

  // Step 1: planes.
  result.planes = ExtractPlanes(points, options);

  // Step 2: floor / ceiling among the planes close to horizontal.
  const double kDegToRad = M_PI / 180.0;
  const double cos_max_dev = std::cos(options.max_normal_deviation_deg * kDegToRad);
  const double sin_max_dev = std::sin(options.max_normal_deviation_deg * kDegToRad);
  const Eigen::Vector3d up_prior = options.expected_up_cam0.normalized();
  for (size_t k = 0; k < result.planes.size(); ++k) {
    const Plane& pl = result.planes[k];
    const double c = pl.normal_cam0.dot(up_prior);
    if (std::abs(c) < cos_max_dev) continue;
    // The normal points to the camera's side: up-pointing → the camera is above → floor.
    const int kk = static_cast<int>(k);
    if (c > 0.0) {
      if (result.floor_index < 0 || pl.num_inliers > result.planes[result.floor_index].num_inliers)
        result.floor_index = kk;
    } else {
      if (result.ceiling_index < 0 ||
          pl.num_inliers > result.planes[result.ceiling_index].num_inliers)
        result.ceiling_index = kk;
    }
  }
  if (result.floor_index >= 0) result.planes[result.floor_index].kind = Plane::Kind::kFloor;
  if (result.ceiling_index >= 0) result.planes[result.ceiling_index].kind = Plane::Kind::kCeiling;
  if (result.floor_index >= 0) {
    result.up_cam0 = result.planes[result.floor_index].normal_cam0;
    result.camera_height_m = result.planes[result.floor_index].offset_m;
  } else if (result.ceiling_index >= 0) {
    result.up_cam0 = -result.planes[result.ceiling_index].normal_cam0;
  } else {
    result.status = Status::kNoFloor;
    result.message =
        "no floor or ceiling plane among " + std::to_string(result.planes.size()) + " planes";
    return result;
  }
  const Eigen::Vector3d up = result.up_cam0;

  // Horizontal reference basis (HorizontalBasis).
  Eigen::Vector3d e1, e2;
  HorizontalBasis(up, &e1, &e2);

  // Step 3: walls vote for the Manhattan frame: circular mean of 4θ (inlier-weighted).
  double sum_sin = 0.0, sum_cos = 0.0;
  int num_walls = 0;
  for (size_t k = 0; k < result.planes.size(); ++k) {
    Plane& pl = result.planes[k];
    if (pl.kind != Plane::Kind::kUnknown) continue;
    if (std::abs(pl.normal_cam0.dot(up)) > sin_max_dev) continue;
    pl.kind = Plane::Kind::kWall;
    ++num_walls;
    const double theta = std::atan2(pl.normal_cam0.dot(e2), pl.normal_cam0.dot(e1));
    sum_sin += pl.num_inliers * std::sin(4.0 * theta);
    sum_cos += pl.num_inliers * std::cos(4.0 * theta);
  }
  double yaw = 0.0;  // angle of x_hall from e1 towards e2, in (−π/4, π/4]
  if (num_walls > 0) yaw = std::atan2(sum_sin, sum_cos) / 4.0;
  const Eigen::Vector3d x_hall = std::cos(yaw) * e1 + std::sin(yaw) * e2;
  const Eigen::Vector3d y_hall = up.cross(x_hall);
  Eigen::Matrix3d R_cam0_hall;
  R_cam0_hall.col(0) = x_hall;
  R_cam0_hall.col(1) = y_hall;
  R_cam0_hall.col(2) = up;

  // Step 3b (Manhattan refinement): every classified plane's normal is one of the hallway
  // axes ±x, ±y, ±z; snap each to its axis under the first estimate and fit the rotation
  // to all of them at once (weighted orthogonal Procrustes, via Horn's method on the point
  // pairs ±axis → ±normal, whose centroids are zero). The walls then also correct the part
  // of the floor normal's error that lies along the wall normals.
  if (options.manhattan_refinement && num_walls > 0) {
    std::vector<Eigen::Vector3d> axes, normals;
    std::vector<double> weights;
    for (const Plane& pl : result.planes) {
      if (pl.kind == Plane::Kind::kUnknown) continue;
      const Eigen::Vector3d n_hall = R_cam0_hall.transpose() * pl.normal_cam0;
      Eigen::Index k;
      n_hall.cwiseAbs().maxCoeff(&k);
      Eigen::Vector3d axis = Eigen::Vector3d::Zero();
      axis[k] = n_hall[k] > 0.0 ? 1.0 : -1.0;
      axes.push_back(axis);
      normals.push_back(pl.normal_cam0);
      weights.push_back(static_cast<double>(pl.num_inliers));
    }
    const Eigen::Index m = static_cast<Eigen::Index>(axes.size());
    Eigen::Matrix3Xd src(3, 2 * m), dst(3, 2 * m);
    Eigen::VectorXd w(2 * m);
    for (Eigen::Index k = 0; k < m; ++k) {
      src.col(2 * k) = axes[k];
      src.col(2 * k + 1) = -axes[k];
      dst.col(2 * k) = normals[k];
      dst.col(2 * k + 1) = -normals[k];
      w[2 * k] = w[2 * k + 1] = weights[k];
    }
    const HornResult fit = EstimateRigidMotionHorn(src, dst, w);
    if (fit.ok()) {
      R_cam0_hall = fit.T_dst_src.linear();
      result.up_cam0 = R_cam0_hall.col(2);
    }
  }
  result.R_hall_cam0 = R_cam0_hall.transpose();

  if (num_walls == 0) {
    result.status = Status::kNoWall;
    result.message = "no wall plane: yaw relative to the corridor unknown (set to 0)";
    return result;
  }
  result.status = Status::kOk;
  return result;
}

}  // namespace vo
