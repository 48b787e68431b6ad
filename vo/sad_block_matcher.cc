#include "vo/sad_block_matcher.h"

#include <algorithm>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <sstream>

#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#define VO_SAD_HAVE_AVX2 1
#else
#define VO_SAD_HAVE_AVX2 0
#endif

namespace vo {
namespace {

constexpr int16_t kNoCost = INT16_MAX;

// cv::StereoBM's PREFILTER_XSOBEL of the image padded by `pad_left` columns on the left,
// `half` on the right and `half` rows above and below (BORDER_REPLICATE): the 3x3 x-Sobel
// response clipped to [-cap, cap] and offset by cap (so 0..2 cap), the padded image's rows
// mirrored at its top and bottom (reflect-101), its first and last columns set to cap.
// Computed from the unpadded image without building the padded one: replicated rows and
// columns make reflect-101 on the padded image the same as clamping into the image, and every
// padding column has equal neighbours (response 0, value cap).
void PrefilterXSobelPadded(const cv::Mat& src, int cap, int pad_left, int half, cv::Mat* dst) {
  const int w = src.cols, h = src.rows;
  dst->create(h + 2 * half, w + pad_left + half, CV_8UC1);
  // The horizontal differences of source rows, each computed once: slot y % 3 holds row y
  // (consecutive output rows read clamped rows y - 1, y, y + 1, so the three never collide).
  std::vector<int16_t> diff(3 * static_cast<size_t>(w));
  int slot_row[3] = {-1, -1, -1};
  auto row_diff = [&](int y) -> const int16_t* {
    int16_t* d = &diff[static_cast<size_t>(y % 3) * w];
    if (slot_row[y % 3] == y) return d;
    slot_row[y % 3] = y;
    const uint8_t* row = src.ptr<uint8_t>(y);
    if (w == 1) {
      d[0] = 0;
      return d;
    }
    d[0] = static_cast<int16_t>(row[1] - row[0]);
    for (int x = 1; x < w - 1; ++x) d[x] = static_cast<int16_t>(row[x + 1] - row[x - 1]);
    d[w - 1] = static_cast<int16_t>(row[w - 1] - row[w - 2]);
    return d;
  };
  for (int Y = 0; Y < dst->rows; ++Y) {
    uint8_t* out = dst->ptr<uint8_t>(Y);
    std::fill(out, out + pad_left, static_cast<uint8_t>(cap));
    std::fill(out + pad_left + w, out + dst->cols, static_cast<uint8_t>(cap));
    // Rows Y - 1, Y, Y + 1 of the padded image, clamped into the source.
    const auto clamped = [&](int r) { return std::min(std::max(Y - half - 1 + r, 0), h - 1); };
    const int y0 = clamped(0), y1 = clamped(1), y2 = clamped(2);
    const int16_t* d0 = row_diff(y0);
    const int16_t* d1 = row_diff(y1);
    const int16_t* d2 = row_diff(y2);
    uint8_t* o = out + pad_left;
    const int16_t lo = static_cast<int16_t>(-cap), hi = static_cast<int16_t>(cap);
    for (int x = 0; x < w; ++x) {
      const int16_t v = static_cast<int16_t>(d0[x] + 2 * d1[x] + d2[x]);
      o[x] = static_cast<uint8_t>(std::min(std::max(v, lo), hi) + cap);
    }
  }
}

inline uint8_t AbsDiff(uint8_t a, uint8_t b) { return a > b ? a - b : b - a; }

#ifdef __SSE2__
// |v - r[i]| for the 16 bytes at r, each byte on its own (one saturating difference is zero).
inline __m128i AbsDiff16(__m128i v, const uint8_t* r) {
  const __m128i rv = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r));
  return _mm_or_si128(_mm_subs_epu8(v, rv), _mm_subs_epu8(rv, v));
}
#endif

// The inner loops run over the disparity index k (n = num_disparities, a multiple of 16).
// SSE2 (every x86-64) versions with portable scalar fallbacks that compute the same values.

// colsum[k] += |a_add - r_add[k]| - |a_sub - r_sub[k]| (modulo 2^16; the true sums fit).
inline void UpdateColumn(int16_t* colsum, uint8_t a_add, const uint8_t* r_add, uint8_t a_sub,
                         const uint8_t* r_sub, int n) {
#ifdef __SSE2__
  const __m128i zero = _mm_setzero_si128();
  const __m128i va = _mm_set1_epi8(static_cast<char>(a_add));
  const __m128i vs = _mm_set1_epi8(static_cast<char>(a_sub));
  for (int k = 0; k < n; k += 16) {
    const __m128i da = AbsDiff16(va, r_add + k);
    const __m128i ds = AbsDiff16(vs, r_sub + k);
    __m128i* c = reinterpret_cast<__m128i*>(colsum + k);
    __m128i lo = _mm_loadu_si128(c), hi = _mm_loadu_si128(c + 1);
    lo = _mm_sub_epi16(_mm_add_epi16(lo, _mm_unpacklo_epi8(da, zero)), _mm_unpacklo_epi8(ds, zero));
    hi = _mm_sub_epi16(_mm_add_epi16(hi, _mm_unpackhi_epi8(da, zero)), _mm_unpackhi_epi8(ds, zero));
    _mm_storeu_si128(c, lo);
    _mm_storeu_si128(c + 1, hi);
  }
#else
  for (int k = 0; k < n; ++k) {
    colsum[k] =
        static_cast<int16_t>(colsum[k] + AbsDiff(a_add, r_add[k]) - AbsDiff(a_sub, r_sub[k]));
  }
#endif
}

