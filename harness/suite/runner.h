// Running a suite: each run of this shard as a child `vobench run` process (at most `jobs` at
// once) writing into the suite's output folder (folder.h), resumable, and the merge of the
// folders of a suite's shards. The summary (summary.h) is written at the end of both.
//
// Resume: a run whose runs/<id>/suite_run.json records the same spec hash (effective scenario,
// VO options, stride, max_frames) is kept; anything else is redone; the shard's tmp/ folder and
// marked runs/*.partial leftovers are removed. The hash does not cover the vobench binary: use
// --force after changing the code.
#pragma once

#include <string>
#include <vector>

#include "harness/suite/spec.h"
#include "harness/suite/summary.h"

namespace harness {

struct SuiteOptions {
  std::string out_dir;     // output folder (created; an earlier folder of the same suite resumes)
  int jobs = 1;            // child processes at once, >= 1
  Shard shard;             // the part of the suite to run
  bool force = false;      // redo finished runs too
  bool progress = true;    // progress bar and per-run lines on stderr
  bool run_plots = false;  // per-run PNG plots (slower); the summary plot is always made
  std::string vobench_binary;  // the command run for each run ("" = this executable)
};

// Runs the suite (this shard's runs) and writes the output folder and its summary. Returns false
// only when the suite could not be run at all (bad output folder, interrupted, cannot write);
// failed runs are recorded in *result (check result->ok()).
bool RunSuite(const Suite& suite, const SuiteOptions& options, SuiteResult* result,
              std::string* error);

// Combines the output folders of a suite's shards into `out_dir` (runs copied, summary written
// as an unsharded run would). All shards must be of the same suite (same runs and spec hashes).
// Runs finished in none of them are `missing` in the summary.
bool MergeSuiteShards(const std::vector<std::string>& shard_dirs, const std::string& out_dir,
                      SuiteResult* result, std::string* error);

}  // namespace harness
