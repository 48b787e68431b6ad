#include "vo/matcher.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <sstream>

#include "vo/kalman_matcher.h"
#include "vo/lk_matcher.h"
#include "vo/ncc_mutual_matcher.h"
#include "vo/sift_ratio_matcher.h"
#include "vo/svd_matcher.h"

namespace vo {
namespace {

struct TypeName {
  MatcherType type;
  const char* name;
};
constexpr TypeName kTypeNames[] = {
    {MatcherType::kSvdProximity, "svd_proximity"}, {MatcherType::kSvdNcc, "svd_ncc"},
    {MatcherType::kSvdNccGabor, "svd_ncc_gabor"},  {MatcherType::kNccMutual, "ncc_mutual"},
    {MatcherType::kLucasKanade, "lucas_kanade"},   {MatcherType::kKalman, "kalman"},
    {MatcherType::kSiftRatio, "sift_ratio"},
};

bool Fail(std::ostringstream& msg, std::string* error) {
  if (msg.tellp() == 0) return true;
  if (error != nullptr) *error = msg.str();
  return false;
}

}  // namespace

const char* ToString(MatcherType type) {
  for (const TypeName& t : kTypeNames) {
    if (t.type == type) return t.name;
  }
  return "unknown";
}

const char* ToString(PredictionMode mode) {
  return mode == PredictionMode::kNone ? "none" : "motion_prior";
}

bool ParsePredictionMode(const std::string& name, PredictionMode* mode) {
  if (name == "none") {
    *mode = PredictionMode::kNone;
  } else if (name == "motion_prior") {
    *mode = PredictionMode::kMotionPrior;
  } else {
    return false;
  }
  return true;
}

bool ParseMatcherType(const std::string& name, MatcherType* type) {
  for (const TypeName& t : kTypeNames) {
    if (name == t.name) {
      *type = t.type;
      return true;
    }
  }
  return false;
}

// ---- Options validation -------------------------------------------------------------------

bool SvdMatcherOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!(sigma_px > 0.0) || !std::isfinite(sigma_px)) {
    msg << "SvdMatcherOptions::sigma_px must be finite and > 0, got " << sigma_px;
  } else if (!(cutoff_sigmas >= 1.0 && cutoff_sigmas <= 10.0)) {
    msg << "SvdMatcherOptions::cutoff_sigmas must be in [1, 10], got " << cutoff_sigmas;
  } else if (!(min_weight >= 0.0 && min_weight <= 1.0)) {
    msg << "SvdMatcherOptions::min_weight must be in [0, 1], got " << min_weight;
  } else if (!(min_entry >= 0.0 && min_entry <= min_weight)) {
    msg << "SvdMatcherOptions::min_entry must be in [0, min_weight], got " << min_entry;
  } else if (!(min_pairing >= 0.0 && min_pairing <= 1.0)) {
    msg << "SvdMatcherOptions::min_pairing must be in [0, 1], got " << min_pairing;
  } else if (!(min_ncc >= 0.0 && min_ncc <= 1.0)) {
    msg << "SvdMatcherOptions::min_ncc must be in [0, 1], got " << min_ncc;
  } else if (!(gabor_min_ncc >= 0.0 && gabor_min_ncc <= 1.0)) {
    msg << "SvdMatcherOptions::gabor_min_ncc must be in [0, 1], got " << gabor_min_ncc;
  } else if (!(max_phase_diff_rad >= 0.0 && max_phase_diff_rad <= 3.14159265358979323846)) {
    msg << "SvdMatcherOptions::max_phase_diff_rad must be in [0, pi], got " << max_phase_diff_rad;
  } else if (max_component_size < 2) {
    msg << "SvdMatcherOptions::max_component_size must be >= 2, got " << max_component_size;
  } else if (!(guard_growth > 1.0) || !std::isfinite(guard_growth)) {
    msg << "SvdMatcherOptions::guard_growth must be finite and > 1, got " << guard_growth;
  } else if (!(guard_max_entry > 0.0 && guard_max_entry <= 1.0)) {
    msg << "SvdMatcherOptions::guard_max_entry must be in (0, 1], got " << guard_max_entry;
  } else if (jacobi_max_size < 2) {
    msg << "SvdMatcherOptions::jacobi_max_size must be >= 2, got " << jacobi_max_size;
  } else if (!(coherence_sigmas >= 0.0) || !std::isfinite(coherence_sigmas)) {
    msg << "SvdMatcherOptions::coherence_sigmas must be finite and >= 0, got " << coherence_sigmas;
  } else if (!(coherence_min_px >= 0.0) || !std::isfinite(coherence_min_px)) {
    msg << "SvdMatcherOptions::coherence_min_px must be finite and >= 0, got " << coherence_min_px;
  } else if (!(coherence_radius_px > 0.0) || !std::isfinite(coherence_radius_px)) {
    msg << "SvdMatcherOptions::coherence_radius_px must be finite and > 0, got "
        << coherence_radius_px;
  } else if (coherence_neighbours < 2) {
    msg << "SvdMatcherOptions::coherence_neighbours must be >= 2, got " << coherence_neighbours;
  }
  return Fail(msg, error);
}

