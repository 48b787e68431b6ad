#include "vo/recovery.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/texture_util.h"
#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

using vobench_test::RotationAngleRad;

constexpr double kDeg = M_PI / 180.0;

Eigen::Isometry3d Pose(double yaw_deg, double roll_deg, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll_deg * kDeg, Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() = t;
  return T;
}

struct Fixture {
  StereoCamera camera = test::TestCamera();
  ConstantVelocity velocity;
  std::vector<Feature> features;  // none: the image centre is far away
  BridgeContext Context(const Eigen::Isometry3d& T_world_prev, const cv::Mat& left = cv::Mat()) {
    BridgeContext c;
    c.T_world_prev = T_world_prev;
    c.current_left = left;
    c.features = &features;
    c.velocity = &velocity;
    return c;
  }
};

TEST(RecoveryTest, ALostFrameIsBridgedByThePriorExactly) {
  Fixture f;
  Recovery recovery(f.camera, RecoveryOptions(), MotionOptions(), TrackerOptions());
  const Eigen::Isometry3d T_world_prev = Pose(30.0, 0.0, Eigen::Vector3d(1.0, 0.0, 2.0));
  const Eigen::Isometry3d v = Pose(2.0, 0.0, Eigen::Vector3d(0.0, 0.0, 0.05));
  f.velocity.Move(v, 1.0);
  OdometryResult result;
  // No images: the constant velocity, bit for bit.
  EXPECT_TRUE(recovery.BridgedPose(f.Context(T_world_prev), &result).matrix() ==
              (T_world_prev * v).matrix());
  EXPECT_FALSE(result.rotation_from_shift);
  // The caller's prior replaces it.
  MotionPrior prior;
  prior.T_prev_curr = Pose(-4.0, 0.0, Eigen::Vector3d(0.1, 0.0, 0.0));
  BridgeContext c = f.Context(T_world_prev);
  c.prior = &prior;
  EXPECT_TRUE(recovery.BridgedPose(c, &result).matrix() ==
              (T_world_prev * prior.T_prev_curr).matrix());
  // A chained pose is taken as it is.
  const Eigen::Isometry3d chained = Pose(1.0, 0.0, Eigen::Vector3d(3.0, 0.0, 0.0));
  EXPECT_TRUE(recovery.BridgedPose(c, &result, &chained).matrix() == chained.matrix());
}

TEST(RecoveryTest, AGroundVehiclesBridgeIsPlanar) {
  Fixture f;
  MotionOptions motion;
  motion.ground_vehicle = true;
  RecoveryOptions o;
  o.vehicle_bridge_alignment = false;  // no features to align with here
  Recovery recovery(f.camera, o, motion, TrackerOptions());
  // The world's up is the camera's −y at the previous pose (a level camera).
  Eigen::Isometry3d T_world_prev = Eigen::Isometry3d::Identity();
  T_world_prev.linear().col(0) = -Eigen::Vector3d::UnitY();
  T_world_prev.linear().col(1) = -Eigen::Vector3d::UnitZ();
  T_world_prev.linear().col(2) = Eigen::Vector3d::UnitX();
  // A velocity with 3° of roll and a step up: the bridge keeps only the yaw and the planar step.
  f.velocity.Move(Pose(2.0, 3.0, Eigen::Vector3d(0.0, -0.02, 0.05)), 1.0);
  BridgeContext c = f.Context(T_world_prev);
  c.world_up_known = true;
  OdometryResult result;
  const Eigen::Isometry3d T = T_world_prev.inverse() * recovery.BridgedPose(c, &result);
  EXPECT_TRUE(IsVehicleLike(T, -Eigen::Vector3d::UnitY(), 1e-9, 1e-12));
  EXPECT_NEAR(Eigen::AngleAxisd(T.linear()).angle(), 2.0 * kDeg, 0.02 * kDeg);
  // Without the up known: the velocity as it is.
  c.world_up_known = false;
  EXPECT_FALSE(IsVehicleLike(T_world_prev.inverse() * recovery.BridgedPose(c, &result),
                             -Eigen::Vector3d::UnitY(), 1.0, 0.01));
}

