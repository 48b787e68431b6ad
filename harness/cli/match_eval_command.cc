#include "harness/cli/match_eval_command.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "harness/interrupt.h"
#include "harness/match_eval.h"
#include "harness/output_folder.h"
#include "harness/path_names.h"
#include "harness/pipeline.h"
#include "harness/plots/plots.h"
#include "harness/progress.h"
#include "harness/render.h"
#include "harness/trajectory_io.h"
#include "harness/vo_config.h"

namespace harness {
namespace {

struct MatchEvalArgs {
  std::string scenario = "l_hallway";
  std::string strides = "1,2,3,5,8";
  std::string matchers;  // "" = all
  std::string prediction = "motion_prior";
  std::string config;  // VO config whose matcher options are evaluated ("" = the defaults)
  std::string out;     // "" = out/match_eval/<scenario>
  int max_frames = 0;
  double correct_px = 2.0;  // a match is correct within this of the ground-truth position
  bool quiet = false;
};

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

int RunMatchEval(const MatchEvalArgs& args) {
  std::string out = args.out;
  std::string error;
  sim::Scenario scenario;
  if (!ResolveScenario(args.scenario, &scenario, &error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 2;
  }
  if (const std::string closed = ClosedLoopProblem(scenario, "match-eval"); !closed.empty()) {
    std::fprintf(stderr, "vobench match-eval: %s\n", closed.c_str());
    return 2;
  }
  if (ExportsRawFrames(scenario)) {
    // The frames would be rectified (RectifyScenarioSequence), and the depth that scores the
    // matches is the raw view's, dropped with it.
    std::fprintf(stderr,
                 "vobench match-eval: %s: camera.distortion / calibration_error.rotation_deg: "
                 "match-eval scores matches by the simulator's depth, which belongs to the raw "
                 "view and is not rectified with the frames; evaluate the matchers without them\n",
                 scenario.source_path.c_str());
    return 2;
  }
  MatchEvalOptions options;
  if (!args.config.empty()) {  // the matcher's options and its gate scale; the rest stays as it is
    vo::OdometryOptions vo_options;
    if (!LoadVoConfig(args.config, &vo_options, &error)) {
      std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
      return 2;
    }
    options.matcher = vo_options.tracker.matcher;
    options.prediction_radius_scale = vo_options.tracker.prior_radius_scale;
  }
  if (!ParseIntList(args.strides, &options.strides)) {
    std::fprintf(stderr,
                 "vobench match-eval: --strides: expected comma-separated integers, got '%s'\n",
                 args.strides.c_str());
    return 2;
  }
  if (!args.matchers.empty()) {
    options.matchers.clear();
    std::stringstream ss(args.matchers);
    std::string name;
    while (std::getline(ss, name, ',')) {
      vo::MatcherType t;
      if (!vo::ParseMatcherType(name, &t)) {
        std::fprintf(stderr,
                     "vobench match-eval: --matchers: unknown matcher '%s' (svd_proximity, "
                     "svd_ncc, svd_ncc_gabor, ncc_mutual, lucas_kanade, kalman, sift_ratio)\n",
                     name.c_str());
        return 2;
      }
      options.matchers.push_back(t);
    }
  }
  if (!vo::ParsePredictionMode(args.prediction, &options.prediction)) {
    std::fprintf(stderr,
                 "vobench match-eval: --prediction: expected none or motion_prior, got '%s'\n",
                 args.prediction.c_str());
    return 2;
  }
  if (!(args.correct_px > 0.0) || !std::isfinite(args.correct_px)) {
    std::fprintf(stderr,
                 "vobench match-eval: --correct-px: expected a finite distance > 0, got %g\n",
                 args.correct_px);
    return 2;
  }
  options.correct_px = args.correct_px;
  if (!options.IsValid(&error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 2;
  }
  if (out.empty()) {
    if (!CheckPathName(scenario.name, "scenario name", &error)) {
      std::fprintf(stderr, "vobench match-eval: %s (give --out)\n", error.c_str());
      return 2;
    }
    out = "out/match_eval/" + scenario.name;
  }
  OutputFolder folder;  // marked and locked now, published when complete
  if (!folder.Create(out, "match-eval", &error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }

  // Simulate the scenario into memory: images, ground-truth depth and poses.
  StereoSequence sequence;
  std::vector<DatasetFrame> simulated;
  if (!OpenScenarioSequence(scenario, &sequence, &error) ||
      !ReadAllFrames(sequence.next, args.max_frames, sequence.expected_frames,
                     "simulate " + scenario.name, !args.quiet, out, &simulated, &error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }
  std::vector<GroundTruthFrame> frames;
  for (const DatasetFrame& f : simulated)
    frames.push_back({f.left, f.right, f.depth_m, f.T_world_cam0});
  simulated.clear();
  std::vector<MatchEvalRow> rows;
  Progress progress("match-eval", 1, !args.quiet);
  if (!EvaluateMatchers(frames, sequence.camera, options, &rows, &error, [&](int done, int total) {
        progress.set_total(total);
        progress.Update(done);
      })) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }
  progress.Finish(static_cast<int>(rows.size()));
  if (InterruptSignal() != 0) {
    std::fprintf(stderr, "vobench match-eval: %s\n",
                 InterruptedMessage(static_cast<int>(frames.size()),
                                    static_cast<int>(frames.size()), "frames", out)
                     .c_str());
    return 1;
  }
  const std::string work = folder.path(), csv = out + "/match_eval.csv";
  if (!WriteMatchEvalCsv(work + "/match_eval.csv", rows, &error) ||
      !WriteTextFile(work + "/scenario.yaml", sim::ScenarioToYaml(scenario), &error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }
  if (!RunPlot({"match-eval", work + "/match_eval.csv", work + "/match_eval.png"}, &error))
    std::fprintf(stderr, "vobench match-eval: warning: no plot: %s\n", error.c_str());
  if (!folder.Publish(&error)) {
    std::fprintf(stderr, "vobench match-eval: %s\n", error.c_str());
    return 1;
  }
  std::printf("%-14s %6s %6s %8s %8s %9s %7s %7s %9s\n", "matcher", "stride", "pairs", "matches",
              "correct", "precision", "recall", "F1", "ms/pair");
  for (const auto& r : rows)
    std::printf("%-14s %6d %6d %8ld %8ld %9.4f %7.4f %7.4f %9.2f\n", r.matcher.c_str(), r.stride,
                r.pairs, r.matches, r.correct, r.precision, r.recall, r.f1, r.ms_per_pair);
  std::printf("wrote %s and %s/match_eval.png\n", csv.c_str(), out.c_str());
  return 0;
}

}  // namespace

Command AddMatchEvalCommand(CLI::App& app) {
  auto a = std::make_shared<MatchEvalArgs>();
  CLI::App* match_eval = app.add_subcommand(
      "match-eval", "Matcher precision/recall/F1 per stride against the simulator's ground truth");
  match_eval->add_option("scenario", a->scenario, "Scenario YAML file or built-in name")
      ->capture_default_str();
  match_eval->add_option("--strides", a->strides, "Frame strides, comma-separated")
      ->capture_default_str();
  match_eval->add_option("--matchers", a->matchers,
                         "Matchers, comma-separated (default: all seven)");
  match_eval
      ->add_option("--prediction", a->prediction,
                   "Search centre of every matcher: motion_prior (constant velocity from the "
                   "previous pair's ground truth, as the VO predicts) or none (the paper's form)")
      ->capture_default_str();
  match_eval->add_option("--config", a->config,
                         "VO options (YAML): its matcher.* options (the type is set by "
                         "--matchers) and tracker.prior_radius_scale are evaluated");
  match_eval->add_option("--out,-o", a->out, "Output folder (default out/match_eval/<scenario>)");
  match_eval->add_option("--max-frames", a->max_frames, "Use only the first N frames (0 = all)")
      ->check(AtLeast(0));
  match_eval
      ->add_option("--correct-px", a->correct_px,
                   "A match is correct when its current feature lies within this distance of "
                   "the ground-truth position (pixels, > 0); 1 asks for better placed matches")
      ->capture_default_str();
  match_eval->add_flag("-q,--quiet", a->quiet, "No progress display");
  return {match_eval, [a] { return RunMatchEval(*a); }};
}

}  // namespace harness
