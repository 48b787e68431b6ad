// The summary of a suite across its runs: one row per run (status, axes, metrics.json), written
// as summary.csv (every metric), summary.md (per-configuration medians, a pivot by scenario and
// configuration, the runs) and summary.png (harness/plots/suite_plot.py), and printed as a table.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/suite/spec.h"

namespace harness {

// One row of the summary.
struct SuiteRow {
  SuiteRun run;
  std::string status;      // ok | failed | missing
  nlohmann::json metrics;  // metrics.json of the run (ok only)
  double wall_s = 0.0;     // wall time of the child (s)
  bool ran_now = false;    // run by this call (not kept from before)
};

struct SuiteResult {
  std::vector<SuiteRow> rows;  // this shard's runs, in suite order
  int kept = 0;                // finished before and kept
  int ran = 0;                 // run now and finished
  int failed = 0;
  int missing = 0;
  double wall_s = 0.0;  // wall time of the whole call (s)
  bool ok() const { return failed == 0 && missing == 0; }
};

// The summary's columns: axes and status, then every key of the metric registry (in
// metrics.json order; dotted keys as they are; a key a run's metrics.json does not have, or
// null, is an empty cell or "nan": an external configuration has no lost_frames, a built-in one
// no command_wall_s); the timing columns (SuiteTimingColumns: the registry's timing metrics, an
// external configuration's command_wall_s and command_peak_rss_mb, and the run's wall_s) are
// the last ones and the only ones that vary between identical runs.
const std::vector<std::string>& SuiteSummaryColumns();
const std::vector<std::string>& SuiteTimingColumns();

// The printed table (one line per run, then the per-configuration medians).
std::string SuiteTableText(const SuiteResult& result);

// The rows of `runs` (those in `shard`) from what is on disk in the suite folder `out`: ok
// (finished for its spec hash, with its metrics.json), failed (runs/<id>.failed.txt) or
// missing.
std::vector<SuiteRow> CollectSuiteRows(const std::filesystem::path& out,
                                       const std::vector<SuiteRun>& runs, const Shard& shard);
// Sets result->failed and result->missing from the rows' status.
void CountFailedAndMissing(SuiteResult* result);
// Writes summary.csv, summary.png (a missing matplotlib only warns) and summary.md into `out`,
// each atomically.
bool WriteSuiteSummary(const std::filesystem::path& out, const std::string& name,
                       const SuiteResult& result, std::string* error);

}  // namespace harness