TEST(RecoveryTest, ALostFrameFollowsAPanByTheImageShift) {
  Fixture f;
  Recovery recovery(f.camera, RecoveryOptions(), MotionOptions(), TrackerOptions());
  const int shift = 12;  // the view pans: the content moves 12 px to the left
  const cv::Mat texture = test::BlurredNoise(f.camera.width + shift, f.camera.height, 5, 5, 1.2);
  const cv::Mat previous = texture(cv::Rect(0, 0, f.camera.width, f.camera.height)).clone();
  const cv::Mat current = texture(cv::Rect(shift, 0, f.camera.width, f.camera.height)).clone();
  f.velocity.Move(Eigen::Isometry3d::Identity(), 1.0);  // the prior: standing still
  recovery.EndFrame(f.features, Eigen::Isometry3d::Identity(), previous);
  OdometryResult result;
  const Eigen::Isometry3d T =
      recovery.BridgedPose(f.Context(Eigen::Isometry3d::Identity(), current), &result);
  ASSERT_TRUE(result.rotation_from_shift);
  EXPECT_NEAR(result.image_shift_px.x(), -shift, 0.25);
  EXPECT_NEAR(result.image_shift_px.y(), 0.0, 0.25);
  // The rotation explains the shift at the image centre (far away: rotation only), and it
  // became the prior's rotation.
  EXPECT_LT((PredictedCentreShift(f.camera, T, -1.0) - result.image_shift_px).norm(), 1e-9);
  EXPECT_LT(RotationAngleRad(f.velocity.per_frame().linear(), T.linear()), 1e-12);
  // A still view: no correction.
  Recovery still(f.camera, RecoveryOptions(), MotionOptions(), TrackerOptions());
  still.EndFrame(f.features, Eigen::Isometry3d::Identity(), previous);
  OdometryResult r2;
  f.velocity.Reset();
  still.BridgedPose(f.Context(Eigen::Isometry3d::Identity(), previous), &r2);
  EXPECT_FALSE(r2.rotation_from_shift);
}

TEST(RecoveryTest, WithoutAChainThereIsNothingToChainTo) {
  Fixture f;
  std::string error;
  const std::unique_ptr<Tracker> tracker =
      Tracker::Create(f.camera, TrackerOptions(), MotionOptions(), &error);
  ASSERT_TRUE(tracker) << error;
  Recovery recovery(f.camera, RecoveryOptions(), MotionOptions(), TrackerOptions());
  MatchFrame frame;
  frame.frame_id = 3;
  OdometryResult result;
  result.frame_index = 3;
  Eigen::Isometry3d T;
  EXPECT_FALSE(recovery.ChainLostFrame(tracker.get(), frame,
                                       f.Context(Eigen::Isometry3d::Identity()), &result, &T));
  // A chain to a later (or the same) frame is no chain either.
  recovery.ContinueChain(3, frame, Eigen::Isometry3d::Identity());
  EXPECT_FALSE(recovery.ChainLostFrame(tracker.get(), frame,
                                       f.Context(Eigen::Isometry3d::Identity()), &result, &T));
  EXPECT_EQ(result.chained_to_frame, -1);
}

TEST(RecoveryTest, OptionsRefuseABadFieldByName) {
  test::ExpectOptionsRefuseBadFields<RecoveryOptions>({
      {"vehicle_bridge: ", [](RecoveryOptions* o) { o->vehicle_bridge.min_pairs = 0; }},
      {"vehicle_direct: ", [](RecoveryOptions* o) { o->vehicle_direct.pyramid_levels = 0; }},
      {"free_direct: ", [](RecoveryOptions* o) { o->free_direct.min_pixels = 0; }},
      {"rotation_min_shift_score", [](RecoveryOptions* o) { o->rotation_min_shift_score = 1.5; }},
      {"rotation_min_peak_ratio", [](RecoveryOptions* o) { o->rotation_min_peak_ratio = 0.5; }},
      {"rotation_min_residual_px", [](RecoveryOptions* o) { o->rotation_min_residual_px = -1.0; }},
      {"vehicle_rotation_min_shift_score",
       [](RecoveryOptions* o) { o->vehicle_rotation_min_shift_score = -2.0; }},
      {"vehicle_rotation_min_peak_ratio",
       [](RecoveryOptions* o) { o->vehicle_rotation_min_peak_ratio = 0.9; }},
      {"vehicle_max_vertical_shift_ratio",
       [](RecoveryOptions* o) { o->vehicle_max_vertical_shift_ratio = NAN; }},
      {"reinit_after_lost_frames", [](RecoveryOptions* o) { o->reinit_after_lost_frames = 0; }},
  });
}

