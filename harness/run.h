// `vobench run`: the VO frame by frame on a simulated scenario or a dataset folder, compared
// with the ground truth; writes a run folder (trajectories, per-frame log, options, metrics,
// plots, report page). The steps are the run pipeline's (pipeline.h, run_folder.h).
//
// Run folder (run_folder.h):
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
//   trajectory.png, errors.png, timing.png, report.md
#pragma once

#include <string>

#include "harness/pipeline.h"
#include "harness/run_folder.h"
#include "sim/scenario.h"
#include "vo/odometry.h"

namespace harness {

struct RunOptions {
  std::string out_dir;        // run folder; replaced if it holds an earlier run
  bool progress = true;       // progress display on stderr
  bool plots = true;          // PNG plots (python3-matplotlib)
  std::string outline_scene;  // MJCF scene whose walls outline the trajectory plot ("" = none)
  int max_frames = 0;         // stop after this many frames of the source (0 = all)
  int frame_stride = 1;       // the VO sees every k-th source frame (0, k, 2k, ...; less overlap
                              // between its frames), >= 1; metrics are on those frames
  // The closed loop (StereoSequence::feedback) and what a simulated robot did
  // (StereoSequence::navigation); empty for none.
  EstimateFeedback feedback;
  NavigationSource navigation;
  // The sequence's gyro for the VO (StereoOdometry::SetGyro; used with imu.gyro_prior on), when
  // has_gyro: a sequence with an IMU whose mounting is known (StereoSequence).
  bool has_gyro = false;
  vo::GyroCalibration gyro;
  std::string ground_truth_not_gravity_aligned;  // why the ground truth's world is not
                                                 // gravity-aligned ("" = it is): no
                                                 // initial-orientation error then
};

// The whole pipeline: runs the VO over `source` (RunFrames), summarises (Summarize) and
// writes the run folder (WriteRunFolder). Frames without ground truth
// (DatasetFrame::has_gt false: a real sequence whose ground truth does not cover every frame)
// are run and logged, but the metrics compare only the frames with ground truth (at least 2,
// otherwise there are none and metrics.json leaves them out).
bool RunOdometry(const std::string& name, const vo::StereoCamera& camera, FrameSource source,
                 int expected_frames, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, const std::string& scenario_yaml, RunSummary* summary,
                 std::string* error);

// The sequence's gyro for the VO (its mounting and noise numbers): true with an IMU whose
// mounting is known (StereoSequence::has_imu and imu_extrinsics_known), false otherwise.
bool SequenceGyro(const StereoSequence& sequence, vo::GyroCalibration* gyro);

// RunOdometry on a sequence (its name, camera, frames, scenario and outline).
bool RunSequence(const StereoSequence& sequence, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, RunSummary* summary, std::string* error);

// Simulates `scenario` and runs the VO on it.
bool RunScenario(const sim::Scenario& scenario, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, RunSummary* summary, std::string* error);

// Whether a frame limit and stride leave the VO at least the 2 frames it needs, from the frames
// a source gives (`estimated`: about that many, sim::EstimatedFrames; refused only when twice
// the estimate would not do). "" when fine, else the problem, naming the option: "--max-frames
// 1: ...", "--stride 1000: ...". Checked before anything is simulated or written.
std::string FrameBudgetProblem(int frames, bool estimated, int max_frames, int stride);

// Runs the VO on a dataset folder in the KITTI layout.
bool RunKittiDataset(const std::string& dir, const vo::OdometryOptions& vo_options,
                     const RunOptions& options, RunSummary* summary, std::string* error);

}  // namespace harness
