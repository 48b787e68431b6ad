#include "vo/prior_motion.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

using test::TestCamera;
using vobench_test::IsNearPose;

constexpr double kDeg = M_PI / 180.0;
constexpr double kExactRad = 1e-9;  // exact data, nothing to trade against the prior
constexpr double kExactM = 1e-9;

// A robot turning in front of a wall: yaw about the camera's y axis and a small translation.
Eigen::Isometry3d Motion(double yaw_deg, const Eigen::Vector3d& t_m) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = t_m;
  return T;
}

// Exact stereo correspondence of p_prev under the true T_prev_curr.
StereoCorrespondence Exact(const StereoCamera& cam, const Eigen::Isometry3d& T_prev_curr,
                           const Eigen::Vector3d& p_prev) {
  StereoCorrespondence c;
  c.p_prev_cam0 = p_prev;
  const Eigen::Vector3d p_curr = T_prev_curr.inverse() * p_prev;
  Eigen::Vector2d uv;
  EXPECT_TRUE(cam.ProjectLeft(p_curr, &uv));
  c.uv_curr_px = uv;
  c.disparity_curr_px = cam.DisparityFromDepth(p_curr.z());
  return c;
}

// Points on a plain wall 0.85 m ahead, a few specks.
std::vector<Eigen::Vector3d> WallSpecks() {
  return {{0.45, -0.20, 0.85}, {-0.28, -0.27, 0.85}, {-0.31, 0.15, 0.86}};
}

double RotationErrorRad(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

TEST(PriorMotionTest, AMeasuredRotationLetsOnePointGiveTheTranslation) {
  // A robot that stopped to turn in front of a wall: the prior's rotation is the gyro's (exact,
  // σ 0.05°), its translation the constant velocity's cruise step (10 cm a frame) where the
  // camera moved 1 cm. No rotation correction explains 10 cm at 0.85 m; each point's own
  // translation does (gyro_prior.h: the few-point motion with the gyro's rotation).
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_true = Motion(6.0, {0.01, 0.0, 0.002});
  Eigen::Isometry3d prior = T_true;
  prior.translation() = Eigen::Vector3d(0.0, 0.0, 0.10);
  std::vector<StereoCorrespondence> corr;
  for (const Eigen::Vector3d& p : WallSpecks()) corr.push_back(Exact(cam, T_true, p));
  PriorMotionOptions options;
  options.prior_rotation_sigma_deg = 0.05;
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, prior, options);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.num_inliers, 3);
  // The fit is the MAP one: the prior's translation (σ 1 cm) still pulls a few millimetres.
  EXPECT_THAT(r.T_prev_curr, IsNearPose(T_true, 0.01 * kDeg, 0.01));
  // An extrapolated rotation (the default σ, 2°): no such hypothesis, as before.
  const PriorMotionResult d = EstimateMotionWithPrior(cam, corr, prior);
  EXPECT_FALSE(d.ok && (d.T_prev_curr.translation() - T_true.translation()).norm() < 1e-3)
      << d.message;
}

TEST(PriorMotionTest, ExactWhenTheTruthIsThePrior) {
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_true = Motion(2.2, {0.006, 0.0, 0.001});
  std::vector<StereoCorrespondence> corr;
  for (const Eigen::Vector3d& p : WallSpecks()) corr.push_back(Exact(cam, T_true, p));
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, T_true);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.num_inliers, 3);
  EXPECT_THAT(r.T_prev_curr, IsNearPose(T_true, kExactRad, kExactM));
}

// The prior missed the start of a turn (no rotation, 2.2° true): three specks recover the
// rotation to a small fraction of the prior's error.
TEST(PriorMotionTest, ThreeSpecksRecoverAMissedTurn) {
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_true = Motion(2.2, {0.006, 0.0, 0.001});
  const Eigen::Isometry3d T_prior = Motion(0.0, {0.006, 0.0, 0.001});
  std::vector<StereoCorrespondence> corr;
  for (const Eigen::Vector3d& p : WallSpecks()) corr.push_back(Exact(cam, T_true, p));
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, T_prior);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.num_inliers, 3);
  // Points at one depth cannot tell a yaw from a sideways step exactly; the prior's σ decide
  // the split, and the image residual stays far below a pixel.
  EXPECT_LT(RotationErrorRad(r.T_prev_curr, T_true), 0.1 * 2.2 * kDeg);
  EXPECT_LT((r.T_prev_curr.translation() - T_true.translation()).norm(), 0.003);
  EXPECT_LT(r.rms_reprojection_px, 0.2);
}

