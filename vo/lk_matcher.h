// Pyramidal Lucas–Kanade tracking (Bouguet's implementation, cv::calcOpticalFlowPyrLK), the
// first baseline of Kwolek section VI, made one-to-one between the two feature lists:
//   1. every previous feature is tracked into the current image (sub-pixel flow);
//   2. optionally tracked back (forward-backward check): lost when it misses its start by more
//      than max_fb_error_px;
//   3. each tracked point is associated with the nearest current feature within
//      association_radius_px; conflicts resolved greedily by distance (one-to-one).
// The tracked positions themselves are not returned (the interface pairs existing features);
// Match::score = 1 − distance / association_radius_px ∈ (0, 1]. Stateless; the image pyramids
// are cached in the frames (FrameCues::lk_pyramid) and reused when a frame becomes previous.
#pragma once

#include <vector>

#include "vo/matcher.h"

namespace vo {

class LucasKanadeMatcher : public FrameMatcher {
 public:
  using Options = LucasKanadeMatcherOptions;

  // Options must be valid (CreateFrameMatcher checks them).
  explicit LucasKanadeMatcher(const Options& options);

  MatcherType type() const override { return MatcherType::kLucasKanade; }

 protected:
  std::vector<Match> DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                             const MatchPrediction& prediction, MatcherSummary* summary) override;

 private:
  const std::vector<cv::Mat>& Pyramid(const MatchFrame& frame) const;

  Options options_;
};

}  // namespace vo
