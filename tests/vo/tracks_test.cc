#include "vo/tracks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

namespace vo {
namespace {

// n features at distinct positions; feature i of frame f sits at (10 i + f, 20) with
// disparity 5 (depth) unless i is in no_depth.
std::vector<Feature> MakeFeatures(int n, int frame, std::vector<int> no_depth = {}) {
  std::vector<Feature> features(n);
  for (int i = 0; i < n; ++i) {
    features[i].uv_px = Eigen::Vector2d(10.0 * i + frame, 20.0);
    if (std::find(no_depth.begin(), no_depth.end(), i) == no_depth.end()) {
      features[i].disparity_px = 5.0;
      features[i].p_cam0 = Eigen::Vector3d(i, frame, 5.0);
    }
  }
  return features;
}

TEST(TracksTest, FirstFrameStartsOneTrackPerFeature) {
  TrackManager tm;
  std::vector<Feature> f0 = MakeFeatures(4, 0);
  const TrackUpdateResult r = tm.AddFrame(0, &f0, {});
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.num_new, 4);
  EXPECT_EQ(r.num_extended, 0);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(f0[i].track_id, i);
    EXPECT_EQ(f0[i].track_age, 0);
  }
  EXPECT_EQ(tm.tracks().size(), 4u);
  EXPECT_THAT(tm.window_frame_ids(), ::testing::ElementsAre(0));
}

TEST(TracksTest, MatchesInheritIdAndAge) {
  TrackManager tm;
  std::vector<Feature> f0 = MakeFeatures(3, 0);
  ASSERT_TRUE(tm.AddFrame(10, &f0, {}).ok());
  // Frame 11: current 0 ← previous 2, current 2 ← previous 0; current 1 and 3 are new.
  std::vector<Feature> f1 = MakeFeatures(4, 1, /*no_depth=*/{2});
  const TrackUpdateResult r = tm.AddFrame(11, &f1, {{2, 0, 1.0}, {0, 2, 1.0}});
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.num_extended, 2);
  EXPECT_EQ(r.num_new, 2);
  EXPECT_EQ(f1[0].track_id, f0[2].track_id);
  EXPECT_EQ(f1[0].track_age, 1);
  EXPECT_EQ(f1[2].track_id, f0[0].track_id);
  EXPECT_EQ(f1[1].track_id, 3);  // ids are never reused: 0..2 taken in frame 10
  EXPECT_EQ(f1[3].track_id, 4);
  EXPECT_EQ(f1[1].track_age, 0);

  const Track* t = tm.FindTrack(f0[0].track_id);
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->observations.size(), 2u);
  EXPECT_TRUE(t->alive);
  EXPECT_EQ(t->first_frame_id(), 10);
  EXPECT_EQ(t->last_frame_id(), 11);
  EXPECT_EQ(t->observations[1].feature_index, 2);
  EXPECT_EQ(t->observations[1].uv_left_px, f1[2].uv_px);
  EXPECT_FALSE(t->observations[1].has_depth());  // feature 2 of frame 11 has no depth
  EXPECT_TRUE(t->observations[0].has_depth());
  EXPECT_EQ(t->observations[0].p_cam0, f0[0].p_cam0);
  EXPECT_EQ(t->observations[0].uv_right_px(), Eigen::Vector2d(0.0 - 5.0, 20.0));

  // Track of previous feature 1 was not extended: still in the window, no longer alive.
  const Track* dead = tm.FindTrack(f0[1].track_id);
  ASSERT_NE(dead, nullptr);
  EXPECT_FALSE(dead->alive);
}

TEST(TracksTest, ChainsOverManyFramesAndSlidesTheWindow) {
  TrackManagerOptions options;
  options.window_size = 3;
  TrackManager tm(options);
  // One feature matched through 6 frames (ids 0..5), plus a second one seen in frame 0 only.
  std::vector<Feature> f = MakeFeatures(2, 0);
  ASSERT_TRUE(tm.AddFrame(0, &f, {}).ok());
  const int64_t long_id = f[0].track_id;
  const int64_t short_id = f[1].track_id;
  int total_removed = 0;
  for (int frame = 1; frame < 6; ++frame) {
    std::vector<Feature> next = MakeFeatures(1, frame);
    const TrackUpdateResult r = tm.AddFrame(frame, &next, {{0, 0, 1.0}});
    ASSERT_TRUE(r.ok()) << r.message;
    total_removed += r.num_removed;
    EXPECT_EQ(next[0].track_id, long_id);
    EXPECT_EQ(next[0].track_age, frame);  // counts every earlier frame, beyond the window
    f = next;
  }
  EXPECT_THAT(tm.window_frame_ids(), ::testing::ElementsAre(3, 4, 5));
  const Track* t = tm.FindTrack(long_id);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->age, 5);
  ASSERT_EQ(t->observations.size(), 3u);  // only the window's frames
  EXPECT_EQ(t->first_frame_id(), 3);
  EXPECT_EQ(t->last_frame_id(), 5);
  // The frame-0-only track left with frame 0 (removed when frame 3 arrived).
  EXPECT_EQ(tm.FindTrack(short_id), nullptr);
  EXPECT_EQ(total_removed, 1);
  EXPECT_THAT(tm.TrackIdsSeenInAtLeast(3), ::testing::ElementsAre(long_id));
  EXPECT_TRUE(tm.TrackIdsSeenInAtLeast(4).empty());
}