// colsum[k] += |a - r[k]|.
inline void AddColumn(int16_t* colsum, uint8_t a, const uint8_t* r, int n) {
#ifdef __SSE2__
  const __m128i zero = _mm_setzero_si128();
  const __m128i va = _mm_set1_epi8(static_cast<char>(a));
  for (int k = 0; k < n; k += 16) {
    const __m128i d = AbsDiff16(va, r + k);
    __m128i* c = reinterpret_cast<__m128i*>(colsum + k);
    _mm_storeu_si128(c, _mm_add_epi16(_mm_loadu_si128(c), _mm_unpacklo_epi8(d, zero)));
    _mm_storeu_si128(c + 1, _mm_add_epi16(_mm_loadu_si128(c + 1), _mm_unpackhi_epi8(d, zero)));
  }
#else
  for (int k = 0; k < n; ++k) colsum[k] = static_cast<int16_t>(colsum[k] + AbsDiff(a, r[k]));
#endif
}

// c[k] = prev[k] + add[k] - sub[k]: the window cost one pixel to the right.
inline void SlideRight(int16_t* c, const int16_t* prev, const int16_t* add, const int16_t* sub,
                       int n) {
#ifdef __SSE2__
  for (int k = 0; k < n; k += 8) {
    const __m128i p = _mm_loadu_si128(reinterpret_cast<const __m128i*>(prev + k));
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(add + k));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(sub + k));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(c + k), _mm_sub_epi16(_mm_add_epi16(p, a), b));
  }
#else
  for (int k = 0; k < n; ++k) c[k] = static_cast<int16_t>(prev[k] + add[k] - sub[k]);
#endif
}

// Smallest cost and its first index.
inline void ArgMin(const int16_t* c, int n, int* best, int16_t* best_cost) {
#ifdef __SSE2__
  __m128i m = _mm_loadu_si128(reinterpret_cast<const __m128i*>(c));
  for (int k = 8; k < n; k += 8) {
    m = _mm_min_epi16(m, _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + k)));
  }
  m = _mm_min_epi16(m, _mm_shuffle_epi32(m, _MM_SHUFFLE(1, 0, 3, 2)));
  m = _mm_min_epi16(m, _mm_shuffle_epi32(m, _MM_SHUFFLE(2, 3, 0, 1)));
  m = _mm_min_epi16(m, _mm_shufflelo_epi16(_mm_shufflehi_epi16(m, _MM_SHUFFLE(2, 3, 0, 1)),
                                           _MM_SHUFFLE(2, 3, 0, 1)));
  for (int k = 0;; k += 8) {
    const int mask = _mm_movemask_epi8(
        _mm_cmpeq_epi16(m, _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + k))));
    if (mask != 0) {
      *best = k + __builtin_ctz(static_cast<unsigned>(mask)) / 2;
      *best_cost = c[*best];
      return;
    }
  }
#else
  int16_t m = c[0];
  for (int k = 1; k < n; ++k) m = std::min(m, c[k]);
  int b = 0;
  while (c[b] != m) ++b;
  *best = b;
  *best_cost = m;
#endif
}

// True when some k with |k - best| > 1 has c[k] <= thresh.
inline bool Ambiguous(const int16_t* c, int n, int best, int thresh) {
#ifdef __SSE2__
  const __m128i t = _mm_set1_epi16(static_cast<int16_t>(std::min(thresh, int{INT16_MAX})));
  const __m128i b = _mm_set1_epi16(static_cast<int16_t>(best));
  const __m128i one = _mm_set1_epi16(1), minus_one = _mm_set1_epi16(-1);
  const __m128i eight = _mm_set1_epi16(8);
  __m128i kidx = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
  __m128i any = _mm_setzero_si128();
  for (int k = 0; k < n; k += 8, kidx = _mm_add_epi16(kidx, eight)) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + k));
    const __m128i dk = _mm_sub_epi16(kidx, b);
    const __m128i far = _mm_or_si128(_mm_cmpgt_epi16(dk, one), _mm_cmpgt_epi16(minus_one, dk));
    any = _mm_or_si128(any, _mm_andnot_si128(_mm_cmpgt_epi16(v, t), far));  // v <= t && far
  }
  return _mm_movemask_epi8(any) != 0;
#else
  for (int k = 0; k < n; ++k) {
    if (c[k] <= thresh && (k < best - 1 || k > best + 1)) return true;
  }
  return false;
#endif
}

// Right view, one left pixel's costs c[k] for the right pixels q0 + k (reversed index):
// keep the smaller cost and its k.
inline void RightMinUpdate(const int16_t* c, int16_t* rmin, int16_t* rbest, int n) {
#ifdef __SSE2__
  __m128i kidx = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
  const __m128i eight = _mm_set1_epi16(8);
  for (int k = 0; k < n; k += 8, kidx = _mm_add_epi16(kidx, eight)) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + k));
    __m128i* pm = reinterpret_cast<__m128i*>(rmin + k);
    __m128i* pb = reinterpret_cast<__m128i*>(rbest + k);
    const __m128i m = _mm_loadu_si128(pm);
    const __m128i better = _mm_cmpgt_epi16(m, v);
    _mm_storeu_si128(pm, _mm_min_epi16(m, v));
    _mm_storeu_si128(pb, _mm_or_si128(_mm_and_si128(better, kidx),
                                      _mm_andnot_si128(better, _mm_loadu_si128(pb))));
  }
