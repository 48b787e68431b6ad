// Inter-frame feature matching: the FrameMatcher plug-in point, the frame it works on (with
// its per-frame cue cache), every matcher's Options, and the factory.
//
// A matcher maps (previous frame, current frame) to ONE-TO-ONE matches: no previous index and
// no current index appears twice. Matchers (MatcherType), header in brackets:
//   kSvdProximity  Scott & Longuet-Higgins (1991): G_ij = exp(−d²/2σ²), P = U Vᵀ [svd_matcher]
//   kSvdNcc        Kwolek eq. (1): G_ij = C_ij · exp(−d²/2σ²)                     [svd_matcher]
//   kSvdNccGabor   Kwolek III-C: proximity · NCC · Gabor phase (the default)      [svd_matcher]
//   kNccMutual     NCC in a search radius + mutual check (Nistér 2004)     [ncc_mutual_matcher]
//   kLucasKanade   pyramidal LK tracking + association to current features         [lk_matcher]
//   kKalman        constant-velocity Kalman corner tracker (Kwolek VI)         [kalman_matcher]
//   kSiftRatio     SIFT descriptors, Lowe's ratio test + mutual check      [sift_ratio_matcher]
// Cues are cached per frame (MatchFrame::cues): keep the current MatchFrame and pass it as
// `prev` to the next call (move it, or keep it in a ring of frames), and its NCC patches,
// Gabor phases and LK pyramid are not computed again. kSiftRatio reads
// MatchFrame::descriptors, e.g. FeatureSet::descriptors from features.h.
// Adding one = a .h/.cc pair, a test, an enum value, a `case` in CreateFrameMatcher().
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vo/gabor.h"
#include "vo/ncc.h"
#include "vo/types.h"

namespace vo {

enum class MatcherType {
  kSvdProximity,
  kSvdNcc,
  kSvdNccGabor,
  kNccMutual,
  kLucasKanade,
  kKalman,
  kSiftRatio,
};

// "svd_proximity", "svd_ncc", "svd_ncc_gabor", "ncc_mutual", "lucas_kanade", "kalman",
// "sift_ratio".
const char* ToString(MatcherType type);
// Inverse of ToString; false (and *type untouched) for an unknown name.
bool ParseMatcherType(const std::string& name, MatcherType* type);

// Where the pipeline (odometry.h) centres every matcher's position gate.
enum class PredictionMode {
  kNone,         // on the feature's previous position: the paper's form (Kwolek III-B)
  kMotionPrior,  // on its predicted position: the previous 3D point moved by the motion prior
                 // (constant velocity, or one given by the caller), with a coarse-to-fine
                 // image-shift search when the prior is weak and a guided second pass
};
// "none", "motion_prior".
const char* ToString(PredictionMode mode);
// Inverse of ToString; false (and *mode untouched) for an unknown name.
bool ParsePredictionMode(const std::string& name, PredictionMode* mode);

// Per-frame similarity cues, computed lazily by the matchers and kept with the frame, so a
// frame's cues are computed once and reused when it becomes the previous frame. Each entry
// records what produced it and is recomputed when asked with other options. Not thread-safe:
// one frame must not be matched from two threads at once.
struct FrameCues {
  std::shared_ptr<const NccPatches> ncc;        // NCC patches of every feature (or null)
  std::shared_ptr<const GaborResponses> gabor;  // Gabor phases/amplitudes (or null)
  std::vector<cv::Mat> lk_pyramid;              // cv::buildOpticalFlowPyramid output (or empty)
  int lk_window_px = 0;                         // window the pyramid was built for
  int lk_max_level = -1;                        // max level the pyramid was built for
  std::shared_ptr<const std::vector<Eigen::Vector2f>> gradients;  // Kalman: mean gradients
  int gradient_window_px = 0;  // window the gradients were averaged over

  void Clear() { *this = FrameCues(); }
};

// One frame as the matchers see it.
struct MatchFrame {
  int64_t frame_id = -1;          // optional identity (e.g. the frame counter); -1 = unknown. The
                                  // stateful Kalman matcher uses it to recognise its last frame
  cv::Mat image;                  // left image, CV_8UC1 (a shallow, reference-counted header; the
                                  // pixels must not be modified while the frame is in use)
  std::vector<Feature> features;  // features of `image`; matches index into this vector
  cv::Mat descriptors;     // optional: one row per feature (SIFT: CV_32F, 128 columns); needed
                           // by kSiftRatio only, may be empty otherwise
  mutable FrameCues cues;  // cache filled by the matchers; call ClearCues() after changing
                           // `image` or any feature position

