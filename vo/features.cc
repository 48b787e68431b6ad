#include "vo/features.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <utility>

namespace vo {
namespace {

bool Fail(std::ostringstream& msg, std::string* error) {
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

// Image usable by a detector: non-empty 8-bit grey, larger than twice the margin.
bool UsableImage(const cv::Mat& image, int margin) {
  return !image.empty() && image.type() == CV_8UC1 && image.cols > 2 * margin &&
         image.rows > 2 * margin;
}

bool InsideMargin(double x, double y, const cv::Size& size, int margin) {
  return x >= margin && y >= margin && x <= size.width - 1 - margin &&
         y <= size.height - 1 - margin;
}

// The house ordering: response descending, then row, then column ascending.
bool StrongerFirst(double r_a, double x_a, double y_a, double r_b, double x_b, double y_b) {
  if (r_a != r_b) return r_a > r_b;
  if (y_a != y_b) return y_a < y_b;
  return x_a < x_b;
}

// Fast path of the Harris response for aperture 3: integer Sobel derivatives, integer
// running sums of the structure tensor over the block, one float pass for R. Same scaling
// and window anchoring as cv::cornerHarris (derivatives scaled by 1 / (4 * block * 255),
// unnormalised block sums), about twice as fast at 320x240. Pixels closer than block/2 to the
// edge of `image` are left at 0. Exact in int32 while block^2 * 1020^2 < 2^31: block <= 31.
constexpr int kFastHarrisMaxBlock = 31;

// Adds (sign = 1) or removes (sign = -1) one row of derivative products to the column sums.
inline __attribute__((always_inline)) void AccumulateRow(const int16_t* __restrict gx,
                                                         const int16_t* __restrict gy, int width,
                                                         int sign, int* __restrict sxx,
                                                         int* __restrict syy, int* __restrict sxy) {
  for (int x = 0; x < width; ++x) {
    const int a = gx[x], b = gy[x];
    sxx[x] += sign * a * a;
    syy[x] += sign * b * b;
    sxy[x] += sign * a * b;
  }
}

// Block-wide horizontal sums: out[x] = sum_{j < block} in[x + j], x < n (loops ordered so
// that the compiler vectorises along x).
inline __attribute__((always_inline)) void BoxRow(const int* __restrict in, int n, int block,
                                                  int* __restrict out) {
  for (int x = 0; x < n; ++x) out[x] = in[x];
  for (int j = 1; j < block; ++j) {
    for (int x = 0; x < n; ++x) out[x] += in[x + j];
  }
}

// R = det(M) - k trace(M)^2 from the block sums of one row.
inline __attribute__((always_inline)) void HarrisRow(const int* __restrict mxx,
                                                     const int* __restrict myy,
                                                     const int* __restrict mxy, int n, float scale2,
                                                     float k, float* __restrict out) {
  for (int x = 0; x < n; ++x) {
    const float a = static_cast<float>(mxx[x]) * scale2;
    const float c = static_cast<float>(myy[x]) * scale2;
    const float b = static_cast<float>(mxy[x]) * scale2;
    out[x] = a * c - b * b - k * (a + c) * (a + c);
  }
}

// The response's rows [half, height - block + half], columns [half, half + width - block + 1)
// from the derivatives (the block sums in `sums`, 6 * width ints, zero on entry).
inline __attribute__((always_inline)) void HarrisRowsImpl(const cv::Mat& dx, const cv::Mat& dy,
                                                          int block, float scale2, float k,
                                                          int* sums, cv::Mat* response) {
  const int width = dx.cols, height = dx.rows, half = block / 2;
  int* sxx = sums;
  int* syy = sxx + width;
  int* sxy = syy + width;
  int* mxx = sxy + width;
  int* myy = mxx + width;
  int* mxy = myy + width;
  const int n = width - block + 1;
  for (int row = 0; row < block; ++row) {
    AccumulateRow(dx.ptr<int16_t>(row), dy.ptr<int16_t>(row), width, 1, sxx, syy, sxy);
  }
  // Output row y uses window rows [y - half, y - half + block) (cv::boxFilter's anchor).
  for (int y = half;; ++y) {
    BoxRow(sxx, n, block, mxx);
    BoxRow(syy, n, block, myy);
    BoxRow(sxy, n, block, mxy);
    HarrisRow(mxx, myy, mxy, n, scale2, k, response->ptr<float>(y) + half);
    const int add = y - half + block, remove = y - half;
    if (add >= height) break;
    AccumulateRow(dx.ptr<int16_t>(add), dy.ptr<int16_t>(add), width, 1, sxx, syy, sxy);
    AccumulateRow(dx.ptr<int16_t>(remove), dy.ptr<int16_t>(remove), width, -1, sxx, syy, sxy);
  }
}

// Compiled twice: for every x86-64 (SSE2) and, where the CPU has it, for AVX2 (twice the
// lanes). The same values either way: integer sums, and element-wise float products and
// differences without contraction (-ffp-contract=off), whatever the vector width
// (FeaturesTest.TheHarrisResponseIsTheSameWithAndWithoutAvx2).
__attribute__((flatten)) void HarrisRowsBaseline(const cv::Mat& dx, const cv::Mat& dy, int block,
                                                 float scale2, float k, int* sums,
                                                 cv::Mat* response) {
  HarrisRowsImpl(dx, dy, block, scale2, k, sums, response);
}
#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2"), flatten)) void HarrisRowsAvx2(const cv::Mat& dx, const cv::Mat& dy,
                                                             int block, float scale2, float k,
                                                             int* sums, cv::Mat* response) {
  HarrisRowsImpl(dx, dy, block, scale2, k, sums, response);
}
bool HarrisHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}
#else
bool HarrisHasAvx2() { return false; }
#endif

void FastHarris(const cv::Mat& image, int block, double k, bool allow_avx2, cv::Mat* dx,
                cv::Mat* dy, std::vector<int>* sums, cv::Mat* response) {
  cv::Sobel(image, *dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REFLECT_101);
  cv::Sobel(image, *dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REFLECT_101);
  const int width = image.cols, height = image.rows, half = block / 2;
  response->create(height, width, CV_32F);
  if (width < block || height < block) {
    response->setTo(0.0f);
    return;
  }
  // Column sums over the current window rows of gx^2, gy^2, gx*gy, then their block sums.
  sums->assign(6 * static_cast<size_t>(width), 0);
  const int n = width - block + 1;
  // The rows below write rows [half, last_row], columns [half, half + n): zero the rest.
  const int last_row = height - block + half;
  response->rowRange(0, half).setTo(0.0f);
  response->rowRange(last_row + 1, height).setTo(0.0f);
  for (int y = half; y <= last_row; ++y) {
    float* row = response->ptr<float>(y);
    std::fill(row, row + half, 0.0f);
    std::fill(row + half + n, row + width, 0.0f);
  }
  const double scale = 1.0 / (4.0 * block * 255.0);
  const float scale2 = static_cast<float>(scale * scale);
#if defined(__x86_64__) && defined(__GNUC__)
  if (allow_avx2 && HarrisHasAvx2()) {
    HarrisRowsAvx2(*dx, *dy, block, scale2, static_cast<float>(k), sums->data(), response);
    return;
  }
#endif
  HarrisRowsBaseline(*dx, *dy, block, scale2, static_cast<float>(k), sums->data(), response);
}

// ------------------------------------------------------------------------------------------
// Harris corners (Harris & Stephens 1988), the paper's detector.
class HarrisDetector final : public FeatureDetector {
 public:
  explicit HarrisDetector(const DetectorOptions& options) : options_(options) {}