TEST(TracksTest, RejectsBadInputWithoutChangingState) {
  TrackManager tm;
  std::vector<Feature> f0 = MakeFeatures(2, 0);
  EXPECT_EQ(tm.AddFrame(0, &f0, {{0, 0, 1.0}}).status, TrackUpdateResult::Status::kInvalidInput)
      << "matches on the first frame";
  ASSERT_TRUE(tm.AddFrame(0, &f0, {}).ok());
  std::vector<Feature> f1 = MakeFeatures(2, 1);
  EXPECT_EQ(tm.AddFrame(0, &f1, {}).status, TrackUpdateResult::Status::kInvalidInput)
      << "frame id not increasing";
  EXPECT_EQ(tm.AddFrame(1, &f1, {{2, 0, 1.0}}).status, TrackUpdateResult::Status::kInvalidInput)
      << "previous index out of range";
  EXPECT_EQ(tm.AddFrame(1, &f1, {{0, 5, 1.0}}).status, TrackUpdateResult::Status::kInvalidInput)
      << "current index out of range";
  const TrackUpdateResult dup = tm.AddFrame(1, &f1, {{0, 0, 1.0}, {1, 0, 1.0}});
  EXPECT_EQ(dup.status, TrackUpdateResult::Status::kInvalidInput);
  EXPECT_THAT(dup.message, ::testing::HasSubstr("one-to-one"));
  EXPECT_EQ(tm.AddFrame(1, nullptr, {}).status, TrackUpdateResult::Status::kInvalidInput);
  // Nothing changed: the window still holds frame 0 only, and frame 1 can still be added.
  EXPECT_THAT(tm.window_frame_ids(), ::testing::ElementsAre(0));
  EXPECT_EQ(f1[0].track_id, -1);
  ASSERT_TRUE(tm.AddFrame(1, &f1, {{1, 0, 1.0}}).ok());
  EXPECT_EQ(f1[0].track_id, f0[1].track_id);
}

TEST(TracksTest, ResetRestartsIds) {
  TrackManager tm;
  std::vector<Feature> f0 = MakeFeatures(3, 0);
  ASSERT_TRUE(tm.AddFrame(0, &f0, {}).ok());
  tm.Reset();
  EXPECT_TRUE(tm.tracks().empty());
  EXPECT_TRUE(tm.window_frame_ids().empty());
  std::vector<Feature> f1 = MakeFeatures(1, 0);
  ASSERT_TRUE(tm.AddFrame(0, &f1, {}).ok());  // frame id 0 accepted again after Reset
  EXPECT_EQ(f1[0].track_id, 0);
}

TEST(TracksTest, WindowOfOneKeepsExtendingTracks) {
  TrackManagerOptions options;
  options.window_size = 1;
  TrackManager tm(options);
  std::vector<Feature> f = MakeFeatures(1, 0);
  ASSERT_TRUE(tm.AddFrame(0, &f, {}).ok());
  for (int frame = 1; frame < 4; ++frame) {
    std::vector<Feature> next = MakeFeatures(1, frame);
    ASSERT_TRUE(tm.AddFrame(frame, &next, {{0, 0, 1.0}}).ok());
    EXPECT_EQ(next[0].track_id, 0);
    EXPECT_EQ(next[0].track_age, frame);
  }
  EXPECT_EQ(tm.tracks().size(), 1u);
  EXPECT_EQ(tm.tracks().at(0).observations.size(), 1u);
}

TEST(TracksTest, OptionsValidation) {
  TrackManagerOptions options;
  options.window_size = 0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("window_size"));
  TrackManager tm(options);
  std::vector<Feature> f = MakeFeatures(1, 0);
  EXPECT_EQ(tm.AddFrame(0, &f, {}).status, TrackUpdateResult::Status::kInvalidInput);
}

}  // namespace
}  // namespace vo