  void ClearCues() const { cues.Clear(); }
};

// Cached cue accessors (compute on first use, or when the cache was built with other options
// or for another number of features).
const NccPatches& FrameNccPatches(const MatchFrame& frame, const NccOptions& options);
const GaborResponses& FrameGaborResponses(const MatchFrame& frame, const GaborBank& bank);

// What one MatchFrames() call did.
struct MatcherSummary {
  bool ok = true;              // false for invalid input (e.g. kSiftRatio without descriptors)
  std::string message;         // why not ok; empty when ok
  int num_prev = 0;            // features in the previous frame
  int num_curr = 0;            // features in the current frame
  int num_candidates = 0;      // pairs whose cost/similarity was evaluated
  int num_matches = 0;         // matches returned
  int num_components = 0;      // SVD matchers: connected components solved
  int largest_component = 0;   // SVD matchers: rows + columns of the largest one solved
  int num_guard_splits = 0;    // SVD matchers: times the component-size guard raised the bound
  int num_rank_deficient = 0;  // SVD matchers: blocks with (numerically) zero singular values
  int num_svd_fallbacks = 0;   // SVD matchers: blocks whose Gram eigensolver failed, solved
                               // by an SVD instead
  int num_incoherent = 0;      // matches dropped by the motion-coherence test (SVD matchers)
  double cue_time_ms = 0.0;    // computing per-frame cues (0 when cached)
  double match_time_ms = 0.0;  // everything else
};

// Where each previous feature is expected in the current image, and how far to look around
// it. Built by the pipeline from the motion prior (odometry.h) or a coarse-to-fine image-shift
// estimate (image_motion.h); empty = no prediction (the paper's form: every position-gated cue
// is centred on the feature's previous position).
struct MatchPrediction {
  std::vector<Eigen::Vector2d> uv_px;  // one per previous feature (pixels, current left image),
                                       // or empty; non-finite entries fall back to the
                                       // previous position
  double radius_scale = 1.0;  // scales every position gate of the matcher (SVD σ and cutoff,
                              // NCC search radius, Kalman gate, SIFT radius; LK's prediction
                              // seeds the flow, its association radius is unscaled): < 1
                              // for a guided re-match around a known motion, > 1 for a weak
                              // prior; in [0.05, 20]

  bool coherence_test = true;  // matchers with a motion-coherence test (SVD) run it; the
                               // pipeline's guided pass turns it off: its centres come from a
                               // RANSAC motion the matches already agree with (measured on
                               // l_hallway seeds 1-10: the same accuracy, 0.03 ms less)

  bool empty() const { return uv_px.empty(); }
  // Centre of the search for previous feature i: the prediction when given and finite, else
  // `previous_uv_px`.
  Eigen::Vector2d Centre(int i, const Eigen::Vector2d& previous_uv_px) const {
    if (i < 0 || i >= static_cast<int>(uv_px.size()) || !uv_px[i].allFinite()) {
      return previous_uv_px;
    }
    return uv_px[i];
  }
};

// The plug-in point.
class FrameMatcher {
 public:
  virtual ~FrameMatcher() = default;

  // One-to-one matches between prev.features and curr.features, sorted by `prev`; each
  // Match::score is matcher-specific (larger = better, documented per matcher). Expected
  // failures (missing descriptors, empty images where needed) give no matches and
  // summary->ok = false; so does a prediction whose size differs from prev.features (or a
  // radius_scale out of range). `summary` may be null. Without `prediction` the position
  // gates are centred on the previous positions.
  std::vector<Match> MatchFrames(const MatchFrame& prev, const MatchFrame& curr,
                                 MatcherSummary* summary = nullptr) {
    return MatchFrames(prev, curr, MatchPrediction(), summary);
  }
  std::vector<Match> MatchFrames(const MatchFrame& prev, const MatchFrame& curr,
                                 const MatchPrediction& prediction,
                                 MatcherSummary* summary = nullptr);

  // Forgets any state carried between calls (only kKalman has some). Call it when the
  // sequence restarts or frames are skipped.
  virtual void Reset() {}

  virtual MatcherType type() const = 0;

 protected:
  // The matcher itself; `prediction` is checked (empty or one finite-or-not entry per
  // previous feature, radius_scale in range) and `summary` is never null, reset, with the
  // frames' feature counts set. Called only when both frames have features, unless
  // SeesEveryFrame().
  virtual std::vector<Match> DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                                     const MatchPrediction& prediction,
                                     MatcherSummary* summary) = 0;
  // True for a matcher with state across frames that must see a frame without features too.
  virtual bool SeesEveryFrame() const { return false; }
};