#else
  for (int k = 0; k < n; ++k) {
    if (c[k] < rmin[k]) {
      rmin[k] = c[k];
      rbest[k] = static_cast<int16_t>(k);
    }
  }
#endif
}

// Right view uniqueness: amb[k] |= c[k] <= thresh[k] and |k - rbest[k]| > 1.
inline void RightAmbiguity(const int16_t* c, const int16_t* thresh, const int16_t* rbest,
                           int16_t* amb, int n) {
#ifdef __SSE2__
  __m128i kidx = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
  const __m128i eight = _mm_set1_epi16(8), one = _mm_set1_epi16(1), minus_one = _mm_set1_epi16(-1);
  for (int k = 0; k < n; k += 8, kidx = _mm_add_epi16(kidx, eight)) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + k));
    const __m128i t = _mm_loadu_si128(reinterpret_cast<const __m128i*>(thresh + k));
    const __m128i dk =
        _mm_sub_epi16(kidx, _mm_loadu_si128(reinterpret_cast<const __m128i*>(rbest + k)));
    const __m128i far = _mm_or_si128(_mm_cmpgt_epi16(dk, one), _mm_cmpgt_epi16(minus_one, dk));
    __m128i* pa = reinterpret_cast<__m128i*>(amb + k);
    _mm_storeu_si128(
        pa, _mm_or_si128(_mm_loadu_si128(pa), _mm_andnot_si128(_mm_cmpgt_epi16(v, t), far)));
  }
#else
  for (int k = 0; k < n; ++k) {
    const int dk = k - rbest[k];
    amb[k] |= static_cast<int16_t>(c[k] <= thresh[k] && (dk > 1 || dk < -1));
  }
#endif
}

// Fixed-point (1/16 px) disparity from the best index and its neighbours' costs, equiangular
// interpolation as cv::StereoBM: p = cost at d - 1, n = cost at d + 1.
inline int16_t SubPixel(int d, int c, int p, int n) {
  const int denom = p + n - 2 * c + std::abs(p - n);
  const int offset = denom != 0 ? (p - n) * 256 / denom : 0;
  return static_cast<int16_t>((d * 256 + offset + 15) >> 4);
}

}  // namespace

