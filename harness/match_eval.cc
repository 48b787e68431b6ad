#include "harness/match_eval.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>

#include "harness/trajectory_io.h"

namespace harness {
namespace {

// Ground-truth depth at the feature's pixel, or 0 when missing or ambiguous (depth edge).
double FeatureDepth(const cv::Mat& depth, const Eigen::Vector2d& uv, double ambiguous_rel) {
  const int c = static_cast<int>(std::lround(uv.x()));
  const int r = static_cast<int>(std::lround(uv.y()));
  if (r < 1 || c < 1 || r >= depth.rows - 1 || c >= depth.cols - 1) return 0.0;
  const double z = depth.at<float>(r, c);
  if (!(z > 0)) return 0.0;
  double lo = z, hi = z;
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc) {
      const double v = depth.at<float>(r + dr, c + dc);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  return hi - lo > ambiguous_rel * z ? 0.0 : z;
}

struct FrameFeatures {
  vo::MatchFrame frame;
  std::vector<double> gt_depth;  // per feature; 0 = left out
};

bool Prepare(const GroundTruthFrame& gt, int64_t id, vo::FeatureDetector* detector,
             vo::DisparityEstimator* disparity, const vo::StereoCamera& camera,
             const MatchEvalOptions& o, FrameFeatures* out, std::string* error) {
  vo::FeatureSet set = detector->DetectWithDescriptors(gt.left);
  const vo::DisparityResult disp = disparity->Compute(gt.left, gt.right);
  if (!disp.ok) {
    *error = "disparity: " + disp.message;
    return false;
  }
  vo::AttachDepth(disp.disparity_px, camera, &set.features, o.depth);
  // Drop features without stereo depth (as the VO does), keeping descriptor rows aligned.
  out->frame = vo::MatchFrame();
  out->frame.frame_id = id;
  out->frame.image = gt.left;
  out->gt_depth.clear();
  cv::Mat descriptors;
  for (size_t i = 0; i < set.features.size(); ++i) {
    if (!set.features[i].has_depth()) continue;
    out->frame.features.push_back(set.features[i]);
    if (!set.descriptors.empty()) descriptors.push_back(set.descriptors.row(static_cast<int>(i)));
    out->gt_depth.push_back(FeatureDepth(gt.depth_m, set.features[i].uv_px, o.ambiguous_depth_rel));
  }
  out->frame.descriptors = descriptors;
  return true;
}

}  // namespace

bool MatchEvalOptions::IsValid(std::string* error) const {
  std::string why;
  if (strides.empty()) why = "strides: need at least one";
  for (int s : strides)
    if (s < 1) why = "strides: each must be >= 1";
  if (matchers.empty()) why = "matchers: need at least one";
  if (!(correct_px > 0)) why = "correct_px: must be > 0";
  if (why.empty() && !detector.IsValid(&why)) why = "detector: " + why;
  if (why.empty() && !disparity.IsValid(&why)) why = "disparity: " + why;
  if (why.empty()) return true;
  if (error) *error = why;
  return false;
}

bool ProjectGroundTruth(const vo::StereoCamera& camera, const GroundTruthFrame& a,
                        const GroundTruthFrame& b, const Eigen::Vector2d& uv_px, double depth_m,
                        double depth_agree_rel, Eigen::Vector2d* uv_b_px) {
  const Eigen::Vector3d p_a = camera.BackprojectDepth(uv_px.x(), uv_px.y(), depth_m);
  const Eigen::Vector3d p_b = b.T_world_cam0.inverse() * (a.T_world_cam0 * p_a);
  if (!camera.ProjectLeft(p_b, uv_b_px, 0.05)) return false;
  const int c = static_cast<int>(std::lround(uv_b_px->x()));
  const int r = static_cast<int>(std::lround(uv_b_px->y()));
  if (r < 0 || c < 0 || r >= b.depth_m.rows || c >= b.depth_m.cols) return false;
  const double z = b.depth_m.at<float>(r, c);
  return z > 0 && std::abs(z - p_b.z()) <= depth_agree_rel * p_b.z() + 0.01;
}

bool EvaluateMatchers(const std::vector<GroundTruthFrame>& frames, const vo::StereoCamera& camera,
                      const MatchEvalOptions& o, std::vector<MatchEvalRow>* rows,
                      std::string* error, const std::function<void(int, int)>& progress) {
  if (!o.IsValid(error)) return false;
  if (frames.size() < 2) {
    *error = "need at least 2 frames";
    return false;
  }
  // Features of every frame, once per detector kind (Harris-type and SIFT).
  std::vector<FrameFeatures> harris(frames.size()), sift;
  bool need_sift = false;
  for (auto m : o.matchers) need_sift |= m == vo::MatcherType::kSiftRatio;
  int total = static_cast<int>(frames.size()) * (need_sift ? 2 : 1);
  for (int s : o.strides)
    total += static_cast<int>(o.matchers.size()) * static_cast<int>((frames.size() - 1) / s);
  int done = 0;
  vo::DisparityEstimator disparity(o.disparity);
  for (int pass = 0; pass < (need_sift ? 2 : 1); ++pass) {
    vo::DetectorOptions d = o.detector;
    if (pass == 1) d.type = vo::DetectorType::kSift;
    auto detector = vo::CreateFeatureDetector(d, error);
    if (!detector) return false;
    std::vector<FrameFeatures>& out = pass == 0 ? harris : sift;
    out.resize(frames.size());
    for (size_t k = 0; k < frames.size(); ++k) {
      if (!Prepare(frames[k], static_cast<int64_t>(k), detector.get(), &disparity, camera, o,
                   &out[k], error))
        return false;
      if (progress) progress(++done, total);
    }
  }

  rows->clear();
  for (vo::MatcherType type : o.matchers) {
    std::vector<FrameFeatures>& feats = type == vo::MatcherType::kSiftRatio ? sift : harris;
    for (int s : o.strides) {
      vo::MatcherOptions mo = o.matcher;
      mo.type = type;
      auto matcher = vo::CreateFrameMatcher(mo, error);
      if (!matcher) return false;
      MatchEvalRow row;
      row.matcher = vo::ToString(type);
      row.stride = s;
      double ms = 0.0;
      for (size_t k = 0; k + s < frames.size(); k += s) {
        const FrameFeatures& a = feats[k];
        const FrameFeatures& b = feats[k + s];
        // The same prediction for every matcher: constant velocity from the previous pair.
        vo::MatchPrediction prediction;
        if (o.prediction == vo::PredictionMode::kMotionPrior && k >= static_cast<size_t>(s)) {
          prediction.radius_scale = o.prediction_radius_scale;
          const Eigen::Isometry3d T_ref_curr =
              frames[k - s].T_world_cam0.inverse() * frames[k].T_world_cam0;
          prediction.uv_px =
              vo::PredictFeaturePositions(camera, a.frame.features, T_ref_curr, 1e-6);
        }
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<vo::Match> matches = matcher->MatchFrames(a.frame, b.frame, prediction);
        ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                  .count();
        // Ground-truth position in frame k+s of each evaluated feature of frame k.
        std::vector<Eigen::Vector2d> gt(a.frame.features.size());
        std::vector<int> status(a.frame.features.size(), 0);  // 0 left out, 1 invisible, 2 visible
        for (size_t i = 0; i < a.frame.features.size(); ++i) {
          if (a.gt_depth[i] <= 0) continue;
          status[i] =
              ProjectGroundTruth(camera, frames[k], frames[k + s], a.frame.features[i].uv_px,
                                 a.gt_depth[i], o.depth_agree_rel, &gt[i])
                  ? 2
                  : 1;
          if (status[i] == 2) {
            for (const auto& f : b.frame.features)
              if ((f.uv_px - gt[i]).norm() <= o.correct_px) {
                ++row.possible;
                break;
              }
          }
        }
        for (const vo::Match& m : matches) {
          if (status[m.prev] == 0) continue;
          ++row.matches;
          if (status[m.prev] == 2 &&
              (b.frame.features[m.curr].uv_px - gt[m.prev]).norm() <= o.correct_px)
            ++row.correct;
        }
        ++row.pairs;
        if (progress) progress(++done, total);
      }
      row.precision = row.matches > 0 ? static_cast<double>(row.correct) / row.matches : 0.0;
      row.recall = row.possible > 0 ? static_cast<double>(row.correct) / row.possible : 0.0;
      row.f1 = row.precision + row.recall > 0
                   ? 2 * row.precision * row.recall / (row.precision + row.recall)
                   : 0.0;
      row.ms_per_pair = row.pairs > 0 ? ms / row.pairs : 0.0;
      rows->push_back(row);
    }
  }
  return true;
}

void AccumulateVoMatchStats(const vo::StereoCamera& camera, const GroundTruthFrame& reference,
                            const GroundTruthFrame& current,
                            const std::vector<vo::Feature>& reference_features,
                            const std::vector<vo::Feature>& features,
                            const std::vector<vo::Match>& matches,
                            const std::vector<bool>& inlier_mask, const MatchEvalOptions& o,
                            VoMatchStats* stats) {
  if (reference.depth_m.empty() || current.depth_m.empty() || matches.empty()) return;
  bool any = false;
  for (size_t k = 0; k < matches.size(); ++k) {
    const vo::Match& m = matches[k];
    if (m.prev < 0 || m.curr < 0 || m.prev >= static_cast<int>(reference_features.size()) ||
        m.curr >= static_cast<int>(features.size()))
      continue;
    const Eigen::Vector2d& uv = reference_features[m.prev].uv_px;
    const double z = FeatureDepth(reference.depth_m, uv, o.ambiguous_depth_rel);
    if (z <= 0.0) continue;
    Eigen::Vector2d uv_gt;
    const bool correct =
        ProjectGroundTruth(camera, reference, current, uv, z, o.depth_agree_rel, &uv_gt) &&
        (features[m.curr].uv_px - uv_gt).norm() <= o.correct_px;
    const bool inlier = k < inlier_mask.size() && inlier_mask[k];
    ++stats->matches;
    stats->correct += correct;
    stats->inliers += inlier;
    stats->inliers_correct += inlier && correct;
    any = true;
  }
  stats->frames += any;
}

bool WriteMatchEvalCsv(const std::string& path, const std::vector<MatchEvalRow>& rows,
                       std::string* error) {
  std::ostringstream out;
  out << "matcher,stride,pairs,matches,correct,possible,precision,recall,f1,ms_per_pair\n";
  char buf[256];
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof(buf), "%s,%d,%d,%ld,%ld,%ld,%.4f,%.4f,%.4f,%.3f\n", r.matcher.c_str(),
                  r.stride, r.pairs, r.matches, r.correct, r.possible, r.precision, r.recall, r.f1,
                  r.ms_per_pair);
    out << buf;
  }
  return WriteTextFile(path, out.str(), error);
}

}  // namespace harness
