#include "vo/kalman_matcher.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>

namespace vo {
namespace {

// Mean Sobel gradient (grey levels / pixel) over a window x window neighbourhood of the
// nearest pixel; pixels outside the image are clamped to the border.
Eigen::Vector2f MeanGradient(const cv::Mat& image, const Eigen::Vector2d& uv, int window) {
  const int half = window / 2;
  const int cx = static_cast<int>(std::lround(uv.x()));
  const int cy = static_cast<int>(std::lround(uv.y()));
  auto at = [&image](int x, int y) {
    x = std::clamp(x, 0, image.cols - 1);
    y = std::clamp(y, 0, image.rows - 1);
    return static_cast<float>(image.at<uint8_t>(y, x));
  };
  float sx = 0.f, sy = 0.f;
  for (int y = cy - half; y <= cy + half; ++y) {
    for (int x = cx - half; x <= cx + half; ++x) {
      sx += (at(x + 1, y - 1) + 2.f * at(x + 1, y) + at(x + 1, y + 1)) -
            (at(x - 1, y - 1) + 2.f * at(x - 1, y) + at(x - 1, y + 1));
      sy += (at(x - 1, y + 1) + 2.f * at(x, y + 1) + at(x + 1, y + 1)) -
            (at(x - 1, y - 1) + 2.f * at(x, y - 1) + at(x + 1, y - 1));
    }
  }
  const float scale = 1.f / (8.f * window * window);  // Sobel weights sum to 8 per side
  return Eigen::Vector2f(sx * scale, sy * scale);
}

}  // namespace

KalmanMatcher::KalmanMatcher(const Options& options, const NccOptions& ncc)
    : options_(options), ncc_(ncc) {
  std::string error;
  const bool valid = options_.IsValid(&error) && ncc_.IsValid(&error);
  AbortUnlessValid("KalmanMatcher", valid, error);
}

void KalmanMatcher::Reset() {
  tracks_.clear();
  last_frame_id_ = -1;
  has_state_ = false;
}

int KalmanMatcher::num_continued_tracks() const {
  return static_cast<int>(
      std::count_if(tracks_.begin(), tracks_.end(), [](const Track& t) { return t.age >= 1; }));
}

KalmanMatcher::Track KalmanMatcher::NewTrack(const Eigen::Vector2d& uv,
                                             const Eigen::Vector2f& gradient) const {
  Track t;
  t.x << uv.x(), uv.y(), 0.0, 0.0;
  const double r2 = options_.measurement_noise_px * options_.measurement_noise_px;
  const double v2 = options_.initial_velocity_std_px * options_.initial_velocity_std_px;
  t.P = Eigen::Vector4d(r2, r2, v2, v2).asDiagonal();
  t.g = gradient.cast<double>();
  t.g_var = options_.gradient_noise * options_.gradient_noise;
  t.last_uv = uv;
  t.age = 0;
  return t;
}

bool KalmanMatcher::Continues(const MatchFrame& prev) const {
  if (!has_state_ || tracks_.size() != prev.features.size()) return false;
  if (prev.frame_id >= 0 && last_frame_id_ >= 0 && prev.frame_id != last_frame_id_) return false;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    if (tracks_[i].last_uv != prev.features[i].uv_px) return false;
  }
  return true;
}

const std::vector<Eigen::Vector2f>& KalmanMatcher::Gradients(const MatchFrame& frame) const {
  FrameCues& cues = frame.cues;
  if (cues.gradients == nullptr || cues.gradient_window_px != options_.gradient_window_px ||
      cues.gradients->size() != frame.features.size()) {
    auto g = std::make_shared<std::vector<Eigen::Vector2f>>();
    g->reserve(frame.features.size());
    for (const Feature& f : frame.features) {
      g->push_back(MeanGradient(frame.image, f.uv_px, options_.gradient_window_px));
    }
    cues.gradients = std::move(g);
    cues.gradient_window_px = options_.gradient_window_px;
  }
  return *cues.gradients;
}

