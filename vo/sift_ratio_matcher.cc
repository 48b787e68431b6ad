#include "vo/sift_ratio_matcher.h"

#include <chrono>
#include <cmath>
#include <limits>

namespace vo {
namespace {

constexpr int kLanes = 8;  // lane-wise partial sums: vectorisable without reassociation

// Squared L2 distance between two float rows of length n.
float SquaredDistance(const float* a, const float* b, int n) {
  float acc[kLanes] = {0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f};
  int k = 0;
  for (; k + kLanes <= n; k += kLanes) {
    for (int l = 0; l < kLanes; ++l) {
      const float d = a[k + l] - b[k + l];
      acc[l] += d * d;
    }
  }
  float sum = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
  for (; k < n; ++k) sum += (a[k] - b[k]) * (a[k] - b[k]);
  return sum;
}

// Two nearest neighbours so far.
struct Nearest2 {
  int best = -1;
  float d1 = std::numeric_limits<float>::infinity();  // squared distances
  float d2 = std::numeric_limits<float>::infinity();
  void Offer(int idx, float d) {
    if (d < d1) {
      d2 = d1;
      d1 = d;
      best = idx;
    } else if (d < d2) {
      d2 = d;
    }
  }
};

bool DescriptorsUsable(const MatchFrame& f) {
  return f.descriptors.type() == CV_32F &&
         f.descriptors.rows == static_cast<int>(f.features.size()) && f.descriptors.cols > 0;
}

}  // namespace

SiftRatioMatcher::SiftRatioMatcher(const Options& options) : options_(options) {
  std::string error;
  const bool valid = options_.IsValid(&error);
  AbortUnlessValid("SiftRatioMatcher", valid, error);
}

std::vector<Match> SiftRatioMatcher::DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                                             const MatchPrediction& prediction,
                                             MatcherSummary* summary) {
  MatcherSummary& s = *summary;
  if (!DescriptorsUsable(prev) || !DescriptorsUsable(curr) ||
      prev.descriptors.cols != curr.descriptors.cols) {
    s.ok = false;
    s.message =
        "SiftRatioMatcher: both frames need CV_32F descriptors, one row per feature, of equal "
        "width";
    return {};
  }
  const auto t0 = std::chrono::steady_clock::now();
  const int dim = prev.descriptors.cols;
  const cv::Mat dp = prev.descriptors.isContinuous() ? prev.descriptors : prev.descriptors.clone();
  const cv::Mat dc = curr.descriptors.isContinuous() ? curr.descriptors : curr.descriptors.clone();

  // Nearest two current descriptors of every previous feature, and the nearest previous
  // descriptor of every current feature (for the mutual check).
  std::vector<Nearest2> of_prev(s.num_prev), of_curr(s.num_curr);
  auto offer = [&](int i, int j) {
    ++s.num_candidates;
    const float d = SquaredDistance(dp.ptr<float>(i), dc.ptr<float>(j), dim);
    of_prev[i].Offer(j, d);
    of_curr[j].Offer(i, d);
  };
  if (options_.search_radius_px > 0.0) {
    // Around the predicted position (the previous one without a prediction).
    const double radius = options_.search_radius_px * prediction.radius_scale;
    const PointGrid grid(FeaturePositions(curr.features), radius);
    for (int i = 0; i < s.num_prev; ++i) {
      grid.ForEachWithin(prediction.Centre(i, prev.features[i].uv_px), radius,
                         [&](int j, double) { offer(i, j); });
    }
  } else {
    for (int i = 0; i < s.num_prev; ++i) {
      for (int j = 0; j < s.num_curr; ++j) offer(i, j);
    }
  }

  // Ratio test (on distances, not squared), mutual check, then one-to-one.
  std::vector<CandidatePair> candidates;
  const double ratio2 = options_.ratio * options_.ratio;
  for (int i = 0; i < s.num_prev; ++i) {
    const Nearest2& n = of_prev[i];
    if (n.best < 0) continue;
    if (std::isfinite(n.d2) && !(n.d1 < ratio2 * n.d2)) continue;
    if (options_.mutual && of_curr[n.best].best != i) continue;
    const double r = std::isfinite(n.d2) && n.d2 > 0.f ? std::sqrt(n.d1 / n.d2) : 0.0;
    candidates.push_back(CandidatePair{i, n.best, r});
  }
  std::vector<Match> matches =
      GreedyOneToOne(std::move(candidates), [](double r) { return 1.0 - r; });
  s.match_time_ms = MsSince(t0);
  s.num_matches = static_cast<int>(matches.size());
  return matches;
}

}  // namespace vo
