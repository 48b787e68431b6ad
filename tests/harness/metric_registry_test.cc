// The metric registry drives metrics.json, summary.csv, tune's objectives and check's metrics:
// each of them is checked against the registry here, so a metric added to the registry shows up
// everywhere, and nothing else names metrics on its own.
#include "harness/metric_registry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "harness/check.h"
#include "harness/suite.h"

namespace {

using harness::MetricGroup;
using harness::RunMetrics;
using json = nlohmann::ordered_json;

harness::RunSummary FullSummary() {
  harness::RunSummary s;
  s.name = "full";
  s.has_ground_truth = true;
  s.ground_truth_frames = 10;
  s.metrics.frames = 10;
  s.metrics.end_pose_error_m = 0.25;
  s.metrics.ate_rmse_m = 0.125;
  s.match_stats.matches = 100;
  s.lost_frames = 3;
  s.initial_orientation_ok = true;
  s.initial_orientation_error_deg = 1.5;
  s.has_navigation = true;
  s.navigation.reached_goal = true;
  s.navigation.end_error_m = 0.05;
  s.navigation.max_waypoint_error_m = 0.02;
  s.navigation.wall_contacts = 0;
  for (const char* stage :
       {"ba", "depth", "detect", "disparity", "guided", "match", "motion", "predict"})
    s.stage_ms_median[stage] = 1.5;
  return s;
}

TEST(MetricRegistryTest, MetricsJsonHoldsExactlyTheRegistrysKeysInOrder) {
  const json j = json::parse(harness::MetricsJson(FullSummary()));
  std::vector<std::string> keys;  // flattened, in file order
  for (const auto& [k, v] : j.items()) {
    if (v.is_object()) {
      for (const auto& [k2, v2] : v.items()) keys.push_back(k + "." + k2);
    } else {
      keys.push_back(k);
    }
  }
  // Every figure applies: no *_reason entry is written.
  std::vector<std::string> expected = {"name"};
  for (const harness::MetricInfo& m : RunMetrics())
    if (!m.reason) expected.push_back(m.key);
  EXPECT_EQ(keys, expected);
  EXPECT_DOUBLE_EQ(j["end_pose_error_m"].get<double>(), 0.25);
  EXPECT_EQ(j["lost_frames"].get<int>(), 3);
  ASSERT_NE(harness::FindMetricValue(j, "stage_ms_median.ba"), nullptr);
  EXPECT_DOUBLE_EQ(harness::FindMetricValue(j, "stage_ms_median.ba")->get<double>(), 1.5);
  EXPECT_EQ(harness::FindMetricValue(j, "stage_ms_median.nothing"), nullptr);
  EXPECT_EQ(harness::FindMetricValue(j, "nothing"), nullptr);
}

TEST(MetricRegistryTest, GroupsDecideWhatARunWithoutGroundTruthWrites) {
  harness::RunSummary s = FullSummary();
  s.has_ground_truth = false;
  s.match_stats.matches = 0;
  s.has_navigation = false;
  const json j = json::parse(harness::MetricsJson(s));
  for (const harness::MetricInfo& m : RunMetrics()) {
    const bool written = harness::FindMetricValue(j, m.key) != nullptr;
    EXPECT_EQ(written, m.group != MetricGroup::kAccuracy && m.group != MetricGroup::kMatches &&
                           m.group != MetricGroup::kNavigation && !m.reason)
        << m.key;
  }
}

// A figure that does not apply is null with its reason right after it (no sentinel numbers);
// tune's objective reads it as NaN with the reason.
TEST(MetricRegistryTest, NotApplicableFiguresAreNullWithTheirReason) {
  harness::RunSummary s = FullSummary();
  const double nan = std::nan("");
  s.metrics.end_pose_error_pct = s.metrics.drift_pct = s.metrics.drift_deg_per_m = nan;
  s.metrics.kitti_drift_pct = s.metrics.kitti_drift_deg_per_m = nan;
  s.metrics.rpe_distance_trans_rmse_m = s.metrics.rpe_distance_rot_rmse_deg = nan;
  s.metrics.end_pose_error_pct_reason = s.metrics.drift_reason = s.metrics.kitti_drift_reason =
      "too short";
  s.metrics.rpe_distance_reason = "no pair";
  s.initial_orientation_error_deg = nan;
  s.initial_orientation_error_reason = "ground truth not gravity-aligned";
  const std::string text = harness::MetricsJson(s);
  const json j = json::parse(text);
  EXPECT_TRUE(j["initial_orientation_error_deg"].is_null());
  EXPECT_EQ(j["initial_orientation_error_reason"], "ground truth not gravity-aligned");
  for (const char* k : {"end_pose_error_pct", "drift_pct", "drift_deg_per_m", "kitti_drift_pct",
                        "kitti_drift_deg_per_m", "rpe_distance_trans_rmse_m"})
    EXPECT_TRUE(j[k].is_null()) << k;
  EXPECT_EQ(j["end_pose_error_pct_reason"], "too short");
  EXPECT_EQ(j["drift_reason"], "too short");
  EXPECT_EQ(j["kitti_drift_reason"], "too short");
  EXPECT_EQ(j["rpe_distance_reason"], "no pair");
  EXPECT_EQ(text.find("-1"), std::string::npos) << text;  // no sentinel
  // Now every key of the registry is there, in its order.
  std::vector<std::string> keys, expected = {"name"};
  for (const auto& [k, v] : j.items())
    if (!v.is_object()) keys.push_back(k);
  for (const harness::MetricInfo& m : RunMetrics())
    if (m.key.find('.') == std::string::npos) expected.push_back(m.key);
  EXPECT_EQ(keys, expected);
  double v = 0.0;
  std::string why;
  EXPECT_TRUE(harness::ObjectiveValue(s, "drift_pct", &v, &why));
  EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(why, "too short");
  EXPECT_TRUE(harness::ObjectiveValue(s, "ate_rmse_m", &v, &why));
  EXPECT_EQ(v, 0.125);
  EXPECT_EQ(why, "");
}

TEST(MetricRegistryTest, EveryEntryIsComplete) {
  std::set<std::string> keys;
  for (const harness::MetricInfo& m : RunMetrics()) {
    EXPECT_TRUE(keys.insert(m.key).second) << "duplicate key " << m.key;
    EXPECT_FALSE(m.meaning.empty()) << m.key;
    EXPECT_TRUE(static_cast<bool>(m.value)) << m.key;
    // Keys end in their unit, as the project's names do (frames and plain counts excepted).
    const std::map<std::string, std::string> suffix = {{"m", "_m"}, {"deg", "_deg"}, {"%", "_pct"}};
    if (suffix.count(m.unit)) {
      const std::string& end = suffix.at(m.unit);
      EXPECT_EQ(m.key.substr(m.key.size() - end.size()), end) << m.key;
    }
    if (m.unit == "ms") {
      EXPECT_NE(m.key.find("ms"), std::string::npos) << m.key;
    }
    // What tune minimises and check compares is never a wall-clock time.
    if (m.tune_objective || m.check_tolerance >= 0) {
      EXPECT_NE(m.group, MetricGroup::kTiming) << m.key;
      EXPECT_EQ(m.better, harness::Better::kLower) << m.key;
    }
  }
}

TEST(MetricRegistryTest, SummaryCsvColumnsAreTheRegistrysWithTimingLast) {
  const std::vector<std::string>& cols = harness::SuiteSummaryColumns();
  const std::vector<std::string>& timing = harness::SuiteTimingColumns();
  // Every key of metrics.json is a column: the column set is the axes and status, the
  // registry's keys and wall_s, nothing else.
  std::set<std::string> expected = {"id", "scenario", "config", "seed", "stride", "max_frames",
                                    "status", "wall_s",
                                    // an external configuration's command (suite/external.h)
                                    "command_wall_s", "command_peak_rss_mb"};
  for (const harness::MetricInfo& m : RunMetrics()) {
    expected.insert(m.key);
    const bool timed = std::find(timing.begin(), timing.end(), m.key) != timing.end();
    EXPECT_EQ(timed, m.group == MetricGroup::kTiming) << m.key;
  }
  EXPECT_EQ(std::set<std::string>(cols.begin(), cols.end()), expected);
  EXPECT_EQ(cols.size(), expected.size());  // no column twice
  for (const char* k : {"platform", "has_ground_truth", "initial_orientation_ok",
                        "initial_floor_refined", "frame_stride", "kitti_drift_pct"})
    EXPECT_NE(std::find(cols.begin(), cols.end(), k), cols.end()) << k;
  ASSERT_GE(cols.size(), timing.size());
  EXPECT_TRUE(
      std::equal(timing.begin(), timing.end(), cols.end() - static_cast<long>(timing.size())));
  EXPECT_EQ(timing.back(), "wall_s");
}

TEST(MetricRegistryTest, TuneAndCheckTakeTheirMetricsFromTheRegistry) {
  const std::vector<std::string> objectives = harness::TuneObjectiveMetrics();
  EXPECT_NE(std::find(objectives.begin(), objectives.end(), "ate_rmse_m"), objectives.end());
  double v = 0.0;
  EXPECT_TRUE(harness::ObjectiveValue(FullSummary(), "ate_rmse_m", &v));
  EXPECT_DOUBLE_EQ(v, 0.125);
  EXPECT_FALSE(harness::ObjectiveValue(FullSummary(), "vo_ms_median", &v));  // timing
  EXPECT_FALSE(harness::ObjectiveValue(FullSummary(), "no_such_metric", &v));
  const std::vector<std::string> checked = harness::CheckedMetrics();
  EXPECT_EQ(checked,
            (std::vector<std::string>{"end_pose_error_m", "end_rotation_error_deg", "ate_rmse_m",
                                      "rpe_trans_rmse_m", "drift_pct", "lost_frames"}));
  const harness::Baseline rule = harness::DefaultBaselineRule();
  for (const std::string& k : checked)
    EXPECT_DOUBLE_EQ(rule.absolute_tolerance.at(k), harness::FindMetric(k)->check_tolerance) << k;
  EXPECT_EQ(harness::ListOfNames({"a", "b", "c"}), "a, b or c");
}

}  // namespace