bool NccMutualMatcherOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!(search_radius_px > 0.0) || !std::isfinite(search_radius_px)) {
    msg << "NccMutualMatcherOptions::search_radius_px must be finite and > 0, got "
        << search_radius_px;
  } else if (!(min_score >= 0.0 && min_score <= 1.0)) {
    msg << "NccMutualMatcherOptions::min_score must be in [0, 1], got " << min_score;
  }
  return Fail(msg, error);
}

bool LucasKanadeMatcherOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (window_px < 5 || window_px % 2 == 0) {
    msg << "LucasKanadeMatcherOptions::window_px must be odd and >= 5, got " << window_px;
  } else if (max_level < 0 || max_level > 8) {
    msg << "LucasKanadeMatcherOptions::max_level must be in [0, 8], got " << max_level;
  } else if (max_iterations < 1) {
    msg << "LucasKanadeMatcherOptions::max_iterations must be >= 1, got " << max_iterations;
  } else if (!(epsilon_px > 0.0)) {
    msg << "LucasKanadeMatcherOptions::epsilon_px must be > 0, got " << epsilon_px;
  } else if (!(min_eig_threshold >= 0.0)) {
    msg << "LucasKanadeMatcherOptions::min_eig_threshold must be >= 0, got " << min_eig_threshold;
  } else if (!std::isfinite(max_fb_error_px)) {
    msg << "LucasKanadeMatcherOptions::max_fb_error_px must be finite, got " << max_fb_error_px;
  } else if (!(association_radius_px > 0.0) || !std::isfinite(association_radius_px)) {
    msg << "LucasKanadeMatcherOptions::association_radius_px must be finite and > 0, got "
        << association_radius_px;
  }
  return Fail(msg, error);
}

bool KalmanMatcherOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  auto positive = [&msg](double v, const char* name) {
    if (msg.tellp() == 0 && (!(v > 0.0) || !std::isfinite(v))) {
      msg << "KalmanMatcherOptions::" << name << " must be finite and > 0, got " << v;
    }
  };
  positive(measurement_noise_px, "measurement_noise_px");
  positive(process_noise_px, "process_noise_px");
  positive(initial_velocity_std_px, "initial_velocity_std_px");
  positive(gate_chi2, "gate_chi2");
  positive(max_search_radius_px, "max_search_radius_px");
  positive(gradient_noise, "gradient_noise");
  positive(gradient_process_noise, "gradient_process_noise");
  positive(ncc_scale, "ncc_scale");
  positive(max_cost, "max_cost");
  if (msg.tellp() == 0 && (gradient_window_px < 3 || gradient_window_px % 2 == 0)) {
    msg << "KalmanMatcherOptions::gradient_window_px must be odd and >= 3, got "
        << gradient_window_px;
  }
  if (msg.tellp() == 0 && !(min_ncc >= 0.0 && min_ncc <= 1.0)) {
    msg << "KalmanMatcherOptions::min_ncc must be in [0, 1], got " << min_ncc;
  }
  return Fail(msg, error);
}

