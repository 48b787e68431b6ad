// vobench: the command-line front of the test bench.
//   vobench render SCENARIO --out DIR [--format kitti|euroc|tum]
//   vobench eval --dataset DIR --format kitti|euroc|tum ... (harness/eval_command.h)
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <opencv2/core/utility.hpp>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <sstream>

#include "harness/cli/command.h"
#include "harness/eval.h"
#include "harness/eval_command.h"
#include "harness/interrupt.h"
#include "harness/match_eval.h"
#include "harness/output_folder.h"
#include "harness/path_names.h"
#include "harness/plots/plots.h"
#include "harness/progress.h"
#include "harness/render.h"
#include "harness/run.h"
#include "harness/suite_cli.h"
#include "harness/vo_config.h"
#include "harness/trajectory_io.h"
#include "harness/tune_command.h"

namespace {

int RunRender(const std::string& scenario_arg, const std::string& out, const std::string& format,
              bool overwrite, bool quiet) {
  std::string error;
  sim::Scenario scenario;
  if (!harness::ResolveScenario(scenario_arg, &scenario, &error)) {
    std::fprintf(stderr, "vobench render: %s\n", error.c_str());
    return 2;
  }
  harness::RenderOptions options;
  if (!harness::ParseDatasetFormat(format, &options.format)) {
    std::fprintf(stderr, "vobench render: --format: expected kitti, euroc or tum, got '%s'\n", format.c_str());
    return 2;
  }
  options.overwrite = overwrite;
  options.progress = !quiet;
  harness::RenderSummary s;
  if (!harness::RenderScenario(scenario, out, options, &s, &error)) {
    std::fprintf(stderr, "vobench render: %s\n", error.c_str());
    return 1;
  }
  std::printf("scenario        %s\n", scenario.name.c_str());
  std::printf("output          %s (%s layout)\n", out.c_str(), harness::DatasetFormatName(options.format));
  std::printf("frames          %d (%.1f s at %.1f Hz)\n", s.frames, s.sim_time_s, scenario.rate_hz);
  std::printf("image size      %dx%d, baseline %.3f m\n", scenario.camera.width, scenario.camera.height,
              scenario.camera.baseline_m);
  std::printf("path length     %.3f m\n", s.path_length_m);
  std::printf("render speed    %.1f stereo frames/s (with depth, incl. physics and writing)\n", s.frames_per_s);
  std::printf("GL renderer     %s\n", s.gl_renderer.c_str());
  return 0;
}

// Comma-separated integers ("1,2,3,5,8").
bool ParseIntList(const std::string& text, std::vector<int>* out) {
  out->clear();
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      const int v = std::stoi(item, &used);
      if (used != item.size()) return false;
      out->push_back(v);
    } catch (...) {
      return false;
    }
  }
  return !out->empty();
}