// The planes as the frame-by-frame update made them before they were deferred: fit each
// frame's features, else carry the last planes (at most 30 frames), else none.
class EagerScenePlanes {
 public:
  explicit EagerScenePlanes(const StereoCamera& camera) : camera_(camera) {}
  void EndFrame(const std::vector<Feature>& features, const Eigen::Isometry3d& T_prev_curr) {
    std::vector<ScenePlane> fitted;
    if (FitScenePlanes(camera_, features, 1.0, 6, 0.6, 0.05, 3, &fitted)) {
      planes_ = fitted;
      age_ = 0;
    } else if (!planes_.empty() && T_prev_curr.matrix().allFinite() && ++age_ <= 30) {
      std::vector<ScenePlane> moved;
      for (const ScenePlane& plane : planes_) {
        const ScenePlane m = TransformPlane(plane, T_prev_curr);
        if (m.distance_m > 0.0) moved.push_back(m);
      }
      planes_.swap(moved);
    } else {
      planes_.clear();
    }
  }
  const std::vector<ScenePlane>& planes() const { return planes_; }

 private:
  StereoCamera camera_;
  std::vector<ScenePlane> planes_;
  int age_ = 0;
};

// Features on two planes (a floor and a wall) that FitScenePlanes finds, or five scattered in
// depth, too few for a plane; shifted a little per frame.
std::vector<Feature> PlaneFeatures(const StereoCamera& camera, bool on_planes, int frame) {
  std::vector<Feature> features;
  SplitMix64 rng(1000 + frame);
  for (int i = 0; i < (on_planes ? 60 : 5); ++i) {
    Feature f;
    f.uv_px = Eigen::Vector2d(20.0 + 280.0 * rng.Uniform(), 20.0 + 200.0 * rng.Uniform());
    double z;
    if (!on_planes) {
      z = 1.0 + 9.0 * rng.Uniform();
    } else if (i % 2 == 0) {  // the wall z = 3 + 0.01 frame
      z = 3.0 + 0.01 * frame;
    } else {  // the floor y = 1 (camera frame, y down), below the horizon
      f.uv_px.y() = camera.cy_px + 10.0 + 100.0 * rng.Uniform();
      z = camera.fy_px * 1.0 / (f.uv_px.y() - camera.cy_px);
    }
    f.p_cam0 = camera.BackprojectDepth(f.uv_px.x(), f.uv_px.y(), z);
    f.disparity_px = camera.fx_px * camera.baseline_m / z;
    if (i % 13 == 0) f.disparity_px = -1.0;  // some without depth
    features.push_back(f);
  }
  return features;
}

TEST(RecoveryTest, ScenePlanesAreTheFrameByFrameUpdates) {
  const StereoCamera camera = test::TestCamera();
  MotionOptions motion;
  motion.ground_vehicle = true;  // the vehicle's direct alignment keeps the planes
  // Which frames have planes: runs of fits, gaps shorter and longer than the 30 frames a plane
  // is carried, a non-finite motion; asked every frame, now and then, or after long gaps.
  auto fits = [](int k) { return k < 5 || (k >= 20 && k < 22) || (k >= 60 && k < 64) || k == 100; };
  for (int ask_every : {1, 7, 45}) {
    Recovery recovery(camera, RecoveryOptions(), motion, TrackerOptions());
    EagerScenePlanes eager(camera);
    int nonempty = 0, compared = 0;
    for (int k = 0; k < 140; ++k) {
      Eigen::Isometry3d T = Pose(0.5 * std::sin(0.1 * k), 0.0, Eigen::Vector3d(0.0, 0.0, 0.05));
      if (k == 62) T.translation().x() = std::numeric_limits<double>::quiet_NaN();
      const std::vector<Feature> features = PlaneFeatures(camera, fits(k), k);
      recovery.EndFrame(features, T, cv::Mat());
      eager.EndFrame(features, T);
      if (k % ask_every != 0) continue;
      const std::vector<ScenePlane>& lazy = recovery.ScenePlanes();
      ASSERT_EQ(lazy.size(), eager.planes().size()) << "frame " << k << ", every " << ask_every;
      for (size_t i = 0; i < lazy.size(); ++i) {
        EXPECT_TRUE(lazy[i].normal == eager.planes()[i].normal) << "frame " << k;
        EXPECT_EQ(lazy[i].distance_m, eager.planes()[i].distance_m) << "frame " << k;
        EXPECT_EQ(lazy[i].inliers, eager.planes()[i].inliers) << "frame " << k;
      }
      nonempty += lazy.empty() ? 0 : 1;
      ++compared;
    }
    EXPECT_GT(nonempty, 0) << "every " << ask_every;
    EXPECT_LT(nonempty, compared) << "every " << ask_every;
  }
}

}  // namespace
}  // namespace vo