  DetectorType type() const override { return DetectorType::kHarris; }

  std::vector<Feature> Detect(const cv::Mat& image) override {
    std::vector<Feature> features;
    const int margin = options_.border_margin_px;
    if (!UsableImage(image, margin)) return features;
    const HarrisOptions& h = options_.harris;

    // Corner response R = det(M) - k trace(M)^2 of the windowed structure tensor M, computed
    // only where features may lie plus the filters' support (OpenCV filters read the pixels
    // around a sub-matrix, so the values equal those of the full image).
    const cv::Rect inner(margin, margin, image.cols - 2 * margin, image.rows - 2 * margin);
    const int support = h.block_size / 2 + h.aperture_size / 2 + 1;
    const cv::Rect region = cv::Rect(inner.x - support, inner.y - support,
                                     inner.width + 2 * support, inner.height + 2 * support) &
                            cv::Rect(0, 0, image.cols, image.rows);
    ComputeResponse(image(region));
    const cv::Rect inner_in_region = inner - region.tl();

    // Candidates: 3x3 local maxima inside the margin with R above the absolute threshold;
    // the strongest of them sets the relative threshold, applied next.
    cv::dilate(response_, dilated_, cv::Mat());
    candidates_.clear();
    // R > 0 always (edges and flat areas have R <= 0).
    const float lower =
        std::max(static_cast<float>(h.min_response), std::numeric_limits<float>::min());
    float max_response = 0.0f;
    const int width = inner_in_region.width;
    row_mask_.resize(static_cast<size_t>(width) + sizeof(uint64_t));
    std::fill(row_mask_.begin() + width, row_mask_.end(), 0);
    for (int ry = inner_in_region.y; ry < inner_in_region.y + inner_in_region.height; ++ry) {
      const float* __restrict r = response_.ptr<float>(ry) + inner_in_region.x;
      const float* __restrict m = dilated_.ptr<float>(ry) + inner_in_region.x;
      uint8_t* __restrict mask = row_mask_.data();
      // Branch-free test (vectorised), then a sparse scan skipping 8 empty bytes at a time.
      for (int i = 0; i < width; ++i) mask[i] = (r[i] == m[i]) & (r[i] >= lower);
      for (int i = 0; i < width; i += 8) {
        uint64_t word;
        std::memcpy(&word, mask + i, sizeof(word));
        if (word == 0) continue;
        for (int j = i; j < std::min(i + 8, width); ++j) {
          if (!mask[j]) continue;
          candidates_.push_back({r[j], j + inner_in_region.x + region.x, ry + region.y});
          max_response = std::max(max_response, r[j]);
        }
      }
    }
    if (candidates_.empty()) return features;
    const float threshold = static_cast<float>(h.quality_level * max_response);
    candidates_.erase(
        std::remove_if(candidates_.begin(), candidates_.end(),
                       [threshold](const Candidate& c) { return c.response < threshold; }),
        candidates_.end());
    std::sort(candidates_.begin(), candidates_.end(), [](const Candidate& a, const Candidate& b) {
      return StrongerFirst(a.response, a.x, a.y, b.response, b.x, b.y);
    });

    // Greedy non-maximum suppression in a disc: strongest first, a candidate survives when
    // no survivor lies closer than nms_radius_px. A grid of radius-sized cells keeps the
    // neighbour search to 3x3 cells.
    const double radius = h.nms_radius_px;
    const double radius2 = radius * radius;
    const int cell = std::max(1, static_cast<int>(std::ceil(radius)));
    const int grid_cols = image.cols / cell + 1;
    const int grid_rows = image.rows / cell + 1;
    // Survivors per cell as linked lists: grid_head_[cell] -> next_[i] -> ... -> -1.
    grid_head_.assign(static_cast<size_t>(grid_cols) * grid_rows, -1);
    next_.clear();
    const bool bucketing = options_.bucket_cols > 0;
    // Without bucketing the first max_features survivors are the answer.
    const size_t stop_at = (!bucketing && options_.max_features > 0)
                               ? static_cast<size_t>(options_.max_features)
                               : candidates_.size();
    features.reserve(std::min(stop_at, candidates_.size()));
    for (const Candidate& c : candidates_) {
      if (features.size() >= stop_at) break;
      const int gx = c.x / cell;
      const int gy = c.y / cell;
      bool suppressed = false;
      for (int ny = std::max(0, gy - 1); ny <= std::min(grid_rows - 1, gy + 1) && !suppressed;
           ++ny) {
        for (int nx = std::max(0, gx - 1); nx <= std::min(grid_cols - 1, gx + 1); ++nx) {
          for (int i = grid_head_[static_cast<size_t>(ny) * grid_cols + nx]; i >= 0; i = next_[i]) {
            const Eigen::Vector2d& p = features[i].uv_px;
            const double dx = p.x() - c.x, dy = p.y() - c.y;
            if (dx * dx + dy * dy < radius2) {
              suppressed = true;
              break;
            }
          }
          if (suppressed) break;
        }
      }
      if (suppressed) continue;
      int& head = grid_head_[static_cast<size_t>(gy) * grid_cols + gx];
      next_.push_back(head);
      head = static_cast<int>(features.size());
      Feature f;
      f.uv_px = Eigen::Vector2d(c.x, c.y);
      f.response = c.response;
      features.push_back(f);
    }

    // Count limit and bucketing.
    if (bucketing || (options_.max_features > 0 &&
                      features.size() > static_cast<size_t>(options_.max_features))) {
      const std::vector<int> keep = SelectFeatures(features, image.size(), options_);
      std::vector<Feature> selected;
      selected.reserve(keep.size());
      for (int i : keep) selected.push_back(features[i]);
      features.swap(selected);
    }

    if (h.subpixel && !features.empty()) Refine(image, &features);
    return features;
  }

