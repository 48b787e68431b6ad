// SVD correspondence of Scott & Longuet-Higgins ("An algorithm for associating the features of
// two images", Proc. R. Soc. B 1991) with the similarity cues of Kwolek, section III:
//
//   G_ij = exp(−d_ij² / 2σ²)                         kProximity         (III-A)
//   G_ij = C_ij · exp(−d_ij² / 2σ²)                  kProximityNcc      eq. (1), C from eq. (2)
//   G_ij = C_ij · S_ij · exp(−d_ij² / 2σ²)           kProximityNccGabor III-C, S from eq. (5)
//
// d_ij = image distance between previous feature i and current feature j (pixels). Then
// G = U S Vᵀ, S → I, P = U Vᵀ (the orthogonal factor of G), and i↔j is a match iff P_ij is the
// largest element of its row AND of its column, plus the minimum-weight acceptance
// G_ij >= min_weight and P_ij >= min_pairing (an outlier with no true partner stays
// unmatched). Beyond the paper, the appearance cues must also pass their own thresholds:
// C_ij >= min_ncc (kProximityNcc; gabor_min_ncc for kProximityNccGabor) and a mean wrapped
// phase difference <= max_phase_diff_rad, i.e. S_ij >= exp(−β · max_phase_diff_rad)
// (kProximityNccGabor).
// G mixes proximity in, so a feature whose true partner was not detected is otherwise paired
// with a near neighbour that merely looks unlike it; the cue thresholds remove most of these
// (set them to 0 and π for the paper's rule alone). They do not change G or P. Then the
// motion-coherence test (RejectIncoherentMatches, matcher.h; coherence_sigmas = 0 turns it
// off) drops a match that moves unlike its neighbouring matches.
// Match::score = P_ij.
//
// Sparse solution (the default). The Gaussian makes G nearly block-diagonal, so:
//   1. candidate pairs come from a grid index over the current features within
//      cutoff_sigmas·σ; the cues (NCC, Gabor) are evaluated only for those pairs;
//   2. entries below min_entry are dropped;
//   3. the bipartite graph of the remaining entries is split into connected components
//      (union-find); rows/columns of different components share no entry;
//   4. each block's P is computed densely: closed form for a single row/column, otherwise
//      from the eigen-decomposition of the smaller Gram matrix (GᵀG = V S² Vᵀ,
//      P = G V S⁻¹ Vᵀ; ~3× faster than an SVD), and the row/column maxima are taken inside
//      the block.
// If the dropped entries of G are exactly zero, the SVD of G is the union of the blocks' SVDs
// and this is exact, except where the dense P is not unique anyway: a rank-deficient G, whose
// dense SVD pairs left and right null vectors (possibly of different blocks) arbitrarily.
// Here S → I is applied to the nonzero singular values only (P = G (GᵀG)^{+½}, unique;
// MatcherSummary::num_rank_deficient counts such blocks; singular values below 1e-6 of the
// block's largest count as zero). With the cutoff and min_entry it is an approximation;
// svd_matcher_test measures its agreement with the dense reference on realistic data.
//
// Guard against one huge component (dense texture, large σ, many features): a component with
// more than max_component_size rows + columns has its entry bound raised by guard_growth and
// is split again, repeatedly, up to guard_max_entry; what is left above that is solved densely.
// Raising the bound only drops weak entries (below min_weight these cannot be accepted as
// matches anyway, but they do influence P); MatcherSummary::num_guard_splits counts the raises.
// With the appearance cues the guard rarely acts (wrong pairs have small G); with proximity
// alone and features denser than σ the graph percolates and the guarded result departs more
// from the dense one (Jaccard 0.75–0.97 in the tests' scenes, precision within 0.02, and
// worse for σ well above the feature spacing).
//
// Options::dense = true is the reference: G over all pairs and one BDCSVD of the n×m matrix.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "vo/gabor.h"
#include "vo/matcher.h"
#include "vo/ncc.h"

namespace vo {

class SvdMatcher : public FrameMatcher {
 public:
  using Options = SvdMatcherOptions;
  enum class Cues {
    kProximity,          // Scott & Longuet-Higgins: proximity only; needs no image
    kProximityNcc,       // eq. (1)
    kProximityNccGabor,  // proximity × NCC × Gabor phase similarity (the paper's method)
  };

  // Options must be valid (CreateFrameMatcher checks them).
  SvdMatcher(const Options& options, Cues cues, const NccOptions& ncc = NccOptions(),
             const GaborOptions& gabor = GaborOptions());

  MatcherType type() const override;

  const Options& options() const { return options_; }
  Cues cues() const { return cues_; }

 protected:
  std::vector<Match> DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                             const MatchPrediction& prediction, MatcherSummary* summary) override;

 private:
  Options options_;
  Cues cues_;
  NccOptions ncc_;
  std::unique_ptr<GaborBank> bank_;  // only for kProximityNccGabor
};

// One nonzero entry of a sparse G.
struct SvdEntry {
  int row = -1;            // previous feature
  int col = -1;            // current feature
  double value = 0.0;      // G_ij, >= 0
  bool acceptable = true;  // false: the pair may shape P but never be returned as a match
};

// Per-pair "acceptable" flags of a dense G (1 = may be returned as a match).
using SvdAcceptMatrix = Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic>;

// The pairing step on a sparse G (rows × cols, absent entries are 0), by connected components
// with the size guard; uses min_entry, min_weight, min_pairing, max_component_size,
// guard_growth, guard_max_entry, jacobi_max_size. Fills the component fields of *summary
// (may be null). Returns one-to-one matches sorted by row, score = P_ij.
std::vector<Match> SvdPairSparse(int rows, int cols, std::vector<SvdEntry> entries,
                                 const SvdMatcherOptions& options, MatcherSummary* summary);

// The dense reference: one BDCSVD of the whole G; uses min_weight and min_pairing, and the
// flags of `acceptable` when not null (same shape as G).
std::vector<Match> SvdPairDense(const Eigen::MatrixXd& G, const SvdMatcherOptions& options,
                                const SvdAcceptMatrix* acceptable = nullptr);

}  // namespace vo
