#include "vo/tracks.h"

#include <sstream>

namespace vo {

bool TrackManagerOptions::IsValid(std::string* error) const {
  if (window_size >= 1) return true;
  if (error) *error = "window_size must be >= 1, got " + std::to_string(window_size);
  return false;
}

const char* ToString(TrackUpdateResult::Status status) {
  switch (status) {
    case TrackUpdateResult::Status::kOk:
      return "ok";
    case TrackUpdateResult::Status::kInvalidInput:
      return "invalid_input";
  }
  return "unknown";
}

TrackManager::TrackManager(const TrackManagerOptions& options) : options_(options) {}

void TrackManager::Reset() {
  tracks_.clear();
  window_.clear();
  prev_track_ids_.clear();
  next_id_ = 0;
}

const Track* TrackManager::FindTrack(int64_t id) const {
  const auto it = tracks_.find(id);
  return it == tracks_.end() ? nullptr : &it->second;
}

std::vector<int64_t> TrackManager::TrackIdsSeenInAtLeast(int min_frames) const {
  std::vector<int64_t> ids;
  for (const auto& [id, track] : tracks_)
    if (static_cast<int>(track.observations.size()) >= min_frames) ids.push_back(id);
  return ids;
}

TrackUpdateResult TrackManager::AddFrame(int64_t frame_id, std::vector<Feature>* features,
                                         const std::vector<Match>& matches) {
  TrackUpdateResult result;
  std::ostringstream msg;
  std::string error;
  // Validate everything before touching the state.
  if (!options_.IsValid(&error))
    msg << error;
  else if (features == nullptr)
    msg << "features must not be null";
  else if (!window_.empty() && frame_id <= window_.back())
    msg << "frame_id " << frame_id << " must be larger than the previous " << window_.back();
  else if (window_.empty() && !matches.empty())
    msg << "the first frame cannot have matches (got " << matches.size() << ")";
  if (msg.tellp() != 0) {
    result.message = msg.str();
    return result;
  }
  const int num_prev = static_cast<int>(prev_track_ids_.size());
  const int num_curr = static_cast<int>(features->size());
  std::vector<int> prev_of_curr(num_curr, -1);
  std::vector<bool> prev_used(num_prev, false);
  for (size_t k = 0; k < matches.size(); ++k) {
    const Match& m = matches[k];
    if (m.prev < 0 || m.prev >= num_prev || m.curr < 0 || m.curr >= num_curr) {
      msg << "match " << k << " (" << m.prev << " -> " << m.curr << ") is out of range ("
          << num_prev << " previous, " << num_curr << " current features)";
    } else if (prev_used[m.prev] || prev_of_curr[m.curr] >= 0) {
      msg << "match " << k << " (" << m.prev << " -> " << m.curr << ") is not one-to-one";
    }
    if (msg.tellp() != 0) {
      result.message = msg.str();
      return result;
    }
    prev_used[m.prev] = true;
    prev_of_curr[m.curr] = m.prev;
  }

  // Every track stops being alive; the ones extended below become alive again.
  for (auto& [id, track] : tracks_) track.alive = false;

  std::vector<int64_t> curr_track_ids(num_curr, -1);
  for (int i = 0; i < num_curr; ++i) {
    Feature& f = (*features)[i];
    Track* track = nullptr;
    if (prev_of_curr[i] >= 0) {
      const auto it = tracks_.find(prev_track_ids_[prev_of_curr[i]]);
      if (it != tracks_.end())
        track = &it->second;  // always present: tracks of the
                              // latest frame are in the window
    }
    if (track != nullptr) {
      ++track->age;
      ++result.num_extended;
    } else {
      Track fresh;
      fresh.id = next_id_++;
      fresh.age = 0;
      track = &tracks_.emplace(fresh.id, fresh).first->second;
      ++result.num_new;
    }
    track->alive = true;
    TrackObservation obs;
    obs.frame_id = frame_id;
    obs.feature_index = i;
    obs.uv_left_px = f.uv_px;
    obs.disparity_px = f.has_depth() ? f.disparity_px : -1.0;
    if (f.has_depth()) obs.p_cam0 = f.p_cam0;
    track->observations.push_back(obs);
    f.track_id = track->id;
    f.track_age = track->age;
    curr_track_ids[i] = track->id;
  }
  prev_track_ids_.swap(curr_track_ids);

  // Slide the window: drop observations of frames that left it, then empty tracks.
  window_.push_back(frame_id);
  while (static_cast<int>(window_.size()) > options_.window_size) window_.pop_front();
  const int64_t oldest = window_.front();
  for (auto it = tracks_.begin(); it != tracks_.end();) {
    std::vector<TrackObservation>& obs = it->second.observations;
    size_t drop = 0;
    while (drop < obs.size() && obs[drop].frame_id < oldest) ++drop;
    obs.erase(obs.begin(), obs.begin() + static_cast<std::ptrdiff_t>(drop));
    if (obs.empty()) {
      it = tracks_.erase(it);
      ++result.num_removed;
    } else {
      ++it;
    }
  }
  result.status = TrackUpdateResult::Status::kOk;
  return result;
}

}  // namespace vo
