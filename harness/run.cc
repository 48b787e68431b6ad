#include "harness/run.h"

#include <limits>

#include "harness/eval.h"
#include "harness/vo_config.h"

namespace harness {

bool RunOdometry(const std::string& name, const vo::StereoCamera& camera, FrameSource source,
                 int expected_frames, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, const std::string& scenario_yaml, RunSummary* summary,
                 std::string* error) {
  RunFramesOptions frames_options;
  frames_options.max_frames = options.max_frames;
  frames_options.frame_stride = options.frame_stride;
  frames_options.expected_frames = expected_frames;
  frames_options.progress = options.progress;
  frames_options.out_dir = options.out_dir;
  frames_options.feedback = options.feedback;
  if (!frames_options.IsValid(error)) return false;  // before the folder: fail fast
  auto odometry = vo::StereoOdometry::Create(camera, vo_options, error);
  if (!odometry) {
    *error = "invalid VO options or camera: " + *error;
    return false;
  }
  if (options.has_gyro) odometry->SetGyro(options.gyro);
  OutputFolder folder;  // written as a marked DIR.partial-<pid>-<random>, moved into place
  if (!OpenRunFolder(options.out_dir, &folder, error)) return false;
  RunRecords records;
  if (!RunFrames(name, source, *odometry, frames_options, &records, error) ||
      !Summarize(records, summary, error))
    return false;
  summary->platform = vo::ToString(odometry->options().platform);
  if (options.navigation) {
    summary->has_navigation = true;
    summary->navigation = options.navigation();
  }
  if (!options.ground_truth_not_gravity_aligned.empty() &&
      summary->initial_orientation_error_reason.empty()) {
    summary->initial_orientation_error_deg = std::numeric_limits<double>::quiet_NaN();
    summary->initial_orientation_error_reason = options.ground_truth_not_gravity_aligned;
  }
  RunFolderContents contents;
  contents.options_yaml = VoConfigToYaml(odometry->options());
  contents.scenario_yaml = scenario_yaml;
  contents.plots = options.plots;
  contents.outline_scene = options.outline_scene;
  return WriteRunFolder(records, *summary, contents, options.out_dir, &folder, error);
}

bool SequenceGyro(const StereoSequence& sequence, vo::GyroCalibration* gyro) {
  if (!sequence.has_imu || !sequence.imu_extrinsics_known) return false;
  *gyro = vo::GyroCalibration();
  gyro->R_imu_cam = sequence.T_imu_cam0.linear();
  gyro->noise_density = sequence.imu.gyro_noise_density;
  gyro->random_walk = sequence.imu.gyro_random_walk;
  return true;
}

bool RunSequence(const StereoSequence& sequence, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, RunSummary* summary, std::string* error) {
  RunOptions o = options;
  if (o.outline_scene.empty()) o.outline_scene = sequence.outline_scene;
  o.ground_truth_not_gravity_aligned = sequence.ground_truth_not_gravity_aligned;
  o.feedback = sequence.feedback;
  o.navigation = sequence.navigation;
  o.has_gyro = SequenceGyro(sequence, &o.gyro);
  return RunOdometry(
      sequence.name, sequence.camera, sequence.next, sequence.expected_frames,
      vo::ResolvePlatform(vo_options, sequence.axle_behind_camera_m, sequence.camera_pitch_deg), o,
      sequence.scenario_yaml, summary, error);
}

bool RunScenario(const sim::Scenario& scenario, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, RunSummary* summary, std::string* error) {
  StereoSequence sequence;
  return OpenScenarioSequence(scenario, &sequence, error) &&
         RunSequence(sequence, vo_options, options, summary, error);
}

std::string FrameBudgetProblem(int frames, bool estimated, int max_frames, int stride) {
  if (max_frames == 1) return "--max-frames 1: the VO needs at least 2 frames (0 = all)";
  if (max_frames > 1 && max_frames <= stride)
    return "--stride " + std::to_string(stride) + " with --max-frames " +
           std::to_string(max_frames) + " leaves the VO 1 frame; it needs at least 2";
  const int available = estimated ? 2 * frames : frames;
  if (available <= stride && (max_frames == 0 || max_frames > frames))
    return "--stride " + std::to_string(stride) + ": the sequence has " +
           (estimated ? "about " : "") + std::to_string(frames) +
           " frames, so the VO would see 1; it needs at least 2";
  return "";
}

bool RunKittiDataset(const std::string& dir, const vo::OdometryOptions& vo_options,
                     const RunOptions& options, RunSummary* summary, std::string* error) {
  EvalOptions kitti;  // the KITTI layout with its own poses.txt, if any
  EvalInfo info;
  StereoSequence sequence;
  return OpenDataset(dir, kitti, &sequence, &info, error) &&
         RunSequence(sequence, vo_options, options, summary, error);
}

}  // namespace harness
