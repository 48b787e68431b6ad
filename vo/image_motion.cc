#include "vo/image_motion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <opencv2/core/check.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

namespace vo {
namespace {

constexpr int kMinImageSidePx = 8;     // smallest accepted input, and smallest pyramid level side
constexpr double kMinVariance = 1e-2;  // grey levels² per pixel: below this an overlap is flat
                                       // and its ZNCC undefined (the shift is not scored)
constexpr int kMaxRecentre = 4;     // window re-centrings per finer level while the best is on its
                                    // border
constexpr int kLanes = 16;          // independent partial sums: lets the compiler vectorise
constexpr int kChunk = 16384;       // products per int32 partial sum: 255² · 16384 < 2^31
constexpr double kUnscored = -2.0;  // below any ZNCC

// Exact Σ a[i]·b[i] of two byte rows.
inline int64_t DotU8(const uint8_t* a, const uint8_t* b, int n) {
  int64_t total = 0;
  int x = 0;
  while (x < n) {
    const int end = std::min(n, x + kChunk);
    int32_t acc[kLanes] = {};
    for (; x + kLanes <= end; x += kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        acc[l] += static_cast<int32_t>(a[x + l]) * static_cast<int32_t>(b[x + l]);
      }
    }
    int32_t chunk = 0;
    for (; x < end; ++x) chunk += static_cast<int32_t>(a[x]) * static_cast<int32_t>(b[x]);
    total += chunk;
    for (int l = 0; l < kLanes; ++l) total += acc[l];
  }
  return total;
}

// Exact Σ a[i] and Σ a[i]² of a byte row, added to *sum and *sq.
inline void SumU8(const uint8_t* a, int n, int64_t* sum, int64_t* sq) {
  int x = 0;
  while (x < n) {
    const int end = std::min(n, x + kChunk);
    int32_t s[kLanes] = {}, q[kLanes] = {};
    for (; x + kLanes <= end; x += kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        const int32_t v = a[x + l];
        s[l] += v;
        q[l] += v * v;
      }
    }
    for (; x < end; ++x) {
      const int32_t v = a[x];
      *sum += v;
      *sq += v * v;
    }
    for (int l = 0; l < kLanes; ++l) *sum += s[l], *sq += q[l];
  }
}

// Integral images of v and v² restricted to a few column boundaries: entry (y, i) is the sum
// over rows < y and columns < xs[i]. With every column as a boundary this is the ordinary
// integral image; at the finer levels only the edges of the (2r+1)² overlaps are needed, so
// building it costs one pass over the image and (h + 1) × (few) entries of memory.
class BoxTable {
 public:
  // `xs`: column boundaries in [0, image.cols], any order, duplicates allowed.
  void Build(const cv::Mat& image, std::vector<int> xs) {
    std::sort(xs.begin(), xs.end());
    xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
    k_ = static_cast<int>(xs.size());
    index_.assign(image.cols + 1, -1);
    for (int i = 0; i < k_; ++i) index_[xs[i]] = i;
    sum_.assign(static_cast<size_t>(image.rows + 1) * k_, 0);
    sq_.assign(static_cast<size_t>(image.rows + 1) * k_, 0);
    for (int y = 0; y < image.rows; ++y) {
      const uint8_t* row = image.ptr<uint8_t>(y);
      const int64_t* s_up = sum_.data() + static_cast<size_t>(y) * k_;
      const int64_t* q_up = sq_.data() + static_cast<size_t>(y) * k_;
      int64_t* s = sum_.data() + static_cast<size_t>(y + 1) * k_;
      int64_t* q = sq_.data() + static_cast<size_t>(y + 1) * k_;
      int64_t row_s = 0, row_q = 0;
      int x = 0;
      for (int i = 0; i < k_; ++i) {
        SumU8(row + x, xs[i] - x, &row_s, &row_q);
        x = xs[i];
        s[i] = s_up[i] + row_s;
        q[i] = q_up[i] + row_q;
      }
    }
  }

  bool Has(int x) const { return x >= 0 && x < static_cast<int>(index_.size()) && index_[x] >= 0; }

  // Σ v and Σ v² over [x0, x1) × [y0, y1); x0 and x1 must be boundaries.
  void Box(int x0, int x1, int y0, int y1, double* s, double* ss) const {
    const size_t a = static_cast<size_t>(y0) * k_, b = static_cast<size_t>(y1) * k_;
    const int i0 = index_[x0], i1 = index_[x1];
    *s = static_cast<double>(sum_[b + i1] - sum_[b + i0] - sum_[a + i1] + sum_[a + i0]);
    *ss = static_cast<double>(sq_[b + i1] - sq_[b + i0] - sq_[a + i1] + sq_[a + i0]);
  }