// A pure rotation seen at one far point, the prior's translation exact: the 1-point solver
// puts the point on its bearing, the pan is exact.
TEST(PriorMotionTest, OneFarPointGivesThePan) {
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_true = Motion(-3.0, Eigen::Vector3d::Zero());
  const Eigen::Isometry3d T_prior = Eigen::Isometry3d::Identity();
  PriorMotionOptions options;
  options.min_inliers = 1;
  const std::vector<StereoCorrespondence> corr = {
      Exact(cam, T_true, Eigen::Vector3d(0.0, 0.0, 40.0))};
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, T_prior, options);
  ASSERT_TRUE(r.ok) << r.message;
  // The point pins the bearing: the pan is recovered up to the MAP's pull towards the prior,
  // σ_px² / (f² σ_rot²) ≈ 1 % of the prior's 3° error.
  EXPECT_LT(RotationErrorRad(r.T_prev_curr, T_true), 0.02 * 3.0 * kDeg);
  // With a vague prior the 1-point solution is exact.
  options.prior_rotation_sigma_deg = 1e4;
  const PriorMotionResult vague = EstimateMotionWithPrior(cam, corr, T_prior, options);
  ASSERT_TRUE(vague.ok) << vague.message;
  EXPECT_LT(RotationErrorRad(vague.T_prev_curr, T_true), 1e-7);
}

// Many points at several depths: the data decide, the prior's pull vanishes.
TEST(PriorMotionTest, ManyPointsOverruleAWrongPrior) {
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_true = Motion(2.0, {0.01, -0.002, 0.03});
  const Eigen::Isometry3d T_prior = Motion(0.5, {0.0, 0.0, 0.04});
  std::vector<StereoCorrespondence> corr;
  for (int i = 0; i < 40; ++i) {
    const double x = -1.0 + 0.05 * i, y = 0.4 * std::sin(1.7 * i), z = 1.0 + 0.1 * (i % 7);
    corr.push_back(Exact(cam, T_true, Eigen::Vector3d(x * z * 0.5, y * z * 0.5, z)));
  }
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, T_prior);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.num_inliers, 40);
  // The MAP keeps a small pull towards the prior (1.5° and 14 mm off here).
  EXPECT_LT(RotationErrorRad(r.T_prev_curr, T_true), 0.03 * 1.5 * kDeg);
  EXPECT_LT((r.T_prev_curr.translation() - T_true.translation()).norm(), 0.1 * 0.014);
  EXPECT_LT(r.rms_reprojection_px, 0.1);
  // A vague prior (σ × 10⁴): the exact motion, to rounding.
  PriorMotionOptions vague_options;
  vague_options.prior_rotation_sigma_deg *= 1e4;
  vague_options.prior_translation_sigma_m *= 1e4;
  const PriorMotionResult vague = EstimateMotionWithPrior(cam, corr, T_prior, vague_options);
  ASSERT_TRUE(vague.ok) << vague.message;
  EXPECT_THAT(vague.T_prev_curr, IsNearPose(T_true, 1e-8, 1e-9));
}

TEST(PriorMotionTest, GrossOutliersAreNotInliers) {
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_true = Motion(2.2, {0.006, 0.0, 0.001});
  const Eigen::Isometry3d T_prior = Motion(1.5, {0.006, 0.0, 0.0});
  std::vector<StereoCorrespondence> corr;
  for (const Eigen::Vector3d& p : WallSpecks()) corr.push_back(Exact(cam, T_true, p));
  corr.push_back(Exact(cam, T_true, Eigen::Vector3d(0.1, 0.1, 0.85)));
  corr.back().uv_curr_px += Eigen::Vector2d(25.0, -12.0);  // a wrong match
  corr.push_back(Exact(cam, T_true, Eigen::Vector3d(-0.1, 0.2, 0.85)));
  corr.back().uv_curr_px.y() += 9.0;
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, T_prior);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.num_inliers, 3);
  EXPECT_THAT(r.inlier_mask, ::testing::ElementsAre(true, true, true, false, false));
  EXPECT_LT(RotationErrorRad(r.T_prev_curr, T_true), 0.1 * 0.7 * kDeg);
}