// ---- Options of every matcher -------------------------------------------------------------

// SVD matchers (kSvdProximity, kSvdNcc, kSvdNccGabor), svd_matcher.h.
struct SvdMatcherOptions {
  double sigma_px = 10.0;  // σ of the proximity term exp(−d²/2σ²) (pixels), > 0: about the
                           // expected inter-frame image motion; small = local interactions
  double cutoff_sigmas = 3.0;  // pairs farther apart than cutoff_sigmas · σ get G_ij = 0
                               // (sparse mode), in [1, 10]; 3σ: exp(−4.5) = 0.011
  double min_entry = 1e-3;     // sparse mode: entries of G below this are dropped before the
                               // components are formed, in [0, min_weight]
  double min_weight = 0.02;    // minimum-weight acceptance: i↔j needs G_ij >= this, in [0, 1]
                               // (an outlier with no true partner stays unmatched)
  double min_pairing = 0.3;    // and P_ij >= this (P = U Vᵀ, entries in [−1, 1]), in [0, 1]
  double min_ncc = 0.8;        // and C_ij >= this (eq. (2) scale; 0.8 is ρ >= 0.6) for
                               // kSvdNcc, in [0, 1]; 0 = the paper's rule alone
  double gabor_min_ncc = 0.6;  // the same threshold for kSvdNccGabor (0.6 is ρ >= 0.2), in
                               // [0, 1]: its phase cue and the coherence test below reject
                               // what the lower bar lets through, and the true pairs whose
                               // patches changed are kept. Measured (match-eval l_hallway,
                               // texture seeds 7 and 3, strides 1-8), against 0.8 and a phase
                               // bound of 0.8 without the coherence test: recall +1.0-3.0 %,
                               // precision 0.987-0.997 -> 0.990-0.998
  double max_phase_diff_rad = 0.9;  // and the (weighted) mean wrapped phase difference of
                                    // the Gabor bank <= this, i.e. S_ij >= exp(−β · this), for
                                    // kSvdNccGabor (rad, [0, π]; π = the paper's rule alone);
                                    // unrelated phases average π/2. Was 0.8 (see gabor_min_ncc)
  bool dense = false;  // reference mode: G over all n×m pairs (no cutoff, no dropping) and one
                       // BDCSVD of the whole matrix, as in the paper; slow (~135 ms at 500×500)
  int max_component_size = 200;  // guard: a component with more rows + columns than this is
                                 // split by raising its entry bound (× guard_growth, repeated);
                                 // >= 2. 200 keeps every block <= ~100×100 (~2 ms)
  double guard_growth = 2.0;     // factor the guard raises the entry bound by, > 1
  double guard_max_entry = 0.9;  // the guard stops raising at this bound and solves what is
                                 // left densely, in (0, 1]
  int jacobi_max_size = 16;      // blocks whose Gram eigensolver fails (never seen) fall back
                                 // to JacobiSVD up to min(rows, cols) = this, BDCSVD above; >= 2
  // Motion coherence (beyond the paper; RejectIncoherentMatches): a match whose displacement
  // from its search centre differs from the median displacement of its neighbouring matches
  // by more than max(coherence_min_px, coherence_sigmas · σ · radius_scale) is dropped. It
  // removes the pairs the cues let through when a feature's true partner was not detected
  // (a near neighbour that looks alike), also when the prediction itself is off (the
  // neighbours share its error). Measured on l_hallway (match-eval, texture seeds 7 and 3,
  // strides 1-8): precision 0.989-0.994 -> 0.990-0.998 at the same recall.
  double coherence_sigmas = 0.6;  // the tolerance in units of the gate's σ (0.6 · 10 px · 0.5
                                  // = 3 px around the motion prior); 0 = no coherence test,
                                  // >= 0
  double coherence_min_px = 2.0;  // the tolerance never falls below this (pixels), >= 0
  double coherence_radius_px = 60.0;  // neighbours: matches whose previous features lie within
                                      // this of the match's (pixels), > 0
  int coherence_neighbours = 6;       // at most this many, the nearest; a match with fewer than
                                      // two neighbours is kept, >= 2

  bool IsValid(std::string* error) const;
};