 private:
  struct Candidate {
    float response;
    int x, y;
  };

  // Harris response of `image` into response_ (see HarrisResponse()).
  void ComputeResponse(const cv::Mat& image) {
    const HarrisOptions& h = options_.harris;
    if (h.aperture_size == 3 && h.block_size <= kFastHarrisMaxBlock) {
      FastHarris(image, h.block_size, h.k, true, &dx_, &dy_, &sums_, &response_);
    } else {
      cv::cornerHarris(image, response_, h.block_size, h.aperture_size, h.k,
                       cv::BORDER_REFLECT_101);
    }
  }

  // Sub-pixel positions by cv::cornerSubPix. A corner that drifts out of its search window
  // or out of the margin keeps its integer position.
  void Refine(const cv::Mat& image, std::vector<Feature>* features) const {
    const HarrisOptions& h = options_.harris;
    std::vector<cv::Point2f> points;
    points.reserve(features->size());
    for (const Feature& f : *features) {
      points.emplace_back(static_cast<float>(f.uv_px.x()), static_cast<float>(f.uv_px.y()));
    }
    const int w = h.subpixel_half_window_px;
    cv::cornerSubPix(image, points, cv::Size(w, w), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                      h.subpixel_max_iterations, h.subpixel_epsilon_px));
    for (size_t i = 0; i < points.size(); ++i) {
      Feature& f = (*features)[i];
      const double x = points[i].x, y = points[i].y;
      if (std::isfinite(x) && std::isfinite(y) && std::abs(x - f.uv_px.x()) <= w &&
          std::abs(y - f.uv_px.y()) <= w &&
          InsideMargin(x, y, image.size(), options_.border_margin_px)) {
        f.uv_px = Eigen::Vector2d(x, y);
      }
    }
  }

