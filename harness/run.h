// `vobench run`: the VO frame by frame on a simulated scenario or a dataset folder, compared
// with the ground truth; writes a run folder (trajectories, per-frame log, options, metrics,
// plots, report page).
//
// Run folder:
//   trajectory_tum.txt / trajectory_kitti.txt   the estimate T_world_cam0 in the VO's world
//   estimate_in_gt_world_tum.txt                the estimate anchored at the first ground-truth
//                                               pose (same frame as groundtruth_tum.txt)
//   groundtruth_tum.txt / groundtruth_kitti.txt  ground truth T_world_cam0 (simulator world)
//   per_frame.csv      status, counts, per-stage ms, errors per frame
//   metrics.json       summary (frames, path_length_m, end_pose_error_m, end_pose_error_pct,
//                      ate_rmse_m, lost_frames, vo_ms_median, vo_ms_p95, ...)
//   vo_options.yaml    effective VO options (accepted by --config)
//   scenario.yaml      effective scenario (simulated runs)
//   trajectory.png, errors.png, timing.png, report.md
#pragma once

#include <functional>
#include <map>
#include <string>

#include "harness/dataset.h"
#include "harness/match_eval.h"
#include "harness/metrics.h"
#include "sim/scenario.h"
#include "vo/odometry.h"

namespace harness {

struct RunSummary {
  std::string name;
  TrajectoryMetrics metrics;
  int lost_frames = 0;        // frames without a measured motion (vo::IsLostFrame)
  int reinitialisations = 0;  // of those, frames the VO re-initialised on
  int frames_not_initialised = 0;  // frames before the first one the VO initialised on: no
                                   // pose, not in the trajectories, metrics or lost_frames
  double vo_ms_median = 0.0;
  double vo_ms_p95 = 0.0;
  std::map<std::string, double> stage_ms_median;  // disparity, detect, depth, match, motion, ba
  double features_median = 0.0;
  double inliers_median = 0.0;
  bool initial_orientation_ok = false;
  double initial_orientation_error_deg = -1.0;  // vs ground truth; < 0 when not known
  bool has_ground_truth = false;  // at least 2 frames with ground truth: the metrics are set
  int ground_truth_frames = 0;    // frames with a ground-truth pose; the metrics use these only
  VoMatchStats match_stats;  // the VO's matches against the ground truth (simulated runs and
                             // datasets with depth); matches == 0 when not available
  int frame_stride = 1;  // RunOptions::frame_stride of the run
};

struct RunOptions {
  std::string out_dir;        // run folder; replaced if it holds an earlier run
  bool progress = true;       // progress display on stderr
  bool plots = true;          // PNG plots (python3-matplotlib)
  std::string outline_scene;  // MJCF scene whose walls outline the trajectory plot ("" = none)
  int max_frames = 0;         // stop after this many frames of the source (0 = all)
  int frame_stride = 1;       // the VO sees every k-th source frame (0, k, 2k, ...; less overlap
                              // between its frames), >= 1; metrics are on those frames
};

// A source of stereo frames: fills *frame, returns false at the end (error empty) or on error.
using FrameSource = std::function<bool(DatasetFrame* frame, std::string* error)>;

// Runs the VO over `source` and writes the run folder. Frames without ground truth
// (DatasetFrame::has_gt false: a real sequence whose ground truth does not cover every frame)
// are run and logged, but the metrics compare only the frames with ground truth (at least 2,
// otherwise there are none and metrics.json leaves them out).
bool RunOdometry(const std::string& name, const vo::StereoCamera& camera, FrameSource source,
                 int expected_frames, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, const std::string& scenario_yaml, RunSummary* summary,
                 std::string* error);

// Simulates `scenario` and runs the VO on it.
bool RunScenario(const sim::Scenario& scenario, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, RunSummary* summary, std::string* error);

// Runs the VO on a dataset folder in the KITTI layout.
bool RunKittiDataset(const std::string& dir, const vo::OdometryOptions& vo_options,
                     const RunOptions& options, RunSummary* summary, std::string* error);

// The summary as metrics.json text.
std::string MetricsJson(const RunSummary& summary);

}  // namespace harness