// kNccMutual (Nistér, Naroditsky & Bergen 2004), ncc_mutual_matcher.h.
struct NccMutualMatcherOptions {
  double search_radius_px = 30.0;  // candidates within this image distance (pixels), > 0
  double min_score = 0.85;         // accept only C >= this (eq. (2) scale, [0, 1]; 0.85 is
                                   // ρ >= 0.7)

  bool IsValid(std::string* error) const;
};

// kLucasKanade (Bouguet's pyramidal LK, cv::calcOpticalFlowPyrLK), lk_matcher.h.
struct LucasKanadeMatcherOptions {
  int window_px = 21;                  // LK integration window side (pixels), odd, >= 5
  int max_level = 3;                   // pyramid levels above the image, 0..8
  int max_iterations = 30;             // per-level iteration limit, >= 1
  double epsilon_px = 0.01;            // per-level stop when an update is below this (pixels), > 0
  double min_eig_threshold = 1e-4;     // OpenCV's minimum eigenvalue of the normalised spatial
                                       // gradient matrix; weaker points are lost, >= 0
  double max_fb_error_px = 1.0;        // forward-backward check: the point tracked back must land
                                       // within this of where it started (pixels); <= 0 disables
  double association_radius_px = 2.0;  // a tracked point is associated with the nearest
                                       // current feature within this (pixels), > 0

  bool IsValid(std::string* error) const;
};

// kKalman (Kwolek section VI), kalman_matcher.h.
struct KalmanMatcherOptions {
  double measurement_noise_px = 1.0;      // std of a corner position measurement (pixels), > 0
  double process_noise_px = 2.0;          // std of the per-frame velocity change (pixels/frame),
                                          // white-acceleration model, > 0
  double initial_velocity_std_px = 15.0;  // std of the unknown velocity of a new track
                                          // (pixels/frame), > 0
  double gate_chi2 = 9.21;  // position gate on the Mahalanobis d² (χ², 2 dof; 9.21 = 99 %)
  double max_search_radius_px = 60.0;  // hard cap of the candidate search (pixels), > 0
  int gradient_window_px = 5;          // the gradient vector of a corner is the mean Sobel gradient
                                       // over this window (pixels), odd, >= 3
  double gradient_noise = 8.0;         // std of a gradient measurement (grey/pixel), > 0
  double gradient_process_noise = 4.0;  // std of the per-frame gradient change (grey/pixel), > 0
  double min_ncc = 0.85;   // candidates need C >= this (eq. (2) scale; 0.85 is ρ >= 0.7),
                           // [0, 1]
  double ncc_scale = 0.1;  // the NCC term is ((1 − C) / ncc_scale)², > 0
  double max_cost = 6.0;   // accept an assignment only when the summed cost (position +
                           // gradient + NCC terms, each a squared normalised deviation)
                           // is <= this, > 0

  bool IsValid(std::string* error) const;
};

// kSiftRatio (Lowe 2004), sift_ratio_matcher.h.
struct SiftRatioMatcherOptions {
  double ratio = 0.8;             // Lowe's ratio: accept when d1 < ratio · d2, in (0, 1]
  bool mutual = true;             // also require prev to be the current feature's nearest neighbour
  double search_radius_px = 0.0;  // only candidates within this image distance (pixels);
                                  // 0 = the whole image, >= 0

  bool IsValid(std::string* error) const;
};

struct MatcherOptions {
  MatcherType type = MatcherType::kSvdNccGabor;  // which matcher CreateFrameMatcher builds
  PredictionMode prediction = PredictionMode::kMotionPrior;  // where the pipeline centres the
                                                             // position gates (read by
                                                             // StereoOdometry, not the matchers)
  NccOptions ncc;      // NCC cue: kSvdNcc, kSvdNccGabor, kNccMutual, kKalman
  GaborOptions gabor;  // Gabor phase cue: kSvdNccGabor
  SvdMatcherOptions svd;
  NccMutualMatcherOptions ncc_mutual;
  LucasKanadeMatcherOptions lucas_kanade;
  KalmanMatcherOptions kalman;
  SiftRatioMatcherOptions sift_ratio;

  bool IsValid(std::string* error) const;  // checks the parts the chosen type uses
};

// Factory on options.type. Returns nullptr (and fills *error when given) for invalid options.
std::unique_ptr<FrameMatcher> CreateFrameMatcher(const MatcherOptions& options,
                                                 std::string* error = nullptr);

// ---- Helpers shared by the matchers (and useful to tests) ---------------------------------

