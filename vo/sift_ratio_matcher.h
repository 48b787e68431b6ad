// Descriptor matching with Lowe's ratio test ("Distinctive image features from scale-invariant
// keypoints", IJCV 2004), the modern reference: for every previous feature the two nearest
// current descriptors (L2) among the candidates (all current features, or those within
// search_radius_px); accepted when d1 < ratio · d2, and (mutual) when the previous feature is
// also the nearest descriptor of that current feature among its own candidates. A lone
// candidate (no second neighbour) passes the ratio test. Ties resolved greedily (one-to-one).
// Match::score = 1 − d1 / d2 ∈ [0, 1] (1 for a lone candidate).
// Needs MatchFrame::descriptors in both frames: CV_32F, one row per feature, equal widths
// (SIFT: 128; see FeatureSet in features.h). Stateless.
#pragma once

#include <vector>

#include "vo/matcher.h"

namespace vo {

class SiftRatioMatcher : public FrameMatcher {
 public:
  using Options = SiftRatioMatcherOptions;

  // Options must be valid (CreateFrameMatcher checks them).
  explicit SiftRatioMatcher(const Options& options);

  MatcherType type() const override { return MatcherType::kSiftRatio; }

 protected:
  std::vector<Match> DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                             const MatchPrediction& prediction, MatcherSummary* summary) override;

 private:
  Options options_;
};

}  // namespace vo