bool SiftRatioMatcherOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!(ratio > 0.0 && ratio <= 1.0)) {
    msg << "SiftRatioMatcherOptions::ratio must be in (0, 1], got " << ratio;
  } else if (!(search_radius_px >= 0.0) || !std::isfinite(search_radius_px)) {
    msg << "SiftRatioMatcherOptions::search_radius_px must be finite and >= 0, got "
        << search_radius_px;
  }
  return Fail(msg, error);
}

bool MatcherOptions::IsValid(std::string* error) const {
  switch (type) {
    case MatcherType::kSvdProximity:
      return svd.IsValid(error);
    case MatcherType::kSvdNcc:
      return ncc.IsValid(error) && svd.IsValid(error);
    case MatcherType::kSvdNccGabor:
      return ncc.IsValid(error) && gabor.IsValid(error) && svd.IsValid(error);
    case MatcherType::kNccMutual:
      return ncc.IsValid(error) && ncc_mutual.IsValid(error);
    case MatcherType::kLucasKanade:
      return lucas_kanade.IsValid(error);
    case MatcherType::kKalman:
      return ncc.IsValid(error) && kalman.IsValid(error);
    case MatcherType::kSiftRatio:
      return sift_ratio.IsValid(error);
  }
  if (error != nullptr) *error = "MatcherOptions::type is not a known MatcherType";
  return false;
}

std::unique_ptr<FrameMatcher> CreateFrameMatcher(const MatcherOptions& options,
                                                 std::string* error) {
  if (!options.IsValid(error)) return nullptr;
  switch (options.type) {
    case MatcherType::kSvdProximity:
      return std::make_unique<SvdMatcher>(options.svd, SvdMatcher::Cues::kProximity, options.ncc,
                                          options.gabor);
    case MatcherType::kSvdNcc:
      return std::make_unique<SvdMatcher>(options.svd, SvdMatcher::Cues::kProximityNcc, options.ncc,
                                          options.gabor);
    case MatcherType::kSvdNccGabor:
      return std::make_unique<SvdMatcher>(options.svd, SvdMatcher::Cues::kProximityNccGabor,
                                          options.ncc, options.gabor);
    case MatcherType::kNccMutual:
      return std::make_unique<NccMutualMatcher>(options.ncc_mutual, options.ncc);
    case MatcherType::kLucasKanade:
      return std::make_unique<LucasKanadeMatcher>(options.lucas_kanade);
    case MatcherType::kKalman:
      return std::make_unique<KalmanMatcher>(options.kalman, options.ncc);
    case MatcherType::kSiftRatio:
      return std::make_unique<SiftRatioMatcher>(options.sift_ratio);
  }
  return nullptr;  // unreachable: IsValid rejects unknown types
}

// ---- Cue cache ----------------------------------------------------------------------------

const NccPatches& FrameNccPatches(const MatchFrame& frame, const NccOptions& options) {
  FrameCues& cues = frame.cues;
  if (cues.ncc == nullptr || cues.ncc->options() != options ||
      cues.ncc->size() != static_cast<int>(frame.features.size())) {
    auto patches = std::make_shared<NccPatches>();
    patches->Compute(frame.image, frame.features, options);
    cues.ncc = std::move(patches);
  }
  return *cues.ncc;
}

const GaborResponses& FrameGaborResponses(const MatchFrame& frame, const GaborBank& bank) {
  FrameCues& cues = frame.cues;
  if (cues.gabor == nullptr || cues.gabor->options != bank.options() ||
      cues.gabor->size() != static_cast<int>(frame.features.size())) {
    cues.gabor = std::make_shared<GaborResponses>(bank.Compute(frame.image, frame.features));
  }
  return *cues.gabor;
}

// ---- Helpers ------------------------------------------------------------------------------