  DetectorOptions options_;
  // Scratch, reused between calls.
  cv::Mat response_, dilated_, dx_, dy_;
  std::vector<int> sums_;
  std::vector<Candidate> candidates_;
  std::vector<int> grid_head_, next_;
  std::vector<uint8_t> row_mask_;
};

// ------------------------------------------------------------------------------------------
// SIFT (Lowe 2004), the paper's alternative detector.
class SiftDetector final : public FeatureDetector {
 public:
  explicit SiftDetector(const DetectorOptions& options) : options_(options) {
    const SiftOptions& s = options_.sift;
    // nfeatures = 0: OpenCV keeps all; the count limit is applied by us, deterministically.
    sift_ = cv::SIFT::create(0, s.octave_layers, s.contrast_threshold, s.edge_threshold, s.sigma);
  }

  DetectorType type() const override { return DetectorType::kSift; }

  std::vector<Feature> Detect(const cv::Mat& image) override {
    return DetectWithDescriptors(image).features;
  }

  FeatureSet DetectWithDescriptors(const cv::Mat& image) override {
    FeatureSet set;
    const int margin = options_.border_margin_px;
    if (!UsableImage(image, margin)) return set;

    mask_.create(image.size(), CV_8UC1);
    mask_.setTo(0);
    mask_(cv::Rect(margin, margin, image.cols - 2 * margin, image.rows - 2 * margin)).setTo(255);
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    sift_->detectAndCompute(image, mask_, keypoints, descriptors);

    // Deterministic order: response desc, row, column, then orientation.
    std::vector<int> order;
    order.reserve(keypoints.size());
    for (int i = 0; i < static_cast<int>(keypoints.size()); ++i) {
      const cv::KeyPoint& k = keypoints[i];
      if (InsideMargin(k.pt.x, k.pt.y, image.size(), margin)) order.push_back(i);
    }
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      const cv::KeyPoint& ka = keypoints[a];
      const cv::KeyPoint& kb = keypoints[b];
      if (ka.response != kb.response || ka.pt.y != kb.pt.y || ka.pt.x != kb.pt.x) {
        return StrongerFirst(ka.response, ka.pt.x, ka.pt.y, kb.response, kb.pt.x, kb.pt.y);
      }
      if (ka.angle != kb.angle) return ka.angle < kb.angle;
      return a < b;
    });

    // SIFT emits one keypoint per dominant orientation at the same position: keep the first.
    std::vector<Feature> candidates;
    std::vector<int> candidate_index;
    std::set<std::pair<float, float>> seen;
    for (int i : order) {
      const cv::KeyPoint& k = keypoints[i];
      if (options_.sift.unique_positions && !seen.insert({k.pt.x, k.pt.y}).second) continue;
      Feature f;
      f.uv_px = Eigen::Vector2d(k.pt.x, k.pt.y);
      f.response = k.response;
      candidates.push_back(f);
      candidate_index.push_back(i);
    }

    const std::vector<int> keep = SelectFeatures(candidates, image.size(), options_);
    set.features.reserve(keep.size());
    set.keypoints.reserve(keep.size());
    if (!keep.empty())
      set.descriptors.create(static_cast<int>(keep.size()), descriptors.cols, descriptors.type());
    for (size_t j = 0; j < keep.size(); ++j) {
      const int i = candidate_index[keep[j]];
      set.features.push_back(candidates[keep[j]]);
      set.keypoints.push_back(keypoints[i]);
      descriptors.row(i).copyTo(set.descriptors.row(static_cast<int>(j)));
    }
    return set;
  }

 private:
  DetectorOptions options_;
  cv::Ptr<cv::SIFT> sift_;
  cv::Mat mask_;
};

}  // namespace

