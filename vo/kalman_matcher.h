// Kalman-filter corner tracking, the second baseline of Kwolek section VI. Every track carries
//   - a constant-velocity Kalman filter on its image position: state (u, v, du, dv) in pixels
//     and pixels/frame, white-acceleration process noise (process_noise_px), position
//     measurements with noise measurement_noise_px;
//   - a random-walk Kalman filter on its gradient vector (the mean Sobel gradient over a
//     gradient_window_px window, grey levels/pixel), noise gradient_noise /
//     gradient_process_noise.
// For a previous feature (track) i and a current feature j the cost is the sum of
//   (i)   the gradient difference scaled by the gradient filter's std:
//         |g_j − ĝ_i|² / (P_g + R_g);
//   (ii)  the predicted-position difference scaled by the position filter's covariance:
//         the Mahalanobis d² = νᵀ S⁻¹ ν of the innovation ν = z_j − H x̂ (gated at gate_chi2);
//   (iii) the cross correlation of the 11×11 patches, eq. (2): ((1 − C_ij) / ncc_scale)²
//         (candidates need C_ij >= min_ncc);
// and the assignment is greedy by increasing cost (one-to-one), accepted up to max_cost.
// Match::score = exp(−cost / 2) ∈ (0, 1].
//
// State: the matcher keeps the tracks of the last current frame. A call continues them when
// `prev` is that frame: same frame_id (when both are >= 0), same number of features and the
// same feature positions; otherwise (first call, a skipped or different frame) every previous
// feature starts a new track with zero velocity and velocity std initial_velocity_std_px.
// Matched tracks are updated with the current measurement; unmatched current features start
// new tracks; unmatched previous tracks end. Reset() forgets everything.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "vo/matcher.h"
#include "vo/ncc.h"

namespace vo {

class KalmanMatcher : public FrameMatcher {
 public:
  using Options = KalmanMatcherOptions;

  // Options must be valid (CreateFrameMatcher checks them).
  KalmanMatcher(const Options& options, const NccOptions& ncc = NccOptions());

  void Reset() override;
  MatcherType type() const override { return MatcherType::kKalman; }

  // Number of tracks carried (those of the last current frame) and how many of them were
  // continued from an earlier frame (age >= 1). For tests and diagnostics.
  int num_tracks() const { return static_cast<int>(tracks_.size()); }
  int num_continued_tracks() const;
  // Velocity estimate (pixels/frame) of the track of feature i of the last current frame.
  Eigen::Vector2d velocity(int i) const { return tracks_[i].x.tail<2>(); }

 protected:
  std::vector<Match> DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                             const MatchPrediction& prediction, MatcherSummary* summary) override;
  // Its tracks live across frames: it sees every frame, one without features included.
  bool SeesEveryFrame() const override { return true; }

 private:
  struct Track {
    Eigen::Vector4d x = Eigen::Vector4d::Zero();        // (u, v, du, dv): px, px/frame
    Eigen::Matrix4d P = Eigen::Matrix4d::Identity();    // its covariance
    Eigen::Vector2d g = Eigen::Vector2d::Zero();        // gradient estimate (grey/px)
    double g_var = 0.0;                                 // variance of each gradient component
    Eigen::Vector2d last_uv = Eigen::Vector2d::Zero();  // last measured position (px)
    int age = 0;                                        // updates so far
  };

  Track NewTrack(const Eigen::Vector2d& uv, const Eigen::Vector2f& gradient) const;
  bool Continues(const MatchFrame& prev) const;
  const std::vector<Eigen::Vector2f>& Gradients(const MatchFrame& frame) const;

  Options options_;
  NccOptions ncc_;
  std::vector<Track> tracks_;  // tracks of the last current frame, by feature index
  int64_t last_frame_id_ = -1;
  bool has_state_ = false;
};

}  // namespace vo
