// The vehicle's up from its motions (VehicleUpEstimate) against an exactly known up.
#include "vo/planar_motion_prior.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "vo/prior_motion.h"  // vo::VehicleMotion

namespace vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDeg;
}

// A camera pitched down by 10° (x right, y down, z forward): the vehicle's up in its frame.
const Eigen::Vector3d kTrueUp =
    Eigen::AngleAxisd(10.0 * kDeg, Eigen::Vector3d::UnitX()) * Eigen::Vector3d(0, -1, 0);

// The true up tilted by `deg` about the camera's x axis (pitch) or z axis (roll).
Eigen::Vector3d Tilted(double deg, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(deg * kDeg, axis) * kTrueUp;
}

TEST(VehicleUpEstimateTest, UnknownUntilAPriorIsGiven) {
  VehicleUpEstimate up;
  EXPECT_FALSE(up.known());
  up.AddMotion(VehicleMotion(kTrueUp, 0.15, 0.05, 0.04), 0.01, 0.005);
  EXPECT_FALSE(up.known());
  EXPECT_FALSE(VehicleUpEstimate(Eigen::Vector3d::Zero(), 0.01).known());
  const VehicleUpEstimate prior(2.0 * kTrueUp, 0.01);
  ASSERT_TRUE(prior.known());
  EXPECT_NEAR((prior.up() - kTrueUp).norm(), 0.0, 1e-12);
}

// Straight driving fixes the tilt along the heading (the prior's pitch error goes), not the roll;
// a turn fixes the roll too. Noise-free motions of a wheeled vehicle with its axle 0.15 m behind,
// weighted far above the prior (σ 1 mm and 0.03° against 1°): the estimate is then within
// 2° · λ_prior / (λ_prior + λ_motions) ≈ 0.04° of the truth.
TEST(VehicleUpEstimateTest, StraightDrivingFixesThePitchATurnTheRoll) {
  const Eigen::Vector3d forward = HorizontalForwardAxis(kTrueUp);
  const Eigen::Vector3d lateral = kTrueUp.cross(forward);
  for (const Eigen::Vector3d& axis : {lateral, forward}) {
    SCOPED_TRACE(axis == lateral ? "prior pitched 2 deg" : "prior rolled 2 deg");
    VehicleUpEstimate up(Tilted(2.0, axis), 1.0 * kDeg);
    for (int k = 0; k < 100; ++k) up.AddMotion(VehicleMotion(kTrueUp, 0.15, 0.0, 0.04), 1e-3, 5e-4);
    const double after_straight = AngleDeg(up.up(), kTrueUp);
    if (axis == lateral)
      EXPECT_LT(after_straight, 0.05);  // the heading's tilt is measured
    else
      EXPECT_NEAR(after_straight, 2.0, 1e-6);  // across the heading nothing moves it
    for (int k = 0; k < 30; ++k)
      up.AddMotion(VehicleMotion(kTrueUp, 0.15, 3.0 * kDeg, 0.0), 1e-3, 5e-4);
    EXPECT_LT(AngleDeg(up.up(), kTrueUp), 0.05);
    EXPECT_NEAR(up.up().norm(), 1.0, 1e-12);
  }
}

TEST(VehicleUpEstimateTest, NonFiniteMotionsAreIgnored) {
  VehicleUpEstimate up(Tilted(2.0, Eigen::Vector3d::UnitZ()), 1.0 * kDeg);
  const Eigen::Vector3d before = up.up();
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = NAN;
  up.AddMotion(bad, 0.01, 0.005);
  EXPECT_EQ(up.up(), before);
}

// EvaluateJets (the Schur bundle adjustment's linearisation) against operator() on ceres::Jet
// (what AutoDiffCostFunction differentiates): the same residuals and derivatives, equal as
// numbers (a zero's sign may differ), for random poses, ups and floors.
TEST(PlanarMotionResidualTest, EvaluateJetsIsTheAutoDiffResidualAndJacobian) {
  using Jet = ceres::Jet<double, 14>;
  std::mt19937 rng(7u);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto random_unit = [&] {
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  };
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    PlanarMotionPrior prior;
    prior.enabled = true;
    prior.up_cam = trial % 5 == 0 ? Eigen::Vector3d(0, -1, 0) : random_unit();
    prior.axle_behind_camera_m = 0.3 * std::abs(normal(rng));
    prior.tilt_sigma_rad = 0.01 + 0.02 * std::abs(normal(rng));
    prior.lift_sigma_m = 0.01;
    prior.slip_sigma_m = 0.02;
    prior.flat_floor = trial % 2 == 0;
    prior.floor_up_world = random_unit();
    prior.floor_height_m = normal(rng);
    prior.floor_tilt_sigma_rad = 0.02;
    prior.floor_height_sigma_m = 0.05;
    const PlanarMotionResidual f(prior);
    Jet a[7], b[7];
    for (Jet* pose : {a, b}) {
      const Eigen::Quaterniond q(Eigen::AngleAxisd(M_PI * normal(rng), random_unit()));
      const double values[7] = {q.x(), q.y(), q.z(), q.w(), normal(rng), normal(rng), normal(rng)};
      for (int c = 0; c < 7; ++c) pose[c] = Jet(values[c], (pose == a ? 0 : 7) + c);
    }
    Jet reference[7], fast[7];
    ASSERT_TRUE(f(a, b, reference));
    ASSERT_TRUE(f.EvaluateJets(a, b, fast));
    for (int k = 0; k < 7; ++k) {
      ASSERT_EQ(fast[k].a, reference[k].a) << "trial " << trial << ", residual " << k;
      for (int j = 0; j < 14; ++j)
        ASSERT_EQ(fast[k].v[j], reference[k].v[j])
            << "trial " << trial << ", residual " << k << ", parameter " << j;
    }
    ++compared;
  }
  EXPECT_EQ(compared, 200);
}

}  // namespace
}  // namespace vo
