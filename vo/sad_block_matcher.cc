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

// cv::StereoBM's PREFILTER_XSOBEL: the 3x3 x-Sobel response clipped to [-cap, cap] and offset
// by cap (so 0..2 cap), rows mirrored at the top and bottom (reflect-101), the first and last
// columns set to cap (no gradient).
void PrefilterXSobel(const cv::Mat& src, int cap, cv::Mat* dst) {
  dst->create(src.size(), CV_8UC1);
  const int w = src.cols, h = src.rows;
  for (int y = 0; y < h; ++y) {
    const int y0 = y > 0 ? y - 1 : std::min(1, h - 1);
    const int y2 = y < h - 1 ? y + 1 : std::max(h - 2, 0);
    const uint8_t* r0 = src.ptr<uint8_t>(y0);
    const uint8_t* r1 = src.ptr<uint8_t>(y);
    const uint8_t* r2 = src.ptr<uint8_t>(y2);
    uint8_t* out = dst->ptr<uint8_t>(y);
    out[0] = out[w - 1] = static_cast<uint8_t>(cap);
    for (int x = 1; x < w - 1; ++x) {
      const int v = (r0[x + 1] - r0[x - 1]) + 2 * (r1[x + 1] - r1[x - 1]) + (r2[x + 1] - r2[x - 1]);
      out[x] = static_cast<uint8_t>(std::min(std::max(v, -cap), cap) + cap);
    }
  }
}

inline uint8_t AbsDiff(uint8_t a, uint8_t b) { return a > b ? a - b : b - a; }

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
    const __m128i ra = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r_add + k));
    const __m128i rs = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r_sub + k));
    const __m128i da = _mm_or_si128(_mm_subs_epu8(va, ra), _mm_subs_epu8(ra, va));
    const __m128i ds = _mm_or_si128(_mm_subs_epu8(vs, rs), _mm_subs_epu8(rs, vs));
    __m128i* c = reinterpret_cast<__m128i*>(colsum + k);
    __m128i lo = _mm_loadu_si128(c), hi = _mm_loadu_si128(c + 1);
    lo = _mm_sub_epi16(_mm_add_epi16(lo, _mm_unpacklo_epi8(da, zero)), _mm_unpacklo_epi8(ds, zero));
    hi = _mm_sub_epi16(_mm_add_epi16(hi, _mm_unpackhi_epi8(da, zero)), _mm_unpackhi_epi8(ds, zero));
    _mm_storeu_si128(c, lo);
    _mm_storeu_si128(c + 1, hi);
  }
#else
  for (int k = 0; k < n; ++k) {
    colsum[k] = static_cast<int16_t>(colsum[k] + AbsDiff(a_add, r_add[k]) - AbsDiff(a_sub, r_sub[k]));
  }
#endif
}