// Uniform-grid (bucket) spatial index over 2D points, for radius queries without n² work.
class PointGrid {
 public:
  // Indexes a copy of `points` (pixels) with square cells of side cell_px (> 0).
  PointGrid(std::vector<Eigen::Vector2d> points, double cell_px);

  // Calls fn(index, squared_distance_px2) for every point within radius_px of `center`; the
  // order is deterministic (cell by cell, ascending index within a cell).
  template <typename Fn>
  void ForEachWithin(const Eigen::Vector2d& center, double radius_px, Fn&& fn) const {
    if (points_.empty()) return;
    const double r2 = radius_px * radius_px;
    const int cx0 = std::max(0, CellOf(center.x() - radius_px, min_x_, cols_));
    const int cx1 = std::min(cols_ - 1, CellOf(center.x() + radius_px, min_x_, cols_));
    const int cy0 = std::max(0, CellOf(center.y() - radius_px, min_y_, rows_));
    const int cy1 = std::min(rows_ - 1, CellOf(center.y() + radius_px, min_y_, rows_));
    for (int cy = cy0; cy <= cy1; ++cy) {
      for (int cx = cx0; cx <= cx1; ++cx) {
        const int cell = cy * cols_ + cx;
        for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
          const int idx = order_[k];
          const double d2 = (points_[idx] - center).squaredNorm();
          if (d2 <= r2) fn(idx, d2);
        }
      }
    }
  }

  int size() const { return static_cast<int>(points_.size()); }

 private:
  // Cell index of a coordinate, clamped to [−1, n] (outside cells are skipped by callers).
  int CellOf(double v, double v0, int n) const {
    const double c = std::floor((v - v0) / cell_px_);
    return c < -1.0 ? -1 : (c > n ? n : static_cast<int>(c));
  }

  std::vector<Eigen::Vector2d> points_;
  double cell_px_ = 1.0;
  double min_x_ = 0.0, min_y_ = 0.0;
  int cols_ = 0, rows_ = 0;
  std::vector<int> cell_start_;  // cols_·rows_ + 1 offsets into order_
  std::vector<int> order_;       // point indices sorted by cell (stable)
};

// Positions of a feature vector.
std::vector<Eigen::Vector2d> FeaturePositions(const std::vector<Feature>& features);

// Motion coherence: neighbouring features move alike. For each match m (prev i → curr j) the
// displacement r_m = uv_curr(j) − centre(i) (the prediction's centre, else uv_prev(i)) is
// compared with the per-axis median of r over the (up to) `neighbours` nearest other matches
// whose previous features lie within `radius_px` of uv_prev(i) (nearest first, ties by match
// order); a match with |r_m − median| > max_px is dropped, one with fewer than two neighbours
// kept. The medians include the dropped matches (a robust statistic; one pass, no
// iteration). Returns the kept matches in their input order and sets *num_rejected (may be
// null). Deterministic. The neighbours come from one sweep over the matches sorted by x, which
// stops once |dx| exceeds the k-th distance so far: about O(n · k) for n matches spread over
// the image (~15 µs for 120).
std::vector<Match> RejectIncoherentMatches(const std::vector<Feature>& prev,
                                           const std::vector<Feature>& curr,
                                           const MatchPrediction& prediction,
                                           const std::vector<Match>& matches, double radius_px,
                                           int neighbours, double max_px, int* num_rejected);

// A scored candidate pair for greedy assignment.
struct CandidatePair {
  int prev = -1;
  int curr = -1;
  double cost = 0.0;  // smaller = better
};

// Greedy one-to-one assignment: candidates in ascending cost (ties: prev, then curr), each
// taken when neither side is taken yet. Returns matches sorted by prev, score = score_of(cost).
std::vector<Match> GreedyOneToOne(std::vector<CandidatePair> candidates,
                                  const std::function<double(double)>& score_of);

// True when both frames hold a non-empty CV_8UC1 image (what the image-based matchers need).
bool BothGreyImages(const MatchFrame& prev, const MatchFrame& curr);

// True when no prev index and no curr index appears twice.
bool IsOneToOne(const std::vector<Match>& matches);

// Wall-clock milliseconds since t0 (a MatcherSummary's cue_time_ms and match_time_ms).
double MsSince(std::chrono::steady_clock::time_point t0);

// A matcher's constructor check: unless `valid`, prints "vo::<matcher>: invalid options:
// <error>" and aborts (options reach a matcher checked; bad ones here are a programming error).
void AbortUnlessValid(const char* matcher, bool valid, const std::string& error);

}  // namespace vo
