// `vobench score`: the accuracy metrics of any trajectory file against a ground truth, so an
// estimator that is not this VO (another program, a recorded result) is measured with exactly
// the numbers `run` reports (the metric registry's accuracy group, metric_registry.h).
//
// Association of estimate and ground truth:
//   kitti  line by line (KITTI poses have no stamps): both files must hold the same number of
//          poses; pose i of the estimate is compared with pose i of the ground truth.
//   tum    by time stamp, associate.py's rule (trajectory_io.h, AssociateStamps): pairs closer
//          than max_difference_s, greedily by increasing difference, each stamp used once.
//          The default, 0.02 s, is associate.py's (and `eval`'s for kitti/tum): under half the
//          frame period of cameras up to 25 Hz, so a stamp can never pair with a neighbour's
//          frame when both streams stamp the same frames; give a smaller value for faster
//          cameras, a larger one for streams recorded at different rates.
// The metrics are then computed as Summarize computes a run's (ComputeTrajectoryMetrics over the
// associated pairs, in the estimate's order), so a run folder's own trajectory_kitti.txt and
// groundtruth_kitti.txt give the run's accuracy figures bit for bit; its TUM pair gives them to
// about 1e-12 (the rotation went through a quaternion as text).
#pragma once

#include <cstddef>
#include <string>

#include "harness/pipeline.h"

namespace harness {

enum class TrajectoryFormat { kTum, kKitti };

// "tum" / "kitti"; false for anything else.
bool ParseTrajectoryFormat(const std::string& text, TrajectoryFormat* format);
const char* ToString(TrajectoryFormat format);

struct ScoreOptions {
  TrajectoryFormat format = TrajectoryFormat::kTum;
  double max_difference_s = 0.02;  // tum: largest |t_est - t_gt| associated (s), > 0

  bool IsValid(std::string* error) const;
};

struct ScoreResult {
  RunSummary summary;  // name, has_ground_truth (always true), ground_truth_frames (the
                       // associated pairs), metrics (metrics.frames = the associated pairs)
  TrajectoryFormat format = TrajectoryFormat::kTum;
  double max_difference_s = 0.0;  // tum only
  size_t estimate_poses = 0;
  size_t ground_truth_poses = 0;
};

// Reads both files and computes the metrics. Errors (bad input: a missing file, a malformed
// line, different pose counts for kitti, no time overlap, fewer than 2 associated poses) name
// the file and, for a line, its number.
bool ScoreTrajectory(const std::string& name, const std::string& ground_truth_path,
                     const std::string& estimate_path, const ScoreOptions& options,
                     ScoreResult* result, std::string* error);

// metrics.json of a score: "name", the association ("format", "estimate_poses",
// "ground_truth_poses", "max_difference_s" for tum), "ground_truth_frames", then every metric
// of the registry's accuracy group in registry order, with the values `run` would write.
std::string ScoreMetricsJson(const ScoreResult& result);

// Writes metrics.json into the marked output folder `dir` (kind "score"; output_folder.h:
// written as a work folder and moved into place, an earlier score there replaced).
bool WriteScoreFolder(const ScoreResult& result, const std::string& dir, std::string* error);

}  // namespace harness
