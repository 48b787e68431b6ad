// The metric registry: every number a run reports, named once. It drives metrics.json (keys,
// order, when a key is written), the suite's summary.csv columns (every key), the metrics `tune`
// may minimise, the metrics `check` compares with their tolerance floors, and the labels of the
// suite's plot. Adding a metric is one entry in metric_registry.cc.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/pipeline.h"

namespace harness {

enum class Better {
  kLower,    // an error or a count of failures
  kHigher,   // a precision
  kNeither,  // a description of the run (frames, path length, medians of counts)
};

enum class MetricGroup {
  kRun,       // always written
  kAccuracy,  // written only when the run has ground truth (RunSummary::has_ground_truth)
  kMatches,   // written only when the VO's matches were checked (match_stats.matches > 0)
  kTiming,    // wall-clock times: vary between identical runs, never compared
  // What a simulated robot did (written when RunSummary::has_navigation; sim/navigation.h).
  kNavigation,
};

struct MetricInfo {
  std::string key;   // metrics.json key; "a.b" is nested ({"a": {"b": ...}}) in metrics.json
                     // and the column "a.b" in summary.csv
  std::string unit;  // "m", "%", "deg", "deg/m", "mm", "ms", "frames", "" (a ratio or flag)
  Better better = Better::kNeither;
  MetricGroup group = MetricGroup::kRun;
  std::string meaning;            // how to read it, one line (messages, the README)
  std::string label;              // short axis label of plots ("" = key and unit, see PlotLabel)
  bool reason = false;            // a "*_reason" text: why the figures before it are null (not
                                  // applicable to the run); written only when it is not empty
  bool tune_objective = false;    // may be `tune`'s objective.metric
  double check_tolerance = -1.0;  // >= 0: compared by `vobench check`, with this absolute
                                  // tolerance floor (in the metric's unit)
  std::function<nlohmann::ordered_json(const RunSummary&)> value;  // the value of a run
};

// Every metric in metrics.json order.
const std::vector<MetricInfo>& RunMetrics();
// The metric named `key`, or null.
const MetricInfo* FindMetric(const std::string& key);

// The summary as metrics.json text (the registry's keys in order; "name" first).
// Whether metrics.json holds `m` for `summary`: a reason only beside its null figure, accuracy
// only with ground truth, the VO's match precision only where it was measured.
bool MetricWritten(const MetricInfo& m, const RunSummary& summary);

std::string MetricsJson(const RunSummary& summary);
// The value of a metric in a parsed metrics.json (dotted keys looked up nested); null when
// the file does not have it. Json: nlohmann::json or nlohmann::ordered_json.
template <typename Json>
const Json* FindMetricValue(const Json& metrics, const std::string& key) {
  const Json* node = &metrics;
  for (size_t start = 0;;) {
    const size_t dot = key.find('.', start);
    const std::string part = key.substr(start, dot == std::string::npos ? dot : dot - start);
    if (!node->is_object() || !node->contains(part)) return nullptr;
    node = &(*node)[part];
    if (dot == std::string::npos) return node;
    start = dot + 1;
  }
}

// The axis label of `m` in plots: its label, else "key (unit)".
std::string PlotLabel(const MetricInfo& m);

// The metrics `tune` may minimise (accuracy metrics where lower is better), in order.
std::vector<std::string> TuneObjectiveMetrics();
// The value of an objective metric of a summary; false for a name that is not one. A metric
// that does not apply to the run (null in metrics.json) is NaN, its reason in *not_applicable.
bool ObjectiveValue(const RunSummary& summary, const std::string& key, double* value,
                    std::string* not_applicable = nullptr);

// Why `m` is null for `summary`: the text of the reason entry that follows it in the registry
// ("" when it applies or has no reason entry).
std::string NotApplicableReason(const MetricInfo& m, const RunSummary& summary);

// The metrics `vobench check` compares (never timing), in order, and their tolerance floors.
std::vector<std::string> CheckedMetrics();

// `names` as "a, b, c or d".
std::string ListOfNames(const std::vector<std::string>& names, const std::string& last = "or");

}  // namespace harness