const char* ToString(DetectorType type) {
  switch (type) {
    case DetectorType::kHarris:
      return "harris";
    case DetectorType::kSift:
      return "sift";
  }
  return "unknown";
}

bool HarrisOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (block_size < 2) {
    msg << "harris.block_size must be >= 2, got " << block_size;
  } else if (aperture_size != 3 && aperture_size != 5 && aperture_size != 7) {
    msg << "harris.aperture_size must be 3, 5 or 7, got " << aperture_size;
  } else if (!(k > 0.0 && k < 0.25)) {
    msg << "harris.k must be in (0, 0.25), got " << k;
  } else if (!(quality_level >= 0.0 && quality_level < 1.0)) {
    msg << "harris.quality_level must be in [0, 1), got " << quality_level;
  } else if (!std::isfinite(min_response) || min_response < 0.0) {
    msg << "harris.min_response must be finite and >= 0, got " << min_response;
  } else if (!std::isfinite(nms_radius_px) || nms_radius_px < 1.0) {
    msg << "harris.nms_radius_px must be finite and >= 1, got " << nms_radius_px;
  } else if (subpixel_half_window_px < 1) {
    msg << "harris.subpixel_half_window_px must be >= 1, got " << subpixel_half_window_px;
  } else if (subpixel_max_iterations < 1) {
    msg << "harris.subpixel_max_iterations must be >= 1, got " << subpixel_max_iterations;
  } else if (!std::isfinite(subpixel_epsilon_px) || subpixel_epsilon_px <= 0.0) {
    msg << "harris.subpixel_epsilon_px must be finite and > 0, got " << subpixel_epsilon_px;
  }
  return Fail(msg, error);
}

bool SiftOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (octave_layers < 1) {
    msg << "sift.octave_layers must be >= 1, got " << octave_layers;
  } else if (!std::isfinite(contrast_threshold) || contrast_threshold <= 0.0) {
    msg << "sift.contrast_threshold must be finite and > 0, got " << contrast_threshold;
  } else if (!std::isfinite(edge_threshold) || edge_threshold <= 1.0) {
    msg << "sift.edge_threshold must be finite and > 1, got " << edge_threshold;
  } else if (!std::isfinite(sigma) || sigma <= 0.0) {
    msg << "sift.sigma must be finite and > 0, got " << sigma;
  }
  return Fail(msg, error);
}

