#include "vo/lk_matcher.h"

#include <chrono>
#include <cmath>
#include <opencv2/video/tracking.hpp>

namespace vo {

LucasKanadeMatcher::LucasKanadeMatcher(const Options& options) : options_(options) {
  std::string error;
  const bool valid = options_.IsValid(&error);
  AbortUnlessValid("LucasKanadeMatcher", valid, error);
}

const std::vector<cv::Mat>& LucasKanadeMatcher::Pyramid(const MatchFrame& frame) const {
  FrameCues& cues = frame.cues;
  if (cues.lk_pyramid.empty() || cues.lk_window_px != options_.window_px ||
      cues.lk_max_level != options_.max_level) {
    cues.lk_pyramid.clear();
    cv::buildOpticalFlowPyramid(frame.image, cues.lk_pyramid,
                                cv::Size(options_.window_px, options_.window_px),
                                options_.max_level);
    cues.lk_window_px = options_.window_px;
    cues.lk_max_level = options_.max_level;
  }
  return cues.lk_pyramid;
}

std::vector<Match> LucasKanadeMatcher::DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                                               const MatchPrediction& prediction,
                                               MatcherSummary* summary) {
  MatcherSummary& s = *summary;
  if (!BothGreyImages(prev, curr) || prev.image.size() != curr.image.size()) {
    s.ok = false;
    s.message = "LucasKanadeMatcher: needs CV_8UC1 images of the same size in both frames";
    return {};
  }
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<cv::Mat>& pyr_prev = Pyramid(prev);
  const std::vector<cv::Mat>& pyr_curr = Pyramid(curr);
  s.cue_time_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();

  // 1. Forward tracking of every previous feature.
  //    With a prediction, the flow starts at the predicted position (OPTFLOW_USE_INITIAL_FLOW).
  std::vector<cv::Point2f> pts_prev, pts_fwd, pts_back;
  pts_prev.reserve(s.num_prev);
  for (const Feature& f : prev.features) {
    pts_prev.emplace_back(static_cast<float>(f.uv_px.x()), static_cast<float>(f.uv_px.y()));
  }
  int flow_flags = 0;
  if (!prediction.empty()) {
    pts_fwd.reserve(s.num_prev);
    for (int i = 0; i < s.num_prev; ++i) {
      const Eigen::Vector2d c = prediction.Centre(i, prev.features[i].uv_px);
      pts_fwd.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
    }
    flow_flags = cv::OPTFLOW_USE_INITIAL_FLOW;
  }
  const cv::Size window(options_.window_px, options_.window_px);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  options_.max_iterations, options_.epsilon_px);
  std::vector<uchar> status_fwd, status_back;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(pyr_prev, pyr_curr, pts_prev, pts_fwd, status_fwd, err, window,
                           options_.max_level, criteria, flow_flags, options_.min_eig_threshold);
  // 2. Forward-backward check.
  const bool fb_check = options_.max_fb_error_px > 0.0;
  if (fb_check) {
    // Backward from the tracked points, starting at the previous positions.
    if (flow_flags != 0) pts_back = pts_prev;
    cv::calcOpticalFlowPyrLK(pyr_curr, pyr_prev, pts_fwd, pts_back, status_back, err, window,
                             options_.max_level, criteria, flow_flags, options_.min_eig_threshold);
  }
  // 3. Association with the current features (greedy one-to-one by distance).
  // (Not scaled by prediction.radius_scale: it is the detector's repeatability, not a search
  // gate; the prediction only seeds the flow.)
  const double radius = options_.association_radius_px;
  const PointGrid grid(FeaturePositions(curr.features), radius);
  std::vector<CandidatePair> candidates;
  for (int i = 0; i < s.num_prev; ++i) {
    if (!status_fwd[i]) continue;
    if (fb_check) {
      const double fb = std::hypot(pts_back[i].x - pts_prev[i].x, pts_back[i].y - pts_prev[i].y);
      if (!status_back[i] || !(fb <= options_.max_fb_error_px)) continue;
    }
    const Eigen::Vector2d tracked(pts_fwd[i].x, pts_fwd[i].y);
    grid.ForEachWithin(tracked, radius, [&](int j, double d2) {
      ++s.num_candidates;
      candidates.push_back(CandidatePair{i, j, std::sqrt(d2)});
    });
  }
  std::vector<Match> matches =
      GreedyOneToOne(std::move(candidates), [radius](double d) { return 1.0 - d / radius; });
  s.match_time_ms = MsSince(t0);
  s.num_matches = static_cast<int>(matches.size());
  return matches;
}

}  // namespace vo
