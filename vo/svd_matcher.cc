#include "vo/svd_matcher.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>

namespace vo {
namespace {

// The guard's first bound when min_entry is 0 (a multiplicative raise needs a start).
constexpr double kGuardStartEntry = 1e-4;

// Eigenvalues of the Gram matrix below this fraction of the largest (singular values below
// 1e-6 of the largest) count as zero. Above it the eigenvectors are accurate to ~1e-4 (double
// precision over the squared condition number), far below what moves a row/column maximum.
constexpr double kGramRankTol = 1e-12;

// P = U Vᵀ of a dense block (S → I, Scott & Longuet-Higgins): the orthogonal factor of G,
// from the Gram matrix of the smaller side (a symmetric eigensolver, ~3× faster than an SVD
// of the same size): for a tall G, GᵀG = V S² Vᵀ and P = G V S⁻¹ Vᵀ; for a wide one,
// G Gᵀ = U S² Uᵀ and P = U S⁻¹ Uᵀ G. For a rank-deficient block S → I is applied to the
// nonzero singular values only, P = G (GᵀG)^{+½}: unique, where a full SVD would pair the
// left and right null vectors arbitrarily (implementation-defined). *rank = their number.
Eigen::MatrixXd OrthogonalFactor(const Eigen::MatrixXd& G, int jacobi_max_size, int* rank,
                                 bool* used_svd) {
  *used_svd = false;
  if (G.rows() == 1 || G.cols() == 1) {
    // A single row/column: U = ±1, V = g/|g| (or the transpose): P = g / |g|.
    const double norm = G.norm();
    *rank = norm > 0.0 ? 1 : 0;
    return norm > 0.0 ? Eigen::MatrixXd(G / norm) : Eigen::MatrixXd(G);
  }
  const bool tall = G.rows() >= G.cols();
  const Eigen::MatrixXd gram =
      tall ? Eigen::MatrixXd(G.transpose() * G) : Eigen::MatrixXd(G * G.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);
  if (eig.info() == Eigen::Success) {
    const Eigen::VectorXd& lambda = eig.eigenvalues();  // ascending
    const double floor = kGramRankTol * lambda(lambda.size() - 1);
    Eigen::VectorXd inv_s(lambda.size());
    *rank = 0;
    for (Eigen::Index k = 0; k < lambda.size(); ++k) {
      const bool nonzero = lambda(k) > floor;
      inv_s(k) = nonzero ? 1.0 / std::sqrt(lambda(k)) : 0.0;
      *rank += nonzero ? 1 : 0;
    }
    const Eigen::MatrixXd& Q = eig.eigenvectors();
    const Eigen::MatrixXd W = Q * inv_s.asDiagonal() * Q.transpose();
    return tall ? Eigen::MatrixXd(G * W) : Eigen::MatrixXd(W * G);
  }
  // The eigensolver did not converge (not seen in practice): a full SVD.
  *used_svd = true;
  *rank = static_cast<int>(std::min(G.rows(), G.cols()));
  if (std::min(G.rows(), G.cols()) <= jacobi_max_size) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeThinU | Eigen::ComputeThinV);
    return svd.matrixU() * svd.matrixV().transpose();
  }
  Eigen::BDCSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeThinU | Eigen::ComputeThinV);
  return svd.matrixU() * svd.matrixV().transpose();
}

// Mutual row/column maxima of P with the minimum-weight acceptance. Ties go to the smaller
// index. Appends (row_ids[a], col_ids[b], P_ab) matches.
void AcceptMutualMaxima(const Eigen::MatrixXd& P, const Eigen::MatrixXd& G,
                        const SvdAcceptMatrix* acceptable, const std::vector<int>& row_ids,
                        const std::vector<int>& col_ids, const SvdMatcherOptions& options,
                        std::vector<Match>* matches) {
  const int r = static_cast<int>(P.rows()), c = static_cast<int>(P.cols());
  std::vector<int> col_best(c, 0);
  for (int b = 0; b < c; ++b) {
    int best = 0;
    for (int a = 1; a < r; ++a) {
      if (P(a, b) > P(best, b)) best = a;
    }
    col_best[b] = best;
  }
  for (int a = 0; a < r; ++a) {
    int best = 0;
    for (int b = 1; b < c; ++b) {
      if (P(a, b) > P(a, best)) best = b;
    }
    if (col_best[best] != a) continue;               // not the max of its column
    if (G(a, best) < options.min_weight) continue;   // minimum-weight acceptance
    if (P(a, best) < options.min_pairing) continue;  // weak pairing
    if (!(G(a, best) > 0.0)) continue;               // never pair through a zero entry
    if (acceptable != nullptr && !(*acceptable)(a, best)) continue;  // cue thresholds
    matches->push_back(Match{row_ids[a], col_ids[best], P(a, best)});
  }
}