namespace {

// Largest window side of the sparse evaluation (SadBlockMatcherOptions::IsValid bounds the
// window by its 16-bit cost: block_size <= 127 even at prefilter_cap 1).
constexpr int kMaxWindow = 129;

// Uniqueness threshold of a best cost v: v (1 + uniqueness_ratio / 100), in 1/256 steps.
inline int Threshold(int v, int uniq256) { return v + ((v * uniq256) >> 8); }

// Everything the row loop needs (set up by Compute).
struct RowContext {
  int w = 0, h = 0, nd = 0, dmin = 0, win = 0, half = 0, pad_left = 0, padded_w = 0, ncols = 0,
      nq = 0, uniq256 = 0;
  const cv::Mat* left_pf = nullptr;
  const cv::Mat* right_pf_reversed = nullptr;
  int16_t* column_sums = nullptr;
  int16_t* costs = nullptr;
  int16_t* right_min = nullptr;
  int16_t* right_best = nullptr;
  int16_t* right_thresh = nullptr;
  int16_t* right_ambiguous = nullptr;
  cv::Mat* left_fixed = nullptr;
  cv::Mat* right_fixed = nullptr;
  const cv::Mat* discard = nullptr;
};

template <class K>
void ProcessRows(const RowContext& c) {
  const int w = c.w, h = c.h, nd = c.nd, dmin = c.dmin, win = c.win, half = c.half;
  const int pad_left = c.pad_left, ncols = c.ncols, nq = c.nq, uniq256 = c.uniq256;
  auto base = [&](int j) { return c.padded_w - 1 - (pad_left - half + j) + dmin; };
  for (int y = 0; y < h; ++y) {
    if (y > 0) {  // slide the window down: add padded row y + 2 half, drop row y - 1
      const uint8_t* l_add = c.left_pf->ptr<uint8_t>(y + win - 1);
      const uint8_t* r_add = c.right_pf_reversed->ptr<uint8_t>(y + win - 1);
      const uint8_t* l_sub = c.left_pf->ptr<uint8_t>(y - 1);
      const uint8_t* r_sub = c.right_pf_reversed->ptr<uint8_t>(y - 1);
      for (int j = 0; j < ncols; ++j) {
        const int X = pad_left - half + j;
        const int b = base(j);
        K::UpdateColumn(&c.column_sums[static_cast<size_t>(j) * nd], l_add[X], r_add + b, l_sub[X],
                        r_sub + b, nd);
      }
    }
    // Window costs along the row: a sliding sum of the column sums.
    int16_t* cost0 = c.costs;
    std::fill(cost0, cost0 + nd, 0);
    for (int j = 0; j < win; ++j) {
      const int16_t* cs = &c.column_sums[static_cast<size_t>(j) * nd];
      for (int k = 0; k < nd; ++k) cost0[k] = static_cast<int16_t>(cost0[k] + cs[k]);
    }
    for (int x = 1; x < w; ++x) {
      K::SlideRight(&c.costs[static_cast<size_t>(x) * nd],
                    &c.costs[static_cast<size_t>(x - 1) * nd],
                    &c.column_sums[static_cast<size_t>(x + win - 1) * nd],
                    &c.column_sums[static_cast<size_t>(x - 1) * nd], nd);
    }

    // Left view: best disparity per pixel, uniqueness, sub-pixel.
    int16_t* lout = c.left_fixed->ptr<int16_t>(y);
    const uint8_t* skip = c.discard ? c.discard->ptr<uint8_t>(y) : nullptr;
    for (int x = 0; x < w; ++x) {
      const int16_t* cx = &c.costs[static_cast<size_t>(x) * nd];
      int best = 0;
      int16_t best_cost = 0;
      K::ArgMin(cx, nd, &best, &best_cost);
      if (uniq256 > 0 && !(skip && skip[x]) &&
          K::Ambiguous(cx, nd, best, Threshold(best_cost, uniq256))) {
        lout[x] = kSadInvalidFixed;
        continue;
      }
      const int p = best > 0 ? cx[best - 1] : cx[1];
      const int n = best < nd - 1 ? cx[best + 1] : cx[nd - 2];
      lout[x] = SubPixel(dmin + best, best_cost, p, n);
    }
    if (!c.right_fixed) continue;

    // Right view: right pixel x_r = x - dmin - k collects C(x, k) over the row. Left pixels
    // are visited one vector width apart (interleaved passes), so each pass's vector loads hit
    // exactly the previous iteration's stores instead of straddling them (store-forwarding
    // stalls).
    std::fill(c.right_min, c.right_min + nq, kNoCost);
    std::fill(c.right_best, c.right_best + nq, 0);
    for (int start = 0; start < K::kLanes; ++start) {
      for (int x = start; x < w; x += K::kLanes) {
        const int q0 = w - 1 - x + dmin;
        K::RightMinUpdate(&c.costs[static_cast<size_t>(x) * nd], &c.right_min[q0],
                          &c.right_best[q0], nd);
      }
    }
    std::fill(c.right_ambiguous, c.right_ambiguous + nq, 0);
    if (uniq256 > 0) {
      for (int q = 0; q < nq; ++q) {
        c.right_thresh[q] =
            static_cast<int16_t>(std::min<int>(Threshold(c.right_min[q], uniq256), INT16_MAX));
      }
      for (int start = 0; start < K::kLanes; ++start) {
        for (int x = start; x < w; x += K::kLanes) {
          const int q0 = w - 1 - x + dmin;
          K::RightAmbiguity(&c.costs[static_cast<size_t>(x) * nd], &c.right_thresh[q0],
                            &c.right_best[q0], &c.right_ambiguous[q0], nd);
        }
      }
    }
    int16_t* rout = c.right_fixed->ptr<int16_t>(y);
    for (int xr = 0; xr < w; ++xr) {
      const int q = w - 1 - xr;
      if (c.right_min[q] == kNoCost || c.right_ambiguous[q]) {
        rout[xr] = kSadInvalidFixed;
        continue;
      }
      const int best = c.right_best[q];
      const int x = xr + dmin + best;  // the left pixel of the best match
      const int cq = c.right_min[q];
      // Costs at d -/+ 1 belong to the left pixels x -/+ 1; mirrored where missing.
      const bool has_p = best > 0 && x - 1 >= 0;
      const bool has_n = best < nd - 1 && x + 1 < w;
      int p = has_p ? c.costs[static_cast<size_t>(x - 1) * nd + best - 1] : -1;
      int n = has_n ? c.costs[static_cast<size_t>(x + 1) * nd + best + 1] : -1;
      if (!has_p) p = has_n ? n : cq;
      if (!has_n) n = p;
      rout[xr] = SubPixel(dmin + best, cq, p, n);
    }
  }
}

// One left pixel of Compute's left view: its window costs summed directly (window rows and
// columns outermost, the disparities in the vector lanes), then the same arg-min, uniqueness
// test and sub-pixel step.
template <class K>
int16_t LeftAtImpl(const SadBlockMatcher::Geometry& g, const cv::Mat& left_pf,
                   const cv::Mat& right_pf_reversed, int16_t* c, int x, int y) {
  const int nd = g.nd;
  // Reversed right index of column x + i's candidate k: base(x + i) + k = rev0 - i + k.
  const int rev0 = g.padded_w - 1 - (g.pad_left - g.half + x) + g.dmin;
  const uint8_t* a_rows[kMaxWindow];
  const uint8_t* b_rows[kMaxWindow];
  for (int r = 0; r < g.win; ++r) {
    a_rows[r] = left_pf.ptr<uint8_t>(y + r) + g.pad_left - g.half + x;
    b_rows[r] = right_pf_reversed.ptr<uint8_t>(y + r) + rev0;
  }
  K::WindowCosts(a_rows, b_rows, -1, g.win, nd, c);
  int best = 0;
  int16_t best_cost = 0;
  K::ArgMin(c, nd, &best, &best_cost);
  if (g.uniq256 > 0 && K::Ambiguous(c, nd, best, Threshold(best_cost, g.uniq256))) {
    return kSadInvalidFixed;
  }
  const int p = best > 0 ? c[best - 1] : c[1];
  const int n = best < nd - 1 ? c[best + 1] : c[nd - 2];
  return SubPixel(g.dmin + best, best_cost, p, n);
}

// One right pixel of Compute's right view: the costs D[k] = C(xr + dmin + k, k) of the left
// pixels that land on it (the right window fixed, the left one sliding with k), the minimum
// with Compute's tie order (left pixels visited lane-interleaved: by x mod lanes, then x), its
// uniqueness test and sub-pixel step.
template <class K>
int16_t RightAtImpl(const SadBlockMatcher::Geometry& g, const cv::Mat& left_pf,
                    const cv::Mat& right_pf, int16_t* d, uint8_t* segment, int xr, int y) {
  const int nd = g.nd;
  const int nk = std::min(nd, g.w - xr - g.dmin);  // candidates with a left pixel x < w
  if (nk <= 0) return kSadInvalidFixed;
  const int l0 = g.pad_left - g.half + xr + g.dmin;  // left window column of k = 0
  const int r0 = g.pad_left - g.half + xr;           // the right window's first column
  const int segment_len = nd + g.win - 1;
  const int available = std::min(segment_len, g.padded_w - l0);
  const uint8_t* a_rows[kMaxWindow];
  const uint8_t* b_rows[kMaxWindow];
  for (int r = 0; r < g.win; ++r) {
    // The left row from l0 on, zero past the padded image (only k >= nk read those).
    uint8_t* row_segment = segment + static_cast<size_t>(r) * segment_len;
    std::copy_n(left_pf.ptr<uint8_t>(y + r) + l0, available, row_segment);
    std::fill(row_segment + available, row_segment + segment_len, 0);
    a_rows[r] = right_pf.ptr<uint8_t>(y + r) + r0;
    b_rows[r] = row_segment;
  }
  K::WindowCosts(a_rows, b_rows, 1, g.win, nd, d);
  const int lanes = g.avx2 ? 16 : 8;
  int best = -1, best_key = 0;
  int16_t best_cost = kNoCost;
  for (int k = 0; k < nk; ++k) {
    const int x = xr + g.dmin + k;
    const int key = (x % lanes) * (g.w + lanes) + x;  // Compute's visiting order
    if (d[k] < best_cost || (best >= 0 && d[k] == best_cost && key < best_key)) {
      best = k;
      best_cost = d[k];
      best_key = key;
    }
  }
  if (best < 0) return kSadInvalidFixed;
  if (g.uniq256 > 0) {
    const int thresh = std::min(Threshold(best_cost, g.uniq256), int{INT16_MAX});
    for (int k = 0; k < nk; ++k) {
      if (d[k] <= thresh && (k < best - 1 || k > best + 1)) return kSadInvalidFixed;
    }
  }
  const bool has_p = best > 0;
  const bool has_n = best + 1 < nk;
  int p = has_p ? d[best - 1] : -1;
  int n = has_n ? d[best + 1] : -1;
  if (!has_p) p = has_n ? n : best_cost;
  if (!has_n) n = p;
  return SubPixel(g.dmin + best, best_cost, p, n);
}

// The kernels of the baseline build (SSE2 on x86-64, scalar elsewhere).
struct KernelsBaseline {
  static constexpr int kLanes = 8;  // int16 lanes of a vector
  static void AddColumn(int16_t* colsum, uint8_t a, const uint8_t* r, int n) {
    vo::AddColumn(colsum, a, r, n);
  }
  // out[k] = sum over r, i < win of |a_rows[r][i] - b_rows[r][i * b_step + k]|, k < n.
  static void WindowCosts(const uint8_t* const* a_rows, const uint8_t* const* b_rows, int b_step,
                          int win, int n, int16_t* out) {
    std::fill(out, out + n, 0);
    for (int r = 0; r < win; ++r) {
      for (int i = 0; i < win; ++i) vo::AddColumn(out, a_rows[r][i], b_rows[r] + i * b_step, n);
    }
  }
  static void UpdateColumn(int16_t* colsum, uint8_t a_add, const uint8_t* r_add, uint8_t a_sub,
                           const uint8_t* r_sub, int n) {
    vo::UpdateColumn(colsum, a_add, r_add, a_sub, r_sub, n);
  }
  static void SlideRight(int16_t* c, const int16_t* prev, const int16_t* add, const int16_t* sub,
                         int n) {
    vo::SlideRight(c, prev, add, sub, n);
  }
  static void ArgMin(const int16_t* c, int n, int* best, int16_t* best_cost) {
    vo::ArgMin(c, n, best, best_cost);
  }
  static bool Ambiguous(const int16_t* c, int n, int best, int thresh) {
    return vo::Ambiguous(c, n, best, thresh);
  }
  static void RightMinUpdate(const int16_t* c, int16_t* rmin, int16_t* rbest, int n) {
    vo::RightMinUpdate(c, rmin, rbest, n);
  }
  static void RightAmbiguity(const int16_t* c, const int16_t* thresh, const int16_t* rbest,
                             int16_t* amb, int n) {
    vo::RightAmbiguity(c, thresh, rbest, amb, n);
  }
};

__attribute__((flatten)) void ProcessRowsBaseline(const RowContext& c) {
  ProcessRows<KernelsBaseline>(c);
}
__attribute__((flatten)) int16_t LeftAtBaseline(const SadBlockMatcher::Geometry& g,
                                                const cv::Mat& lpf, const cv::Mat& rrev, int16_t* c,
                                                int x, int y) {
  return LeftAtImpl<KernelsBaseline>(g, lpf, rrev, c, x, y);
}
__attribute__((flatten)) int16_t RightAtBaseline(const SadBlockMatcher::Geometry& g,
                                                 const cv::Mat& lpf, const cv::Mat& rpf, int16_t* d,
                                                 uint8_t* seg, int xr, int y) {
  return RightAtImpl<KernelsBaseline>(g, lpf, rpf, d, seg, xr, y);
}

#if VO_SAD_HAVE_AVX2
// The same kernels with 256-bit vectors (16 int16 lanes), compiled for AVX2 only here and
// chosen at run time when the CPU has it (SadBlockMatcherOptions::allow_avx2). Same results.
#define VO_AVX2 __attribute__((target("avx2")))
struct KernelsAvx2 {
  static constexpr int kLanes = 16;
  VO_AVX2 static void AddColumn(int16_t* colsum, uint8_t a, const uint8_t* r, int n) {
    const __m128i va = _mm_set1_epi8(static_cast<char>(a));
    for (int k = 0; k < n; k += 16) {
      const __m128i d = AbsDiff16(va, r + k);
      __m256i* p = reinterpret_cast<__m256i*>(colsum + k);
      _mm256_storeu_si256(p, _mm256_add_epi16(_mm256_loadu_si256(p), _mm256_cvtepu8_epi16(d)));
    }
  }
  VO_AVX2 static void UpdateColumn(int16_t* colsum, uint8_t a_add, const uint8_t* r_add,
                                   uint8_t a_sub, const uint8_t* r_sub, int n) {
    const __m128i va = _mm_set1_epi8(static_cast<char>(a_add));
    const __m128i vs = _mm_set1_epi8(static_cast<char>(a_sub));
    for (int k = 0; k < n; k += 16) {
      const __m128i da = AbsDiff16(va, r_add + k);
      const __m128i ds = AbsDiff16(vs, r_sub + k);
      __m256i* p = reinterpret_cast<__m256i*>(colsum + k);
      const __m256i sum =
          _mm256_sub_epi16(_mm256_add_epi16(_mm256_loadu_si256(p), _mm256_cvtepu8_epi16(da)),
                           _mm256_cvtepu8_epi16(ds));
      _mm256_storeu_si256(p, sum);
    }
  }
  // WindowCosts with up to 64 disparities per pass held in registers.
  template <int kBlocks>
  VO_AVX2 static void WindowCostsBlock(const uint8_t* const* a_rows, const uint8_t* const* b_rows,
                                       int b_step, int win, int k0, int16_t* out) {
    __m256i acc[kBlocks];
    for (int b = 0; b < kBlocks; ++b) acc[b] = _mm256_setzero_si256();
    for (int r = 0; r < win; ++r) {
      const uint8_t* a = a_rows[r];
      const uint8_t* row = b_rows[r] + k0;
      for (int i = 0; i < win; ++i) {
        const __m128i va = _mm_set1_epi8(static_cast<char>(a[i]));
        const uint8_t* bp = row + i * b_step;
        for (int b = 0; b < kBlocks; ++b) {
          const __m128i d = AbsDiff16(va, bp + 16 * b);
          acc[b] = _mm256_add_epi16(acc[b], _mm256_cvtepu8_epi16(d));
        }
      }
    }
    for (int b = 0; b < kBlocks; ++b) {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + k0 + 16 * b), acc[b]);
    }
  }
  VO_AVX2 static void WindowCosts(const uint8_t* const* a_rows, const uint8_t* const* b_rows,
                                  int b_step, int win, int n, int16_t* out) {
    int k0 = 0;
    for (; k0 + 64 <= n; k0 += 64) WindowCostsBlock<4>(a_rows, b_rows, b_step, win, k0, out);
    switch ((n - k0) / 16) {
      case 3:
        WindowCostsBlock<3>(a_rows, b_rows, b_step, win, k0, out);
        break;
      case 2:
        WindowCostsBlock<2>(a_rows, b_rows, b_step, win, k0, out);
        break;
      case 1:
        WindowCostsBlock<1>(a_rows, b_rows, b_step, win, k0, out);
        break;
      default:
        break;
    }
  }
  VO_AVX2 static void SlideRight(int16_t* c, const int16_t* prev, const int16_t* add,
                                 const int16_t* sub, int n) {
    for (int k = 0; k < n; k += 16) {
      const __m256i p = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(prev + k));
      const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(add + k));
      const __m256i b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(sub + k));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(c + k),
                          _mm256_sub_epi16(_mm256_add_epi16(p, a), b));
    }
  }
  VO_AVX2 static void ArgMin(const int16_t* c, int n, int* best, int16_t* best_cost) {
    __m256i m = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c));
    for (int k = 16; k < n; k += 16) {
      m = _mm256_min_epi16(m, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + k)));
    }
    __m128i h = _mm_min_epi16(_mm256_castsi256_si128(m), _mm256_extracti128_si256(m, 1));
    h = _mm_min_epi16(h, _mm_shuffle_epi32(h, _MM_SHUFFLE(1, 0, 3, 2)));
    h = _mm_min_epi16(h, _mm_shuffle_epi32(h, _MM_SHUFFLE(2, 3, 0, 1)));
    h = _mm_min_epi16(h, _mm_shufflelo_epi16(_mm_shufflehi_epi16(h, _MM_SHUFFLE(2, 3, 0, 1)),
                                             _MM_SHUFFLE(2, 3, 0, 1)));
    const __m256i mb = _mm256_broadcastw_epi16(h);
    for (int k = 0;; k += 16) {
      const unsigned mask = static_cast<unsigned>(_mm256_movemask_epi8(
          _mm256_cmpeq_epi16(mb, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + k)))));
      if (mask != 0) {
        *best = k + __builtin_ctz(mask) / 2;
        *best_cost = c[*best];
        return;
      }
    }
  }
  VO_AVX2 static bool Ambiguous(const int16_t* c, int n, int best, int thresh) {
    const __m256i t = _mm256_set1_epi16(static_cast<int16_t>(std::min(thresh, int{INT16_MAX})));
    const __m256i b = _mm256_set1_epi16(static_cast<int16_t>(best));
    const __m256i one = _mm256_set1_epi16(1), minus_one = _mm256_set1_epi16(-1);
    const __m256i sixteen = _mm256_set1_epi16(16);
    __m256i kidx = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    __m256i any = _mm256_setzero_si256();
    for (int k = 0; k < n; k += 16, kidx = _mm256_add_epi16(kidx, sixteen)) {
      const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + k));
      const __m256i dk = _mm256_sub_epi16(kidx, b);
      const __m256i far =
          _mm256_or_si256(_mm256_cmpgt_epi16(dk, one), _mm256_cmpgt_epi16(minus_one, dk));
      any = _mm256_or_si256(any, _mm256_andnot_si256(_mm256_cmpgt_epi16(v, t), far));
    }
    return !_mm256_testz_si256(any, any);
  }
  VO_AVX2 static void RightMinUpdate(const int16_t* c, int16_t* rmin, int16_t* rbest, int n) {
    __m256i kidx = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m256i sixteen = _mm256_set1_epi16(16);
    for (int k = 0; k < n; k += 16, kidx = _mm256_add_epi16(kidx, sixteen)) {
      const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + k));
      __m256i* pm = reinterpret_cast<__m256i*>(rmin + k);
      __m256i* pb = reinterpret_cast<__m256i*>(rbest + k);
      const __m256i m = _mm256_loadu_si256(pm);
      const __m256i better = _mm256_cmpgt_epi16(m, v);
      _mm256_storeu_si256(pm, _mm256_min_epi16(m, v));
      _mm256_storeu_si256(pb, _mm256_blendv_epi8(_mm256_loadu_si256(pb), kidx, better));
    }
  }
  VO_AVX2 static void RightAmbiguity(const int16_t* c, const int16_t* thresh, const int16_t* rbest,
                                     int16_t* amb, int n) {
    __m256i kidx = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m256i sixteen = _mm256_set1_epi16(16), one = _mm256_set1_epi16(1),
                  minus_one = _mm256_set1_epi16(-1);
    for (int k = 0; k < n; k += 16, kidx = _mm256_add_epi16(kidx, sixteen)) {
      const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + k));
      const __m256i t = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(thresh + k));
      const __m256i dk =
          _mm256_sub_epi16(kidx, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rbest + k)));
      const __m256i far =
          _mm256_or_si256(_mm256_cmpgt_epi16(dk, one), _mm256_cmpgt_epi16(minus_one, dk));
      __m256i* pa = reinterpret_cast<__m256i*>(amb + k);
      _mm256_storeu_si256(pa, _mm256_or_si256(_mm256_loadu_si256(pa),
                                              _mm256_andnot_si256(_mm256_cmpgt_epi16(v, t), far)));
    }
  }
};

