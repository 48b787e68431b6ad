#include "harness/cli/breakpoint_command.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "harness/breakpoint.h"
#include "harness/path_names.h"
#include "harness/sim_adapter.h"
#include "harness/suite/spec.h"
#include "harness/vo_config.h"

namespace harness {
namespace {

struct BreakpointArgs {
  std::string scenario;
  std::string vary;
  std::string range;
  std::string until;
  std::string config;
  std::string external;  // SUITE.yaml:CONFIG
  int seeds = 1;
  std::string aggregate = "mean";
  int max_frames = 0;
  int stride = 1;
  int max_lost_frames = 0;
  double tolerance = 0.0;
  int scan = 5;
  int max_evals = 40;
  std::string out;  // "" = out/breakpoint/<scenario>_<key>
  bool no_plots = false;
  bool quiet = false;
};

// --external SUITE.yaml:CONFIG: the external configuration CONFIG of the suite file.
bool ReadExternal(const std::string& arg, ExternalEstimator* estimator, std::string* error) {
  const size_t colon = arg.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == arg.size()) {
    *error = "--external '" + arg +
             "': expected SUITE.yaml:CONFIG (a suite file and the name "
             "of one of its external configurations)";
    return false;
  }
  const std::string path = arg.substr(0, colon), name = arg.substr(colon + 1);
  Suite suite;
  if (!LoadSuite(path, &suite, error)) return false;
  std::string names;
  for (const SuiteConfig& c : suite.configs) {
    if (c.external) names += (names.empty() ? "" : ", ") + c.name;
    if (c.name != name) continue;
    if (!c.external) {
      *error = "--external: configuration '" + name + "' of " + path +
               " is the built-in VO; give its options with --config";
      return false;
    }
    *estimator = c.estimator;
    return true;
  }
  *error = "--external: " + path + " has no configuration '" + name +
           "' (external ones: " + (names.empty() ? "none" : names) + ")";
  return false;
}

int RunBreakpointCommand(const BreakpointArgs& a) {
  const auto bad = [](const std::string& message) {
    return PrintFailure("breakpoint", kExitBadInput, message);
  };
  std::string error;
  BreakpointSpec spec;
  spec.scenario_arg = a.scenario;
  spec.key = a.vary;
  spec.range_text = a.range;
  if (!ParseRange(a.range, &spec.lo, &spec.hi, &error) || !ParseUntil(a.until, &spec.until, &error))
    return bad(error);
  if (!ResolveScenario(a.scenario, &spec.scenario, &error)) return bad(error);
  if (!a.config.empty() && !a.external.empty())
    return bad(
        "--config and --external: give one (the built-in VO's options, or an external "
        "estimator)");
  spec.config_path = a.config;
  if (!a.config.empty() && !LoadVoConfig(a.config, &spec.vo_options, &error)) return bad(error);
  spec.external_arg = a.external;
  if (!a.external.empty() && !ReadExternal(a.external, &spec.estimator, &error)) return bad(error);
  spec.seeds = a.seeds;
  spec.aggregate = a.aggregate;
  spec.max_frames = a.max_frames;
  spec.stride = a.stride;
  spec.max_lost_frames = a.max_lost_frames;
  spec.tolerance_given = a.tolerance;
  spec.search.scan_points = a.scan;
  spec.search.max_evals = a.max_evals;
  if (!PrepareBreakpoint(&spec, &error)) return bad(error);
  BreakpointOptions options;
  options.out_dir = a.out;
  if (options.out_dir.empty()) {
    if (!CheckPathName(spec.scenario.name, "scenario name", &error))
      return bad(error + " (give --out)");
    options.out_dir = "out/breakpoint/" + spec.scenario.name + "_" + spec.key;
  }
  options.progress = !a.quiet;
  options.plots = !a.no_plots;
  BreakpointResult result;
  if (!RunBreakpoint(spec, options, &result, &error))
    return PrintFailure("breakpoint", kExitFailed, error);
  std::printf("breakpoint      %s, %s -> %s\n", spec.scenario.name.c_str(), spec.key.c_str(),
              options.out_dir.c_str());
  std::printf("result          %s\n", BreakpointResultLine(spec, result.search).c_str());
  if (!result.search.monotone)
    std::printf(
        "not monotone    the condition was met, then not met at a larger %s "
        "(breakpoint.json: uncrossed_after_crossing)\n",
        spec.key.c_str());
  std::printf("evaluations     %zu (%d seed%s each), %.0f s\n", result.search.points.size(),
              spec.seeds, spec.seeds > 1 ? "s" : "", result.wall_s);
  std::printf("report          %s/report.md\n", options.out_dir.c_str());
  return kExitOk;
}

}  // namespace

Command AddBreakpointCommand(CLI::App& app) {
  auto a = std::make_shared<BreakpointArgs>();
  CLI::App* b = app.add_subcommand(
      "breakpoint",
      "Find the value of a scenario key (or the stride) at which a metric crosses a value: a "
      "coarse scan over a range, then bisection");
  b->add_option("scenario", a->scenario, "Scenario YAML file or built-in name")->required();
  b->add_option("--vary", a->vary,
                "The key varied: a numeric scenario key (noise.pixel_sigma, "
                "robot.turn_rate_dps, noise.motion_blur_exposure_s, ...) or stride")
      ->required();
  b->add_option("--range", a->range, "LO,HI: the range of the key (LO < HI)")->required();
  b->add_option("--until", a->until,
                "METRIC>VALUE (or <, >=, <=): the condition the breaking point crosses, on a "
                "metric of metrics.json (e.g. 'end_pose_error_pct>2')")
      ->required();
  b->add_option("--config", a->config, "VO options of the built-in VO (YAML)");
  b->add_option("--external", a->external,
                "SUITE.yaml:CONFIG: run the external estimator of that suite configuration "
                "instead of the built-in VO");
  b->add_option("--seeds", a->seeds,
                "Noise seeds per point: the scenario's seed and the next N-1 (default 1)")
      ->check(AtLeast(1));
  b->add_option("--aggregate", a->aggregate,
                "A point's value over its seeds: mean, or worst (the largest for > and >=, "
                "the smallest for < and <=)")
      ->check(CLI::IsMember({"mean", "worst"}))
      ->capture_default_str();
  b->add_option("--max-frames", a->max_frames, "Source frames per run (0 = all)")
      ->check(AtLeast(0));
  b->add_option("--stride", a->stride, "The runs' frame stride (when --vary is not stride)")
      ->check(AtLeast(1));
  b->add_option("--max-lost-frames", a->max_lost_frames,
                "A run with more lost frames counts as crossed (-1: lost frames ignored; "
                "built-in VO only)")
      ->check(AtLeast(-1))
      ->capture_default_str();
  b->add_option("--tolerance", a->tolerance,
                "Bracket width to reach (default (HI-LO)/32; integer keys at least 1)")
      ->check(CLI::PositiveNumber);
  b->add_option("--scan", a->scan, "Points of the coarse scan, both ends included")
      ->check(AtLeast(2))
      ->capture_default_str();
  b->add_option("--max-evals", a->max_evals, "Evaluated points at most (scan included)")
      ->check(AtLeast(2))
      ->capture_default_str();
  b->add_option("--out,-o", a->out,
                "Output folder (default out/breakpoint/<scenario>_<key>); an earlier "
                "breakpoint result there is replaced")
      ->check(NonEmpty());
  b->add_flag("--no-plots", a->no_plots, "Skip breakpoint.png");
  b->add_flag("-q,--quiet", a->quiet, "No progress lines");
  return {b, [a] { return RunBreakpointCommand(*a); }};
}

}  // namespace harness
