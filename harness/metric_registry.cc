#include "harness/metric_registry.h"

#include <algorithm>
#include <cmath>

namespace harness {
namespace {

using json = nlohmann::ordered_json;
using Getter = std::function<json(const RunSummary&)>;

MetricInfo Metric(std::string key, std::string unit, Better better, MetricGroup group,
                  std::string meaning, Getter value) {
  MetricInfo m;
  m.key = std::move(key);
  m.unit = std::move(unit);
  m.better = better;
  m.group = group;
  m.meaning = std::move(meaning);
  m.value = std::move(value);
  return m;
}

// A figure that may not apply: NaN is null in metrics.json.
json NumberOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// The reason entry `key` (a text, written only when not empty) of the figures before it.
MetricInfo Reason(std::string key, MetricGroup group, std::string meaning,
                  std::function<std::string(const RunSummary&)> text) {
  MetricInfo m = Metric(std::move(key), "", Better::kNeither, group, std::move(meaning),
                        [text](const RunSummary& s) { return json(text(s)); });
  m.reason = true;
  return m;
}

// An accuracy metric (needs ground truth, lower is better): may be tune's objective; checked
// by `check` when `tolerance` >= 0.
MetricInfo Accuracy(std::string key, std::string unit, std::string meaning,
                    double TrajectoryMetrics::*field, double tolerance = -1.0) {
  MetricInfo m = Metric(std::move(key), std::move(unit), Better::kLower, MetricGroup::kAccuracy,
                        std::move(meaning),
                        [field](const RunSummary& s) { return NumberOrNull(s.metrics.*field); });
  m.tune_objective = true;
  m.check_tolerance = tolerance;
  return m;
}

// `m`, compared by `check` with the absolute tolerance floor `tolerance`.
MetricInfo Checked(MetricInfo m, double tolerance) {
  m.check_tolerance = tolerance;
  return m;
}

// The median time of a pipeline stage (the keys of RunSummary::stage_ms_median).
MetricInfo StageMedian(const std::string& stage, const std::string& what) {
  MetricInfo m =
      Metric("stage_ms_median." + stage, "ms", Better::kLower, MetricGroup::kTiming,
             "median time per frame of the " + what + " stage", [stage](const RunSummary& s) {
               const auto it = s.stage_ms_median.find(stage);
               return it == s.stage_ms_median.end() ? json(0.0) : json(it->second);
             });
  return m;
}

std::vector<MetricInfo> MakeRegistry() {
  using M = TrajectoryMetrics;
  const Better kNeither = Better::kNeither;
  const MetricGroup kRun = MetricGroup::kRun, kAcc = MetricGroup::kAccuracy,
                    kNav = MetricGroup::kNavigation;
  std::vector<MetricInfo> r = {
      Metric("frames", "frames", kNeither, kRun,
             "frames the VO saw from its first initialised one (after the frame stride)",
             [](const RunSummary& s) { return json(s.metrics.frames); }),
      Metric("frame_stride", "frames", kNeither, kRun, "the VO saw every k-th frame of the source",
             [](const RunSummary& s) { return json(s.frame_stride); }),
      Metric("has_ground_truth", "", kNeither, kRun,
             "at least 2 frames had a ground-truth pose (the accuracy metrics are written)",
             [](const RunSummary& s) { return json(s.has_ground_truth); }),
      Metric("ground_truth_frames", "frames", kNeither, kRun,
             "frames with a ground-truth pose; the accuracy metrics use these only",
             [](const RunSummary& s) { return json(s.ground_truth_frames); }),
      Metric("path_length_m", "m", kNeither, kAcc,
             "length of the ground-truth camera path (3-D, the evaluated frames)",
             [](const RunSummary& s) { return json(s.metrics.path_length_m); }),
      Accuracy("end_pose_error_m", "m",
               "position error at the last frame, both trajectories from their first pose",
               &M::end_pose_error_m, 0.01),
      Accuracy("end_pose_error_pct", "%",
               "end_pose_error_m in % of the path length (null: path shorter than 1 m)",
               &M::end_pose_error_pct),
      Reason("end_pose_error_pct_reason", kAcc, "why end_pose_error_pct is null",
             [](const RunSummary& s) { return s.metrics.end_pose_error_pct_reason; }),
      Accuracy("end_rotation_error_deg", "deg", "rotation error at the last frame",
               &M::end_rotation_error_deg, 0.25),
      Accuracy("ate_rmse_m", "m", "RMSE of the positions after SE(3) (Umeyama) alignment",
               &M::ate_rmse_m, 0.005),
      Accuracy("ate_rmse_unaligned_m", "m", "RMSE of the positions from the common start",
               &M::ate_rmse_unaligned_m),
      Accuracy("rpe_trans_rmse_m", "m", "relative pose error over one frame step: translation RMSE",
               &M::rpe_trans_rmse_m, 0.0005),
      Accuracy("rpe_rot_rmse_deg", "deg", "relative pose error over one frame step: rotation RMSE",
               &M::rpe_rot_rmse_deg),
      Metric("rpe_distance_step_m", "m", kNeither, kAcc,
             "distance step of the rpe_distance_* metrics",
             [](const RunSummary& s) { return json(s.metrics.rpe_distance_step_m); }),
      Accuracy("rpe_distance_trans_rmse_m", "m",
               "relative pose error over rpe_distance_step_m of path (evo_rpe --delta_unit m "
               "--all_pairs): translation RMSE",
               &M::rpe_distance_trans_rmse_m),
      Accuracy("rpe_distance_rot_rmse_deg", "deg",
               "relative pose error over rpe_distance_step_m of path: rotation RMSE",
               &M::rpe_distance_rot_rmse_deg),
      Metric("rpe_distance_pairs", "", kNeither, kAcc,
             "frame pairs the rpe_distance_* metrics averaged (0: none, they are null)",
             [](const RunSummary& s) { return json(s.metrics.rpe_distance_pairs); }),
      Reason("rpe_distance_reason", kAcc, "why the rpe_distance_* RMSEs are null",
             [](const RunSummary& s) { return s.metrics.rpe_distance_reason; }),
      Accuracy("drift_pct", "%",
               "vobench's drift: sub-paths of at least 1/8 ... 8/8 of the path from every 10th "
               "frame, translation error / actual sub-path length, averaged",
               &M::drift_pct, 0.25),
      Accuracy("drift_deg_per_m", "deg/m", "vobench's rotation drift, the same sub-paths",
               &M::drift_deg_per_m),
      Reason("drift_reason", kAcc, "why drift_pct and drift_deg_per_m are null",
             [](const RunSummary& s) { return s.metrics.drift_reason; }),
      Accuracy("kitti_drift_pct", "%",
               "the KITTI devkit's translation error: segments of 100..800 m (k x path/10 below "
               "1000 m of path) from every 10th frame to the first frame past L, error / L",
               &M::kitti_drift_pct),
      Accuracy("kitti_drift_deg_per_m", "deg/m",
               "the KITTI devkit's rotation error, the same segments", &M::kitti_drift_deg_per_m),
      Metric("kitti_drift_segments", "", kNeither, kAcc,
             "segments the kitti_drift_* metrics averaged (0: none, they are null)",
             [](const RunSummary& s) { return json(s.metrics.kitti_drift_segments); }),
      Reason("kitti_drift_reason", kAcc, "why the kitti_drift_* metrics are null",
             [](const RunSummary& s) { return s.metrics.kitti_drift_reason; }),
      Metric("matches_evaluated", "", kNeither, MetricGroup::kMatches,
             "VO matches checked against the ground-truth depth and poses",
             [](const RunSummary& s) { return json(s.match_stats.matches); }),
      Metric("match_precision", "", Better::kHigher, MetricGroup::kMatches,
             "share of the VO's matches that are correct (within the match-eval radius)",
             [](const RunSummary& s) { return json(s.match_stats.precision()); }),
      Metric("inlier_match_precision", "", Better::kHigher, MetricGroup::kMatches,
             "share of the RANSAC inliers that are correct",
             [](const RunSummary& s) { return json(s.match_stats.inlier_precision()); }),
      Checked(Metric("lost_frames", "frames", Better::kLower, kRun,
                     "frames without a measured motion (lost, or re-initialised at the "
                     "predicted pose)",
                     [](const RunSummary& s) { return json(s.lost_frames); }),
              2.0),
      Metric("frames_not_initialised", "frames", Better::kLower, kRun,
             "frames before the first one the VO initialised on (no pose, not evaluated)",
             [](const RunSummary& s) { return json(s.frames_not_initialised); }),
      Metric("reinitialisations", "frames", Better::kLower, kRun,
             "lost frames the VO re-initialised on",
             [](const RunSummary& s) { return json(s.reinitialisations); }),
      Metric("bridge_aligned_frames", "frames", Better::kNeither, kRun,
             "lost frames whose bridged forward step or yaw was measured against the previous "
             "frame's features (recovery.vehicle_bridge.enabled)",
             [](const RunSummary& s) { return json(s.bridge_aligned_frames); }),
      Metric("direct_motion_frames", "frames", Better::kNeither, kRun,
             "frames too poor in features for the matchers whose motion was measured by "
             "direct image alignment (recovery.vehicle_direct.enabled; not lost frames)",
             [](const RunSummary& s) { return json(s.direct_motion_frames); }),
      Metric("vo_ms_median", "ms", Better::kLower, MetricGroup::kTiming,
             "median VO time per frame (the first frame excluded)",
             [](const RunSummary& s) { return json(s.vo_ms_median); }),
      Metric("vo_ms_p95", "ms", Better::kLower, MetricGroup::kTiming,
             "95th percentile of the VO time per frame",
             [](const RunSummary& s) { return json(s.vo_ms_p95); }),
      StageMedian("ba", "bundle adjustment"),
      StageMedian("depth", "feature depth"),
      StageMedian("detect", "feature detection"),
      StageMedian("disparity", "disparity"),
      StageMedian("guided", "guided re-matching"),
      StageMedian("match", "matching"),
      StageMedian("motion", "RANSAC motion"),
      StageMedian("predict",
                  "prediction (coarse-to-fine image shift; a lost frame's bridge alignment and "
                  "direct image alignment)"),
      Metric("features_median", "", kNeither, kRun, "median number of features with depth",
             [](const RunSummary& s) { return json(s.features_median); }),
      Metric("inliers_median", "", kNeither, kRun, "median number of RANSAC inliers",
             [](const RunSummary& s) { return json(s.inliers_median); }),
      Metric("initial_orientation_ok", "", kNeither, kRun,
             "the first frame's orientation was found from the hallway's planes",
             [](const RunSummary& s) { return json(s.initial_orientation_ok); }),
      Metric("initial_orientation_error_deg", "deg", Better::kLower, kRun,
             "error of that orientation vs the gravity-aligned ground truth (null: not known)",
             [](const RunSummary& s) { return NumberOrNull(s.initial_orientation_error_deg); }),
      Reason("initial_orientation_error_reason", kRun, "why initial_orientation_error_deg is null",
             [](const RunSummary& s) { return s.initial_orientation_error_reason; }),
      Metric("initial_floor_refined", "", kNeither, kRun,
             "the first frame's floor was refined on the images (orientation_floor_refinement)",
             [](const RunSummary& s) { return json(s.initial_floor_refined); }),
      Metric("platform", "", kNeither, kRun,
             "what the VO ran as: free (6-DoF) or ground_vehicle (platform auto on a known rig)",
             [](const RunSummary& s) { return json(s.platform); }),
      // What the robot did (simulated runs; sim/navigation.h).
      Metric("navigation.mode", "", kNeither, kNav,
             "what the path follower steered on: ground_truth, or vo (the closed loop)",
             [](const RunSummary& s) { return json(s.navigation.mode); }),
      Metric("navigation.reached_goal", "", kNeither, kNav,
             "the follower believed it reached the last waypoint within max_duration_s",
             [](const RunSummary& s) { return json(s.navigation.reached_goal); }),
      Metric("navigation.end_error_m", "m", Better::kLower, kNav,
             "where the robot's wheel axle stopped vs the path's last waypoint",
             [](const RunSummary& s) { return NumberOrNull(s.navigation.end_error_m); }),
      Metric("navigation.max_waypoint_error_m", "m", Better::kLower, kNav,
             "largest true distance from a waypoint when the follower believed it was there "
             "(null: none reached)",
             [](const RunSummary& s) { return NumberOrNull(s.navigation.max_waypoint_error_m); }),
      Reason("navigation.error_reason", kNav, "why the end or waypoint error is null",
             [](const RunSummary& s) {
               if (!std::isfinite(s.navigation.end_error_m))
                 return std::string("the run ended before the robot did (--max-frames)");
               if (!std::isfinite(s.navigation.max_waypoint_error_m))
                 return std::string("the follower never believed it reached a waypoint");
               return std::string();
             }),
      Metric("navigation.wall_contacts", "", Better::kLower, kNav,
             "contact events of the robot with the building's collision geoms (MuJoCo contacts)",
             [](const RunSummary& s) {
               return s.navigation.wall_contacts < 0 ? json(nullptr)
                                                     : json(s.navigation.wall_contacts);
             }),
      Metric("navigation.wall_contact_s", "s", Better::kLower, kNav,
             "simulated time the robot touched the building",
             [](const RunSummary& s) {
               return s.navigation.wall_contacts < 0 ? json(nullptr)
                                                     : json(s.navigation.wall_contact_s);
             }),
      Reason("navigation.wall_contacts_reason", kNav, "why the wall contacts are null",
             [](const RunSummary& s) {
               return s.navigation.wall_contacts < 0
                          ? std::string(
                                "the scene's building has no collision geoms (its walls "
                                "are drawn only)")
                          : std::string();
             }),
  };
  for (MetricInfo& m : r) {
    if (m.key == "end_pose_error_pct") m.label = "end-pose error (% of path)";
    if (m.key == "ate_rmse_m") m.label = "ATE RMSE (m)";
  }
  return r;
}

}  // namespace

bool MetricWritten(const MetricInfo& m, const RunSummary& s) {
  if (m.reason && m.value(s).get<std::string>().empty()) return false;  // the figure applies
  switch (m.group) {
    case MetricGroup::kAccuracy:
      return s.has_ground_truth;  // without ground truth there is nothing to compare with
    case MetricGroup::kMatches:
      return s.match_stats.matches > 0;
    case MetricGroup::kNavigation:
      return s.has_navigation;
    default:
      return true;
  }
}

const std::vector<MetricInfo>& RunMetrics() {
  static const std::vector<MetricInfo> kRegistry = MakeRegistry();
  return kRegistry;
}

const MetricInfo* FindMetric(const std::string& key) {
  for (const MetricInfo& m : RunMetrics())
    if (m.key == key) return &m;
  return nullptr;
}

std::string MetricsJson(const RunSummary& s) {
  json j;
  j["name"] = s.name;
  for (const MetricInfo& m : RunMetrics()) {
    if (!MetricWritten(m, s)) continue;
    const size_t dot = m.key.find('.');
    if (dot == std::string::npos)
      j[m.key] = m.value(s);
    else
      j[m.key.substr(0, dot)][m.key.substr(dot + 1)] = m.value(s);
  }
  return j.dump(2) + "\n";
}

std::string PlotLabel(const MetricInfo& m) {
  if (!m.label.empty()) return m.label;
  return m.unit.empty() ? m.key : m.key + " (" + m.unit + ")";
}

std::vector<std::string> TuneObjectiveMetrics() {
  std::vector<std::string> keys;
  for (const MetricInfo& m : RunMetrics())
    if (m.tune_objective) keys.push_back(m.key);
  return keys;
}

bool ObjectiveValue(const RunSummary& summary, const std::string& key, double* value,
                    std::string* not_applicable) {
  const MetricInfo* m = FindMetric(key);
  if (m == nullptr || !m->tune_objective) return false;
  const json v = m->value(summary);
  *value = v.is_number() ? v.get<double>() : std::nan("");
  if (not_applicable != nullptr)
    *not_applicable = v.is_number() ? "" : NotApplicableReason(*m, summary);
  return true;
}

std::string NotApplicableReason(const MetricInfo& m, const RunSummary& summary) {
  const auto& r = RunMetrics();
  for (size_t i = 0; i < r.size(); ++i) {
    if (r[i].key != m.key) continue;
    for (size_t k = i + 1; k < r.size(); ++k)
      if (r[k].reason) return r[k].value(summary).get<std::string>();
    break;
  }
  return "";
}

std::vector<std::string> CheckedMetrics() {
  std::vector<std::string> keys;
  for (const MetricInfo& m : RunMetrics())
    if (m.check_tolerance >= 0) keys.push_back(m.key);
  return keys;
}

std::string ListOfNames(const std::vector<std::string>& names, const std::string& last) {
  std::string text;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i > 0) text += i + 1 == names.size() ? " " + last + " " : ", ";
    text += names[i];
  }
  return text;
}

}  // namespace harness
