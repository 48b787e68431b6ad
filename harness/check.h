// `vobench check`: re-runs a short suite and compares its accuracy metrics with a committed
// baseline (results/baseline.json); a metric worse than its baseline by more than its tolerance,
// or a run that failed or is missing, fails the check.
//
// Baseline file (JSON):
//   {
//     "suite": "../suites/ci.yaml",          the suite, relative to the baseline file
//     "tolerance_rule": "...",               how the tolerances were chosen (text)
//     "relative_tolerance": 0.25,            --update: tolerance = max(relative * |value|,
//     "absolute_tolerance": {"ate_rmse_m": 0.005, ...},        absolute[metric])
//     "runs": {
//       "<run id>": {
//         "<metric>": {"value": 0.012, "tolerance": 0.005, "lower_is_better": true}, ...
//       }, ...
//     }
//   }
// Only accuracy metrics are checked (CheckedMetrics() of the metric registry), never timing.
// Tolerances may be edited by hand; --update keeps the rule (relative, absolute) of the existing
// file.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "harness/metric_registry.h"  // CheckedMetrics
#include "harness/suite.h"

namespace harness {

struct BaselineMetric {
  std::string name;             // metrics.json key
  double value = 0.0;           // reference value (NaN when the run had none)
  double tolerance = 0.0;       // allowed worsening, in the metric's unit, >= 0
  bool lower_is_better = true;  // direction in which the metric improves
};

struct BaselineRun {
  std::string id;
  std::vector<BaselineMetric> metrics;
};

struct Baseline {
  std::string suite;                // as written: relative to the baseline file (or absolute)
  std::string suite_path;           // resolved path of the suite file
  std::string tolerance_rule;       // explanation kept in the file
  double relative_tolerance = 0.2;  // fraction of |value|, >= 0
  std::map<std::string, double> absolute_tolerance;  // per metric, in its unit, >= 0
  std::vector<BaselineRun> runs;                     // in suite order
};

// The rule a new baseline gets when there is no earlier file.
Baseline DefaultBaselineRule();

// Reads a baseline file (strict: unknown keys and bad values are refused, naming file and key).
bool LoadBaseline(const std::string& path, Baseline* baseline, std::string* error);

// The baseline as JSON text; `suite` is written as given in baseline.suite.
std::string BaselineJson(const Baseline& baseline);

// A new baseline from a suite result with `rule`'s tolerances. Fails when a run is not ok.
bool MakeBaseline(const SuiteResult& result, const Baseline& rule, Baseline* baseline,
                  std::string* error);

struct CheckRow {
  std::string run;
  std::string metric;  // empty for a run-level row (missing / failed / not in baseline)
  double baseline = 0.0;
  double now = 0.0;
  double tolerance = 0.0;
  std::string verdict;  // OK | BETTER | WORSE | FAILED | MISSING | NEW
  std::string note;     // why `now` is null when the baseline has a number (the run's
                        // *_reason text), printed after the verdict
};

struct CheckReport {
  std::vector<CheckRow> rows;
  int worse = 0;   // WORSE, FAILED and MISSING rows
  int better = 0;  // improvements beyond the tolerance (consider --update)
  bool passed() const { return worse == 0; }
};

// Compares a suite result with the baseline. A run of the baseline that is not in the result is
// MISSING, a failed run FAILED, a run of the result not in the baseline NEW (fails: the
// baseline is out of date); a metric is WORSE when it moved in the bad direction by more than
// its tolerance, or is NaN where the baseline is not.
CheckReport CompareToBaseline(const Baseline& baseline, const SuiteResult& result);

// The table: run, metric, baseline, now, delta, tolerance, verdict; `only_moved` leaves out
// rows whose value did not change at all.
std::string CheckTableText(const CheckReport& report, bool only_moved = false);
// The same as a Markdown table.
std::string CheckTableMarkdown(const CheckReport& report);

}  // namespace harness