std::vector<Match> KalmanMatcher::DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                                          const MatchPrediction& prediction,
                                          MatcherSummary* summary) {
  MatcherSummary& s = *summary;
  if (!BothGreyImages(prev, curr)) {
    s.ok = false;
    s.message = "KalmanMatcher: needs CV_8UC1 images in both frames";
    Reset();
    return {};
  }
  auto t0 = std::chrono::steady_clock::now();
  const NccPatches& ncc_prev = FrameNccPatches(prev, ncc_);
  const NccPatches& ncc_curr = FrameNccPatches(curr, ncc_);
  const std::vector<Eigen::Vector2f>& grad_prev = Gradients(prev);
  const std::vector<Eigen::Vector2f>& grad_curr = Gradients(curr);
  s.cue_time_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();

  // Tracks of the previous frame: continued, or new ones.
  if (!Continues(prev)) {
    tracks_.clear();
    for (int i = 0; i < s.num_prev; ++i) {
      tracks_.push_back(NewTrack(prev.features[i].uv_px, grad_prev[i]));
    }
  }

  // Prediction: constant velocity, white-acceleration noise (per axis q²·[¼ ½; ½ 1]).
  Eigen::Matrix4d F = Eigen::Matrix4d::Identity();
  F(0, 2) = F(1, 3) = 1.0;
  const double q2 = options_.process_noise_px * options_.process_noise_px;
  Eigen::Matrix4d Q = Eigen::Matrix4d::Zero();
  for (int a = 0; a < 2; ++a) {
    Q(a, a) = 0.25 * q2;
    Q(a, a + 2) = Q(a + 2, a) = 0.5 * q2;
    Q(a + 2, a + 2) = q2;
  }
  const double r2 = options_.measurement_noise_px * options_.measurement_noise_px;
  const double rg2 = options_.gradient_noise * options_.gradient_noise;
  const double qg2 = options_.gradient_process_noise * options_.gradient_process_noise;
  for (Track& t : tracks_) {
    t.x = F * t.x;
    t.P = F * t.P * F.transpose() + Q;
    t.g_var += qg2;
  }

  // Candidates and their costs.
  // With a prediction (the ego-motion of the camera), the gate is centred on it instead of the
  // filter's image-velocity prediction, and scaled like every matcher's position gate.
  const double max_radius = options_.max_search_radius_px * prediction.radius_scale;
  const double gate_chi2 = options_.gate_chi2 * prediction.radius_scale * prediction.radius_scale;
  const PointGrid grid(FeaturePositions(curr.features), std::min(max_radius, 32.0));
  std::vector<CandidatePair> candidates;
  for (int i = 0; i < s.num_prev; ++i) {
    const Track& t = tracks_[i];
    if (!ncc_prev.valid(i)) continue;
    const Eigen::Matrix2d S = t.P.topLeftCorner<2, 2>() + r2 * Eigen::Matrix2d::Identity();
    const Eigen::Matrix2d Si = S.inverse();
    const double max_eig = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(S).eigenvalues()(1);
    const double radius = std::min(max_radius, std::sqrt(gate_chi2 * max_eig));
    const Eigen::Vector2d predicted = prediction.Centre(i, Eigen::Vector2d(t.x.head<2>()));
    const double grad_var = t.g_var + rg2;
    grid.ForEachWithin(predicted, radius, [&](int j, double) {
      ++s.num_candidates;
      // (ii) predicted-position difference, scaled by the innovation covariance.
      const Eigen::Vector2d nu = curr.features[j].uv_px - predicted;
      const double d2_pos = nu.dot(Si * nu);
      if (d2_pos > gate_chi2) return;
      // (iii) cross correlation, eq. (2).
      const double c = ncc_prev.Score(i, ncc_curr, j);
      if (c < options_.min_ncc) return;
      const double d_ncc = (1.0 - c) / options_.ncc_scale;
      // (i) gradient difference, scaled by the gradient filter's std.
      const double d2_grad = (grad_curr[j].cast<double>() - t.g).squaredNorm() / grad_var;
      const double cost = d2_pos + d2_grad + d_ncc * d_ncc;
      if (cost <= options_.max_cost) candidates.push_back(CandidatePair{i, j, cost});
    });
  }
  std::vector<Match> matches =
      GreedyOneToOne(std::move(candidates), [](double cost) { return std::exp(-0.5 * cost); });

  // Update: matched tracks take the measurement; unmatched current features start tracks.
  std::vector<Track> next(s.num_curr);
  std::vector<char> matched(s.num_curr, 0);
  for (const Match& m : matches) {
    Track t = tracks_[m.prev];
    const Eigen::Matrix2d S = t.P.topLeftCorner<2, 2>() + r2 * Eigen::Matrix2d::Identity();
    const Eigen::Matrix<double, 4, 2> K = t.P.leftCols<2>() * S.inverse();
    const Eigen::Vector2d z = curr.features[m.curr].uv_px;
    t.x += K * (z - t.x.head<2>());
    t.P = (Eigen::Matrix4d::Identity() - K * Eigen::Matrix<double, 2, 4>::Identity()) * t.P;
    t.P = 0.5 * (t.P + t.P.transpose());
    const double kg = t.g_var / (t.g_var + rg2);  // scalar gain of the gradient filter
    t.g += kg * (grad_curr[m.curr].cast<double>() - t.g);
    t.g_var *= (1.0 - kg);
    t.last_uv = z;
    ++t.age;
    next[m.curr] = t;
    matched[m.curr] = 1;
  }
  for (int j = 0; j < s.num_curr; ++j) {
    if (!matched[j]) next[j] = NewTrack(curr.features[j].uv_px, grad_curr[j]);
  }
  tracks_ = std::move(next);
  last_frame_id_ = curr.frame_id;
  has_state_ = true;

  s.match_time_ms = MsSince(t0);
  s.num_matches = static_cast<int>(matches.size());
  return matches;
}

}  // namespace vo
