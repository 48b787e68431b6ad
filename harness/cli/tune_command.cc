#include "harness/cli/tune_command.h"

#include <cstdio>
#include <memory>
#include <string>

#include "harness/tune.h"

namespace harness {
namespace {

struct TuneArgs {
  std::string file;   // the tune file (YAML, see tune.h)
  std::string out;    // output folder; "" = out/tune/<name>
  int max_evals = 0;  // > 0: replaces the file's optimizer.max_evals
  bool no_plots = false;
  bool quiet = false;
};

int RunTuneCommand(const TuneArgs& args) {
  std::string error;
  TuneSpec spec;
  if (!LoadTuneSpec(args.file, &spec, &error)) {
    std::fprintf(stderr, "vobench tune: %s\n", error.c_str());
    return 2;
  }
  TuneOptions options;
  options.out_dir = args.out.empty() ? "out/tune/" + spec.name : args.out;
  options.progress = !args.quiet;
  options.plots = !args.no_plots;
  options.max_evals = args.max_evals;
  TuneSummary summary;
  if (!RunTune(spec, options, &summary, &error)) {
    std::fprintf(stderr, "vobench tune: %s\n", error.c_str());
    return 1;
  }
  const OptimizationResult& r = summary.optimization;
  std::printf("tune            %s -> %s\n", spec.name.c_str(), options.out_dir.c_str());
  std::printf("search          %s, %zu evaluations (%d restarts; %s), best at evaluation %d\n",
              spec.optimizer.algorithm.c_str(), r.evaluations.size(), r.restarts,
              r.stop_reason.c_str(), r.best_index);
  std::printf("run time        %.0f s (simulation %.0f s, search %.0f s, validation %.0f s)\n",
              summary.wall_s, summary.simulate_s, summary.search_s, summary.validation_s);
  std::printf("%s", TuneSummaryTable(spec, summary).c_str());
  std::printf("best config     %s/best_vo.yaml (vobench run --config)\n", options.out_dir.c_str());
  std::printf("report          %s/report.md\n", options.out_dir.c_str());
  return 0;
}

}  // namespace

Command AddTuneCommand(CLI::App& app) {
  auto a = std::make_shared<TuneArgs>();
  CLI::App* tune = app.add_subcommand(
      "tune",
      "Search VO parameters against ground truth on training scenarios, score the best on "
      "validation scenarios, write it as a --config file");
  tune->add_option("file", a->file, "Tune file (YAML; see README, section Tuning)")->required();
  tune->add_option(
      "--out,-o", a->out,
      "Output folder (default out/tune/<name>); an earlier tune result there is replaced");
  tune->add_option(
          "--max-evals", a->max_evals,
          "Evaluations budget, the start included (default: the file's optimizer.max_evals)")
      ->check(AtLeast(1));
  tune->add_flag("--no-plots", a->no_plots, "Skip objective.png");
  tune->add_flag("-q,--quiet", a->quiet, "No progress display");
  return {tune, [a] { return RunTuneCommand(*a); }};
}

}  // namespace harness
