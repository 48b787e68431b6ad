#include "harness/suite_cli.h"

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "harness/check.h"
#include "harness/cli/command.h"  // kExitBadInput: bad suite, baseline or flags; nothing written
#include "harness/overrides.h"
#include "harness/suite.h"
#include "harness/vo_config.h"
#include "sim/data_dir.h"

namespace harness {
namespace {

namespace fs = std::filesystem;

constexpr int kExitRunFailed = 1;  // a run failed or is missing; check: a metric got worse

int DefaultJobs() { return std::max(1u, std::thread::hardware_concurrency()); }

[[noreturn]] void Exit(int code) { throw CLI::RuntimeError(code); }

[[noreturn]] void Fail(const char* command, int code, const std::string& message) {
  std::fprintf(stderr, "vobench %s: %s\n", command, message.c_str());
  Exit(code);
}

struct SuiteArgs {
  std::string file, out, shard = "1/1";
  int jobs = DefaultJobs();
  bool force = false, plots = false, quiet = false;
  std::string merge_out;
  std::vector<std::string> merge_dirs;
};

struct CheckArgs {
  std::string baseline = "results/baseline.json", suite, config, out = "out/check";
  std::vector<std::string> sets;
  int jobs = DefaultJobs();
  bool update = false, quiet = false;
};

void PrintResult(const SuiteResult& r, const std::string& out) {
  std::printf("%s", SuiteTableText(r).c_str());
  std::printf("\n%zu runs: %zu ok (%d run now, %d kept), %d failed, %d missing; %.1f s\n",
              r.rows.size(), r.rows.size() - r.failed - r.missing, r.ran, r.kept, r.failed,
              r.missing, r.wall_s);
  std::printf("summary: %s/summary.csv, %s/summary.md\n", out.c_str(), out.c_str());
}

void RunSuiteCommand(const SuiteArgs& a) {
  if (a.file.empty())
    Fail("suite", kExitBadInput,
         "a suite file is required (or: vobench suite merge --out DIR SHARD_DIR...)");
  std::string error;
  SuiteOptions options;
  if (!ParseShard(a.shard, &options.shard, &error)) Fail("suite", kExitBadInput, error);
  Suite suite;
  if (!LoadSuite(a.file, &suite, &error)) Fail("suite", kExitBadInput, error);
  options.out_dir = a.out.empty() ? "out/suite/" + suite.name : a.out;
  options.jobs = a.jobs;
  options.force = a.force;
  options.run_plots = a.plots;
  options.progress = !a.quiet;
  SuiteResult result;
  if (!RunSuite(suite, options, &result, &error)) Fail("suite", kExitRunFailed, error);
  PrintResult(result, options.out_dir);
  if (!result.ok()) {
    std::fprintf(stderr, "vobench suite: %d runs failed, %d missing (see %s/runs/*.failed.txt)\n",
                 result.failed, result.missing, options.out_dir.c_str());
    Exit(kExitRunFailed);
  }
}

void RunMergeCommand(const SuiteArgs& a) {
  std::string error;
  SuiteResult result;
  if (!MergeSuiteShards(a.merge_dirs, a.merge_out, &result, &error))
    Fail("suite merge", kExitBadInput, error);
  PrintResult(result, a.merge_out);
  if (!result.ok()) {
    std::fprintf(stderr, "vobench suite merge: %d runs failed, %d missing in the shards\n",
                 result.failed, result.missing);
    Exit(kExitRunFailed);
  }
}

// --set key=value (value read as YAML: numbers, true/false, strings) into an override map.
bool ParseSets(const std::vector<std::string>& sets, YAML::Node* overrides, std::string* error) {
  *overrides = YAML::Node(YAML::NodeType::Map);
  for (const auto& s : sets) {
    const size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == s.size()) {
      *error = "--set: expected key=value (e.g. matcher.type=ncc_mutual), got '" + s + "'";
      return false;
    }
    const std::string key = s.substr(0, eq);
    if ((*overrides)[key].IsDefined()) {
      *error = "--set: key '" + key + "' is given twice";
      return false;
    }
    try {
      (*overrides)[key] = YAML::Load(s.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      *error = "--set " + s + ": malformed value: " + e.msg;
      return false;
    }
  }
  return true;
}

void RunCheckCommand(const CheckArgs& a) {
  std::string error;
  Baseline baseline = DefaultBaselineRule();
  std::string baseline_path = a.baseline;
  // The default baseline is found from any folder (it lives in the data folder, sim/data_dir.h).
  const std::string in_source = sim::DataDir() + "/" + a.baseline;
  if (!a.update && fs::path(a.baseline).is_relative() && !fs::exists(a.baseline) &&
      fs::exists(in_source))
    baseline_path = in_source;
  const bool have_baseline = fs::exists(baseline_path);
  if (have_baseline) {
    if (!LoadBaseline(baseline_path, &baseline, &error)) Fail("check", kExitBadInput, error);
  } else if (!a.update) {
    Fail("check", kExitBadInput,
         a.baseline + ": no such baseline file (make one with --update --suite FILE)");
  }
  std::string suite_path = a.suite.empty() ? baseline.suite_path : a.suite;
  if (suite_path.empty())
    Fail("check", kExitBadInput, "--suite: required when there is no baseline file yet");
  if (!a.suite.empty()) {
    // The baseline names the suite relative to itself.
    const fs::path base_dir = fs::absolute(a.baseline).parent_path();
    baseline.suite = fs::absolute(a.suite)
                         .lexically_normal()
                         .lexically_relative(base_dir.lexically_normal())
                         .string();
    baseline.suite_path = a.suite;
  }
  const bool modified = !a.config.empty() || !a.sets.empty();
  if (a.update && modified)
    Fail("check", kExitBadInput,
         "--update with --config/--set would record a modified configuration as the baseline; "
         "refused");
  Suite suite;
  if (!LoadSuite(suite_path, &suite, &error)) Fail("check", kExitBadInput, error);
  // --config and --set apply on top of every configuration of the suite.
  YAML::Node sets;
  if (!ParseSets(a.sets, &sets, &error)) Fail("check", kExitBadInput, error);
  for (auto& c : suite.configs) {
    if (!a.config.empty() && !LoadVoConfig(a.config, &c.options, &error))
      Fail("check", kExitBadInput, error);
    if (!a.sets.empty() && !ApplyVoOverrides(sets, "--set", &c.options, &error)) {
      // The line number is one of the generated YAML text: meaningless here.
      Fail("check", kExitBadInput,
           std::regex_replace(error, std::regex(R"(\(VO overrides\):[0-9]+)"), "(VO overrides)"));
    }
  }
  SuiteOptions options;
  options.out_dir = a.out;
  options.jobs = a.jobs;
  options.force = true;  // a check always measures the current code
  options.progress = !a.quiet;
  SuiteResult result;
  if (!RunSuite(suite, options, &result, &error)) Fail("check", kExitRunFailed, error);

  if (a.update) {
    Baseline fresh;
    if (!MakeBaseline(result, baseline, &fresh, &error)) Fail("check", kExitRunFailed, error);
    if (!WriteFileAtomically(a.baseline, BaselineJson(fresh), &error))
      Fail("check", kExitRunFailed, error);
    std::printf("%s", SuiteTableText(result).c_str());
    std::printf("\nwrote %s: %zu runs x %zu metrics (suite %s, %.1f s)\n", a.baseline.c_str(),
                fresh.runs.size(), CheckedMetrics().size(), suite_path.c_str(), result.wall_s);
    return;
  }
  const CheckReport report = CompareToBaseline(baseline, result);
  std::printf("%s", CheckTableText(report).c_str());
  std::string md = "# vobench check\n\nBaseline `" + baseline_path + "`, suite `" + suite_path +
                   "`" + (modified ? " (with --config/--set overrides)" : "") + ": " +
                   (report.passed() ? "passed" : "FAILED") + ".\n\n" + CheckTableMarkdown(report);
  if (!WriteFileAtomically(a.out + "/check.md", md, &error)) Fail("check", kExitRunFailed, error);
  if (!report.passed()) {
    std::printf(
        "\nFAILED: %d regressions (metric worse than baseline + tolerance, or run "
        "failed/missing/new); "
        "suite %.1f s\n",
        report.worse, result.wall_s);
    std::printf("what moved:\n%s", CheckTableText(report, /*only_moved=*/true).c_str());
    Exit(kExitRunFailed);
  }
  std::printf(
      "\npassed: %zu runs within tolerance of %s%s; suite %.1f s\n", baseline.runs.size(),
      baseline_path.c_str(),
      report.better ? " (some metrics improved beyond the tolerance: consider --update)" : "",
      result.wall_s);
}

}  // namespace

void AddSuiteCommands(CLI::App& app) {
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
  merge->callback([sa] { RunMergeCommand(*sa); });
  suite->callback([sa, merge] {
    if (merge->parsed()) return;
    RunSuiteCommand(*sa);
  });

  auto ca = std::make_shared<CheckArgs>();
  CLI::App* check = app.add_subcommand("check",
                                       "Regression check: re-run the baseline's suite and fail "
                                       "when a metric is worse than its tolerance");
  check->add_option("--baseline", ca->baseline, "Baseline file (JSON)")->capture_default_str();
  check->add_option("--suite", ca->suite, "Suite file (default: the one the baseline names)");
  check->add_option("--config", ca->config,
                    "VO config applied on top of every configuration of the suite");
  check->add_option("--set", ca->sets,
                    "VO option override key=value (repeatable), on top of --config");
  check->add_option("--out,-o", ca->out, "Output folder of the check's suite run")
      ->capture_default_str();
  check->add_option("-j,--jobs", ca->jobs, "Runs at once")
      ->capture_default_str()
      ->check(AtLeast(1));
  check->add_flag("--update", ca->update,
                  "Write a new baseline from this run (keeps the tolerance rule)");
  check->add_flag("-q,--quiet", ca->quiet, "No progress display");
  check->callback([ca] { RunCheckCommand(*ca); });
}

}  // namespace harness