 private:
  int k_ = 0;
  std::vector<int> index_;  // column → boundary index, or −1
  std::vector<int64_t> sum_, sq_;
};

// Scores shifts of one pyramid level whose dx lies in a prepared range.
class LevelScorer {
 public:
  LevelScorer(const cv::Mat& prev, const cv::Mat& curr, double min_overlap_fraction)
      : prev_(prev),
        curr_(curr),
        w_(prev.cols),
        h_(prev.rows),
        min_area_(min_overlap_fraction * static_cast<double>(w_) * h_) {}

  // Box tables for every dx in [dx_min, dx_max] (any dy).
  void Prepare(int dx_min, int dx_max) {
    std::vector<int> xp, xc;
    for (int dx = dx_min; dx <= dx_max; ++dx) {
      xp.push_back(std::clamp(-dx, 0, w_));
      xp.push_back(std::clamp(w_ - dx, 0, w_));
      xc.push_back(std::clamp(dx, 0, w_));
      xc.push_back(std::clamp(w_ + dx, 0, w_));
    }
    prev_table_.Build(prev_, std::move(xp));
    curr_table_.Build(curr_, std::move(xc));
  }

  // ZNCC of prev(x) and curr(x + (dx, dy)) over their overlap. False when the overlap is below
  // the minimum area, either side is flat there, or dx was not prepared.
  bool Score(int dx, int dy, double* score) const {
    const int x0 = std::max(0, -dx), x1 = std::min(w_, w_ - dx);
    const int y0 = std::max(0, -dy), y1 = std::min(h_, h_ - dy);
    if (x1 <= x0 || y1 <= y0) return false;
    const int cols = x1 - x0;
    const double n = static_cast<double>(cols) * (y1 - y0);
    if (n < min_area_) return false;
    if (!prev_table_.Has(x0) || !prev_table_.Has(x1)) return false;
    if (!curr_table_.Has(x0 + dx) || !curr_table_.Has(x1 + dx)) return false;

    double sa, saa, sb, sbb;
    prev_table_.Box(x0, x1, y0, y1, &sa, &saa);
    curr_table_.Box(x0 + dx, x1 + dx, y0 + dy, y1 + dy, &sb, &sbb);
    const double var_a = saa - sa * sa / n;
    const double var_b = sbb - sb * sb / n;
    if (!(var_a >= kMinVariance * n) || !(var_b >= kMinVariance * n)) return false;

    int64_t sab = 0;
    for (int y = y0; y < y1; ++y) {
      sab += DotU8(prev_.ptr<uint8_t>(y) + x0, curr_.ptr<uint8_t>(y + dy) + x0 + dx, cols);
    }
    const double cov = static_cast<double>(sab) - sa * sb / n;
    *score = std::clamp(cov / std::sqrt(var_a * var_b), -1.0, 1.0);
    return true;
  }

 private:
  const cv::Mat& prev_;
  const cv::Mat& curr_;
  int w_, h_;
  double min_area_;
  BoxTable prev_table_, curr_table_;
};

// Strict order of candidates: higher score, then smaller dx² + dy², then smaller dx, dy.
inline bool Better(double s, int dx, int dy, double best_s, int best_dx, int best_dy) {
  if (s != best_s) return s > best_s;
  const int n = dx * dx + dy * dy, best_n = best_dx * best_dx + best_dy * best_dy;
  if (n != best_n) return n < best_n;
  if (dx != best_dx) return dx < best_dx;
  return dy < best_dy;
}

// Scores of all shifts in [cx − rx, cx + rx] × [cy − ry, cy + ry] (kUnscored where undefined).
struct Grid {
  int cx = 0, cy = 0, rx = 0, ry = 0;
  std::vector<double> scores;
  int best_dx = 0, best_dy = 0;
  double best = kUnscored;

  bool Inside(int dx, int dy) const { return std::abs(dx - cx) <= rx && std::abs(dy - cy) <= ry; }
  double At(int dx, int dy) const {
    return scores[static_cast<size_t>(dy - cy + ry) * (2 * rx + 1) + (dx - cx + rx)];
  }
  bool found() const { return best > kUnscored; }
};

