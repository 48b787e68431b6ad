// `vobench tune FILE`: searches VO options against the simulator's ground truth on a training
// set of scenarios, reports the chosen options' scores on a separate validation set and
// writes the best configuration as a file `vobench run --config` accepts.
//
// Tune file (YAML; unknown keys, wrong types and bad values are refused as
// "file:line: key 'a.b': ...", sim::YamlReader):
//   name: tune_matcher          # names the output folder (default: the file's stem)
//   base_config: base.yaml      # optional VO config, relative to this file (vo_config.h);
//                               # default: the library defaults. It is the start of the search
//                               # and the "default" the tuned result is compared with
//   train:                      # >= 1 scenarios the objective is computed on
//     - name: train_a           # unique among train and validation (default scenario + index)
//       scenario: l_hallway     # a YAML file relative to this file, or a built-in name
//       set: {textures.seed: 11, seed: 2}  # scenario overrides (dotted keys, overrides.h)
//       max_frames: 120         # use only the first N frames (0 or absent: all)
//   validation:                 # >= 1, same form; each must differ from every training one
//     - {name: val_a, scenario: l_hallway, set: {textures.seed: 21}, max_frames: 120}
//   parameters:                 # >= 1, each key at most once
//     - key: matcher.svd.sigma_px  # a numeric VO option key (as in a run's vo_options.yaml)
//       min: 4                  # range, min < max (inclusive)
//       max: 30
//       type: real              # real | int | scale (default real), see optimizer.h
//       log: true               # log-uniform search (default false), needs min > 0
//       step: 2                 # int only: values min, min + step, ... (default 1)
//   objective:
//     metric: ate_rmse_m        # a trajectory metric (metrics.h, default ate_rmse_m): ate_rmse_m,
//                               # ate_rmse_unaligned_m, end_pose_error_m, end_pose_error_pct,
//                               # end_rotation_error_deg, rpe_trans_rmse_m, rpe_rot_rmse_deg,
//                               # drift_pct, drift_deg_per_m, kitti_drift_pct,
//                               # kitti_drift_deg_per_m, rpe_distance_*; null on a
//                               # sequence (e.g. % on a path < 1 m): an error
//     lost_frame_penalty: 0.05  # added per lost frame, in the metric's unit (default 0.05), >= 0
//     aggregate: mean           # mean | max over the scenarios (default mean)
//   optimizer:
//     algorithm: LN_SBPLX       # random | a derivative-free NLopt algorithm (optimizer.h)
//     max_evals: 50             # distinct evaluations, the start included (default 50)
//     seed: 1                   # (default 1)
//
// Parameters. A `real` or `int` parameter sets its key to the value (int values are rounded to
// the grid inside the objective); a `scale` parameter multiplies every element of a list-valued
// key (matcher.gabor.wavelengths_px) of the base configuration. Keys, ranges and types are
// checked against the VO config reader when the file is loaded: a key it does not know, a
// non-numeric key, or a min or max it refuses is an error naming the key. The base
// configuration's values are the start of the search; they must lie in the ranges (scale: 1).
//
// Score. A scenario's score is  metric + lost_frame_penalty × lost frames  for one run of the
// VO over its frames (the same metrics as `vobench run`); the objective is the mean (or max)
// of the training scenarios' scores; smaller is better. Every scenario is simulated once,
// frames kept in memory; each evaluation re-runs only the VO, which is deterministic, so the
// same parameters give the same score and the same file and seed give the same evaluations.
//
// Output folder (written as DIR.partial and moved into place; an existing DIR is replaced only
// if it holds an earlier tune result, i.e. summary.json):
//   best_vo.yaml      the best options found, every key (vobench run --config accepts it)
//   base_vo.yaml      the start (default) options, every key
//   evaluations.csv   one row per evaluation: eval (0-based; 0 = the start, i.e. the default),
//                     origin ("start", the algorithm, "... restart N"), parameter values, per
//                     training scenario `<name>:<metric>` and `<name>:lost_frames`, objective,
//                     best_objective (best so far)
//   scores.csv        scenario, set (train|validation), frames, and for config default|tuned
//                     the metric, lost frames and score
//   summary.json      the same in one JSON document, plus counts and timings
//   report.md         default vs tuned per scenario, the chosen values, the search
//   objective.png     objective per evaluation and the best so far; parameters in the box
//   tune.yaml         a copy of the tune file
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "harness/dataset.h"
#include "harness/metrics.h"
#include "harness/optimizer.h"
#include "sim/scenario.h"
#include "vo/odometry.h"