PointGrid::PointGrid(std::vector<Eigen::Vector2d> points, double cell_px)
    : points_(std::move(points)), cell_px_(cell_px > 0.0 ? cell_px : 1.0) {
  if (points_.empty()) return;
  double max_x = points_[0].x(), max_y = points_[0].y();
  min_x_ = max_x;
  min_y_ = max_y;
  for (const Eigen::Vector2d& p : points_) {
    min_x_ = std::min(min_x_, p.x());
    min_y_ = std::min(min_y_, p.y());
    max_x = std::max(max_x, p.x());
    max_y = std::max(max_y, p.y());
  }
  // Keep the grid bounded even for a tiny cell over a huge extent.
  constexpr double kMaxCellsPerAxis = 4096.0;
  cell_px_ = std::max(
      {cell_px_, (max_x - min_x_) / kMaxCellsPerAxis, (max_y - min_y_) / kMaxCellsPerAxis});
  cols_ = static_cast<int>(std::floor((max_x - min_x_) / cell_px_)) + 1;
  rows_ = static_cast<int>(std::floor((max_y - min_y_) / cell_px_)) + 1;
  std::vector<int> cell_of(points_.size());
  cell_start_.assign(static_cast<size_t>(cols_) * rows_ + 1, 0);
  for (size_t i = 0; i < points_.size(); ++i) {
    const int cx = std::min(cols_ - 1, static_cast<int>((points_[i].x() - min_x_) / cell_px_));
    const int cy = std::min(rows_ - 1, static_cast<int>((points_[i].y() - min_y_) / cell_px_));
    cell_of[i] = cy * cols_ + cx;
    ++cell_start_[cell_of[i] + 1];
  }
  std::partial_sum(cell_start_.begin(), cell_start_.end(), cell_start_.begin());
  order_.resize(points_.size());
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t i = 0; i < points_.size(); ++i) order_[fill[cell_of[i]]++] = static_cast<int>(i);
}

std::vector<Match> RejectIncoherentMatches(const std::vector<Feature>& prev,
                                           const std::vector<Feature>& curr,
                                           const MatchPrediction& prediction,
                                           const std::vector<Match>& matches, double radius_px,
                                           int neighbours, double max_px, int* num_rejected) {
  const size_t n = matches.size();
  auto from = [&](size_t m) -> const Eigen::Vector2d& { return prev[matches[m].prev].uv_px; };
  std::vector<Eigen::Vector2d> displacement(n);
  for (size_t m = 0; m < n; ++m) {
    displacement[m] = curr[matches[m].curr].uv_px - prediction.Centre(matches[m].prev, from(m));
  }
  // The k nearest other matches within the radius, by (squared distance, index): a sweep over
  // the matches sorted by x that stops once |dx| exceeds the k-th distance found so far.
  std::vector<int> by_x(n);
  std::iota(by_x.begin(), by_x.end(), 0);
  std::sort(by_x.begin(), by_x.end(), [&](int a, int b) {
    return from(a).x() < from(b).x() || (from(a).x() == from(b).x() && a < b);
  });
  std::vector<double> sx(n), sy(n);  // positions in that order
  std::vector<size_t> rank(n);
  for (size_t r = 0; r < n; ++r) {
    rank[by_x[r]] = r;
    sx[r] = from(by_x[r]).x();
    sy[r] = from(by_x[r]).y();
  }
  std::vector<Match> kept;
  kept.reserve(n);
  const size_t k_max = static_cast<size_t>(std::max(neighbours, 2));
  const double radius_sq = radius_px * radius_px;
  std::vector<std::pair<double, int>> near(k_max + 1);  // sorted (d², index), `count` used
  std::vector<double> xs(k_max), ys(k_max);
  for (size_t m = 0; m < n; ++m) {
    size_t count = 0;
    double bound = radius_sq;  // the k-th distance once k are found
    const size_t p = rank[m];
    auto consider = [&](size_t r, double dx) {
      const double dy = sy[r] - sy[p];
      const double d2 = dx * dx + dy * dy;
      if (d2 > bound) return;
      const std::pair<double, int> entry(d2, by_x[r]);
      size_t q = count;
      while (q > 0 && entry < near[q - 1]) {
        near[q] = near[q - 1];
        --q;
      }
      near[q] = entry;
      if (count < k_max) ++count;
      if (count == k_max) bound = near[k_max - 1].first;
    };
    for (size_t r = p + 1; r < n; ++r) {
      const double dx = sx[r] - sx[p];
      if (dx * dx > bound) break;
      consider(r, dx);
    }
    for (size_t r = p; r-- > 0;) {
      const double dx = sx[r] - sx[p];
      if (dx * dx > bound) break;
      consider(r, dx);
    }
    if (count < 2) {
      kept.push_back(matches[m]);
      continue;
    }
    for (size_t q = 0; q < count; ++q) {
      xs[q] = displacement[near[q].second].x();
      ys[q] = displacement[near[q].second].y();
    }
    std::sort(xs.begin(), xs.begin() + count);
    std::sort(ys.begin(), ys.begin() + count);
    const Eigen::Vector2d median(xs[count / 2], ys[count / 2]);
    if ((displacement[m] - median).norm() <= max_px) kept.push_back(matches[m]);
  }
  if (num_rejected != nullptr) *num_rejected = static_cast<int>(n - kept.size());
  return kept;
}

