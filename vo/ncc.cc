#include "vo/ncc.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace vo {
namespace {

constexpr int kMaxWindowPx = 63;  // upper bound of NccOptions::window_px
constexpr int kLanes = 8;         // patch stride granularity (floats), for vectorised dots

// Programmer errors abort with a message (no exceptions across the vo API).
void CheckOrDie(bool ok, const char* message) {
  if (ok) return;
  std::fprintf(stderr, "vo/ncc: %s\n", message);
  std::abort();
}

// Nearest pixel of a sub-pixel position.
inline cv::Point NearestPixel(const Eigen::Vector2d& uv_px) {
  return cv::Point(static_cast<int>(std::lround(uv_px.x())),
                   static_cast<int>(std::lround(uv_px.y())));
}

inline bool PatchInside(const cv::Mat& image, const cv::Point& c, int half) {
  return c.x - half >= 0 && c.y - half >= 0 && c.x + half < image.cols && c.y + half < image.rows;
}

// Dot product of two float arrays whose length is a multiple of kLanes. The lane-wise partial
// sums let the compiler vectorise without reassociating a scalar reduction.
inline float DotLanes(const float* a, const float* b, int n) {
  float acc[kLanes] = {0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f};
  for (int k = 0; k < n; k += kLanes) {
    for (int l = 0; l < kLanes; ++l) acc[l] += a[k + l] * b[k + l];
  }
  return ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
}

}  // namespace

bool NccOptions::IsValid(std::string* error) const {
  auto fail = [error](const char* message) {
    if (error != nullptr) *error = message;
    return false;
  };
  if (window_px < 3 || window_px > kMaxWindowPx || window_px % 2 == 0) {
    return fail("NccOptions::window_px must be odd and in [3, 63]");
  }
  if (!(min_stddev >= 0.0) || !std::isfinite(min_stddev)) {
    return fail("NccOptions::min_stddev must be finite and >= 0");
  }
  return true;
}

double NccScore(const cv::Mat& image_a, const Eigen::Vector2d& center_a, const cv::Mat& image_b,
                const Eigen::Vector2d& center_b, const NccOptions& options, NccStatus* status) {
  CheckOrDie(image_a.type() == CV_8UC1 && image_b.type() == CV_8UC1,
             "NccScore needs CV_8UC1 images");
  const int half = options.window_px / 2;
  const cv::Point ca = NearestPixel(center_a);
  const cv::Point cb = NearestPixel(center_b);
  NccStatus s = NccStatus::kOk;
  if (!PatchInside(image_a, ca, half) || !PatchInside(image_b, cb, half)) {
    s = NccStatus::kOutOfBounds;
  }
  double score = 0.0;
  if (s == NccStatus::kOk) {
    // Means, then the centred sums of eq. (2).
    const double n = static_cast<double>(options.window_px) * options.window_px;
    double sum_a = 0.0, sum_b = 0.0;
    for (int dy = -half; dy <= half; ++dy) {
      const uint8_t* ra = image_a.ptr<uint8_t>(ca.y + dy);
      const uint8_t* rb = image_b.ptr<uint8_t>(cb.y + dy);
      for (int dx = -half; dx <= half; ++dx) {
        sum_a += ra[ca.x + dx];
        sum_b += rb[cb.x + dx];
      }
    }
    const double mean_a = sum_a / n, mean_b = sum_b / n;
    double saa = 0.0, sbb = 0.0, sab = 0.0;
    for (int dy = -half; dy <= half; ++dy) {
      const uint8_t* ra = image_a.ptr<uint8_t>(ca.y + dy);
      const uint8_t* rb = image_b.ptr<uint8_t>(cb.y + dy);
      for (int dx = -half; dx <= half; ++dx) {
        const double a = ra[ca.x + dx] - mean_a, b = rb[cb.x + dx] - mean_b;
        saa += a * a;
        sbb += b * b;
        sab += a * b;
      }
    }
    const double sigma_a = std::sqrt(saa / n), sigma_b = std::sqrt(sbb / n);
    if (sigma_a < options.min_stddev || sigma_b < options.min_stddev || sigma_a == 0.0 ||
        sigma_b == 0.0) {
      s = NccStatus::kFlat;
    } else {
      // eq. (2): C = Σ(I−Ī)(T−T̄) / (2 W² σ_I σ_T) + ½
      score = std::clamp(sab / (2.0 * n * sigma_a * sigma_b) + 0.5, 0.0, 1.0);
    }
  }
  if (status != nullptr) *status = s;
  return score;
}

void NccPatches::Compute(const cv::Mat& image, const std::vector<Feature>& features,
                         const NccOptions& options) {
  CheckOrDie(image.type() == CV_8UC1, "NccPatches::Compute needs a CV_8UC1 image");
  options_ = options;
  const int w = options.window_px, half = w / 2, n = w * w;
  stride_ = (n + kLanes - 1) / kLanes * kLanes;
  data_.assign(features.size() * static_cast<size_t>(stride_), 0.f);
  status_.assign(features.size(), NccStatus::kOk);
  for (size_t i = 0; i < features.size(); ++i) {
    const cv::Point c = NearestPixel(features[i].uv_px);
    if (!PatchInside(image, c, half)) {
      status_[i] = NccStatus::kOutOfBounds;
      continue;
    }
    float* patch = data_.data() + i * stride_;
    // Copy the W×W window; integer sum for the mean.
    int sum = 0;
    for (int dy = -half, k = 0; dy <= half; ++dy) {
      const uint8_t* row = image.ptr<uint8_t>(c.y + dy) + c.x - half;
      for (int dx = 0; dx < w; ++dx, ++k) {
        patch[k] = row[dx];
        sum += row[dx];
      }
    }
    // Zero mean, then unit norm: ρ of two such patches is their dot product.
    const float mean = static_cast<float>(sum) / static_cast<float>(n);
    double ss = 0.0;
    for (int k = 0; k < n; ++k) {
      patch[k] -= mean;
      ss += static_cast<double>(patch[k]) * patch[k];
    }
    const double sigma = std::sqrt(ss / n);
    if (sigma < options.min_stddev || sigma == 0.0) {
      status_[i] = NccStatus::kFlat;
      std::fill(patch, patch + stride_, 0.f);
      continue;
    }
    const float inv_norm = static_cast<float>(1.0 / std::sqrt(ss));
    for (int k = 0; k < n; ++k) patch[k] *= inv_norm;
  }
}

double NccPatches::Correlation(int i, const NccPatches& other, int j) const {
  if (status_[i] != NccStatus::kOk || other.status_[j] != NccStatus::kOk) return 0.0;
  CheckOrDie(stride_ == other.stride_, "NccPatches: patch sets of different window sizes");
  const double rho = DotLanes(data_.data() + static_cast<size_t>(i) * stride_,
                              other.data_.data() + static_cast<size_t>(j) * other.stride_, stride_);
  return std::clamp(rho, -1.0, 1.0);
}

double NccPatches::Score(int i, const NccPatches& other, int j) const {
  if (status_[i] != NccStatus::kOk || other.status_[j] != NccStatus::kOk) return 0.0;
  // eq. (2) in the normalised form: C = ½ ρ + ½.
  return 0.5 * Correlation(i, other, j) + 0.5;
}

}  // namespace vo
