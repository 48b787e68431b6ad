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
// unmatched). Match::score = P_ij.
//
// Sparse solution (the default). The Gaussian makes G nearly block-diagonal, so:
//   1. candidate pairs come from a grid index over the current features within
//      cutoff_sigmas·σ; the cues (NCC, Gabor) are evaluated only for those pairs;
//   2. entries below min_entry are dropped;
//   3. the bipartite graph of the remaining entries is split into connected components
//      (union-find); rows/columns of different components share no entry;
//   4. each component's block is solved by a small dense SVD (closed form for a single
//      row/column, JacobiSVD up to jacobi_max_size, BDCSVD above), and the row/column maxima
//      are taken inside the block.
// If G has exactly the dropped entries equal to zero, the SVD of G is the union of the blocks'
// SVDs and this is exact, up to degenerate cases where the dense P is not unique anyway (rank
// deficient G: the dense SVD pairs null vectors of different blocks arbitrarily). With the
// cutoff and min_entry it is an approximation; svd_matcher_test measures its agreement with
// the dense reference on realistic data.
//
// Guard against one huge component (dense texture, large σ, many features): a component with
// more than max_component_size rows + columns has its entry bound raised by guard_growth and
// is split again, repeatedly, up to guard_max_entry; what is left above that is solved densely.
// Raising the bound only drops weak entries (below min_weight these cannot be accepted as
// matches anyway, but they do influence P); MatcherSummary::num_guard_splits counts the raises.
//
// Options::dense = true is the reference: G over all pairs and one BDCSVD of the n×m matrix.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

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

  std::vector<Match> MatchFrames(const MatchFrame& prev, const MatchFrame& curr,
                                 MatcherSummary* summary = nullptr) override;
  MatcherType type() const override;

  const Options& options() const { return options_; }
  Cues cues() const { return cues_; }

 private:
  Options options_;
  Cues cues_;
  NccOptions ncc_;
  std::unique_ptr<GaborBank> bank_;  // only for kProximityNccGabor
};

// One nonzero entry of a sparse G.
struct SvdEntry {
  int row = -1;  // previous feature
  int col = -1;  // current feature
  double value = 0.0;  // G_ij, >= 0
};

// The pairing step on a sparse G (rows × cols, absent entries are 0), by connected components
// with the size guard; uses min_entry, min_weight, min_pairing, max_component_size,
// guard_growth, guard_max_entry, jacobi_max_size. Fills the component fields of *summary
// (may be null). Returns one-to-one matches sorted by row, score = P_ij.
std::vector<Match> SvdPairSparse(int rows, int cols, std::vector<SvdEntry> entries,
                                 const SvdMatcherOptions& options, MatcherSummary* summary);

// The dense reference: one BDCSVD of the whole G; uses min_weight and min_pairing.
std::vector<Match> SvdPairDense(const Eigen::MatrixXd& G, const SvdMatcherOptions& options);

}  // namespace vo
