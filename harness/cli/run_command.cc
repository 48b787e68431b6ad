#include "harness/cli/run_command.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include "harness/eval.h"
#include "harness/path_names.h"
#include "harness/render.h"
#include "harness/run.h"
#include "harness/sequence_cache.h"
#include "harness/vo_config.h"

namespace harness {
namespace {

struct RunArgs {
  std::string scenario = "l_hallway";
  std::string config;
  std::string dataset;
  std::string out;             // "" = out/run/<scenario or dataset folder name>
  std::string sequence_cache;  // "" = simulate here; else the shared sequences' folder
  int max_frames = 0;
  int stride = 1;
  bool no_plots = false;
  bool quiet = false;
};

int RunRun(const std::string& scenario_arg, const std::string& config, const std::string& dataset,
           std::string out, const std::string& sequence_cache, int max_frames, int stride,
           bool no_plots, bool quiet) {
  std::string error;
  if (max_frames < 0) {  // also refused by the option's check; kept for callers of RunRun
    std::fprintf(stderr, "vobench run: --max-frames: must be >= 0, got %d\n", max_frames);
    return 2;
  }
  vo::OdometryOptions vo_options;
  if (!config.empty() && !LoadVoConfig(config, &vo_options, &error)) {
    std::fprintf(stderr, "vobench run: %s\n", error.c_str());
    return 2;
  }
  RunOptions options;
  options.progress = !quiet;
  options.plots = !no_plots;
  options.max_frames = max_frames;
  options.frame_stride = stride;
  RunSummary summary;
  bool ok;
  if (!dataset.empty() && !sequence_cache.empty()) {
    std::fprintf(stderr,
                 "vobench run: --sequence-cache: only for a simulated scenario, not "
                 "with --dataset\n");
    return 2;
  }
  if (!dataset.empty()) {
    if (out.empty()) {
      const std::string name = DatasetName(dataset);
      if (!CheckPathName(name, "dataset folder name", &error)) {
        std::fprintf(stderr, "vobench run: %s (give --out)\n", error.c_str());
        return 2;
      }
      out = "out/run/" + name;
    }
    options.out_dir = out;
    ok = RunKittiDataset(dataset, vo_options, options, &summary, &error);
  } else {
    sim::Scenario scenario;
    if (!ResolveScenario(scenario_arg, &scenario, &error)) {
      std::fprintf(stderr, "vobench run: %s\n", error.c_str());
      return 2;
    }
    if (const std::string problem =
            FrameBudgetProblem(sim::EstimatedFrames(scenario), true, max_frames, stride);
        !problem.empty()) {
      std::fprintf(stderr, "vobench run: %s\n", problem.c_str());
      return 2;
    }
    if (out.empty()) {
      if (!CheckPathName(scenario.name, "scenario name", &error)) {
        std::fprintf(stderr, "vobench run: %s (give --out)\n", error.c_str());
        return 2;
      }
      out = "out/run/" + scenario.name;
    }
    options.out_dir = out;
    // A closed-loop run's frames depend on its VO: it simulates in the loop, never from a cache.
    if (sequence_cache.empty() || !ClosedLoopProblem(scenario, "").empty()) {
      ok = RunScenario(scenario, vo_options, options, &summary, &error);
    } else {
      StereoSequence sequence;  // the first max_frames frames, simulated once for every run
      ok = OpenSharedScenarioSequence(scenario, max_frames, sequence_cache, !quiet, &sequence,
                                      &error) &&
           RunSequence(sequence, vo_options, options, &summary, &error);
    }
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

void PrintRunTable(const RunSummary& s, const std::string& out) {
  const TrajectoryMetrics& m = s.metrics;
  std::printf("run             %s -> %s\n", s.name.c_str(), out.c_str());
  std::printf("frames          %d (lost %d, re-initialised %d)\n", m.frames, s.lost_frames,
              s.reinitialisations);
  if (!s.platform.empty())
    std::printf("platform        %s%s\n", s.platform.c_str(),
                s.platform == "ground_vehicle"
                    ? " (the rig's wheel axle known; platform: free in --config for 6-DoF)"
                    : "");
  if (s.has_ground_truth) {
    std::printf("path length     %.3f m (camera, 3-D)\n", m.path_length_m);
    if (std::isfinite(m.end_pose_error_pct))
      std::printf("end-pose error  %.4f m (%.2f %% of the path), rotation %.3f deg\n",
                  m.end_pose_error_m, m.end_pose_error_pct, m.end_rotation_error_deg);
    else
      std::printf("end-pose error  %.4f m, rotation %.3f deg; %% of the path n/a (%s)\n",
                  m.end_pose_error_m, m.end_rotation_error_deg,
                  m.end_pose_error_pct_reason.c_str());
    std::printf("ATE RMSE        %.4f m (SE(3)-aligned), %.4f m (from the start)\n", m.ate_rmse_m,
                m.ate_rmse_unaligned_m);
    if (std::isfinite(m.drift_pct))
      std::printf("drift           %.3f %%, %.4f deg/m\n", m.drift_pct, m.drift_deg_per_m);
    else
      std::printf("drift           n/a (%s)\n", m.drift_reason.c_str());
    if (std::isfinite(m.kitti_drift_pct))
      std::printf("KITTI drift     %.3f %%, %.4f deg/m (devkit, %d segments)\n", m.kitti_drift_pct,
                  m.kitti_drift_deg_per_m, m.kitti_drift_segments);
    else
      std::printf("KITTI drift     n/a (%s)\n", m.kitti_drift_reason.c_str());
    if (std::isfinite(s.initial_orientation_error_deg))
      std::printf("initial orient. %.2f deg from ground truth (plane-based%s)\n",
                  s.initial_orientation_error_deg,
                  s.initial_floor_refined ? ", floor or ceiling refined on the images" : "");
    else
      std::printf("initial orient. n/a (%s)\n", s.initial_orientation_error_reason.c_str());
    if (!s.initial_floor_message.empty() && !s.initial_floor_refined)
      std::printf("                %s\n", s.initial_floor_message.c_str());
  }
  std::printf("VO time/frame   median %.2f ms, p95 %.2f ms |", s.vo_ms_median, s.vo_ms_p95);
  for (const auto& [k, v] : s.stage_ms_median) std::printf(" %s %.2f", k.c_str(), v);
  std::printf("\n");
}

Command AddRunCommand(CLI::App& app) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* run = app.add_subcommand("run",
                                     "Run the VO on a simulated scenario (or a KITTI-layout "
                                     "dataset) and compare with ground truth");
  run->add_option("scenario", a->scenario, "Scenario YAML file or built-in name")
      ->capture_default_str();
  run->add_option("--config", a->config, "VO options (YAML; see a run folder's vo_options.yaml)");
  run->add_option("--dataset", a->dataset,
                  "Read a dataset folder in the KITTI layout instead of simulating");
  run->add_option("--out,-o", a->out,
                  "Run folder (default out/run/<name>); an earlier run there is replaced")
      ->check(NonEmpty());
  run->add_option("--max-frames", a->max_frames, "Stop after N frames (0 = all)")
      ->check(AtLeast(0));
  run->add_option("--stride", a->stride,
                  "The VO sees every k-th frame (less overlap); --max-frames counts all frames")
      ->check(AtLeast(1));
  run->add_option("--sequence-cache", a->sequence_cache,
                  "Folder of simulated sequences shared by runs of the same scenario, seed and "
                  "--max-frames (a suite's): the first run simulates the sequence into it, the "
                  "others (other --config or --stride) read its frames, bit for bit the same")
      ->check(NonEmpty());
  run->add_flag("--no-plots", a->no_plots, "Skip the PNG plots");
  run->add_flag("-q,--quiet", a->quiet, "No progress display");
  return {run, [a] {
            return RunRun(a->scenario, a->config, a->dataset, a->out, a->sequence_cache,
                          a->max_frames, a->stride, a->no_plots, a->quiet);
          }};
}

}  // namespace harness
