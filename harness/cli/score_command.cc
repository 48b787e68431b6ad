#include "harness/cli/score_command.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "harness/path_names.h"
#include "harness/score.h"

namespace harness {
namespace {

struct ScoreArgs {
  std::string gt;
  std::string est;
  std::string format;
  std::string out;  // default out/score/<estimate file name without extension>
  double max_difference_s = 0.02;
};

// max_difference_given: --max-difference was on the command line.
int RunScore(const ScoreArgs& a, bool max_difference_given) {
  ScoreOptions options;
  if (!ParseTrajectoryFormat(a.format, &options.format))
    return PrintFailure("score", kExitBadInput,
                        "--format: expected tum or kitti, got '" + a.format + "'");
  if (max_difference_given && options.format == TrajectoryFormat::kKitti)
    return PrintFailure("score", kExitBadInput,
                        "--max-difference: only for --format tum (KITTI poses are paired line "
                        "by line)");
  options.max_difference_s = a.max_difference_s;
  std::string error;
  if (!options.IsValid(&error))
    return PrintFailure("score", kExitBadInput, "--max-difference: " + error);
  const std::string name = std::filesystem::path(a.est).stem().string();
  if (a.out.empty() && !CheckPathName(name, "estimate file name", &error))
    return PrintFailure("score", kExitBadInput, error + " (give --out)");
  const std::string out = a.out.empty() ? "out/score/" + name : a.out;
  ScoreResult result;
  if (!ScoreTrajectory(name, a.gt, a.est, options, &result, &error))
    return PrintFailure("score", kExitBadInput, error);
  if (!WriteScoreFolder(result, out, &error)) return PrintFailure("score", kExitFailed, error);
  const TrajectoryMetrics& m = result.summary.metrics;
  std::printf("score           %s -> %s\n", a.est.c_str(), out.c_str());
  if (options.format == TrajectoryFormat::kTum)
    std::printf(
        "frames          %d of %zu estimated poses associated with %zu ground-truth poses "
        "(by time, max difference %g s)\n",
        m.frames, result.estimate_poses, result.ground_truth_poses, options.max_difference_s);
  else
    std::printf("frames          %d (KITTI poses, paired line by line)\n", m.frames);
  std::printf("path length     %.3f m\n", m.path_length_m);
  std::printf("end-pose error  %.4f m (%.2f %% of the path), rotation %.3f deg\n",
              m.end_pose_error_m, m.end_pose_error_pct, m.end_rotation_error_deg);
  std::printf("ATE RMSE        %.4f m (SE(3)-aligned), %.4f m (from the start)\n", m.ate_rmse_m,
              m.ate_rmse_unaligned_m);
  std::printf("drift           %.3f %%, %.4f deg/m\n", m.drift_pct, m.drift_deg_per_m);
  std::printf("metrics         %s/metrics.json\n", out.c_str());
  return kExitOk;
}

}  // namespace

Command AddScoreCommand(CLI::App& app) {
  auto a = std::make_shared<ScoreArgs>();
  CLI::App* score = app.add_subcommand(
      "score",
      "Score a trajectory file of any estimator against a ground truth: every accuracy metric "
      "of `run`, written as metrics.json");
  score->add_option("--gt", a->gt, "Ground-truth trajectory file")->required();
  score->add_option("--est", a->est, "Estimated trajectory file")->required();
  score
      ->add_option("--format", a->format,
                   "Both files' format: tum (t tx ty tz qx qy qz qw; associated by time) or "
                   "kitti (12 numbers per line; paired line by line)")
      ->required();
  score->add_option("--out,-o", a->out,
                    "Output folder for metrics.json (default out/score/<estimate file name>); "
                    "an earlier score there is replaced");
  score
      ->add_option("--max-difference", a->max_difference_s,
                   "tum: largest estimate to ground-truth time difference associated (s)")
      ->capture_default_str();
  return {score, [a, score] { return RunScore(*a, score->count("--max-difference") > 0); }};
}

}  // namespace harness