inline void AddColumn(int16_t* colsum, uint8_t a, const uint8_t* r, int n) {
  for (int k = 0; k < n; ++k) colsum[k] = static_cast<int16_t>(colsum[k] + AbsDiff(a, r[k]));
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
  const __m128i eight = _mm_set1_epi16(8), one = _mm_set1_epi16(1),
                minus_one = _mm_set1_epi16(-1);
  for (int k = 0; k < n; k += 8, kidx = _mm_add_epi16(kidx, eight)) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + k));
    const __m128i t = _mm_loadu_si128(reinterpret_cast<const __m128i*>(thresh + k));
    const __m128i dk =
        _mm_sub_epi16(kidx, _mm_loadu_si128(reinterpret_cast<const __m128i*>(rbest + k)));
    const __m128i far = _mm_or_si128(_mm_cmpgt_epi16(dk, one), _mm_cmpgt_epi16(minus_one, dk));
    __m128i* pa = reinterpret_cast<__m128i*>(amb + k);
    _mm_storeu_si128(pa, _mm_or_si128(_mm_loadu_si128(pa),
                                      _mm_andnot_si128(_mm_cmpgt_epi16(v, t), far)));
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
  auto threshold = [&](int v) { return v + ((v * uniq256) >> 8); };
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
      K::SlideRight(&c.costs[static_cast<size_t>(x) * nd], &c.costs[static_cast<size_t>(x - 1) * nd],
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
      if (uniq256 > 0 && !(skip && skip[x]) && K::Ambiguous(cx, nd, best, threshold(best_cost))) {
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
        K::RightMinUpdate(&c.costs[static_cast<size_t>(x) * nd], &c.right_min[q0], &c.right_best[q0],
                       nd);
      }
    }
    std::fill(c.right_ambiguous, c.right_ambiguous + nq, 0);
    if (uniq256 > 0) {
      for (int q = 0; q < nq; ++q) {
        c.right_thresh[q] = static_cast<int16_t>(std::min<int>(threshold(c.right_min[q]), INT16_MAX));
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

// The kernels of the baseline build (SSE2 on x86-64, scalar elsewhere).
struct KernelsBaseline {
  static constexpr int kLanes = 8;  // int16 lanes of a vector
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

#if VO_SAD_HAVE_AVX2
// The same kernels with 256-bit vectors (16 int16 lanes), compiled for AVX2 only here and
// chosen at run time when the CPU has it (SadBlockMatcherOptions::allow_avx2). Same results.
#define VO_AVX2 __attribute__((target("avx2")))
struct KernelsAvx2 {
  static constexpr int kLanes = 16;
  VO_AVX2 static void UpdateColumn(int16_t* colsum, uint8_t a_add, const uint8_t* r_add,
                                   uint8_t a_sub, const uint8_t* r_sub, int n) {
    const __m128i va = _mm_set1_epi8(static_cast<char>(a_add));
    const __m128i vs = _mm_set1_epi8(static_cast<char>(a_sub));
    for (int k = 0; k < n; k += 16) {
      const __m128i ra = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r_add + k));
      const __m128i rs = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r_sub + k));
      const __m128i da = _mm_or_si128(_mm_subs_epu8(va, ra), _mm_subs_epu8(ra, va));
      const __m128i ds = _mm_or_si128(_mm_subs_epu8(vs, rs), _mm_subs_epu8(rs, vs));
      __m256i* p = reinterpret_cast<__m256i*>(colsum + k);
      const __m256i sum = _mm256_sub_epi16(
          _mm256_add_epi16(_mm256_loadu_si256(p), _mm256_cvtepu8_epi16(da)),
          _mm256_cvtepu8_epi16(ds));
      _mm256_storeu_si256(p, sum);
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
  VO_AVX2 static void RightAmbiguity(const int16_t* c, const int16_t* thresh,
                                     const int16_t* rbest, int16_t* amb, int n) {
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

void SadBlockMatcher::Compute(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_fixed,
                              cv::Mat* right_fixed, const cv::Mat* discard) {
  const SadBlockMatcherOptions& o = options_;
  const int w = left.cols, h = left.rows;
  const int nd = o.num_disparities;
  const int dmin = o.min_disparity_px;
  const int dmax = dmin + nd - 1;
  const int half = o.block_size / 2;
  const int win = o.block_size;
  // Padding: search range + half a window on the left, half a window elsewhere.
  const int pad_left = dmax + half;
  const int padded_w = w + pad_left + half;
  cv::copyMakeBorder(left, padded_, half, half, pad_left, half, cv::BORDER_REPLICATE);
  PrefilterXSobel(padded_, o.prefilter_cap, &left_pf_);
  cv::copyMakeBorder(right, padded_, half, half, pad_left, half, cv::BORDER_REPLICATE);
  PrefilterXSobel(padded_, o.prefilter_cap, &right_pf_);
  // Mirrored right rows: the right pixels X - d for d = dmin, dmin + 1, ... are then contiguous.
  cv::flip(right_pf_, right_pf_reversed_, 1);

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
  const int uniq256 = o.uniqueness_ratio * 256 / 100;

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
  if (o.allow_avx2 && __builtin_cpu_supports("avx2")) {
    ProcessRowsAvx2(ctx);
    return;
  }
#endif
  ProcessRowsBaseline(ctx);
}

}  // namespace vo