bool DetectorOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (type != DetectorType::kHarris && type != DetectorType::kSift) {
    msg << "type: unknown value " << static_cast<int>(type);
  } else if (max_features < 0) {
    msg << "max_features must be >= 0 (0 = no limit), got " << max_features;
  } else if (border_margin_px < 0) {
    msg << "border_margin_px must be >= 0, got " << border_margin_px;
  } else if (bucket_cols < 0 || bucket_rows < 0 || (bucket_cols > 0) != (bucket_rows > 0)) {
    msg << "bucket_cols and bucket_rows must both be > 0 (bucketing) or both 0, got " << bucket_cols
        << " x " << bucket_rows;
  } else if (max_per_bucket < 1) {
    msg << "max_per_bucket must be >= 1, got " << max_per_bucket;
  }
  if (msg.tellp() != 0) return Fail(msg, error);
  switch (type) {
    case DetectorType::kHarris:
      return harris.IsValid(error);
    case DetectorType::kSift:
      return sift.IsValid(error);
  }
  return true;
}

bool HarrisResponse(const cv::Mat& image, const HarrisOptions& options, cv::Mat* response,
                    bool allow_avx2) {
  if (response == nullptr || image.empty() || image.type() != CV_8UC1 ||
      !options.IsValid(nullptr)) {
    return false;
  }
  if (options.aperture_size == 3 && options.block_size <= kFastHarrisMaxBlock) {
    cv::Mat dx, dy;
    std::vector<int> sums;
    FastHarris(image, options.block_size, options.k, allow_avx2, &dx, &dy, &sums, response);
  } else {
    cv::cornerHarris(image, *response, options.block_size, options.aperture_size, options.k,
                     cv::BORDER_REFLECT_101);
  }
  return true;
}

FeatureSet FeatureDetector::DetectWithDescriptors(const cv::Mat& image) {
  FeatureSet set;
  set.features = Detect(image);
  set.keypoints.reserve(set.features.size());
  for (const Feature& f : set.features) {
    set.keypoints.emplace_back(
        cv::Point2f(static_cast<float>(f.uv_px.x()), static_cast<float>(f.uv_px.y())),
        /*size=*/1.0f, /*angle=*/-1.0f, static_cast<float>(f.response));
  }
  return set;
}

std::unique_ptr<FeatureDetector> CreateFeatureDetector(const DetectorOptions& options,
                                                       std::string* error) {
  std::string why;
  if (!options.IsValid(&why)) {
    if (error) *error = "invalid DetectorOptions: " + why;
    return nullptr;
  }
  switch (options.type) {
    case DetectorType::kHarris:
      return std::make_unique<HarrisDetector>(options);
    case DetectorType::kSift:
      return std::make_unique<SiftDetector>(options);
  }
  return nullptr;
}

std::vector<int> SelectFeatures(const std::vector<Feature>& sorted_features,
                                const cv::Size& image_size, const DetectorOptions& options) {
  std::vector<int> keep;
  const size_t limit =
      options.max_features > 0 ? static_cast<size_t>(options.max_features) : sorted_features.size();
  const bool bucketing = options.bucket_cols > 0 && options.bucket_rows > 0;
  if (!bucketing) {
    keep.resize(std::min(limit, sorted_features.size()));
    std::iota(keep.begin(), keep.end(), 0);
    return keep;
  }
  // Grid over the region features may occupy: [margin, size - margin).
  const int margin = options.border_margin_px;
  const double cell_w =
      std::max(1.0, static_cast<double>(image_size.width - 2 * margin)) / options.bucket_cols;
  const double cell_h =
      std::max(1.0, static_cast<double>(image_size.height - 2 * margin)) / options.bucket_rows;
  std::vector<int> count(static_cast<size_t>(options.bucket_cols) * options.bucket_rows, 0);
  for (int i = 0; i < static_cast<int>(sorted_features.size()) && keep.size() < limit; ++i) {
    const Eigen::Vector2d& uv = sorted_features[i].uv_px;
    if (!uv.allFinite()) continue;
    const int cx = std::clamp(static_cast<int>(std::floor((uv.x() - margin) / cell_w)), 0,
                              options.bucket_cols - 1);
    const int cy = std::clamp(static_cast<int>(std::floor((uv.y() - margin) / cell_h)), 0,
                              options.bucket_rows - 1);
    int& n = count[static_cast<size_t>(cy) * options.bucket_cols + cx];
    if (n >= options.max_per_bucket) continue;
    ++n;
    keep.push_back(i);
  }
  return keep;
}

}  // namespace vo