TEST(PriorMotionTest, TooFewInliersIsNotOk) {
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_true = Motion(2.2, Eigen::Vector3d::Zero());
  std::vector<StereoCorrespondence> corr = {Exact(cam, T_true, WallSpecks()[0])};
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, T_true);  // min_inliers 2
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.num_inliers, 1);
  // Two that agree among five (three wrong): below min_inlier_fraction 0.5.
  corr.push_back(Exact(cam, T_true, WallSpecks()[1]));
  for (int k = 0; k < 3; ++k) {
    corr.push_back(Exact(cam, T_true, WallSpecks()[2]));
    corr.back().uv_curr_px += Eigen::Vector2d(20.0 + 15.0 * k, -30.0 + 25.0 * k);
  }
  const PriorMotionResult fraction = EstimateMotionWithPrior(cam, corr, T_true);
  EXPECT_FALSE(fraction.ok);
  EXPECT_EQ(fraction.num_inliers, 2);
  corr.resize(2);
  EXPECT_TRUE(EstimateMotionWithPrior(cam, corr, T_true).ok);
  const PriorMotionResult none = EstimateMotionWithPrior(cam, {}, T_true);
  EXPECT_FALSE(none.ok);
  EXPECT_EQ(none.num_inliers, 0);
  EXPECT_THAT(none.T_prev_curr, IsNearPose(T_true, 0.0, 0.0));
}

TEST(PriorMotionTest, InvalidInputIsNotOk) {
  const StereoCamera cam = TestCamera();
  std::vector<StereoCorrespondence> corr = {
      Exact(cam, Eigen::Isometry3d::Identity(), WallSpecks()[0])};
  PriorMotionOptions bad;
  bad.prior_rotation_sigma_deg = 0.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("prior_rotation_sigma_deg"));
  EXPECT_FALSE(EstimateMotionWithPrior(cam, corr, Eigen::Isometry3d::Identity(), bad).ok);
  Eigen::Isometry3d nan_prior = Eigen::Isometry3d::Identity();
  nan_prior.translation().x() = std::nan("");
  EXPECT_FALSE(EstimateMotionWithPrior(cam, corr, nan_prior).ok);
  corr[0].uv_curr_px.x() = std::nan("");
  EXPECT_FALSE(EstimateMotionWithPrior(cam, corr, Eigen::Isometry3d::Identity()).ok);
}

