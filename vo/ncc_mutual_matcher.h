// NCC matching with a mutual-consistency check (Nistér, Naroditsky & Bergen, "Visual
// odometry", CVPR 2004; the baseline of Kwolek section III-A): every previous feature is
// compared with every current feature within search_radius_px by the NCC of eq. (2); i↔j is
// a match when j is i's best candidate AND i is j's best candidate, and C_ij >= min_score.
// Match::score = C_ij ∈ [0, 1]. Stateless; uses the frames' cached NCC patches.
#pragma once

#include <vector>

#include "vo/matcher.h"
#include "vo/ncc.h"

namespace vo {

class NccMutualMatcher : public FrameMatcher {
 public:
  using Options = NccMutualMatcherOptions;

  // Options must be valid (CreateFrameMatcher checks them).
  NccMutualMatcher(const Options& options, const NccOptions& ncc = NccOptions());

  MatcherType type() const override { return MatcherType::kNccMutual; }

 protected:
  std::vector<Match> DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                             const MatchPrediction& prediction, MatcherSummary* summary) override;

 private:
  Options options_;
  NccOptions ncc_;
};

}  // namespace vo
