#include "harness/cli/check_command.h"

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "harness/check.h"
#include "harness/overrides.h"
#include "harness/suite.h"
#include "harness/vo_config.h"
#include "sim/data_dir.h"

namespace harness {
namespace {

namespace fs = std::filesystem;

struct CheckArgs {
  std::string baseline = "results/baseline.json", suite, config, out = "out/check";
  std::vector<std::string> sets;
  int jobs = DefaultJobs();
  bool update = false, quiet = false;
};

// --set key=value (value read as YAML: numbers, true/false, strings) into an override map.
bool ParseSets(const std::vector<std::string>& sets, YAML::Node* overrides, std::string* error) {
  *overrides = YAML::Node(YAML::NodeType::Map);
  for (const auto& s : sets) {
    const size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == s.size()) {
      *error = "--set: expected key=value (e.g. tracker.matcher.type=ncc_mutual), got '" + s + "'";
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

int RunCheckCommand(const CheckArgs& a) {
  std::string error;
  Baseline baseline = DefaultBaselineRule();
  std::string baseline_path = a.baseline;
  // The default baseline is found from any folder (it lives in the data folder, sim/data_dir.h).
  const std::string in_source = sim::DataDir() + "/" + a.baseline;
  if (!a.update && fs::path(a.baseline).is_relative() && !fs::exists(a.baseline) &&
      fs::exists(in_source))
    baseline_path = in_source;
  std::error_code ec;
  if (fs::is_directory(baseline_path, ec))
    return PrintFailure("check", kExitBadInput,
                        baseline_path +
                            ": is a folder, not a baseline file (name the JSON file, e.g. "
                            "results/baseline.json)");
  // --update writes through a symbolic link to its target (the link stays a link).
  const std::string write_path = fs::is_symlink(fs::symlink_status(a.baseline, ec))
                                     ? fs::weakly_canonical(a.baseline, ec).string()
                                     : a.baseline;
  if (a.update && fs::is_directory(write_path, ec))
    return PrintFailure("check", kExitBadInput,
                        a.baseline + ": is a folder, not a baseline file (name the JSON file)");
  const bool have_baseline = fs::exists(baseline_path);
  if (have_baseline) {
    if (!LoadBaseline(baseline_path, &baseline, &error))
      return PrintFailure("check", kExitBadInput, error);
  } else if (!a.update) {
    return PrintFailure(
        "check", kExitBadInput,
        a.baseline + ": no such baseline file (make one with --update --suite FILE)");
  }
  std::string suite_path = a.suite.empty() ? baseline.suite_path : a.suite;
  if (suite_path.empty())
    return PrintFailure("check", kExitBadInput,
                        "--suite: required when there is no baseline file yet");
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
    return PrintFailure(
        "check", kExitBadInput,
        "--update with --config/--set would record a modified configuration as the baseline; "
        "refused");
  Suite suite;
  if (!LoadSuite(suite_path, &suite, &error)) return PrintFailure("check", kExitBadInput, error);
  // --config and --set apply on top of every configuration of the suite.
  YAML::Node sets;
  if (!ParseSets(a.sets, &sets, &error)) return PrintFailure("check", kExitBadInput, error);
  for (auto& c : suite.configs) {
    if (!a.config.empty() && !LoadVoConfig(a.config, &c.options, &error))
      return PrintFailure("check", kExitBadInput, error);
    if (!a.sets.empty() && !ApplyVoOverrides(sets, "--set", &c.options, &error)) {
      // The line number is one of the generated YAML text: meaningless here.
      return PrintFailure(
          "check", kExitBadInput,
          std::regex_replace(error, std::regex(R"(\(VO overrides\):[0-9]+)"), "(VO overrides)"));
    }
  }
  SuiteOptions options;
  options.out_dir = a.out;
  options.jobs = a.jobs;
  options.force = true;  // a check always measures the current code
  options.progress = !a.quiet;
  SuiteResult result;
  if (!RunSuite(suite, options, &result, &error)) return PrintFailure("check", kExitFailed, error);

  if (a.update) {
    Baseline fresh;
    if (!MakeBaseline(result, baseline, &fresh, &error))
      return PrintFailure("check", kExitFailed, error);
    if (!WriteFileAtomically(write_path, BaselineJson(fresh), &error))
      return PrintFailure("check", kExitFailed, error);
    std::printf("%s", SuiteTableText(result).c_str());
    std::printf("\nwrote %s: %zu runs x %zu metrics (suite %s, %.1f s)\n", a.baseline.c_str(),
                fresh.runs.size(), CheckedMetrics().size(), suite_path.c_str(), result.wall_s);
    return kExitOk;
  }
  const CheckReport report = CompareToBaseline(baseline, result);
  std::printf("%s", CheckTableText(report).c_str());
  std::string md = "# vobench check\n\nBaseline `" + baseline_path + "`, suite `" + suite_path +
                   "`" + (modified ? " (with --config/--set overrides)" : "") + ": " +
                   (report.passed() ? "passed" : "FAILED") + ".\n\n" + CheckTableMarkdown(report);
  if (!WriteFileAtomically(a.out + "/check.md", md, &error))
    return PrintFailure("check", kExitFailed, error);
  if (!report.passed()) {
    std::printf(
        "\nFAILED: %d regressions (metric worse than baseline + tolerance, or run "
        "failed/missing/new); "
        "suite %.1f s\n",
        report.worse, result.wall_s);
    std::printf("what moved:\n%s", CheckTableText(report, /*only_moved=*/true).c_str());
    return kExitFailed;
  }
  std::printf(
      "\npassed: %zu runs within tolerance of %s%s; suite %.1f s\n", baseline.runs.size(),
      baseline_path.c_str(),
      report.better ? " (some metrics improved beyond the tolerance: consider --update)" : "",
      result.wall_s);
  return kExitOk;
}

}  // namespace

Command AddCheckCommand(CLI::App& app) {
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
  return {check, [ca] { return RunCheckCommand(*ca); }};
}

}  // namespace harness