VO_AVX2 __attribute__((flatten)) void ProcessRowsAvx2(const RowContext& c) {
  ProcessRows<KernelsAvx2>(c);
}
VO_AVX2 __attribute__((flatten)) int16_t LeftAtAvx2(const SadBlockMatcher::Geometry& g,
                                                    const cv::Mat& lpf, const cv::Mat& rrev,
                                                    int16_t* c, int x, int y) {
  return LeftAtImpl<KernelsAvx2>(g, lpf, rrev, c, x, y);
}
VO_AVX2 __attribute__((flatten)) int16_t RightAtAvx2(const SadBlockMatcher::Geometry& g,
                                                     const cv::Mat& lpf, const cv::Mat& rpf,
                                                     int16_t* d, uint8_t* seg, int xr, int y) {
  return RightAtImpl<KernelsAvx2>(g, lpf, rpf, d, seg, xr, y);
}
#undef VO_AVX2
#endif  // VO_SAD_HAVE_AVX2

}  // namespace

bool SadBlockMatcherOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (min_disparity_px < 0) {
    msg << "min_disparity_px must be >= 0, got " << min_disparity_px;
  } else if (num_disparities < 16 || num_disparities % 16 != 0) {
    msg << "num_disparities must be a positive multiple of 16, got " << num_disparities;
  } else if (block_size < 3 || block_size % 2 == 0) {
    msg << "block_size must be odd and >= 3, got " << block_size;
  } else if (prefilter_cap < 1 || prefilter_cap > 63) {
    msg << "prefilter_cap must be in [1, 63], got " << prefilter_cap;
  } else if (block_size * block_size * 2 * prefilter_cap > INT16_MAX) {
    msg << "block_size " << block_size << " with prefilter_cap " << prefilter_cap
        << " overflows the 16-bit window cost (block_size² · 2 · prefilter_cap must be <= 32767)";
  } else if (uniqueness_ratio < 0 || uniqueness_ratio > 100) {
    msg << "uniqueness_ratio must be in [0, 100] percent, got " << uniqueness_ratio;
  }
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

