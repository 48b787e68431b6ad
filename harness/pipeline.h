// The run pipeline: the one path from stereo frames to numbers that every command running the
// VO takes (`run`, `eval` and `tune` directly; `suite` and `check` through `run` child
// processes; `match-eval` reads its frames through the same sequences).
//
//   StereoSequence ──RunFrames──▶ RunRecords ──Summarize──▶ RunSummary ──WriteRunFolder──▶ files
//   (frames, camera,   (the VO,      (per frame:    (no I/O)     (metrics,     (run_folder.h:
//    ground truth)      no I/O)       result, GT)                 medians)      ownership, plots)
//
// RunFrames and Summarize do no I/O and are unit-tested on their own; the run folder's files
// are written in one place (run_folder.h).
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "harness/dataset.h"
#include "harness/match_eval.h"
#include "harness/metrics.h"
#include "sim/navigation.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "vo/odometry.h"

namespace harness {

// A source of stereo frames: fills *frame, returns false at the end (error empty) or on error.
using FrameSource = std::function<bool(DatasetFrame* frame, std::string* error)>;
// The closed loop: the VO's result of the frame the source gave last, handed back to the source
// before its next frame (a simulated robot steering on the VO, sim/navigation.h).
using EstimateFeedback = std::function<void(const vo::OdometryResult& result)>;
// What a simulated robot did (sim/navigation.h), asked once the source is exhausted.
using NavigationSource = std::function<sim::NavigationReport()>;

// A stereo sequence to run the VO on: its frames, camera and what the run folder records of it.
struct StereoSequence {
  std::string name;           // run name (scenario name or dataset folder name)
  vo::StereoCamera camera;    // rectified stereo camera of the frames
  FrameSource next;           // the frames in order (with ground truth where known)
  int expected_frames = 0;    // frames the source will give (for progress; 0 = unknown)
  std::string scenario_yaml;  // effective scenario (simulated sequences; "" otherwise)
  std::string outline_scene;  // MJCF scene whose walls outline the trajectory plot ("" = none)
  double axle_behind_camera_m = -1.0;  // the rig's wheel axle behind the camera (metres) when
                                       // the source knows it (a simulated scenario's
                                       // camera.forward_m, a dataset's rig.yaml); < 0 = unknown.
                                       // A run resolves the VO's platform on it
                                       // (vo::ResolvePlatform: auto is a ground vehicle with
                                       // this axle when it is known); vo_options.yaml records
                                       // the resolved platform and the values used
  // The rig's camera pitch (downward tilt, degrees) when the source knows it (a scenario's
  // camera.pitch_deg, rig.yaml); NaN = unknown. A ground vehicle takes its up from it when the
  // first frame shows no floor or ceiling (vo::ResolvePlatform).
  double camera_pitch_deg = std::numeric_limits<double>::quiet_NaN();
  // Why the ground truth's world is not gravity-aligned ("" when it is: simulated runs, the
  // KITTI layout with T_world_cam0first.txt, EuRoC's and TUM's motion-capture worlds). Then a
  // run reports no initial-orientation error (RunSummary::initial_orientation_error_reason).
  std::string ground_truth_not_gravity_aligned;
  // An IMU: the frames carry its samples since the previous frame (DatasetFrame::imu). A
  // simulated scenario always has one (its imu keys, the IMU's pose on the rig); a EuRoC folder
  // when mav0/imu0/data.csv is there (imu: its sensor.yaml's rate and noise numbers; T_imu_cam0:
  // cam0's T_BS, the body being the IMU as in EuRoC, turned by the rectification's rotation).
  // The VO uses its gyro (vo_options.yaml imu.gyro_prior, vo/gyro_prior.h) when T_imu_cam0 is
  // known (imu_extrinsics_known: a simulated scenario, a EuRoC folder; not yet a bag, whose
  // camera_info carries no mounting on the IMU).
  bool has_imu = false;
  sim::ImuOptions imu;                                           // rate and noise numbers
  Eigen::Isometry3d T_imu_cam0 = Eigen::Isometry3d::Identity();  // cam0 in the IMU frame
  bool imu_extrinsics_known = false;                             // T_imu_cam0 is the rig's
  // A simulated scenario: what the robot did (its navigation report); with navigation: vo also
  // the feedback that steers it on the VO's estimates. Empty otherwise.
  NavigationSource navigation;
  EstimateFeedback feedback;
};

// A simulated scenario as a sequence (the simulator lives as long as the sequence's source).
// With navigation: vo the robot steers on the VO: the sequence's feedback must be called with
// each frame's result (RunFrames does), and its frames cannot be simulated ahead of the VO.
bool OpenScenarioSequence(const sim::Scenario& scenario, StereoSequence* sequence,
                          std::string* error);
// A simulated sequence (`next`, `feedback` and T_imu_cam0 set) onto the frames the VO takes:
// with a lens or a rotated cam1 in the exported calibration (camera.distortion,
// calibration_error.rotation_deg), its frames rectified by ExportedRectification
// (harness/sim_adapter.h) as `vobench eval --format euroc` rectifies the EuRoC render of it: the
// rectified camera, the ground truth of the rectified left camera, no depth (it belongs to the
// raw view), the closed loop's estimates turned back to the raw camera. Nothing changes for a
// pinhole pair. OpenScenarioSequence and OpenCachedSequence (sequence_cache.h) call it.
bool RectifyScenarioSequence(const sim::Scenario& scenario,
                             const sim::StereoCalibration& calibration, StereoSequence* sequence,
                             std::string* error);
// What such a sequence says of itself, from the scenario and its simulator's calibration:
// every field but `next` (shared with the cached sequences of sequence_cache.h).
void DescribeScenarioSequence(const sim::Scenario& scenario,
                              const sim::StereoCalibration& calibration, int expected_frames,
                              StereoSequence* sequence);

// "" when `command` may simulate `scenario` without a VO in the loop (frames rendered ahead,
// kept in memory or on disk); else why not: navigation: vo steers the robot on the VO's
// estimates, so only `run` can simulate it. Names the scenario file and key.
std::string ClosedLoopProblem(const sim::Scenario& scenario, const std::string& command);

// Frames of `source` into memory (up to max_frames, 0 = all), with a progress display named
// `label` and the interrupt check of every long loop (the message names `out`).
bool ReadAllFrames(const FrameSource& source, int max_frames, int expected_frames,
                   const std::string& label, bool progress, const std::string& out,
                   std::vector<DatasetFrame>* frames, std::string* error);

// A source over frames in memory (they must outlive it).
FrameSource FramesInMemory(const std::vector<DatasetFrame>& frames);

// One frame the VO saw.
struct FrameRecord {
  int64_t source_index = 0;  // position in the source (0, k, 2k, ... with frame stride k)
  double time_s = 0.0;       // time stamp (s)
  vo::OdometryResult result;
  bool has_gt = false;                                                // ground truth known
  Eigen::Isometry3d T_world_cam0_gt = Eigen::Isometry3d::Identity();  // when has_gt
};

// What RunFrames records of a run.
struct RunRecords {
  std::string name;
  int frame_stride = 1;
  std::vector<FrameRecord> frames;  // every frame the VO saw, in order
  VoMatchStats match_stats;  // the VO's matches against the ground truth (frames with depth);
                             // matches == 0 when not available or not asked for
};

struct RunFramesOptions {
  int max_frames = 0;       // stop after this many frames of the source (0 = all)
  int frame_stride = 1;     // the VO sees every k-th source frame (0, k, 2k, ...), >= 1
  int expected_frames = 0;  // frames of the source (for progress; 0 = unknown)
  bool progress = true;     // progress display on stderr ("vo <name>")
  bool match_stats = true;  // check the VO's matches against the ground-truth depth and poses
  std::string out_dir;      // named in the message of an interrupted run
  // Called with each frame's result, before the source's next frame (the closed loop), or none.
  EstimateFeedback feedback;

