#include "vo/front_end.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

namespace vo {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

std::unique_ptr<FrontEnd> FrontEnd::Create(const StereoCamera& camera,
                                           const OdometryOptions& options, std::string* error) {
  std::unique_ptr<FrontEnd> front(new FrontEnd(camera, options));
  std::string why;
  front->detector_ = CreateFeatureDetector(options.detector, &why);
  if (front->detector_ && options.adaptive_min_features > 0 &&
      options.detector.type == DetectorType::kHarris) {
    DetectorOptions weak = options.detector;
    weak.harris.quality_level =
        std::min(options.detector.harris.quality_level, options.adaptive_quality_level);
    front->weak_detector_ = CreateFeatureDetector(weak, &why);
  }
  if (!front->detector_) {
    if (error) *error = why;
    return nullptr;
  }
  return front;
}

FrontEnd::FrontEnd(const StereoCamera& camera, const OdometryOptions& options)
    : camera_(camera),
      depth_(options.depth),
      adaptive_min_features_(options.adaptive_min_features),
      disparity_(std::make_unique<DisparityEstimator>(options.disparity)) {}

FrontEndFrame FrontEnd::Process(const cv::Mat& left, const cv::Mat& right, int num_disparities,
                                bool dense, OdometryResult* result) {
  FrontEndFrame out;
  result->num_disparities = num_disparities;
  Clock::time_point t = Clock::now();
  const DisparityResult disparity = dense
                                        ? disparity_->Compute(left, right, num_disparities)
                                        : disparity_->PrepareAtPixels(left, right, num_disparities);
  result->times.disparity_ms = ElapsedMs(t);
  if (!disparity.ok) {
    out.message = "disparity: " + disparity.message;
    return out;
  }
  out.disparity_px = disparity.disparity_px;

  // Features in the left image.
  t = Clock::now();
  FeatureSet set = detector_->DetectWithDescriptors(left);
  if (weak_detector_ && static_cast<int>(set.features.size()) < adaptive_min_features_) {
    // A weakly textured view: detect again with the lower relative threshold.
    FeatureSet more = weak_detector_->DetectWithDescriptors(left);
    if (more.features.size() > set.features.size()) set = std::move(more);
  }
  result->times.detect_ms = ElapsedMs(t);
  result->num_features = static_cast<int>(set.features.size());

  // Depth from the disparity map; features without depth are dropped (with their descriptors).
  t = Clock::now();
  if (dense) {
    AttachDepth(disparity.disparity_px, camera_, &set.features, depth_);
    result->disparity_pixels = camera_.width * camera_.height;
  } else {
    AttachDepth(disparity_.get(), camera_, &set.features, depth_);
    const DisparityEstimator::PixelCounts counts = disparity_->pixel_counts();
    result->disparity_pixels = counts.left + counts.right;
    result->times.disparity_ms += ElapsedMs(t);  // the evaluation is the disparity stage's work
    t = Clock::now();
  }
  MatchFrame& frame = out.frame;
  std::vector<int> kept;
  for (size_t i = 0; i < set.features.size(); ++i) {
    if (set.features[i].has_depth() && set.features[i].p_cam0.allFinite()) {
      kept.push_back(static_cast<int>(i));
    }
  }
  frame.features.reserve(kept.size());
  for (int i : kept) frame.features.push_back(set.features[i]);
  if (!set.descriptors.empty()) {
    frame.descriptors.create(static_cast<int>(kept.size()), set.descriptors.cols,
                             set.descriptors.type());
    for (size_t k = 0; k < kept.size(); ++k) {
      set.descriptors.row(kept[k]).copyTo(frame.descriptors.row(static_cast<int>(k)));
    }
  }
  result->times.depth_ms = ElapsedMs(t);
  result->num_features_with_depth = static_cast<int>(frame.features.size());
  out.ok = true;
  return out;
}

int SceneNumDisparities(const std::vector<Feature>& features, const OdometryOptions& options) {
  if (!options.disparity_range_from_scene) return 0;
  double max_disparity = 0.0;
  for (const Feature& f : features) {
    if (f.has_depth()) max_disparity = std::max(max_disparity, f.disparity_px);
  }
  const double wanted =
      max_disparity * (1.0 + options.disparity_range_margin) + options.disparity_range_margin_px;
  const int n = 16 * static_cast<int>(std::ceil(wanted / 16.0));
  if (max_disparity > 0.0 && n < options.disparity.num_disparities) return std::max(16, n);
  return 0;
}

std::vector<Feature> KeepFeaturesWithDepth(const StereoCamera& camera,
                                           const std::vector<Feature>& features,
                                           std::vector<int>* index_map) {
  index_map->assign(features.size(), -1);
  std::vector<Feature> kept;
  for (size_t i = 0; i < features.size(); ++i) {
    Feature f = features[i];
    if (!f.uv_px.allFinite() || !std::isfinite(f.disparity_px) || !f.has_depth()) continue;
    f.p_cam0 = camera.Backproject(f.uv_px.x(), f.uv_px.y(), f.disparity_px);
    if (!f.p_cam0.allFinite()) continue;
    f.track_id = -1;
    f.track_age = 0;
    (*index_map)[i] = static_cast<int>(kept.size());
    kept.push_back(f);
  }
  return kept;
}

std::vector<Match> ReindexMatches(const std::vector<Match>& matches,
                                  const std::vector<int>& prev_index_map,
                                  const std::vector<int>& curr_index_map, size_t num_prev_kept,
                                  size_t num_curr_kept) {
  std::vector<Match> out;
  std::vector<bool> prev_used(num_prev_kept, false);
  std::vector<bool> curr_used(num_curr_kept, false);
  for (const Match& m : matches) {
    if (m.prev < 0 || m.prev >= static_cast<int>(prev_index_map.size()) || m.curr < 0 ||
        m.curr >= static_cast<int>(curr_index_map.size())) {
      continue;
    }
    const int p = prev_index_map[m.prev];
    const int c = curr_index_map[m.curr];
    if (p < 0 || c < 0 || prev_used[p] || curr_used[c]) continue;
    prev_used[p] = curr_used[c] = true;
    out.push_back(Match{p, c, m.score});
  }
  std::sort(out.begin(), out.end(), [](const Match& a, const Match& b) { return a.prev < b.prev; });
  return out;
}

}  // namespace vo
