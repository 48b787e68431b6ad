// `vobench suite`: scenarios × VO configurations × noise seeds × frame strides, each run as a
// child `vobench run` process (at most `jobs` at once), resumable, splittable into shards, with
// a summary table across the runs.
//
// Suite file (YAML; unknown keys are refused with the file, line and key; see suites/*.yaml):
//   name: hallway               # suite name ([A-Za-z0-9_.-], no "__")
//   max_frames: 0               # optional default for every scenario (source frames, 0 = all)
//   scenarios:                  # at least one
//     - name: l_hallway         # optional (default: the scenario's name); unique
//       scenario: l_hallway     # a built-in scenario (scenes/) or a YAML file relative to
//                               # the suite file
//       set: {noise.pixel_sigma: 3}   # optional scenario overrides (dotted keys, overrides.h)
//       max_frames: 200         # optional: stop after this many source frames
//   configs:                    # at least one
//     - name: paper             # required, unique
//       config: vo.yaml         # optional VO config file relative to the suite file
//       set: {matcher.type: ncc_mutual}   # optional VO overrides, applied after `config`
//   seeds: [1, 2]               # optional noise seeds (default: each scenario's own seed)
//   strides: [1, 2]             # optional frame strides (default [1])
//
// Runs are the product scenarios × configs × seeds × strides in that nesting order (the stride
// varies fastest); run i (from 0) has the id `<scenario>__<config>__s<seed>__k<stride>`.
//
// Output folder (OUT), a marked folder of kind "suite" (harness/output_folder.h: an existing OUT
// without that marker is refused):
//   .vobench.json   the marker; .shard<i>of<N>.lock / .merge.lock while a call writes
//   suite.json      manifest: suite name, the shard, every run of the suite (id, axes, spec hash)
//   suite.yaml      copy of the suite file
//   specs/<id>.scenario.yaml, specs/<id>.vo.yaml
//                   effective inputs of each run (what the child reads)
//   runs/<id>/      finished run folders (`vobench run` layout + suite_run.json: spec hash,
//                   wall time). A run appears here only when finished: the child writes under
//                   tmp/shard<i>of<N>/<id>, the suite adds suite_run.json and renames it into
//                   runs/ (shards sharing one output folder keep out of each other's tmp/);
//                   an existing runs/<id> is replaced only when it is a marked run folder.
//   runs/<id>.failed.txt   a failed run: command, exit status, the tail of its log
//   logs/<id>.log   stdout and stderr of the child
//   summary.csv, summary.md, summary.png   the table across runs (written atomically)
//
// Resume: a run whose runs/<id>/suite_run.json records the same spec hash (effective scenario,
// VO options, stride, max_frames) is kept; anything else is redone; the shard's tmp/ folder and
// marked runs/*.partial leftovers are removed. The hash does not cover the vobench binary: use --force
// after changing the code.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/scenario.h"
#include "vo/odometry.h"

namespace harness {

struct SuiteScenario {
  std::string name;        // id component
  sim::Scenario scenario;  // the base scenario with the suite's overrides applied
  int max_frames = 0;      // source frames per run (0 = all)
};

struct SuiteConfig {
  std::string name;             // id component
  vo::OdometryOptions options;  // effective VO options
};

struct Suite {
  std::string name;
  std::string source_path;  // the suite file ("" when parsed from text)
  std::string source_text;  // its text
  std::vector<SuiteScenario> scenarios;
  std::vector<SuiteConfig> configs;
  std::vector<uint64_t> seeds;  // empty: each scenario's own seed
  std::vector<int> strides = {1};
};

// Reads and checks a suite file: every scenario and config is loaded and every override applied
// here, so a bad suite fails before anything runs. Errors name the file, line and key.
bool LoadSuite(const std::string& path, Suite* suite, std::string* error);
// The same from text; relative paths are resolved against `base_dir`.
bool ParseSuite(const std::string& yaml_text, const std::string& source_name,
                const std::string& base_dir, Suite* suite, std::string* error);

// One run of a suite.
struct SuiteRun {
  int index = 0;              // position in the suite's fixed order, from 0
  std::string id;             // <scenario>__<config>__s<seed>__k<stride>
  std::string scenario;       // SuiteScenario::name
  std::string config;         // SuiteConfig::name
  uint64_t seed = 0;          // noise seed of the run
  int stride = 1;             // frame stride
  int max_frames = 0;         // source frames (0 = all)
  std::string scenario_yaml;  // effective scenario (named after the id), as the child reads it
  std::string vo_yaml;        // effective VO options, as the child reads them
  std::string spec_hash;      // 16 hex digits: FNV-1a over the inputs (portable: the scene file
                              // enters by name and content, not by absolute path)
};

// The runs of `suite` in their fixed order.
std::vector<SuiteRun> ExpandSuite(const Suite& suite);

// A part of a suite: shard i of n (1 <= i <= n) holds the runs whose index % n == i - 1.
struct Shard {
  int index = 1;
  int count = 1;
  bool Contains(int run_index) const { return run_index % count == index - 1; }
};
// Parses "i/N"; the error says what was expected.
bool ParseShard(const std::string& text, Shard* shard, std::string* error);

struct SuiteOptions {
  std::string out_dir;     // output folder (created; an earlier folder of the same suite resumes)
  int jobs = 1;            // child processes at once, >= 1
  Shard shard;             // the part of the suite to run
  bool force = false;      // redo finished runs too
  bool progress = true;    // progress bar and per-run lines on stderr
  bool run_plots = false;  // per-run PNG plots (slower); the summary plot is always made
  std::string vobench_binary;  // the command run for each run ("" = this executable)
};

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

// The summary's columns: axes and status, then the metric registry's metrics (csv ones, in
// metrics.json order; dotted keys as they are); the timing columns (SuiteTimingColumns: the
// registry's timing metrics and the run's wall_s) are the last ones and the only ones that
// vary between identical runs.
const std::vector<std::string>& SuiteSummaryColumns();
const std::vector<std::string>& SuiteTimingColumns();

// The printed table (one line per run, then the per-configuration medians).
std::string SuiteTableText(const SuiteResult& result);

// Writes `text` to `path` through a temporary file and a rename (readers never see half a file).
bool WriteFileAtomically(const std::string& path, const std::string& text, std::string* error);

// 64-bit FNV-1a of `text` as 16 hex digits (stable across machines and builds).
std::string Fnv1aHex(const std::string& text);

}  // namespace harness