std::vector<Eigen::Vector2d> FeaturePositions(const std::vector<Feature>& features) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(features.size());
  for (const Feature& f : features) points.push_back(f.uv_px);
  return points;
}

std::vector<Match> GreedyOneToOne(std::vector<CandidatePair> candidates,
                                  const std::function<double(double)>& score_of) {
  std::sort(candidates.begin(), candidates.end(),
            [](const CandidatePair& a, const CandidatePair& b) {
              if (a.cost != b.cost) return a.cost < b.cost;
              if (a.prev != b.prev) return a.prev < b.prev;
              return a.curr < b.curr;
            });
  int max_prev = -1, max_curr = -1;
  for (const CandidatePair& c : candidates) {
    max_prev = std::max(max_prev, c.prev);
    max_curr = std::max(max_curr, c.curr);
  }
  std::vector<char> prev_taken(max_prev + 1, 0), curr_taken(max_curr + 1, 0);
  std::vector<Match> matches;
  for (const CandidatePair& c : candidates) {
    if (prev_taken[c.prev] || curr_taken[c.curr]) continue;
    prev_taken[c.prev] = curr_taken[c.curr] = 1;
    matches.push_back(Match{c.prev, c.curr, score_of(c.cost)});
  }
  std::sort(matches.begin(), matches.end(),
            [](const Match& a, const Match& b) { return a.prev < b.prev; });
  return matches;
}

bool IsOneToOne(const std::vector<Match>& matches) {
  std::vector<int> prev, curr;
  for (const Match& m : matches) {
    prev.push_back(m.prev);
    curr.push_back(m.curr);
  }
  std::sort(prev.begin(), prev.end());
  std::sort(curr.begin(), curr.end());
  return std::adjacent_find(prev.begin(), prev.end()) == prev.end() &&
         std::adjacent_find(curr.begin(), curr.end()) == curr.end();
}

bool BothGreyImages(const MatchFrame& prev, const MatchFrame& curr) {
  return !prev.image.empty() && !curr.image.empty() && prev.image.type() == CV_8UC1 &&
         curr.image.type() == CV_8UC1;
}

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void AbortUnlessValid(const char* matcher, bool valid, const std::string& error) {
  if (valid) return;
  std::fprintf(stderr, "vo::%s: invalid options: %s\n", matcher, error.c_str());
  std::abort();
}

std::vector<Match> FrameMatcher::MatchFrames(const MatchFrame& prev, const MatchFrame& curr,
                                             const MatchPrediction& prediction,
                                             MatcherSummary* summary) {
  MatcherSummary local;
  MatcherSummary* s = summary != nullptr ? summary : &local;
  *s = MatcherSummary();
  s->num_prev = static_cast<int>(prev.features.size());
  s->num_curr = static_cast<int>(curr.features.size());
  const bool size_ok = prediction.uv_px.empty() || prediction.uv_px.size() == prev.features.size();
  const bool scale_ok = prediction.radius_scale >= 0.05 && prediction.radius_scale <= 20.0;
  if (!size_ok || !scale_ok) {
    s->ok = false;
    std::ostringstream msg;
    if (!size_ok) {
      msg << "prediction has " << prediction.uv_px.size() << " positions for "
          << prev.features.size() << " previous features";
    } else {
      msg << "prediction radius_scale must be in [0.05, 20], got " << prediction.radius_scale;
    }
    s->message = msg.str();
    return {};
  }
  if ((s->num_prev == 0 || s->num_curr == 0) && !SeesEveryFrame()) return {};
  return DoMatch(prev, curr, prediction, s);
}

}  // namespace vo