void SadBlockMatcher::Prepare(const cv::Mat& left, const cv::Mat& right, int num_disparities) {
  const SadBlockMatcherOptions& o = options_;
  Geometry& g = geometry_;
  g.w = left.cols;
  g.h = left.rows;
  g.nd = num_disparities > 0 ? num_disparities : o.num_disparities;
  g.dmin = o.min_disparity_px;
  g.half = o.block_size / 2;
  g.win = o.block_size;
  // Padding: search range + half a window on the left, half a window elsewhere.
  g.pad_left = g.dmin + g.nd - 1 + g.half;
  g.padded_w = g.w + g.pad_left + g.half;
  g.uniq256 = o.uniqueness_ratio * 256 / 100;
#if VO_SAD_HAVE_AVX2
  g.avx2 = o.allow_avx2 && __builtin_cpu_supports("avx2");
#else
  g.avx2 = false;
#endif
  PrefilterXSobelPadded(left, o.prefilter_cap, g.pad_left, g.half, &left_pf_);
  PrefilterXSobelPadded(right, o.prefilter_cap, g.pad_left, g.half, &right_pf_);
  // Mirrored right rows: the right pixels X - d for d = dmin, dmin + 1, ... are then contiguous.
  cv::flip(right_pf_, right_pf_reversed_, 1);
  pixel_costs_.resize(g.nd);
  segment_.resize(static_cast<size_t>(g.nd + g.win) * g.win);
}