// Exhaustive search of the window; also prepares `scorer` for dx one beyond it on each side
// (the sub-pixel neighbours).
Grid Search(LevelScorer* scorer, int cx, int cy, int rx, int ry) {
  scorer->Prepare(cx - rx - 1, cx + rx + 1);
  Grid g;
  g.cx = cx, g.cy = cy, g.rx = rx, g.ry = ry;
  g.scores.assign(static_cast<size_t>(2 * rx + 1) * (2 * ry + 1), kUnscored);
  size_t i = 0;
  for (int dy = cy - ry; dy <= cy + ry; ++dy) {
    for (int dx = cx - rx; dx <= cx + rx; ++dx, ++i) {
      double s;
      if (!scorer->Score(dx, dy, &s)) continue;
      g.scores[i] = s;
      if (!g.found() || Better(s, dx, dy, g.best, g.best_dx, g.best_dy)) {
        g.best = s, g.best_dx = dx, g.best_dy = dy;
      }
    }
  }
  return g;
}

// Best score / best other local maximum at Chebyshev distance >= 2 (see the header).
double SecondBestRatio(const Grid& g) {
  if (!(g.best > 0.0)) return 1.0;
  double second = kUnscored;
  for (int dy = g.cy - g.ry; dy <= g.cy + g.ry; ++dy) {
    for (int dx = g.cx - g.rx; dx <= g.cx + g.rx; ++dx) {
      const double s = g.At(dx, dy);
      if (s == kUnscored || s <= second) continue;
      if (std::max(std::abs(dx - g.best_dx), std::abs(dy - g.best_dy)) < 2) continue;
      bool peak = true;
      for (int ny = dy - 1; ny <= dy + 1 && peak; ++ny) {
        for (int nx = dx - 1; nx <= dx + 1; ++nx) {
          if ((nx != dx || ny != dy) && g.Inside(nx, ny) && g.At(nx, ny) > s) {
            peak = false;
            break;
          }
        }
      }
      if (peak) second = s;
    }
  }
  if (!(second > 0.0)) return std::numeric_limits<double>::infinity();
  return g.best / second;
}

// Vertex of the parabola through (−1, sm), (0, s0), (+1, sp); 0 unless it is a maximum.
inline double ParabolaOffset(double sm, double s0, double sp) {
  const double denom = sm - 2.0 * s0 + sp;
  if (!(denom < 0.0)) return 0.0;
  return std::clamp(0.5 * (sm - sp) / denom, -0.5, 0.5);
}

// True when the whole image has a grey-level variance below kMinVariance.
bool IsFlat(const cv::Mat& image) {
  int64_t s = 0, ss = 0;
  for (int y = 0; y < image.rows; ++y) SumU8(image.ptr<uint8_t>(y), image.cols, &s, &ss);
  const double n = static_cast<double>(image.cols) * image.rows;
  const double sd = static_cast<double>(s);
  return !(static_cast<double>(ss) - sd * sd / n >= kMinVariance * n);
}

std::string Describe(const char* what, const cv::Mat& m) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), "%s is %dx%d %s", what, m.cols, m.rows,
                cv::typeToString(m.type()).c_str());
  return buf;
}

ImageShiftResult Fail(ImageShiftResult r, std::string message) {
  r.ok = false;
  r.message = std::move(message);
  return r;
}

}  // namespace

bool ImageShiftOptions::IsValid(std::string* error) const {
  auto fail = [error](const char* message) {
    if (error != nullptr) *error = message;
    return false;
  };
  if (coarsest_max_width_px < 16) {
    return fail("ImageShiftOptions::coarsest_max_width_px must be >= 16");
  }
  if (!(max_shift_fraction_x > 0.0 && max_shift_fraction_x <= 0.9)) {
    return fail("ImageShiftOptions::max_shift_fraction_x must be in (0, 0.9]");
  }
  if (!(max_shift_fraction_y >= 0.0 && max_shift_fraction_y <= 0.9)) {
    return fail("ImageShiftOptions::max_shift_fraction_y must be in [0, 0.9]");
  }
  if (refine_radius_px < 1) return fail("ImageShiftOptions::refine_radius_px must be >= 1");
  if (finest_level < 0) return fail("ImageShiftOptions::finest_level must be >= 0");
  if (!(min_overlap_fraction > 0.0 && min_overlap_fraction <= 1.0)) {
    return fail("ImageShiftOptions::min_overlap_fraction must be in (0, 1]");
  }
  if (!(min_score >= -1.0 && min_score <= 1.0)) {
    return fail("ImageShiftOptions::min_score must be in [-1, 1]");
  }
  return true;
}