namespace harness {

struct TuneScenario {
  std::string name;          // unique in the tune file
  std::string scenario_arg;  // as given: file (relative to the tune file) or built-in name
  std::string set_yaml;      // the overrides as one line of YAML ("{}" when none)
  int max_frames = 0;        // 0 = all frames
  int line = 0;              // 1-based line in the tune file
  sim::Scenario scenario;    // resolved, overrides applied, name = `name`
};

struct TuneObjective {
  std::string metric = "ate_rmse_m";  // a TrajectoryMetrics field (see the file format)
  double lost_frame_penalty = 0.05;   // per lost frame, in the metric's unit, >= 0
  std::string aggregate = "mean";     // "mean" or "max" over the scenarios
};

struct TuneSpec {
  std::string name;              // output folder name
  std::string source_path;       // the tune file ("" when parsed from text)
  std::string text;              // the tune file's text
  std::string base_config_path;  // resolved path, "" = library defaults
  vo::OdometryOptions base_options;
  std::vector<TuneScenario> train;
  std::vector<TuneScenario> validation;
  std::vector<Parameter> parameters;
  std::vector<double> start_values;  // the base options' values (scale: 1), one per parameter
  TuneObjective objective;
  OptimizerOptions optimizer;
};

// Parses and validates a tune file; `source_name` names it in messages, `base_dir` resolves
// relative paths. Nothing is simulated yet.
bool ParseTuneSpec(const std::string& yaml_text, const std::string& source_name,
                   const std::string& base_dir, TuneSpec* spec, std::string* error);
bool LoadTuneSpec(const std::string& path, TuneSpec* spec, std::string* error);

// The base options with the parameters set to `values` (one per parameter).
bool ApplyParameters(const TuneSpec& spec, const std::vector<double>& values,
                     vo::OdometryOptions* options, std::string* error);

// A scenario simulated into memory (images and ground-truth poses; no depth).
struct TuneSequence {
  std::string name;
  vo::StereoCamera camera;
  std::vector<DatasetFrame> frames;
  double axle_behind_camera_m = -1.0;  // the rig's (StereoSequence), < 0 = unknown
  double camera_pitch_deg = std::numeric_limits<double>::quiet_NaN();  // the rig's, NaN = unknown
  bool has_gyro = false;     // the sequence's gyro (SequenceGyro), as `vobench run` gives it
  vo::GyroCalibration gyro;  // to the VO (imu.gyro_prior); the frames carry its samples
};
bool SimulateTuneScenario(const TuneScenario& scenario, bool progress, TuneSequence* sequence,
                          std::string* error);

struct SequenceScore {
  TrajectoryMetrics metrics;  // as `vobench run` computes them
  int lost_frames = 0;        // frames without a measured motion (vo::IsLostFrame)
  double metric = 0.0;        // the objective's metric
  double score = 0.0;         // metric + lost_frame_penalty × lost_frames
};

// Runs the VO over the sequence and scores it.
bool ScoreSequence(const TuneSequence& sequence, const vo::OdometryOptions& options,
                   const TuneObjective& objective, SequenceScore* score, std::string* error);
// Mean or max of the scores.
double AggregateScores(const std::vector<SequenceScore>& scores, const TuneObjective& objective);

struct TuneOptions {
  std::string out_dir;   // output folder (see above)
  bool progress = true;  // rendering progress and one line per evaluation on stderr
  bool plots = true;     // objective.png (python3-matplotlib)
  int max_evals = 0;     // > 0: replaces the file's optimizer.max_evals
};

struct TuneScenarioResult {
  std::string name;
  bool train = true;  // training (true) or validation scenario
  int frames = 0;
  SequenceScore base;   // the base (default) options
  SequenceScore tuned;  // the best options found
};

struct TuneSummary {
  OptimizationResult optimization;
  std::vector<TuneScenarioResult> scenarios;   // training first, then validation, file order
  double train_base = 0.0, train_tuned = 0.0;  // objective on the training set
  double validation_base = 0.0, validation_tuned = 0.0;  // the same aggregate on validation
  vo::OdometryOptions best_options;
  double simulate_s = 0.0;    // simulating the scenarios (s)
  double search_s = 0.0;      // the search (s)
  double validation_s = 0.0;  // scoring the validation set (s)
  double wall_s = 0.0;        // everything (s)
};

// Simulates, searches, validates and writes the output folder. Fails before simulating when
// out_dir exists and is not a tune folder.
bool RunTune(const TuneSpec& spec, const TuneOptions& options, TuneSummary* summary,
             std::string* error);

// The summary table printed by `vobench tune` (and in report.md): one line per scenario.
std::string TuneSummaryTable(const TuneSpec& spec, const TuneSummary& summary);

}  // namespace harness