TEST(PriorMotionTest, Deterministic) {
  const StereoCamera cam = TestCamera();
  const Eigen::Isometry3d T_true = Motion(2.2, {0.006, 0.0, 0.001});
  std::vector<StereoCorrespondence> corr;
  for (const Eigen::Vector3d& p : WallSpecks()) corr.push_back(Exact(cam, T_true, p));
  corr[1].uv_curr_px += Eigen::Vector2d(0.3, -0.2);
  const PriorMotionResult a = EstimateMotionWithPrior(cam, corr, Eigen::Isometry3d::Identity());
  const PriorMotionResult b = EstimateMotionWithPrior(cam, corr, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(a.T_prev_curr.matrix() == b.T_prev_curr.matrix());
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
}

// PlanarPart: a planar motion is unchanged; roll, pitch and lift are removed exactly, the yaw
// and the translation across up kept, for any up (here the camera pitched down 10°).
TEST(PlanarPartTest, KeepsTheYawAndRemovesRollPitchAndLift) {
  const Eigen::Vector3d up_level(0.0, -1.0, 0.0);  // camera frame: y down
  const Eigen::Isometry3d planar = Motion(3.0, {0.01, 0.0, 0.04});
  EXPECT_THAT(PlanarPart(planar, up_level), IsNearPose(planar, 1e-12, 1e-15));

  // Pitched camera: up = R_x(10°) applied to (0, -1, 0); the same turn about that up.
  const Eigen::Matrix3d R_pitch =
      Eigen::AngleAxisd(10.0 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d up = R_pitch * up_level;
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = Eigen::AngleAxisd(-3.0 * kDeg, up).toRotationMatrix();
  const Eigen::Vector3d across = up.cross(Eigen::Vector3d::UnitX()).normalized();
  turn.translation() = 0.04 * across + 0.01 * Eigen::Vector3d::UnitX();
  // Disturbed by a pitch of 1.5° (about the camera x), a roll of 0.7° (about the horizontal
  // forward axis) and a lift of 2 cm along up.
  Eigen::Isometry3d disturbed = turn;
  disturbed.linear() = turn.linear() *
                       Eigen::AngleAxisd(1.5 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                       Eigen::AngleAxisd(0.7 * kDeg, across).toRotationMatrix();
  disturbed.translation() += 0.02 * up;
  const Eigen::Isometry3d p = PlanarPart(disturbed, up);
  // The rotation is about up alone, the translation is across it.
  const Eigen::AngleAxisd aa(p.linear());
  EXPECT_NEAR(std::abs(aa.axis().dot(up)), 1.0, 1e-12);
  EXPECT_NEAR(p.translation().dot(up), 0.0, 1e-15);
  EXPECT_LT((p.translation() - turn.translation()).norm(), 1e-15);
  // The twist of the disturbed rotation: the yaw to within the swing's second-order coupling.
  EXPECT_NEAR(RotationErrorRad(p, turn), 0.0, 0.01 * kDeg);
  EXPECT_THAT(PlanarPart(p, up), IsNearPose(p, 1e-12, 1e-15));  // idempotent
  // Bad up: the motion as it is.
  EXPECT_TRUE(PlanarPart(disturbed, Eigen::Vector3d::Zero()).matrix() == disturbed.matrix());
}

// Ground vehicle: the prior pitched by 1°/frame (a weak estimate before the wall) and missing
// the turn; with up given the few-point correction is a yaw and a translation across up, so
// the fit recovers the turn and cannot add roll or pitch to the prior's.
TEST(PriorMotionTest, PlanarCorrectionTurnsAboutUpOnly) {
  const StereoCamera cam = TestCamera();
  const Eigen::Vector3d up(0.0, -1.0, 0.0);
  const Eigen::Isometry3d T_true = Motion(2.2, {0.006, 0.0, 0.001});
  const Eigen::Isometry3d T_prior = Motion(0.0, {0.006, 0.0, 0.001});
  std::vector<StereoCorrespondence> corr;
  for (const Eigen::Vector3d& p : WallSpecks()) corr.push_back(Exact(cam, T_true, p));
  PriorMotionOptions planar_options;
  planar_options.no_sideways_slip = false;  // the 3-parameter planar correction (a free step)
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, T_prior, planar_options, &up);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.num_inliers, 3);
  EXPECT_LT(RotationErrorRad(r.T_prev_curr, T_true), 0.1 * 2.2 * kDeg);
  const Eigen::AngleAxisd aa(r.T_prev_curr.linear());
  EXPECT_NEAR(std::abs(aa.axis().dot(up)), 1.0, 1e-12);  // a yaw, nothing else
  EXPECT_NEAR(r.T_prev_curr.translation().dot(up), 0.0, 1e-12);
  // The same data with the specks nudged by a pixel vertically: the 6-DoF fit tilts the
  // camera to follow them, the planar one cannot.
  for (StereoCorrespondence& c : corr) c.uv_curr_px.y() += 1.0;
  const PriorMotionResult free6 = EstimateMotionWithPrior(cam, corr, T_prior);
  const PriorMotionResult planar = EstimateMotionWithPrior(cam, corr, T_prior, planar_options, &up);
  ASSERT_TRUE(free6.ok && planar.ok);
  const auto tilt_rad = [&](const Eigen::Isometry3d& T) {
    return std::abs(Eigen::AngleAxisd(T.linear()).axis().cross(up).norm() *
                    Eigen::AngleAxisd(T.linear()).angle());
  };
  EXPECT_GT(tilt_rad(free6.T_prev_curr), 0.05 * kDeg);
  EXPECT_LT(tilt_rad(planar.T_prev_curr), 1e-12);
  // A zero up is invalid input.
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  EXPECT_FALSE(EstimateMotionWithPrior(cam, corr, T_prior, PriorMotionOptions(), &zero).ok);
}

// VehicleMotion: an in-place turn moves the camera on a circle of the axle distance about the
// axle; straight travel moves it along its horizontal forward axis; VehicleMotionParameters
// inverts it exactly, also for a pitched camera.
TEST(VehicleMotionTest, TurnsAboutTheAxleAndInvertsExactly) {
  const Eigen::Vector3d up(0.0, -1.0, 0.0);
  const double d = 0.15;
  // In place: the axle point (0, 0, -d) stays where it is, the camera centre moves by
  // d·(R·e_z - e_z).
  const Eigen::Isometry3d turn = VehicleMotion(up, d, -4.44 * kDeg, 0.0);
  const Eigen::Vector3d axle(0.0, 0.0, -d);
  EXPECT_LT((turn * axle - axle).norm(), 1e-15);
  EXPECT_NEAR(turn.translation().norm(), 2.0 * d * std::sin(0.5 * 4.44 * kDeg), 1e-15);
  // Straight: forward along z.
  const Eigen::Isometry3d straight = VehicleMotion(up, d, 0.0, 0.04);
  EXPECT_THAT(straight, IsNearPose(Motion(0.0, {0.0, 0.0, 0.04}), 1e-15, 1e-15));
  // Round trip, level and pitched 10° down.
  const Eigen::Vector3d pitched =
      Eigen::AngleAxisd(10.0 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix() * up;
  for (const Eigen::Vector3d& u : {up, pitched}) {
    for (double yaw : {-7.0, -0.3, 0.0, 2.2}) {
      const Eigen::Isometry3d T = VehicleMotion(u, d, yaw * kDeg, 0.013);
      const Eigen::Vector2d p = VehicleMotionParameters(T, u, d);
      EXPECT_NEAR(p(0), yaw * kDeg, 1e-12);
      EXPECT_NEAR(p(1), 0.013, 1e-12);
    }
  }
}

// No sideways slip: the specks on the wall cannot tell a yaw from a sideways step, a wheel can.
// The truth is an in-place turn about an axle 0.15 m behind the camera (the camera steps
// sideways by 1.2 cm); the prior missed the turn. The vehicle fit with the right axle recovers
// the motion exactly (vague prior); with the axle assumed under the camera, the yaw absorbs the
// step (over-stated by about d/z, here < 20 %); the free planar fit has no such anchor.
TEST(PriorMotionTest, NoSideWaysSlipRecoversAnInPlaceTurn) {
  const StereoCamera cam = TestCamera();
  const Eigen::Vector3d up(0.0, -1.0, 0.0);
  const Eigen::Isometry3d T_true = VehicleMotion(up, 0.15, -4.44 * kDeg, 0.0);
  const Eigen::Isometry3d T_prior = VehicleMotion(up, 0.15, 0.0, 0.0);
  std::vector<StereoCorrespondence> corr;
  for (const Eigen::Vector3d& p : WallSpecks()) corr.push_back(Exact(cam, T_true, p));
  PriorMotionOptions vehicle;
  vehicle.axle_behind_camera_m = 0.15;
  vehicle.prior_rotation_sigma_deg = 1e4;  // vague: the data decide
  const PriorMotionResult exact = EstimateMotionWithPrior(cam, corr, T_prior, vehicle, &up);
  ASSERT_TRUE(exact.ok) << exact.message;
  EXPECT_EQ(exact.num_inliers, 3);
  EXPECT_THAT(exact.T_prev_curr, IsNearPose(T_true, 1e-7, 1e-8));
  // Axle assumed under the camera: the yaw takes the sideways step, by at most d / z.
  vehicle.axle_behind_camera_m = 0.0;
  const PriorMotionResult on_axle = EstimateMotionWithPrior(cam, corr, T_prior, vehicle, &up);
  ASSERT_TRUE(on_axle.ok) << on_axle.message;
  const double yaw = VehicleMotionParameters(on_axle.T_prev_curr, up, 0.0)(0);
  EXPECT_LT(yaw, -4.44 * kDeg);
  EXPECT_GT(yaw, -4.44 * kDeg * (1.0 + 0.15 / 0.85));
}

// A robot that brakes and then turns in place, its camera pitched 20° down: the constant-velocity
// prior keeps the last frame's 8.6 cm step and no yaw (truth: 5° and 2 mm). A yaw alone cannot
// put any point of the wall near its observation (off-centre points are 5-15 px off in height);
// the 1-point hypotheses also fit the forward distance to the point's depth, and every point is
// an inlier of the motion found (l_hallway, pitch 20°, stride 3: 10 of 11 matches were correct
// and the frame was lost).
TEST(PriorMotionTest, APriorThatStillDrivesOnIsCorrectedByOnePointsDepth) {
  const StereoCamera cam = TestCamera();
  const double pitch = 20.0 * kDeg;
  const Eigen::Vector3d up(0.0, -std::cos(pitch), -std::sin(pitch));
  const Eigen::Isometry3d T_true = VehicleMotion(up, 0.15, 5.0 * kDeg, 0.002);
  const Eigen::Isometry3d T_prior = VehicleMotion(up, 0.15, 0.0, 0.086);
  std::vector<StereoCorrespondence> corr;
  for (int k = 0; k < 10; ++k) {
    const double x = -0.4 + 0.08 * k, y = (k % 2 == 0 ? 0.05 : 0.3) - 0.02 * k;
    corr.push_back(Exact(cam, T_true, Eigen::Vector3d(x, y, 0.95 + 0.01 * k)));
  }
  PriorMotionOptions vehicle;
  vehicle.axle_behind_camera_m = 0.15;
  const PriorMotionResult r = EstimateMotionWithPrior(cam, corr, T_prior, vehicle, &up);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.num_inliers, 10);
  // The defaults' prior (σ 2°, 1 cm, 8.4 cm off) pulls a little against ten exact points.
  EXPECT_LT(RotationErrorRad(r.T_prev_curr, T_true), 0.05 * kDeg);
  EXPECT_LT((r.T_prev_curr.translation() - T_true.translation()).norm(), 0.005);
}

}  // namespace
}  // namespace vo
