#include "harness/cli/eval_command.h"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "harness/cli/run_command.h"
#include "harness/eval.h"
#include "harness/path_names.h"
#include "harness/vo_config.h"

namespace harness {
namespace {

struct EvalArgs {
  std::string dataset;
  std::string format;
  std::string gt;
  std::string config;
  std::string out;                 // default out/eval/<dataset folder name>
  RosbagTopics topics;             // rosbag
  std::vector<std::string> calib;  // rosbag: cam0.yaml cam1.yaml
  std::string imu_extrinsics;      // rosbag: Kalibr camchain-imucam.yaml
  int max_frames = 0;
  double max_difference_s = 0.0;
  bool no_plots = false;
  bool quiet = false;
};

// Runs the parsed command; max_difference_given: --max-difference was on the command line;
// rosbag_flag: the first of the rosbag-only flags given ("" = none).
int RunEval(const EvalArgs& a, bool max_difference_given, const std::string& rosbag_flag) {
  std::string error;
  EvalOptions options;
  if (!ParseDatasetFormat(a.format, &options.format)) {
    std::fprintf(stderr, "vobench eval: --format: expected kitti, euroc, tum or rosbag, got '%s'\n",
                 a.format.c_str());
    return 2;
  }
  if (options.format == DatasetFormat::kRosbag && !RosbagSupported()) {
    std::fprintf(stderr, "vobench eval: --format rosbag: %s\n", RosbagUnavailable().c_str());
    return 2;
  }
  if (options.format != DatasetFormat::kRosbag && !rosbag_flag.empty()) {
    std::fprintf(stderr, "vobench eval: %s: only with --format rosbag\n", rosbag_flag.c_str());
    return 2;
  }
  options.rosbag_topics = a.topics;
  if (!a.calib.empty()) {
    options.calib_left = a.calib[0];
    options.calib_right = a.calib[1];
  }
  options.imu_extrinsics = a.imu_extrinsics;
  options.gt_path = a.gt;
  if (max_difference_given && !(a.max_difference_s > 0.0)) {
    std::fprintf(stderr, "vobench eval: --max-difference: expected seconds > 0, got %g\n",
                 a.max_difference_s);
    return 2;
  }
  options.max_difference_s = a.max_difference_s;
  if (a.max_frames < 0) {
    std::fprintf(stderr, "vobench eval: --max-frames: must be >= 0, got %d\n", a.max_frames);
    return 2;
  }
  if (!options.IsValid(&error)) {
    std::fprintf(stderr, "vobench eval: %s\n", error.c_str());
    return 2;
  }
  vo::OdometryOptions vo_options;
  if (!a.config.empty() && !LoadVoConfig(a.config, &vo_options, &error)) {
    std::fprintf(stderr, "vobench eval: %s\n", error.c_str());
    return 2;
  }
  RunOptions run_options;
  if (a.out.empty() && !CheckPathName(DatasetName(a.dataset), "dataset folder name", &error)) {
    std::fprintf(stderr, "vobench eval: %s (give --out)\n", error.c_str());
    return 2;
  }
  run_options.out_dir = a.out.empty() ? "out/eval/" + DatasetName(a.dataset) : a.out;
  run_options.progress = !a.quiet;
  run_options.plots = !a.no_plots;
  run_options.max_frames = a.max_frames;
  RunSummary summary;
  EvalInfo info;
  // A dataset its reader refuses is bad input (exit 2, nothing written); a run that fails, 1.
  StereoSequence sequence;
  if (!OpenDataset(a.dataset, options, &sequence, &info, &error)) {
    std::fprintf(stderr, "vobench eval: %s\n", error.c_str());
    return 2;
  }
  if (!RunSequence(sequence, vo_options, run_options, &summary, &error)) {
    std::fprintf(stderr, "vobench eval: %s\n", error.c_str());
    return 1;
  }
  std::printf("dataset         %s (%s layout), %zu stereo frames", a.dataset.c_str(),
              a.format.c_str(), info.dataset_frames);
  if (info.unpaired_frames > 0) std::printf(", %zu unpaired images left out", info.unpaired_frames);
  std::printf("\n");
  const vo::StereoCamera& cam = info.camera;
  std::printf("camera          %dx%d, fx %.2f fy %.2f cx %.2f cy %.2f px, baseline %.4f m%s\n",
              cam.width, cam.height, cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px, cam.baseline_m,
              info.rectified ? " (rectified from the raw calibration)" : "");
  if (sequence.has_imu) {
    std::printf("imu             %g Hz; ", sequence.imu.rate_hz);
    if (!sequence.imu_extrinsics_known)
      std::printf(
          "its mounting unknown: the gyro not used (--imu-extrinsics "
          "camchain-imucam.yaml)\n");
    else if (!vo_options.imu.gyro_prior)
      std::printf("the gyro not used (imu.gyro_prior: false)\n");
    else
      std::printf("the VO uses its gyro (imu.gyro_prior), cam0 on the IMU from %s\n",
                  info.imu_extrinsics_path.c_str());
  }
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
  PrintRunTable(summary, run_options.out_dir);
  std::printf("report          %s/report.md\n", run_options.out_dir.c_str());
  return 0;
}

}  // namespace

Command AddEvalCommand(CLI::App& app) {
  auto a = std::make_shared<EvalArgs>();
  CLI::App* eval = app.add_subcommand(
      "eval",
      "Run the VO on a recorded stereo sequence (KITTI, EuRoC or TUM-style layout, or a ROS "
      "bag) and, "
      "where ground truth is present, compute the same metrics as `run`");
  eval->add_option("--dataset", a->dataset, "Dataset folder (rosbag: the .bag file)")->required();
  eval->add_option("--format", a->format, "Dataset layout: kitti, euroc, tum or rosbag")
      ->required();
  eval->add_option("--left", a->topics.left, "rosbag: left image topic (sensor_msgs/Image)")
      ->capture_default_str();
  eval->add_option("--right", a->topics.right, "rosbag: right image topic (sensor_msgs/Image)")
      ->capture_default_str();
  eval->add_option("--imu", a->topics.imu, "rosbag: IMU topic (sensor_msgs/Imu; absent = no IMU)")
      ->capture_default_str();
  eval->add_option("--gt-topic", a->topics.ground_truth,
                   "rosbag: ground-truth topic (geometry_msgs/TransformStamped of the left "
                   "camera; absent = no ground truth)")
      ->capture_default_str();
  eval->add_option("--calib", a->calib,
                   "rosbag: two EuRoC sensor.yaml files (cam0 cam1) instead of the image "
                   "topics' camera_info (EuRoC's bags have none)")
      ->expected(2);
  eval->add_option("--imu-extrinsics", a->imu_extrinsics,
                   "rosbag: the cameras' poses on the IMU, a Kalibr camchain-imucam.yaml (cam0's "
                   "T_cam_imu), so the VO can use the bag's gyro (imu.gyro_prior). Default: "
                   "camchain-imucam.yaml beside the bag (render writes it), else the --calib "
                   "files' T_BS (EuRoC: the body is the IMU); none: the gyro is not used");
  eval->add_option("--gt", a->gt,
                   "Ground truth, TUM format (t tx ty tz qx qy qz qw): the left camera for "
                   "kitti/tum, the body/IMU for euroc; for kitti also KITTI poses (12 numbers "
                   "per line). Default: the dataset's own, if any");
  eval->add_option("--config", a->config, "VO options (YAML; see a run folder's vo_options.yaml)");
  eval->add_option("--out,-o", a->out,
                   "Run folder (default out/eval/<dataset folder name>); an earlier run there is "
                   "replaced");
  eval->add_option("--max-frames", a->max_frames, "Stop after N frames (0 = all)")
      ->check(AtLeast(0));
  eval->add_option("--max-difference", a->max_difference_s,
                   "Largest ground-truth to frame time difference associated (s; default 0.02 "
                   "for kitti and tum, 0.003 for euroc and rosbag)");
  eval->add_flag("--no-plots", a->no_plots, "Skip the PNG plots");
  eval->add_flag("-q,--quiet", a->quiet, "No progress display");
  return {eval, [a, eval] {
            std::string rosbag_flag;
            for (const char* flag :
                 {"--left", "--right", "--imu", "--gt-topic", "--calib", "--imu-extrinsics"})
              if (rosbag_flag.empty() && eval->count(flag) > 0) rosbag_flag = flag;
            return RunEval(*a, eval->count("--max-difference") > 0, rosbag_flag);
          }};
}

}  // namespace harness
