// Tests of vo/sliding_window.h on exact synthetic observations: the window keeps the poses of
// its frames only, the bundle adjustment pulls a perturbed newest pose back to the truth, and
// the divergence guard refuses a correction larger than it allows.
#include "vo/sliding_window.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/test_util.h"
#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

using test::TestCamera;

using test::ForwardFrameFeatures;
using test::OneToOneMatches;

// Camera i: 0.1 m forward per frame along the optical axis.
Eigen::Isometry3d TruePose(int i) { return test::ForwardPose(i); }

// Exact stereo features of frame i (feature k = point k of a fixed cloud 3-8 m ahead).
std::vector<Feature> FeaturesOf(int i, const StereoCamera& cam) {
  return ForwardFrameFeatures(i, cam);
}

SlidingWindowOptions Options() {
  SlidingWindowOptions o;
  o.window_frames = 3;
  o.ba.min_frames_per_point = 2;
  return o;
}

// Frames 0..3 at their true poses, frame 3's initial pose moved by `offset`.
SlidingWindow Window(const StereoCamera& cam, const Eigen::Vector3d& offset,
                     const SlidingWindowOptions& options = Options()) {
  SlidingWindow w(options);
  std::vector<Feature> f0 = FeaturesOf(0, cam);
  EXPECT_TRUE(w.Start(0, &f0, TruePose(0)).ok());
  for (int i = 1; i <= 3; ++i) {
    std::vector<Feature> f = FeaturesOf(i, cam);
    Eigen::Isometry3d initial = TruePose(i);
    if (i == 3) initial.translation() += offset;
    EXPECT_TRUE(w.Add(i, &f, OneToOneMatches(f.size()), initial).ok()) << "frame " << i;
  }
  return w;
}

TEST(SlidingWindowTest, KeepsThePosesOfItsFramesOnly) {
  const SlidingWindow w = Window(TestCamera(), Eigen::Vector3d::Zero());
  EXPECT_EQ(w.Pose(0), nullptr);  // 3 frames kept: 1, 2, 3
  for (int i = 1; i <= 3; ++i) ASSERT_NE(w.Pose(i), nullptr) << i;
  EXPECT_EQ(w.tracks().window_frame_ids().size(), 3u);
}

TEST(SlidingWindowTest, BundleAdjustmentPullsTheNewestPoseToTheTruth) {
  const StereoCamera cam = TestCamera();
  SlidingWindow w = Window(cam, Eigen::Vector3d(0.02, -0.01, 0.03));
  const WindowRefinement r = w.Refine(cam, 3);
  ASSERT_TRUE(r.attempted);
  ASSERT_TRUE(r.ran) << r.message;
  EXPECT_FALSE(r.rejected);
  EXPECT_EQ(r.num_frames, 3);
  EXPECT_GT(r.num_points, 0);
  EXPECT_LT((w.Pose(3)->translation() - TruePose(3).translation()).norm(), 1e-6);
  // The oldest pose of the window is the gauge: unchanged.
  EXPECT_TRUE(w.Pose(1)->matrix() == TruePose(1).matrix());
}

TEST(SlidingWindowTest, DivergenceGuardRefusesALargeCorrection) {
  const StereoCamera cam = TestCamera();
  SlidingWindow w = Window(cam, Eigen::Vector3d(0.0, 0.0, 0.4));  // guard: 0.25 m
  const Eigen::Isometry3d before = *w.Pose(3);
  const WindowRefinement r = w.Refine(cam, 3);
  EXPECT_TRUE(r.attempted);
  EXPECT_FALSE(r.ran);
  EXPECT_TRUE(r.rejected);
  EXPECT_NE(r.message.find("bundle adjustment rejected"), std::string::npos) << r.message;
  EXPECT_TRUE(w.Pose(3)->matrix() == before.matrix());  // poses left as they were
}

TEST(SlidingWindowTest, WithoutBundleAdjustmentRefineDoesNothing) {
  SlidingWindowOptions o = Options();
  o.use_bundle_adjustment = false;
  const StereoCamera cam = TestCamera();
  SlidingWindow w = Window(cam, Eigen::Vector3d(0.02, 0.0, 0.0), o);
  const WindowRefinement r = w.Refine(cam, 3);
  EXPECT_FALSE(r.attempted);
  EXPECT_FALSE(r.ran);
  w.Reset();
  EXPECT_EQ(w.Pose(3), nullptr);
}

}  // namespace
}  // namespace vo
