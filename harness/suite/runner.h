// Running a suite: each run of this shard as a child `vobench run` process (at most `jobs` at
// once) writing into the suite's output folder (folder.h), resumable, and the merge of the
// folders of a suite's shards. The summary (summary.h) is written at the end of both.
//
// Each sequence is simulated once per call: the built-in runs get `--sequence-cache
// tmp/<shard>/sequences` (harness/sequence_cache.h), so the first run of a scenario and seed
// simulates it into that folder under a lock and the runs of the other configurations and
// strides read its frames, bit for bit the same (their run folders equal those of runs that
// simulate for themselves). The first run of each sequence is started first, so that with
// several jobs the children simulate different sequences rather than wait on one. The cache
// goes with the work folder when the call ends (a resumed call simulates again the sequences
// of the runs it still has to do).
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
