#include "harness/cli/suite_command.h"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "harness/suite.h"
#include "harness/suite/external.h"

namespace harness {
namespace {

struct SuiteArgs {
  std::string file, out, shard = "1/1";
  int jobs = DefaultJobs();
  bool force = false, plots = false, quiet = false;
  std::string merge_out;
  std::vector<std::string> merge_dirs;
  std::string external_spec, external_out, external_datasets;
};

void PrintResult(const SuiteResult& r, const std::string& out) {
  std::printf("%s", SuiteTableText(r).c_str());
  std::printf("\n%zu runs: %zu ok (%d run now, %d kept), %d failed, %d missing; %.1f s\n",
              r.rows.size(), r.rows.size() - r.failed - r.missing, r.ran, r.kept, r.failed,
              r.missing, r.wall_s);
  std::printf("summary: %s/summary.csv, %s/summary.md\n", out.c_str(), out.c_str());
}

int RunSuiteCommand(const SuiteArgs& a) {
  if (a.file.empty())
    return PrintFailure(
        "suite", kExitBadInput,
        "a suite file is required (or: vobench suite merge --out DIR SHARD_DIR...)");
  std::string error;
  SuiteOptions options;
  if (!ParseShard(a.shard, &options.shard, &error))
    return PrintFailure("suite", kExitBadInput, error);
  Suite suite;
  if (!LoadSuite(a.file, &suite, &error)) return PrintFailure("suite", kExitBadInput, error);
  options.out_dir = a.out.empty() ? "out/suite/" + suite.name : a.out;
  options.jobs = a.jobs;
  options.force = a.force;
  options.run_plots = a.plots;
  options.progress = !a.quiet;
  SuiteResult result;
  if (!RunSuite(suite, options, &result, &error)) return PrintFailure("suite", kExitFailed, error);
  PrintResult(result, options.out_dir);
  if (!result.ok()) {
    std::fprintf(stderr, "vobench suite: %d runs failed, %d missing (see %s/runs/*.failed.txt)\n",
                 result.failed, result.missing, options.out_dir.c_str());
    return kExitFailed;
  }
  return kExitOk;
}

int RunMergeCommand(const SuiteArgs& a) {
  std::string error;
  SuiteResult result;
  if (!MergeSuiteShards(a.merge_dirs, a.merge_out, &result, &error))
    return PrintFailure("suite merge", kExitBadInput, error);
  PrintResult(result, a.merge_out);
  if (!result.ok()) {
    std::fprintf(stderr, "vobench suite merge: %d runs failed, %d missing in the shards\n",
                 result.failed, result.missing);
    return kExitFailed;
  }
  return kExitOk;
}

// The child of an external run (harness/suite/external.h); the suite starts it, users do not.
int RunExternalCommandLine(const SuiteArgs& a) {
  std::string error;
  ExternalRunSpec spec;
  if (!ReadExternalRunSpec(a.external_spec, &spec, &error))
    return PrintFailure("suite external", kExitBadInput, error);
  if (!RunExternalRun(spec, a.external_out, a.external_datasets, &error))
    return PrintFailure("suite external", kExitFailed, error);
  return kExitOk;
}

}  // namespace

Command AddSuiteCommand(CLI::App& app) {
  auto sa = std::make_shared<SuiteArgs>();
  CLI::App* suite = app.add_subcommand("suite",
                                       "Run a suite (scenarios x VO configs x seeds x strides) in "
                                       "parallel, resumable, with a summary table");
  suite->add_option("file", sa->file, "Suite YAML file (see suites/hallway.yaml)");
  suite->add_option("-j,--jobs", sa->jobs, "Runs at once (child processes)")
      ->capture_default_str()
      ->check(AtLeast(1));
  suite->add_option("--out,-o", sa->out,
                    "Output folder (default out/suite/<suite name>); re-running resumes");
  suite
      ->add_option(
          "--shard", sa->shard,
          "Run only part i of N (runs with index % N == i-1), e.g. ${SLURM_ARRAY_TASK_ID}/4")
      ->capture_default_str();
  suite->add_flag("--force", sa->force, "Redo finished runs too");
  suite->add_flag("--plots", sa->plots,
                  "Per-run PNG plots (slower; the summary plot is always made)");
  suite->add_flag("-q,--quiet", sa->quiet, "No progress display");
  CLI::App* merge = suite->add_subcommand(
      "merge", "Combine the output folders of a suite's shards into one summary");
  merge->add_option("--out,-o", sa->merge_out, "Merged output folder")->required();
  merge->add_option("shards", sa->merge_dirs, "Output folders of the shards")->required();
  // Hidden (no group): the child process of an external configuration's run.
  CLI::App* external =
      suite->add_subcommand("external", "Run one external configuration's run (internal)");
  external->group("");
  external->add_option("spec", sa->external_spec, "specs/<id>.external.json")->required();
  external->add_option("--out,-o", sa->external_out, "Run folder")->required();
  external->add_option("--datasets", sa->external_datasets,
                       "Folder of the sequences shared by the runs (default: the run's own)");
  external->add_flag("-q,--quiet", sa->quiet, "No progress display");
  return {suite, [sa, merge, external] {
            if (external->parsed()) return RunExternalCommandLine(*sa);
            return merge->parsed() ? RunMergeCommand(*sa) : RunSuiteCommand(*sa);
          }};
}

}  // namespace harness
