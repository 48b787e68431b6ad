// The run folder: the files of one VO run, written in one place for `run` and `eval` (and so
// for `suite` and `check`, whose runs are `run` child processes).
//
//   trajectory_world_tum.txt                    the estimate T_world_cam0 in the VO's world
//   estimate_in_gt_world_tum.txt                the estimate anchored at the first ground-truth
//                                               pose (same frame as groundtruth_world_tum.txt)
//   groundtruth_world_tum.txt                   ground truth T_world_cam0 (simulator world)
//   trajectory_kitti.txt / groundtruth_kitti.txt  the same relative to their first pose (the
//                                               first line is the identity; KITTI's convention)
//   per_frame.csv      status, counts, per-stage ms, errors per frame
//   metrics.json       summary (frames, path_length_m, end_pose_error_m, end_pose_error_pct,
//                      ate_rmse_m, lost_frames, vo_ms_median, vo_ms_p95, ...; the
//                      metric registry's keys; null + *_reason where not applicable)
//   vo_options.yaml    effective VO options (accepted by --config)
//   scenario.yaml      effective scenario (simulated runs)
//   navigation.csv     closed-loop runs (navigation: vo): believed and true robot path per frame
//   trajectory.png, errors.png, timing.png, report.md (links the plots that were made)
//
// The folder is written as a marked work folder beside DIR and moved into place only when
// complete (OutputFolder: the ownership rules, the lock), so a half-written folder never looks
// finished and a folder vobench did not write is never replaced.
#pragma once

#include <string>

#include "harness/metric_registry.h"  // MetricsJson
#include "harness/output_folder.h"
#include "harness/pipeline.h"
#include "harness/trajectory_io.h"

namespace harness {

// What the run folder records besides the frames and the summary.
struct RunFolderContents {
  std::string options_yaml;   // effective VO options (vo_options.yaml)
  std::string scenario_yaml;  // effective scenario (scenario.yaml; "" = none)
  bool plots = true;          // PNG plots (python3-matplotlib)
  std::string outline_scene;  // MJCF scene whose walls outline the trajectory plot ("" = none)
};

// Opens DIR for writing (locked, into a marked work folder): refused when DIR exists and is not
// a vobench run folder. Call before the frames run, so a refused folder fails fast.
bool OpenRunFolder(const std::string& dir, OutputFolder* folder, std::string* error);

// Writes every file of the run into `folder` (opened by OpenRunFolder), makes the plots and
// publishes it as DIR. Nothing is published on an error or an interrupt.
bool WriteRunFolder(const RunRecords& records, const RunSummary& summary,
                    const RunFolderContents& contents, const std::string& dir, OutputFolder* folder,
                    std::string* error);

// The plots of a written run folder (trajectory.png and errors.png with ground truth,
// timing.png); a missing python3-matplotlib gives a warning on stderr, not an error.
void MakePlots(const std::string& folder, bool has_ground_truth, const std::string& outline_scene);

// A closed-loop run's navigation.csv (navigation: vo): per frame what the follower believed and
// where the robot was (the wheel axle in the world, m; yaw, deg), and whether the VO's estimate
// fixed the belief (0: lost, dead-reckoned).
std::string NavigationCsv(const sim::NavigationReport& navigation);

// The per-frame log (per_frame.csv): one row per frame, frames before the first initialised
// one marked not_initialised (no pose, no error).
std::string PerFrameCsv(const RunRecords& records, const RunSummary& summary);

}  // namespace harness