void SadBlockMatcher::ReleaseDenseScratch() {
  for (std::vector<int16_t>* v :
       {&column_sums_, &costs_, &right_min_, &right_best_, &right_thresh_, &right_ambiguous_}) {
    std::vector<int16_t>().swap(*v);
  }
}

int16_t SadBlockMatcher::LeftAt(int x, int y) {
#if VO_SAD_HAVE_AVX2
  if (geometry_.avx2) {
    return LeftAtAvx2(geometry_, left_pf_, right_pf_reversed_, pixel_costs_.data(), x, y);
  }
#endif
  return LeftAtBaseline(geometry_, left_pf_, right_pf_reversed_, pixel_costs_.data(), x, y);
}

int16_t SadBlockMatcher::RightAt(int xr, int y) {
#if VO_SAD_HAVE_AVX2
  if (geometry_.avx2) {
    return RightAtAvx2(geometry_, left_pf_, right_pf_, pixel_costs_.data(), segment_.data(), xr, y);
  }
#endif
  return RightAtBaseline(geometry_, left_pf_, right_pf_, pixel_costs_.data(), segment_.data(), xr,
                         y);
}

void SadBlockMatcher::Compute(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_fixed,
                              cv::Mat* right_fixed, const cv::Mat* discard, int num_disparities) {
  Prepare(left, right, num_disparities);
  const Geometry& g = geometry_;
  const int w = g.w, h = g.h, nd = g.nd, dmin = g.dmin, half = g.half, win = g.win;
  const int dmax = dmin + nd - 1;
  const int pad_left = g.pad_left, padded_w = g.padded_w;

  // Column j (0 .. w + 2 half - 1) is padded column X = pad_left - half + j; its right
  // candidates for disparity index k sit at reversed index base(j) + k.
  const int ncols = w + 2 * half;
  auto base = [&](int j) { return padded_w - 1 - (pad_left - half + j) + dmin; };
  column_sums_.assign(static_cast<size_t>(ncols) * nd, 0);
  costs_.resize(static_cast<size_t>(w) * nd);
  // Right view, indexed by q = w - 1 - x_r (so a left pixel's candidates are contiguous); room
  // for the candidates with x_r < 0, which are ignored.
  const int nq = w + dmax + 1;
  right_min_.resize(nq);
  right_best_.resize(nq);
  right_ambiguous_.resize(nq);
  right_thresh_.resize(nq);
  left_fixed->create(h, w, CV_16S);
  if (right_fixed) right_fixed->create(h, w, CV_16S);
  const int uniq256 = g.uniq256;

  // Window of the first row: padded rows 0 .. 2 half.
  for (int r = 0; r < win; ++r) {
    const uint8_t* lrow = left_pf_.ptr<uint8_t>(r);
    const uint8_t* rrow = right_pf_reversed_.ptr<uint8_t>(r);
    for (int j = 0; j < ncols; ++j) {
      AddColumn(&column_sums_[static_cast<size_t>(j) * nd], lrow[pad_left - half + j],
                rrow + base(j), nd);
    }
  }

  RowContext ctx;
  ctx.w = w;
  ctx.h = h;
  ctx.nd = nd;
  ctx.dmin = dmin;
  ctx.win = win;
  ctx.half = half;
  ctx.pad_left = pad_left;
  ctx.padded_w = padded_w;
  ctx.ncols = ncols;
  ctx.nq = nq;
  ctx.uniq256 = uniq256;
  ctx.left_pf = &left_pf_;
  ctx.right_pf_reversed = &right_pf_reversed_;
  ctx.column_sums = column_sums_.data();
  ctx.costs = costs_.data();
  ctx.right_min = right_min_.data();
  ctx.right_best = right_best_.data();
  ctx.right_thresh = right_thresh_.data();
  ctx.right_ambiguous = right_ambiguous_.data();
  ctx.left_fixed = left_fixed;
  ctx.right_fixed = right_fixed;
  ctx.discard = discard;
#if VO_SAD_HAVE_AVX2
  if (g.avx2) {
    ProcessRowsAvx2(ctx);
    return;
  }
#endif
  ProcessRowsBaseline(ctx);
}

}  // namespace vo