// Union-find with path halving.
int FindRoot(std::vector<int>& parent, int x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

}  // namespace

std::vector<Match> SvdPairSparse(int rows, int cols, std::vector<SvdEntry> entries,
                                 const SvdMatcherOptions& options, MatcherSummary* summary) {
  for (const SvdEntry& e : entries) {
    if (e.row < 0 || e.row >= rows || e.col < 0 || e.col >= cols) {
      std::fprintf(stderr, "vo::SvdPairSparse: entry (%d, %d) outside a %d x %d matrix\n", e.row,
                   e.col, rows, cols);
      std::abort();
    }
  }
  std::vector<Match> matches;
  int num_components = 0, largest = 0, guard_splits = 0, num_svd = 0, num_rank_deficient = 0;
  // Drop entries below the bound (step 2).
  entries.erase(std::remove_if(entries.begin(), entries.end(),
                               [&](const SvdEntry& e) {
                                 return !(e.value > 0.0) || e.value < options.min_entry;
                               }),
                entries.end());

  // Work items: a set of entries and the bound they were filtered with. The guard pushes
  // re-filtered sub-problems.
  struct Work {
    std::vector<SvdEntry> entries;
    double bound;
  };
  std::vector<Work> stack;
  stack.push_back(Work{std::move(entries), options.min_entry});

  // Node ids: rows 0..rows−1, columns rows..rows+cols−1.
  const size_t num_rows = static_cast<size_t>(std::max(rows, 0));
  const size_t num_cols = static_cast<size_t>(std::max(cols, 0));
  std::vector<int> parent(num_rows + num_cols, 0);
  std::vector<int> comp_of_root(num_rows + num_cols, -1);
  std::vector<int> local_row(num_rows, -1), local_col(num_cols, -1);
  while (!stack.empty()) {
    Work work = std::move(stack.back());
    stack.pop_back();
    // Step 3: connected components of the bipartite graph (union-find).
    for (const SvdEntry& e : work.entries) {
      parent[e.row] = e.row;
      parent[rows + e.col] = rows + e.col;
    }
    for (const SvdEntry& e : work.entries) {
      const int a = FindRoot(parent, e.row), b = FindRoot(parent, rows + e.col);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
    std::vector<std::vector<SvdEntry>> components;
    for (const SvdEntry& e : work.entries) {
      const int root = FindRoot(parent, e.row);
      if (comp_of_root[root] < 0) {
        comp_of_root[root] = static_cast<int>(components.size());
        components.emplace_back();
      }
      components[comp_of_root[root]].push_back(e);
    }
    for (const SvdEntry& e : work.entries) comp_of_root[FindRoot(parent, e.row)] = -1;

    for (std::vector<SvdEntry>& comp : components) {
      // Rows and columns of the component, ascending (canonical block, index tie-breaks).
      std::vector<int> row_ids, col_ids;
      for (const SvdEntry& e : comp) {
        if (local_row[e.row] < 0) {
          local_row[e.row] = 0;
          row_ids.push_back(e.row);
        }
        if (local_col[e.col] < 0) {
          local_col[e.col] = 0;
          col_ids.push_back(e.col);
        }
      }
      std::sort(row_ids.begin(), row_ids.end());
      std::sort(col_ids.begin(), col_ids.end());
      for (size_t a = 0; a < row_ids.size(); ++a) local_row[row_ids[a]] = static_cast<int>(a);
      for (size_t b = 0; b < col_ids.size(); ++b) local_col[col_ids[b]] = static_cast<int>(b);
      const int size = static_cast<int>(row_ids.size() + col_ids.size());

      if (size > options.max_component_size && work.bound < options.guard_max_entry) {
        // Guard: raise the bound inside this component and split it again.
        const double bound =
            std::min(options.guard_max_entry,
                     work.bound > 0.0 ? work.bound * options.guard_growth : kGuardStartEntry);
        Work sub{{}, bound};
        for (const SvdEntry& e : comp) {
          if (e.value >= bound) sub.entries.push_back(e);
        }
        ++guard_splits;
        for (int id : row_ids) local_row[id] = -1;
        for (int id : col_ids) local_col[id] = -1;
        stack.push_back(std::move(sub));
        continue;
      }

      // Step 4: dense SVD of the block, then the mutual maxima inside it.
      Eigen::MatrixXd G = Eigen::MatrixXd::Zero(row_ids.size(), col_ids.size());
      SvdAcceptMatrix acceptable = SvdAcceptMatrix::Zero(row_ids.size(), col_ids.size());
      for (const SvdEntry& e : comp) {
        G(local_row[e.row], local_col[e.col]) = e.value;
        acceptable(local_row[e.row], local_col[e.col]) = e.acceptable ? 1 : 0;
      }
      bool used_svd = false;
      int rank = 0;
      const Eigen::MatrixXd P = OrthogonalFactor(G, options.jacobi_max_size, &rank, &used_svd);
      num_svd += used_svd ? 1 : 0;
      num_rank_deficient += rank < std::min(G.rows(), G.cols()) ? 1 : 0;
      AcceptMutualMaxima(P, G, &acceptable, row_ids, col_ids, options, &matches);
      ++num_components;
      largest = std::max(largest, size);
      for (int id : row_ids) local_row[id] = -1;
      for (int id : col_ids) local_col[id] = -1;
    }
  }
  std::sort(matches.begin(), matches.end(),
            [](const Match& a, const Match& b) { return a.prev < b.prev; });
  if (summary != nullptr) {
    summary->num_components = num_components;
    summary->largest_component = largest;
    summary->num_guard_splits = guard_splits;
    summary->num_svd_fallbacks = num_svd;
    summary->num_rank_deficient = num_rank_deficient;
  }
  return matches;
}

std::vector<Match> SvdPairDense(const Eigen::MatrixXd& G, const SvdMatcherOptions& options,
                                const SvdAcceptMatrix* acceptable) {
  std::vector<Match> matches;
  if (G.rows() == 0 || G.cols() == 0) return matches;
  // G = U S Vᵀ, S → I: P = U Vᵀ (one BDCSVD of the whole matrix, as in the paper).
  Eigen::BDCSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::MatrixXd P = svd.matrixU() * svd.matrixV().transpose();
  std::vector<int> row_ids(G.rows()), col_ids(G.cols());
  std::iota(row_ids.begin(), row_ids.end(), 0);
  std::iota(col_ids.begin(), col_ids.end(), 0);
  AcceptMutualMaxima(P, G, acceptable, row_ids, col_ids, options, &matches);
  return matches;
}

SvdMatcher::SvdMatcher(const Options& options, Cues cues, const NccOptions& ncc,
                       const GaborOptions& gabor)
    : options_(options), cues_(cues), ncc_(ncc) {
  std::string error;
  const bool valid =
      options_.IsValid(&error) && (cues_ == Cues::kProximity || ncc_.IsValid(&error));
  AbortUnlessValid("SvdMatcher", valid, error);
  if (cues_ == Cues::kProximityNccGabor) bank_ = std::make_unique<GaborBank>(gabor);
}

MatcherType SvdMatcher::type() const {
  switch (cues_) {
    case Cues::kProximity:
      return MatcherType::kSvdProximity;
    case Cues::kProximityNcc:
      return MatcherType::kSvdNcc;
    case Cues::kProximityNccGabor:
      break;
  }
  return MatcherType::kSvdNccGabor;
}

std::vector<Match> SvdMatcher::DoMatch(const MatchFrame& prev, const MatchFrame& curr,
                                       const MatchPrediction& prediction, MatcherSummary* summary) {
  MatcherSummary& s = *summary;
  const bool use_ncc = cues_ != Cues::kProximity;
  const bool use_gabor = cues_ == Cues::kProximityNccGabor;
  if (use_ncc && (prev.image.empty() || curr.image.empty() || prev.image.type() != CV_8UC1 ||
                  curr.image.type() != CV_8UC1)) {
    s.ok = false;
    s.message = "SvdMatcher: the NCC/Gabor cues need CV_8UC1 images in both frames";
    return {};
  }

  // Per-frame cues (cached in the frames).
  auto t0 = std::chrono::steady_clock::now();
  const NccPatches* ncc_prev = use_ncc ? &FrameNccPatches(prev, ncc_) : nullptr;
  const NccPatches* ncc_curr = use_ncc ? &FrameNccPatches(curr, ncc_) : nullptr;
  const GaborResponses* gabor_prev = use_gabor ? &FrameGaborResponses(prev, *bank_) : nullptr;
  const GaborResponses* gabor_curr = use_gabor ? &FrameGaborResponses(curr, *bank_) : nullptr;
  s.cue_time_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();

  // The proximity term and the candidate radius are centred on the predicted position of each
  // previous feature (its previous position without a prediction), σ scaled with the gate.
  const double sigma = options_.sigma_px * prediction.radius_scale;
  const double inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
  const double min_ncc = use_gabor ? options_.gabor_min_ncc : options_.min_ncc;
  const double min_phase_similarity =
      use_gabor ? std::exp(-bank_->options().phase_exponent * options_.max_phase_diff_rad) : 0.0;
  // G_ij of one pair: proximity × C_ij (eq. (1)) × S_ij (eq. (5)); stops early (returns 0)
  // once below `bound` (the factors are <= 1, so later ones cannot raise it). *acceptable:
  // the cue thresholds min_ncc / max_phase_diff_rad hold.
  auto weight = [&](int i, int j, double d2, double bound, bool* acceptable) {
    *acceptable = true;
    double g = std::exp(-d2 * inv_two_sigma2);  // proximity: exp(−d²/2σ²)
    if (g < bound) return 0.0;
    if (use_ncc) {
      const double c = ncc_prev->Score(i, *ncc_curr, j);  // eq. (2)
      *acceptable = c >= min_ncc;
      g *= c;
      if (g < bound || g <= 0.0) return 0.0;
    }
    if (use_gabor) {
      const double phase = GaborPhaseSimilarity(*gabor_prev, i, *gabor_curr, j);  // eq. (5)
      *acceptable = *acceptable && phase >= min_phase_similarity;
      g *= phase;
    }
    return g;
  };

  std::vector<Match> matches;
  if (options_.dense) {
    // Reference: all n×m pairs, no cutoff, no dropping.
    Eigen::MatrixXd G(s.num_prev, s.num_curr);
    SvdAcceptMatrix acceptable(s.num_prev, s.num_curr);
    for (int i = 0; i < s.num_prev; ++i) {
      for (int j = 0; j < s.num_curr; ++j) {
        bool ok = true;
        G(i, j) = weight(
            i, j,
            (prediction.Centre(i, prev.features[i].uv_px) - curr.features[j].uv_px).squaredNorm(),
            0.0, &ok);
        acceptable(i, j) = ok ? 1 : 0;
      }
    }
    s.num_candidates = s.num_prev * s.num_curr;
    s.num_components = 1;
    s.largest_component = s.num_prev + s.num_curr;
    matches = SvdPairDense(G, options_, &acceptable);
  } else {
    // Step 1: candidates within the cutoff radius, from a grid over the current features.
    const double radius = options_.cutoff_sigmas * sigma;
    const PointGrid grid(FeaturePositions(curr.features), radius);
    std::vector<SvdEntry> entries;
    entries.reserve(static_cast<size_t>(s.num_prev) * 8);
    for (int i = 0; i < s.num_prev; ++i) {
      grid.ForEachWithin(prediction.Centre(i, prev.features[i].uv_px), radius,
                         [&](int j, double d2) {
                           ++s.num_candidates;
                           bool ok = true;
                           const double g = weight(i, j, d2, options_.min_entry, &ok);
                           if (g > 0.0 && g >= options_.min_entry)
                             entries.push_back(SvdEntry{i, j, g, ok});
                         });
    }
    matches = SvdPairSparse(s.num_prev, s.num_curr, std::move(entries), options_, &s);
  }
  if (options_.coherence_sigmas > 0.0 && prediction.coherence_test) {
    const double max_px = std::max(options_.coherence_min_px, options_.coherence_sigmas * sigma);
    matches = RejectIncoherentMatches(prev.features, curr.features, prediction, matches,
                                      options_.coherence_radius_px, options_.coherence_neighbours,
                                      max_px, &s.num_incoherent);
  }
  s.match_time_ms = MsSince(t0);
  s.num_matches = static_cast<int>(matches.size());
  return matches;
}

}  // namespace vo
