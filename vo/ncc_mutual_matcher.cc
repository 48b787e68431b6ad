#include "vo/ncc_mutual_matcher.h"

#include <chrono>

namespace vo {

NccMutualMatcher::NccMutualMatcher(const Options& options, const NccOptions& ncc)
    : options_(options), ncc_(ncc) {
  std::string error;
  const bool valid = options_.IsValid(&error) && ncc_.IsValid(&error);
  AbortUnlessValid("NccMutualMatcher", valid, error);
}

std::vector<Match> NccMutualMatcher::DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                                             const MatchPrediction& prediction,
                                             MatcherSummary* summary) {
  MatcherSummary& s = *summary;
  if (!BothGreyImages(prev, curr)) {
    s.ok = false;
    s.message = "NccMutualMatcher: needs CV_8UC1 images in both frames";
    return {};
  }
  auto t0 = std::chrono::steady_clock::now();
  const NccPatches& ncc_prev = FrameNccPatches(prev, ncc_);
  const NccPatches& ncc_curr = FrameNccPatches(curr, ncc_);
  s.cue_time_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();

  // Best candidate of every previous and every current feature within the search radius
  // (ties: the first one met, in the grid's deterministic order, then by index).
  std::vector<int> best_of_prev(s.num_prev, -1), best_of_curr(s.num_curr, -1);
  std::vector<double> score_of_prev(s.num_prev, -1.0), score_of_curr(s.num_curr, -1.0);
  // Candidates around the predicted position (the previous one without a prediction).
  const double radius = options_.search_radius_px * prediction.radius_scale;
  const PointGrid grid(FeaturePositions(curr.features), radius);
  for (int i = 0; i < s.num_prev; ++i) {
    if (!ncc_prev.valid(i)) continue;
    grid.ForEachWithin(prediction.Centre(i, prev.features[i].uv_px), radius, [&](int j, double) {
      ++s.num_candidates;
      const double c = ncc_prev.Score(i, ncc_curr, j);  // eq. (2)
      if (c > score_of_prev[i] || (c == score_of_prev[i] && j < best_of_prev[i])) {
        score_of_prev[i] = c;
        best_of_prev[i] = j;
      }
      if (c > score_of_curr[j] || (c == score_of_curr[j] && i < best_of_curr[j])) {
        score_of_curr[j] = c;
        best_of_curr[j] = i;
      }
    });
  }
  // Mutual consistency: i's best is j and j's best is i.
  std::vector<Match> matches;
  for (int i = 0; i < s.num_prev; ++i) {
    const int j = best_of_prev[i];
    if (j < 0 || best_of_curr[j] != i || score_of_prev[i] < options_.min_score) continue;
    matches.push_back(Match{i, j, score_of_prev[i]});
  }
  s.match_time_ms = MsSince(t0);
  s.num_matches = static_cast<int>(matches.size());
  return matches;
}

}  // namespace vo