int RunMatchEval(const std::string& scenario_arg, const std::string& strides_arg,
                 const std::string& matchers_arg, const std::string& prediction_arg, std::string out,
                 int max_frames, bool quiet) {
  std::string error;
  sim::Scenario scenario;
  if (!harness::ResolveScenario(scenario_arg, &scenario, &error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 2;
  }
  harness::MatchEvalOptions options;
  if (!ParseIntList(strides_arg, &options.strides)) {
    std::fprintf(stderr, "vobench match-eval: --strides: expected comma-separated integers, got '%s'\n", strides_arg.c_str());
    return 2;
  }
  if (!matchers_arg.empty()) {
    options.matchers.clear();
    std::stringstream ss(matchers_arg);
    std::string name;
    while (std::getline(ss, name, ',')) {
      vo::MatcherType t;
      if (!vo::ParseMatcherType(name, &t)) {
        std::fprintf(stderr, "vobench match-eval: --matchers: unknown matcher '%s' (svd_proximity, svd_ncc, svd_ncc_gabor, ncc_mutual, lucas_kanade, kalman, sift_ratio)\n", name.c_str());
        return 2;
      }
      options.matchers.push_back(t);
    }
  }
  if (!vo::ParsePredictionMode(prediction_arg, &options.prediction)) {
    std::fprintf(stderr, "vobench match-eval: --prediction: expected none or motion_prior, got '%s'\n",
                 prediction_arg.c_str());
    return 2;
  }
  if (!options.IsValid(&error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 2;
  }
  if (out.empty()) {
    if (!harness::CheckPathName(scenario.name, "scenario name", &error)) {
      std::fprintf(stderr, "vobench match-eval: %s (give --out)\n", error.c_str());
      return 2;
    }
    out = "out/match_eval/" + scenario.name;
  }
  harness::OutputFolder folder;  // marked and locked now, published when complete
  if (!folder.Create(out, "match-eval", &error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }

  // Simulate the scenario into memory: images, ground-truth depth and poses.
  harness::StereoSequence sequence;
  std::vector<harness::DatasetFrame> simulated;
  if (!harness::OpenScenarioSequence(scenario, &sequence, &error) ||
      !harness::ReadAllFrames(sequence.next, max_frames, sequence.expected_frames,
                              "simulate " + scenario.name, !quiet, out, &simulated, &error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }
  std::vector<harness::GroundTruthFrame> frames;
  for (const harness::DatasetFrame& f : simulated)
    frames.push_back({f.left, f.right, f.depth_m, f.T_world_cam0});
  simulated.clear();
  std::vector<harness::MatchEvalRow> rows;
  harness::Progress progress("match-eval", 1, !quiet);
  if (!harness::EvaluateMatchers(frames, sequence.camera, options, &rows, &error,
                                 [&](int done, int total) {
                                   progress.set_total(total);
                                   progress.Update(done);
                                 })) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }
  progress.Finish(static_cast<int>(rows.size()));
  if (harness::InterruptSignal() != 0) {
    std::fprintf(stderr, "vobench match-eval: %s\n",
                 harness::InterruptedMessage(static_cast<int>(frames.size()),
                                             static_cast<int>(frames.size()), "frames", out)
                     .c_str());
    return 1;
  }
  const std::string work = folder.path(), csv = out + "/match_eval.csv";
  if (!harness::WriteMatchEvalCsv(work + "/match_eval.csv", rows, &error) ||
      !harness::WriteTextFile(work + "/scenario.yaml", sim::ScenarioToYaml(scenario), &error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }
  if (!harness::RunPlot({"match-eval", work + "/match_eval.csv", work + "/match_eval.png"}, &error))
    std::fprintf(stderr, "vobench match-eval: warning: no plot: %s\n", error.c_str());
  if (!folder.Publish(&error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }
  std::printf("%-14s %6s %6s %8s %8s %9s %7s %7s %9s\n", "matcher", "stride", "pairs", "matches", "correct",
              "precision", "recall", "F1", "ms/pair");
  for (const auto& r : rows)
    std::printf("%-14s %6d %6d %8ld %8ld %9.4f %7.4f %7.4f %9.2f\n", r.matcher.c_str(), r.stride, r.pairs, r.matches,
                r.correct, r.precision, r.recall, r.f1, r.ms_per_pair);
  std::printf("wrote %s and %s/match_eval.png\n", csv.c_str(), out.c_str());
  return 0;
}

void PrintRunTable(const harness::RunSummary& s, const std::string& out) {
  const harness::TrajectoryMetrics& m = s.metrics;
  std::printf("run             %s -> %s\n", s.name.c_str(), out.c_str());
  std::printf("frames          %d (lost %d, re-initialised %d)\n", m.frames, s.lost_frames,
              s.reinitialisations);
  if (s.has_ground_truth) {
    std::printf("path length     %.3f m\n", m.path_length_m);
    std::printf("end-pose error  %.4f m (%.2f %% of the path), rotation %.3f deg\n", m.end_pose_error_m,
                m.end_pose_error_pct, m.end_rotation_error_deg);
    std::printf("ATE RMSE        %.4f m (SE(3)-aligned), %.4f m (from the start)\n", m.ate_rmse_m, m.ate_rmse_unaligned_m);
    std::printf("drift           %.3f %%, %.4f deg/m\n", m.drift_pct, m.drift_deg_per_m);
    if (s.initial_orientation_error_deg >= 0)
      std::printf("initial orient. %.2f deg from ground truth (plane-based)\n", s.initial_orientation_error_deg);
  }
  std::printf("VO time/frame   median %.2f ms, p95 %.2f ms |", s.vo_ms_median, s.vo_ms_p95);
  for (const auto& [k, v] : s.stage_ms_median) std::printf(" %s %.2f", k.c_str(), v);
  std::printf("\n");
}

int RunRun(const std::string& scenario_arg, const std::string& config, const std::string& dataset,
           std::string out, int max_frames, int stride, bool no_plots, bool quiet) {
  std::string error;
  if (max_frames < 0) {  // also refused by the option's check; kept for callers of RunRun
    std::fprintf(stderr, "vobench run: --max-frames: must be >= 0, got %d\n", max_frames);
    return 2;
  }
  vo::OdometryOptions vo_options;
  if (!config.empty() && !harness::LoadVoConfig(config, &vo_options, &error)) {
    std::fprintf(stderr, "vobench run: %s\n", error.c_str());
    return 2;
  }
  harness::RunOptions options;
  options.progress = !quiet;
  options.plots = !no_plots;
  options.max_frames = max_frames;
  options.frame_stride = stride;
  harness::RunSummary summary;
  bool ok;
  if (!dataset.empty()) {
    if (out.empty()) {
      const std::string name = harness::DatasetName(dataset);
      if (!harness::CheckPathName(name, "dataset folder name", &error)) {
        std::fprintf(stderr, "vobench run: %s (give --out)\n", error.c_str());
        return 2;
      }
      out = "out/run/" + name;
    }
    options.out_dir = out;
    ok = harness::RunKittiDataset(dataset, vo_options, options, &summary, &error);
  } else {
    sim::Scenario scenario;
    if (!harness::ResolveScenario(scenario_arg, &scenario, &error)) {
      std::fprintf(stderr, "vobench run: %s\n", error.c_str());
      return 2;
    }
    if (out.empty()) {
      if (!harness::CheckPathName(scenario.name, "scenario name", &error)) {
        std::fprintf(stderr, "vobench run: %s (give --out)\n", error.c_str());
        return 2;
      }
      out = "out/run/" + scenario.name;
    }
    options.out_dir = out;
    ok = harness::RunScenario(scenario, vo_options, options, &summary, &error);
  }
  if (!ok) {
    std::fprintf(stderr, "vobench run: %s\n", error.c_str());
    return 1;
  }
  PrintRunTable(summary, out);
  std::printf("report          %s/report.md\n", out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // The VO runs on one thread (the timings vobench reports are single-threaded, as the speed
  // target asks); OpenCV's own thread pool would otherwise split StereoBM and filters.
  cv::setNumThreads(1);
  // Ctrl-C / SIGTERM: the commands stop at the next frame, remove their work folders and exit
  // with 128 + the signal (harness/interrupt.h).
  const harness::ScopedInterruptHandlers interrupt_handlers;
  CLI::App app{"vobench: simulation-in-the-loop test bench for stereo visual odometry"};
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Debug logging");

  std::string scenario = "l_hallway", out, format = "kitti";
  bool overwrite = false, quiet = false;
  CLI::App* render = app.add_subcommand("render", "Simulate a scenario and write its stereo sequence (KITTI layout, optionally EuRoC)");
  render->add_option("scenario", scenario, "Scenario YAML file or built-in name (l_hallway, plain_corridor)")->capture_default_str();
  render->add_option("--out,-o", out, "Output folder (must not exist unless --overwrite)")->required();
  render->add_option("--format", format, "Dataset layout: kitti, euroc or tum (euroc and tum also write kitti)")->capture_default_str();
  render->add_flag("--overwrite", overwrite, "Replace an existing output folder if it is a dataset vobench wrote");
  render->add_flag("-q,--quiet", quiet, "No progress display");

  std::string me_scenario = "l_hallway", me_strides = "1,2,3,5,8", me_matchers, me_out,
              me_prediction = "motion_prior";
  int me_max_frames = 0;
  CLI::App* match_eval = app.add_subcommand("match-eval", "Matcher precision/recall/F1 per stride against the simulator's ground truth");
  match_eval->add_option("scenario", me_scenario, "Scenario YAML file or built-in name")->capture_default_str();
  match_eval->add_option("--strides", me_strides, "Frame strides, comma-separated")->capture_default_str();
  match_eval->add_option("--matchers", me_matchers, "Matchers, comma-separated (default: all seven)");
  match_eval->add_option("--prediction", me_prediction,
                         "Search centre of every matcher: motion_prior (constant velocity from the "
                         "previous pair's ground truth, as the VO predicts) or none (the paper's form)")
      ->capture_default_str();
  match_eval->add_option("--out,-o", me_out, "Output folder (default out/match_eval/<scenario>)");
  match_eval->add_option("--max-frames", me_max_frames, "Use only the first N frames (0 = all)")
      ->check(harness::AtLeast(0));
  match_eval->add_flag("-q,--quiet", quiet, "No progress display");

  std::string run_scenario = "l_hallway", run_config, run_dataset, run_out;
  int run_max_frames = 0, run_stride = 1;
  bool run_no_plots = false;
  CLI::App* run = app.add_subcommand("run", "Run the VO on a simulated scenario (or a KITTI-layout dataset) and compare with ground truth");
  run->add_option("scenario", run_scenario, "Scenario YAML file or built-in name")->capture_default_str();
  run->add_option("--config", run_config, "VO options (YAML; see a run folder's vo_options.yaml)");
  run->add_option("--dataset", run_dataset, "Read a dataset folder in the KITTI layout instead of simulating");
  run->add_option("--out,-o", run_out, "Run folder (default out/run/<name>); an earlier run there is replaced");
  run->add_option("--max-frames", run_max_frames, "Stop after N frames (0 = all)")
      ->check(harness::AtLeast(0));
  run->add_option("--stride", run_stride, "The VO sees every k-th frame (less overlap); --max-frames counts all frames")
      ->check(harness::AtLeast(1));
  run->add_flag("--no-plots", run_no_plots, "Skip the PNG plots");
  run->add_flag("-q,--quiet", quiet, "No progress display");

  const auto eval = harness::AddEvalCommand(app);
  harness::TuneCommandArgs tune_args;
  CLI::App* tune = harness::AddTuneCommand(app, &tune_args);
  harness::AddSuiteCommands(app);  // suite, suite merge, check

  // Argument errors exit with 2 (one line on stderr); suite, suite merge and check run inside
  // the parse (their callbacks) and give their own exit codes.
  int rc = harness::ParseCommandLine(app, argc, argv);
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  spdlog::set_pattern("[%l] %v");
  if (rc < 0) {
    if (*render) rc = RunRender(scenario, out, format, overwrite, quiet);
    else if (*run) rc = RunRun(run_scenario, run_config, run_dataset, run_out, run_max_frames, run_stride, run_no_plots, quiet);
    else if (*eval->app) rc = eval->Run(PrintRunTable);
    else if (*tune) rc = harness::RunTuneCommand(tune_args);
    else if (*match_eval)
      rc = RunMatchEval(me_scenario, me_strides, me_matchers, me_prediction, me_out, me_max_frames, quiet);
    else rc = 0;
  }
  // A command stopped by SIGINT/SIGTERM has said so and removed its work; the exit status tells
  // the shell which signal (130, 143).
  if (rc != 0 && harness::InterruptSignal() != 0) rc = harness::InterruptExitCode();
  return rc;
}
