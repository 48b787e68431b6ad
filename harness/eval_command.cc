#include "harness/eval_command.h"

#include <cstdio>

#include "harness/cli/command.h"
#include "harness/eval.h"
#include "harness/path_names.h"
#include "harness/vo_config.h"

namespace harness {

std::shared_ptr<EvalCommand> AddEvalCommand(CLI::App& app) {
  auto c = std::make_shared<EvalCommand>();
  c->app = app.add_subcommand(
      "eval",
      "Run the VO on a recorded stereo sequence (KITTI, EuRoC or TUM-style layout) and, "
      "where ground truth is present, compute the same metrics as `run`");
  c->app->add_option("--dataset", c->dataset, "Dataset folder")->required();
  c->app->add_option("--format", c->format, "Dataset layout: kitti, euroc or tum")->required();
  c->app->add_option("--gt", c->gt,
                     "Ground truth, TUM format (t tx ty tz qx qy qz qw): the left camera for "
                     "kitti/tum, the body/IMU for euroc; for kitti also KITTI poses (12 numbers "
                     "per line). Default: the dataset's own, if any");
  c->app->add_option("--config", c->config,
                     "VO options (YAML; see a run folder's vo_options.yaml)");
  c->app->add_option("--out,-o", c->out,
                     "Run folder (default out/eval/<dataset folder name>); an earlier run there is "
                     "replaced");
  c->app->add_option("--max-frames", c->max_frames, "Stop after N frames (0 = all)")
      ->check(AtLeast(0));
  c->app->add_option("--max-difference", c->max_difference_s,
                     "Largest ground-truth to frame time difference associated (s; default 0.02 "
                     "for kitti and tum, 0.003 for euroc)");
  c->app->add_flag("--no-plots", c->no_plots, "Skip the PNG plots");
  c->app->add_flag("-q,--quiet", c->quiet, "No progress display");
  return c;
}

int EvalCommand::Run(const PrintTable& print_table) const {
  std::string error;
  EvalOptions options;
  if (!ParseDatasetFormat(format, &options.format)) {
    std::fprintf(stderr, "vobench eval: --format: expected kitti, euroc or tum, got '%s'\n",
                 format.c_str());
    return 2;
  }
  options.gt_path = gt;
  if (app->count("--max-difference") > 0 && !(max_difference_s > 0.0)) {
    std::fprintf(stderr, "vobench eval: --max-difference: expected seconds > 0, got %g\n",
                 max_difference_s);
    return 2;
  }
  options.max_difference_s = max_difference_s;
  if (max_frames < 0) {
    std::fprintf(stderr, "vobench eval: --max-frames: must be >= 0, got %d\n", max_frames);
    return 2;
  }
  if (!options.IsValid(&error)) {
    std::fprintf(stderr, "vobench eval: %s\n", error.c_str());
    return 2;
  }
  vo::OdometryOptions vo_options;
  if (!config.empty() && !LoadVoConfig(config, &vo_options, &error)) {
    std::fprintf(stderr, "vobench eval: %s\n", error.c_str());
    return 2;
  }
  RunOptions run_options;
  if (out.empty() && !CheckPathName(DatasetName(dataset), "dataset folder name", &error)) {
    std::fprintf(stderr, "vobench eval: %s (give --out)\n", error.c_str());
    return 2;
  }
  run_options.out_dir = out.empty() ? "out/eval/" + DatasetName(dataset) : out;
  run_options.progress = !quiet;
  run_options.plots = !no_plots;
  run_options.max_frames = max_frames;
  RunSummary summary;
  EvalInfo info;
  if (!EvalDataset(dataset, options, vo_options, run_options, &summary, &info, &error)) {
    std::fprintf(stderr, "vobench eval: %s\n", error.c_str());
    return 1;
  }
  std::printf("dataset         %s (%s layout), %zu stereo frames", dataset.c_str(), format.c_str(),
              info.dataset_frames);
  if (info.unpaired_frames > 0) std::printf(", %zu unpaired images left out", info.unpaired_frames);
  std::printf("\n");
  const vo::StereoCamera& cam = info.camera;
  std::printf("camera          %dx%d, fx %.2f fy %.2f cx %.2f cy %.2f px, baseline %.4f m%s\n",
              cam.width, cam.height, cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px, cam.baseline_m,
              info.rectified ? " (rectified from the raw calibration)" : "");
  if (info.ground_truth_path.empty()) {
    std::printf("ground truth    none: trajectory and per-frame log only, no accuracy metrics\n");
  } else {
    std::printf("ground truth    %s: %zu of %zu frames associated (max difference %g s)",
                info.ground_truth_path.c_str(), info.ground_truth_frames, info.dataset_frames,
                info.max_difference_s);
    if (summary.has_ground_truth)
      std::printf("; metrics over the %d run frames with ground truth\n",
                  summary.ground_truth_frames);
    else
      std::printf("; %d run frame(s) with ground truth: too few, no accuracy metrics\n",
                  summary.ground_truth_frames);
  }
  print_table(summary, run_options.out_dir);
  std::printf("report          %s/report.md\n", run_options.out_dir.c_str());
  return 0;
}

}  // namespace harness