  // False (with the message) for a frame stride below 1.
  bool IsValid(std::string* error) const;
};

// Runs `odometry` over `source` (SIGINT/SIGTERM stop it with InterruptedMessage). No I/O other
// than the progress display.
bool RunFrames(const std::string& name, const FrameSource& source, vo::StereoOdometry& odometry,
               const RunFramesOptions& options, RunRecords* records, std::string* error);

// The frames before the first one the VO initialised on (black, over-exposed, textureless
// starts): they have no pose and are left out of trajectories and metrics. == frames.size()
// when the VO never initialised.
size_t FirstInitialisedFrame(const RunRecords& records);

struct RunSummary {
  std::string name;
  TrajectoryMetrics metrics;
  int lost_frames = 0;             // frames without a measured motion (vo::IsLostFrame)
  int reinitialisations = 0;       // of those, frames the VO re-initialised on
  int bridge_aligned_frames = 0;   // of those, frames whose bridged forward step or yaw was
                                   // measured against the previous frame's features
                                   // (vo::OdometryResult::bridge_aligned)
  int direct_motion_frames = 0;    // frames (not lost) whose motion was measured by direct image
                                   // alignment (vo::OdometryResult::direct_motion)
  int frames_not_initialised = 0;  // frames before the first one the VO initialised on: no
                                   // pose, not in the trajectories, metrics or lost_frames
  double vo_ms_median = 0.0;
  double vo_ms_p95 = 0.0;
  std::map<std::string, double> stage_ms_median;  // disparity, detect, depth, match, motion, ba
  double features_median = 0.0;
  double inliers_median = 0.0;
  bool initial_orientation_ok = false;
  double initial_orientation_error_deg =  // vs the gravity-aligned ground truth; NaN when not
      std::numeric_limits<double>::quiet_NaN();  // known (the reason below)
  std::string initial_orientation_error_reason;  // why it is NaN ("" when it is known)
  bool initial_floor_refined = false;            // its floor was refined on the images
  std::string initial_floor_message;             // what that refinement did, or why not
  bool has_ground_truth = false;  // at least 2 frames with ground truth: the metrics are set
  int ground_truth_frames = 0;    // frames with a ground-truth pose; the metrics use these only
  VoMatchStats match_stats;       // the VO's matches against the ground truth (simulated runs and
                                  // datasets with depth); matches == 0 when not available
  int frame_stride = 1;           // RunFramesOptions::frame_stride of the run
  std::string platform;           // the VO's resolved platform ("free", "ground_vehicle"; set by
                                  // RunOdometry, "" when not known)
  bool has_navigation = false;    // a simulated run: what the robot did (set by RunOdometry)
  sim::NavigationReport navigation;
};

// The summary of a run: trajectory metrics over the frames with ground truth from the first
// initialised frame on (at least 2, otherwise has_ground_truth is false and the metrics are
// left out), counts and medians. Fails when the VO never initialised or fewer than 2 frames
// remain. No I/O.
bool Summarize(const RunRecords& records, RunSummary* summary, std::string* error);

}  // namespace harness
