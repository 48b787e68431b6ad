// External estimators in a suite: a configuration that runs another program instead of this VO.
//
//   configs:
//     - name: my_vo
//       external:
//         command: [my_vo, "{dataset}", "{out}"]   # argv, no shell
//         trajectory: traj_kitti.txt                # written by the command, relative to {out}
//         format: kitti                             # or tum
//         timeout_s: 600                            # optional (default 600)
//
// Placeholders in the command's arguments: {dataset} the run's sequence in the KITTI layout
// (image_0/, image_1/, calib.txt, times.txt, poses.txt, groundtruth_tum.txt, rig.yaml), {euroc}
// the same folder read as EuRoC (its mav0/: cam0/, cam1/, the IMU's imu0/ and body.yaml, the
// ground truth at the IMU rate, as `vobench render --format euroc` writes them), {calib} its
// calib.txt, {out} an empty folder for the command's output. At a stride the IMU stream stays
// whole: a frame kept carries the samples of the frames skipped before it. A first argument with a
// '/' that is relative is a path relative to the suite file; one without is looked up on PATH.
//
// A suite runs an external run as a child `vobench suite external SPEC --out DIR --datasets D`
// (the same child-process path as a built-in run: log, failure record, resume, shards). The
// first child of a sequence simulates the scenario once (the first max_frames source frames)
// into D, the shard's work folder, and writes the strided sequence its run sees (every
// stride-th frame) from it; the external runs on the same sequence share both until the suite
// call ends. Each child runs its command on its sequence (in a process group of its own,
// killed when timeout_s passes or the suite is interrupted), measures its wall time and peak
// memory (wait4's ru_maxrss), scores the trajectory against the sequence's ground truth
// (harness/score.h) and writes a run folder: metrics.json (score's keys, plus frames,
// frame_stride, command_wall_s, command_peak_rss_mb), external.json, the trajectory and the
// ground truth it was scored against, the command's {out} folder as estimate/. The command
// must not change the dataset (other runs read it).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/score.h"

namespace harness {

struct ExternalEstimator {
  std::vector<std::string> command;  // argv with placeholders
  std::string trajectory;            // the command's trajectory file, relative to {out}
  TrajectoryFormat format = TrajectoryFormat::kKitti;
  double timeout_s = 600.0;   // > 0
  std::string program_given;  // command[0] as the suite file gives it, before it was resolved
                              // against the suite's folder: the spec hash sees this one, so it
                              // is the same on every machine ("" = command[0])
};

// The placeholders a command may use, as written ("{dataset}", ...).
const std::vector<std::string>& ExternalPlaceholders();
// False with *why when an argument has a '{...}' that is not a placeholder, or the trajectory
// is not a relative path inside {out}.
bool CheckExternalEstimator(const ExternalEstimator& e, std::string* why);

// The description of one external run (specs/<id>.external.json): the estimator, the scenario
// file, stride and max_frames.
struct ExternalRunSpec {
  std::string id;
  std::string scenario_path;  // the effective scenario YAML (specs/<id>.scenario.yaml)
  int stride = 1;
  int max_frames = 0;
  ExternalEstimator estimator;
};
nlohmann::ordered_json ExternalEstimatorJson(const ExternalEstimator& e);
nlohmann::ordered_json ExternalRunSpecJson(const ExternalRunSpec& spec);
bool ReadExternalRunSpec(const std::string& path, ExternalRunSpec* spec, std::string* error);

// The sequence a run of `spec` sees, every stride-th of the first max_frames source frames of
// its scenario, simulated and written as a dataset in `dir` (KITTI layout, EuRoC's mav0/ with
// the IMU and rig.yaml beside it; DatasetWriter: nothing at dir on failure). Every IMU sample up
// to the last frame written is in imu0/: a frame written carries the samples of the frames
// skipped since the one before it (as the simulator's dropped frames' go with the next frame
// kept); those of the frames after the last one written are left out.
bool WriteSequence(const ExternalRunSpec& spec, const std::string& dir, std::string* error);
// The same from `full_dir`, the sequence written by WriteSequence at stride 1: every
// spec.stride-th of its frames and the IMU samples up to the last of them (imu0/ and the ground
// truth at the IMU rate), read back and written into `dir`. Images, depth, stamps, rig.yaml, the
// sensor.yaml files and imu0/data.csv are the bytes WriteSequence writes at that stride; the
// ground truth (poses.txt, groundtruth_tum.txt, T_world_cam0first.txt, the IMU-rate
// state_groundtruth_estimate0/data.csv) equal to ~1e-15 (a quaternion turned into a rotation
// and back differs in its last bit about half of the time).
bool WriteStridedCopy(const ExternalRunSpec& spec, const std::string& full_dir,
                      const std::string& dir, std::string* error);

// How the command ended.
struct CommandOutcome {
  int wait_status = 0;       // waitpid status (when !timed_out)
  bool timed_out = false;    // killed after timeout_s
  double wall_s = 0.0;       // wall time (s)
  double peak_rss_mb = 0.0;  // peak resident memory of the command (and its waited-for
                             // children), MiB, from wait4's ru_maxrss
};
// Runs a command (PATH lookup for a name without '/') with stdout/stderr inherited, in a
// process group of its own, from a launcher process forked by Start() while this process is
// still small: a process's ru_maxrss keeps the high-water mark of the memory it had before
// exec, so a command forked after the simulator ran would report its ~140 MiB. Run(): after
// timeout_s (or SIGINT/SIGTERM to this process) the group gets SIGTERM, then SIGKILL 2 s
// later; false only when it could not be started or was interrupted. One Run() per launcher.
class CommandLauncher {
 public:
  CommandLauncher() = default;
  ~CommandLauncher();
  CommandLauncher(const CommandLauncher&) = delete;
  CommandLauncher& operator=(const CommandLauncher&) = delete;

  bool Start(std::string* error);
  bool Run(const std::vector<std::string>& argv, double timeout_s, CommandOutcome* outcome,
           std::string* error);

 private:
  int pid_ = -1;            // the launcher
  int argv_fd_ = -1;        // argv to the launcher
  void* result_ = nullptr;  // FILE*: the launcher's reports
};

// The external run of `spec` into the run folder `out_dir` (kind "run", written as a work
// folder and published at the end). The sequence is written into `datasets_dir`: the whole one
// (named by the hash of the scenario without its name, max_frames and the format of the folder,
// so one an older vobench wrote, without the IMU, is never taken), simulated once, and a
// strided copy of it per stride ("<hash>_k<stride>", WriteStridedCopy), where the runs of other
// configurations and strides find them (the suite gives its work folder, removed when the call
// ends); with datasets_dir empty, simulated at the run's stride into the run's work folder and
// removed when scored. False with the reason (the sequence could not be written, the command
// failed or timed out, its trajectory is missing or cannot be scored).
bool RunExternalRun(const ExternalRunSpec& spec, const std::string& out_dir,
                    const std::string& datasets_dir, std::string* error);

}  // namespace harness
