#include "vo/front_end.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "vo/options_check.h"

namespace vo {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

DetectorOptions DefaultOdometryDetectorOptions() {
  DetectorOptions options;
  options.type = DetectorType::kHarris;
  options.max_features = 300;
  options.bucket_cols = 8;
  options.bucket_rows = 6;
  options.max_per_bucket = 10;
  // A lower relative threshold than the detector's 0.01: one bright ceiling light or door
  // edge otherwise sets the bar so high that a weakly textured wall in front of the camera
  // yields 10-15 corners and tracking is lost (seen on the L-hallway's corner approach).
  options.harris.quality_level = 0.001;
  return options;
}

DisparityOptions DefaultOdometryDisparityOptions() {
  DisparityOptions options;
  // The same correlation as cv::StereoBM, with the left-right check's right view taken from
  // the same cost volume instead of a second pass (vo/sad_block_matcher.h).
  options.algorithm = DisparityAlgorithm::kBlockMatchingOneVolume;
  return options;
}

bool FrontEndOptions::IsValid(std::string* error) const {
  DisparityOptions disparity_checked = disparity;
  if (derive_num_disparities) disparity_checked.num_disparities = 16;  // replaced later
  if (!PartIsValid(detector, "detector", error) ||
      !PartIsValid(disparity_checked, "disparity", error) || !PartIsValid(depth, "depth", error)) {
    return false;
  }
  std::ostringstream msg;
  if (!(disparity_min_depth_m > 0.0) || !std::isfinite(disparity_min_depth_m)) {
    msg << "disparity_min_depth_m must be finite and > 0, got " << disparity_min_depth_m;
  } else if (max_num_disparities < 16 || max_num_disparities % 16 != 0) {
    msg << "max_num_disparities must be a multiple of 16 and >= 16, got " << max_num_disparities;
  } else if (disparity_mode != DisparityMode::kDense &&
             disparity_mode != DisparityMode::kAtFeatures) {
    msg << "disparity_mode: unknown value " << static_cast<int>(disparity_mode);
  } else if (disparity_mode == DisparityMode::kAtFeatures &&
             disparity.algorithm != DisparityAlgorithm::kBlockMatchingOneVolume) {
    msg << "disparity_mode at_features needs disparity.algorithm "
        << ToString(DisparityAlgorithm::kBlockMatchingOneVolume) << " (got "
        << ToString(disparity.algorithm) << "); use disparity_mode dense with it";
  } else if (!(disparity_range_margin >= 0.0) || !std::isfinite(disparity_range_margin) ||
             !(disparity_range_margin_px >= 0.0) || !std::isfinite(disparity_range_margin_px)) {
    msg << "disparity_range_margin and disparity_range_margin_px must be finite and >= 0, got "
        << disparity_range_margin << " and " << disparity_range_margin_px;
  } else if (adaptive_min_features < 0) {
    msg << "adaptive_min_features must be >= 0 (0 = off), got " << adaptive_min_features;
  } else if (!(adaptive_quality_level >= 0.0 && adaptive_quality_level < 1.0)) {
    msg << "adaptive_quality_level must be in [0, 1), got " << adaptive_quality_level;
  } else if (min_features < 3) {
    msg << "min_features must be >= 3, got " << min_features;
  }
  return NoBrokenRule(msg, error);
}

int DerivedNumDisparities(const StereoCamera& camera, const FrontEndOptions& options) {
  const double needed = camera.fx_px * camera.baseline_m / options.disparity_min_depth_m;
  const int width_cap = std::max(16, (camera.width - 1) / 16 * 16);
  const int cap = std::min(options.max_num_disparities, width_cap);
  // Clamped in floating point first: an absurd camera (huge fx · baseline) must not overflow.
  const double blocks = std::ceil(std::min(needed, static_cast<double>(cap)) / 16.0);
  const int n = std::min(static_cast<int>(blocks) * 16, cap);
  return std::max(16, n);
}

std::unique_ptr<FrontEnd> FrontEnd::Create(const StereoCamera& camera,
                                           const FrontEndOptions& options, std::string* error) {
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

FrontEnd::FrontEnd(const StereoCamera& camera, const FrontEndOptions& options)
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

int SceneNumDisparities(const std::vector<Feature>& features, const FrontEndOptions& options) {
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