ImageShiftResult EstimateImageShift(const cv::Mat& prev, const cv::Mat& curr,
                                    const ImageShiftOptions& options) {
  ImageShiftResult result;
  std::string error;
  if (!options.IsValid(&error)) return Fail(result, "invalid options: " + error);
  if (prev.empty()) return Fail(result, "prev image is empty");
  if (curr.empty()) return Fail(result, "curr image is empty");
  if (prev.type() != CV_8UC1) return Fail(result, "prev must be CV_8UC1: " + Describe("it", prev));
  if (curr.type() != CV_8UC1) return Fail(result, "curr must be CV_8UC1: " + Describe("it", curr));
  if (prev.size() != curr.size()) {
    return Fail(result, "prev and curr differ in size: " + Describe("prev", prev) + ", " +
                            Describe("curr", curr));
  }
  if (prev.cols < kMinImageSidePx || prev.rows < kMinImageSidePx) {
    return Fail(result, "images are too small (need at least 8x8): " + Describe("prev", prev));
  }

  // Pyramids: halve until the width is small enough (or a side would drop below the minimum).
  std::vector<std::pair<cv::Mat, cv::Mat>> pyramid = {{prev, curr}};
  while (pyramid.back().first.cols > options.coarsest_max_width_px &&
         (pyramid.back().first.cols + 1) / 2 >= kMinImageSidePx &&
         (pyramid.back().first.rows + 1) / 2 >= kMinImageSidePx) {
    std::pair<cv::Mat, cv::Mat> next;
    cv::pyrDown(pyramid.back().first, next.first);
    cv::pyrDown(pyramid.back().second, next.second);
    pyramid.push_back(std::move(next));
  }
  const int coarsest = static_cast<int>(pyramid.size()) - 1;
  const int finest = std::min(options.finest_level, coarsest);
  result.levels = coarsest + 1;

  // Coarsest level: exhaustive search.
  const cv::Mat& top_prev = pyramid[coarsest].first;
  const cv::Mat& top_curr = pyramid[coarsest].second;
  if (IsFlat(top_prev)) return Fail(result, "no texture: prev is uniform at the coarsest level");
  if (IsFlat(top_curr)) return Fail(result, "no texture: curr is uniform at the coarsest level");
  const int max_dx = static_cast<int>(std::floor(options.max_shift_fraction_x * top_prev.cols));
  const int max_dy = static_cast<int>(std::floor(options.max_shift_fraction_y * top_prev.rows));
  auto scorer = std::make_unique<LevelScorer>(top_prev, top_curr, options.min_overlap_fraction);
  Grid grid = Search(scorer.get(), 0, 0, max_dx, max_dy);
  if (!grid.found()) {
    return Fail(result, "no texture: no shift has a textured overlap at the coarsest level");
  }
  result.second_best_ratio = SecondBestRatio(grid);

  // Finer levels: local search around twice the coarser estimate, re-centred while the best
  // lies on the window border.
  const int r = options.refine_radius_px;
  for (int l = coarsest - 1; l >= finest; --l) {
    scorer = std::make_unique<LevelScorer>(pyramid[l].first, pyramid[l].second,
                                           options.min_overlap_fraction);
    int cx = 2 * grid.best_dx, cy = 2 * grid.best_dy;
    grid = Search(scorer.get(), cx, cy, r, r);
    for (int k = 0; k < kMaxRecentre && grid.found(); ++k) {
      if (std::abs(grid.best_dx - cx) < r && std::abs(grid.best_dy - cy) < r) break;
      cx = grid.best_dx, cy = grid.best_dy;
      grid = Search(scorer.get(), cx, cy, r, r);
    }
    if (!grid.found()) {
      char buf[96];
      std::snprintf(buf, sizeof(buf), "no texture: no shift could be scored at pyramid level %d",
                    l);
      return Fail(result, buf);
    }
  }

  // Sub-pixel part from the x and y neighbours of the best shift (one parabola per axis).
  const int bx = grid.best_dx, by = grid.best_dy;
  double off_x = 0.0, off_y = 0.0;
  if (options.subpixel) {
    auto score_at = [&](int dx, int dy, double* s) {
      if (!grid.Inside(dx, dy)) return scorer->Score(dx, dy, s);
      *s = grid.At(dx, dy);
      return *s != kUnscored;
    };
    double sm, sp;
    if (score_at(bx - 1, by, &sm) && score_at(bx + 1, by, &sp)) {
      off_x = ParabolaOffset(sm, grid.best, sp);
    }
    if (score_at(bx, by - 1, &sm) && score_at(bx, by + 1, &sp)) {
      off_y = ParabolaOffset(sm, grid.best, sp);
    }
  }
  const double scale = std::ldexp(1.0, finest);
  result.shift_px = Eigen::Vector2d((bx + off_x) * scale, (by + off_y) * scale);
  result.score = grid.best;
  if (!(result.score >= options.min_score)) {
    char buf[96];
    std::snprintf(buf, sizeof(buf), "best ZNCC %.3f is below min_score %.3f", result.score,
                  options.min_score);
    return Fail(result, buf);
  }
  result.ok = true;
  return result;
}

}  // namespace vo
