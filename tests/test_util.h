// Shared test helpers: pose matchers and named tolerances.
#pragma once

#include <gmock/gmock.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

namespace vobench_test {

// Rotation angle (radians) of R_a^T R_b; atan2 of sin and cos keeps full precision near 0
// (acos of the trace cannot resolve angles below ~2e-8 rad).
inline double RotationAngleRad(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  const Eigen::Matrix3d R = R_a.transpose() * R_b;
  const double c = (R.trace() - 1.0) / 2.0;
  const double s =
      0.5 * Eigen::Vector3d(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1)).norm();
  return std::atan2(s, c);
}

// Matches an Eigen::Isometry3d within tol_rad of rotation and tol_m of translation.
MATCHER_P3(IsNearPose, expected, tol_rad, tol_m,
           "is within " + ::testing::PrintToString(tol_rad) + " rad and " +
               ::testing::PrintToString(tol_m) + " m of the expected pose") {
  const double dr = RotationAngleRad(expected.linear(), arg.linear());
  const double dt = (expected.translation() - arg.translation()).norm();
  *result_listener << "rotation error " << dr << " rad, translation error " << dt << " m";
  return dr <= tol_rad && dt <= tol_m;
}

// Directory of the shared real data sets (../shared/data); tests skip when it is absent.
inline std::string SharedDataDir() { return VOBENCH_SHARED_DATA_DIR; }

}  // namespace vobench_test
