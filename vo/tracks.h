// Multi-frame feature tracks: chains the inter-frame matches (previous → current, one-to-one)
// into tracks with persistent ids, and keeps each track's observations over a sliding window
// of the last `window_size` frames, as the windowed bundle adjustment needs them
// (Kwolek, docs/PAPER.md "refinement": SBA over 3–5 frames; features live 4–5 frames).
//
// Rules, per AddFrame(frame_id, features, matches):
//   * a current feature reached by a match inherits the previous feature's track: same
//     track_id, track_age = previous age + 1;
//   * every other current feature starts a new track: a fresh id (ids increase from 0 and are
//     never reused), track_age = 0;
//   * the frame joins the window; the oldest frame leaves it once the window holds more than
//     window_size frames; observations made in frames that left the window are dropped, and a
//     track with no observation left in the window is removed;
//   * a track not extended in the current frame is no longer "alive" (matching is frame to
//     frame, so it can never be extended again) but its observations stay for the window.
// track_age counts every earlier frame the track was seen in, also those that left the window.
//
// The manager writes track_id and track_age into the current features (so the next frame's
// RANSAC can seed with old tracks). Matches must index the features given to the previous
// AddFrame call and the current features. Not thread-safe.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "vo/types.h"

namespace vo {

// One observation of a track in one frame.
struct TrackObservation {
  int64_t frame_id = -1;                                 // the frame it was made in
  int feature_index = -1;                                // index into that frame's feature vector
  Eigen::Vector2d uv_left_px = Eigen::Vector2d::Zero();  // left-image position (pixels)
  double disparity_px = -1.0;  // x_left − x_right (pixels); < 0 when no depth. The right-image
                               // position is (u − d, v) when has_depth()
  Eigen::Vector3d p_cam0 = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // 3D in that frame's cam0 (metres); NaN when no depth

  bool has_depth() const { return disparity_px > 0.0; }
  Eigen::Vector2d uv_right_px() const {
    return Eigen::Vector2d(uv_left_px.x() - disparity_px, uv_left_px.y());
  }
};

struct Track {
  int64_t id = -1;
  int age = 0;  // number of earlier frames the track was seen in (whole history)
  std::vector<TrackObservation> observations;  // inside the window only, oldest first, one
                                               // per frame, consecutive frames
  bool alive = false;  // observed in the latest frame (can still be extended)

  int64_t first_frame_id() const { return observations.front().frame_id; }
  int64_t last_frame_id() const { return observations.back().frame_id; }
};

struct TrackManagerOptions {
  int window_size = 5;  // frames kept (the bundle-adjustment window), >= 1

  bool IsValid(std::string* error) const;
};

struct TrackUpdateResult {
  enum class Status {
    kOk,
    kInvalidInput,  // bad frame id order, out-of-range or non-one-to-one matches, or matches
                    // without a previous frame; the manager is left unchanged
  };
  Status status = Status::kInvalidInput;
  std::string message;   // empty when kOk
  int num_extended = 0;  // current features that continued a track
  int num_new = 0;       // current features that started a track
  int num_removed = 0;   // tracks removed because they left the window

  bool ok() const { return status == Status::kOk; }
};

const char* ToString(TrackUpdateResult::Status status);

class TrackManager {
 public:
  explicit TrackManager(const TrackManagerOptions& options = TrackManagerOptions());

  // Adds the current frame. frame_id: strictly larger than the previous one. features: the
  // current frame's features (track_id and track_age are overwritten). matches: previous
  // feature index → current feature index, one-to-one; must be empty for the first frame.
  TrackUpdateResult AddFrame(int64_t frame_id, std::vector<Feature>* features,
                             const std::vector<Match>& matches);

  // Tracks with at least one observation in the window, by id.
  const std::map<int64_t, Track>& tracks() const { return tracks_; }
  // Track by id, or nullptr when it does not exist (any more).
  const Track* FindTrack(int64_t id) const;
  // Frame ids in the window, oldest first.
  const std::deque<int64_t>& window_frame_ids() const { return window_; }
  // Ids of the tracks observed in at least min_frames frames of the window, ascending.
  std::vector<int64_t> TrackIdsSeenInAtLeast(int min_frames) const;
  // Forgets everything (ids restart at 0).
  void Reset();

  const TrackManagerOptions& options() const { return options_; }

 private:
  TrackManagerOptions options_;
  std::map<int64_t, Track> tracks_;
  std::deque<int64_t> window_;
  std::vector<int64_t> prev_track_ids_;  // track id of each feature of the previous frame
  int64_t next_id_ = 0;
};

}  // namespace vo
