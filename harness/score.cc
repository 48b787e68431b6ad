#include "harness/score.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "harness/metric_registry.h"
#include "harness/output_folder.h"
#include "harness/trajectory_io.h"

namespace harness {

namespace {

using json = nlohmann::ordered_json;

// "0.1 .. 4.2 s" of a stream's stamps (for the message of streams that do not overlap).
std::string StampRange(const std::vector<StampedPose>& poses) {
  double lo = poses.front().time_s, hi = lo;
  for (const StampedPose& p : poses) {
    lo = std::min(lo, p.time_s);
    hi = std::max(hi, p.time_s);
  }
  return FormatDouble(lo) + " .. " + FormatDouble(hi) + " s";
}

bool ReadPoses(const std::string& path, TrajectoryFormat format, std::vector<StampedPose>* poses,
               std::string* error) {
  if (format == TrajectoryFormat::kTum) return ReadTum(path, poses, error);
  std::vector<Eigen::Isometry3d> kitti;
  if (!ReadKittiPoses(path, &kitti, error)) return false;
  poses->clear();
  for (size_t i = 0; i < kitti.size(); ++i) poses->push_back({static_cast<double>(i), kitti[i]});
  return true;
}

}  // namespace

bool ParseTrajectoryFormat(const std::string& text, TrajectoryFormat* format) {
  if (text == "tum") {
    *format = TrajectoryFormat::kTum;
    return true;
  }
  if (text == "kitti") {
    *format = TrajectoryFormat::kKitti;
    return true;
  }
  return false;
}

const char* ToString(TrajectoryFormat format) {
  return format == TrajectoryFormat::kTum ? "tum" : "kitti";
}

bool ScoreOptions::IsValid(std::string* error) const {
  if (!(max_difference_s > 0.0)) {
    *error = "max difference: expected seconds > 0, got " + FormatDouble(max_difference_s);
    return false;
  }
  return true;
}

bool ScoreTrajectory(const std::string& name, const std::string& ground_truth_path,
                     const std::string& estimate_path, const ScoreOptions& options,
                     ScoreResult* result, std::string* error) {
  if (!options.IsValid(error)) return false;
  std::vector<StampedPose> gt, est;
  if (!ReadPoses(ground_truth_path, options.format, &gt, error) ||
      !ReadPoses(estimate_path, options.format, &est, error))
    return false;
  for (const auto& [path, poses] : {std::pair{&ground_truth_path, &gt}, {&estimate_path, &est}})
    if (poses->size() < 2) {
      *error = *path + ": " + std::to_string(poses->size()) +
               " pose(s); at least 2 are needed to measure a trajectory";
      return false;
    }
  std::vector<Eigen::Isometry3d> est_matched, gt_matched;
  if (options.format == TrajectoryFormat::kKitti) {
    if (est.size() != gt.size()) {
      *error = estimate_path + ": " + std::to_string(est.size()) + " poses, but " +
               ground_truth_path + " has " + std::to_string(gt.size()) +
               "; KITTI poses have no time stamps and are paired line by line, so both files "
               "must hold the same frames";
      return false;
    }
    for (size_t i = 0; i < est.size(); ++i) {
      est_matched.push_back(est[i].T_world_cam);
      gt_matched.push_back(gt[i].T_world_cam);
    }
  } else {
    AssociateOptions associate;
    associate.max_difference_s = options.max_difference_s;
    std::vector<StampedPose> e, g;
    AssociatePoses(est, gt, associate, &e, &g);
    if (e.empty()) {
      *error = estimate_path + ": no time stamp within " + FormatDouble(options.max_difference_s) +
               " s of one in " + ground_truth_path + " (estimate " + StampRange(est) +
               ", ground truth " + StampRange(gt) +
               "); no time overlap: are both in seconds of the same clock?";
      return false;
    }
    if (e.size() < 2) {
      *error = estimate_path + ": only 1 pose within " + FormatDouble(options.max_difference_s) +
               " s of one in " + ground_truth_path + "; at least 2 are needed";
      return false;
    }
    for (size_t i = 0; i < e.size(); ++i) {
      est_matched.push_back(e[i].T_world_cam);
      gt_matched.push_back(g[i].T_world_cam);
    }
  }
  ScoreResult r;
  r.format = options.format;
  r.max_difference_s = options.format == TrajectoryFormat::kTum ? options.max_difference_s : 0.0;
  r.estimate_poses = est.size();
  r.ground_truth_poses = gt.size();
  RunSummary& s = r.summary;
  s.name = name;
  s.has_ground_truth = true;
  s.ground_truth_frames = static_cast<int>(est_matched.size());
  s.metrics = ComputeTrajectoryMetrics(est_matched, gt_matched);
  s.metrics.frames = static_cast<int>(est_matched.size());
  *result = r;
  return true;
}

std::string ScoreMetricsJson(const ScoreResult& r) {
  json j;
  j["name"] = r.summary.name;
  j["format"] = ToString(r.format);
  j["estimate_poses"] = r.estimate_poses;
  j["ground_truth_poses"] = r.ground_truth_poses;
  if (r.format == TrajectoryFormat::kTum) j["max_difference_s"] = r.max_difference_s;
  j["ground_truth_frames"] = r.summary.ground_truth_frames;
  for (const MetricInfo& m : RunMetrics())
    if (m.group == MetricGroup::kAccuracy && MetricWritten(m, r.summary)) {
      const size_t dot = m.key.find('.');  // "a.b" nested, as metrics.json writes it
      if (dot == std::string::npos)
        j[m.key] = m.value(r.summary);
      else
        j[m.key.substr(0, dot)][m.key.substr(dot + 1)] = m.value(r.summary);
    }
  return j.dump(2) + "\n";
}

bool WriteScoreFolder(const ScoreResult& result, const std::string& dir, std::string* error) {
  OutputFolder folder;
  return folder.Create(dir, "score", error) &&
         WriteTextFile(folder.path() + "/metrics.json", ScoreMetricsJson(result), error) &&
         folder.Publish(error);
}

}  // namespace harness
