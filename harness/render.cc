#include "harness/render.h"

#include <chrono>
#include <filesystem>

#include "harness/interrupt.h"
#include "harness/progress.h"

namespace harness {

namespace fs = std::filesystem;

DatasetWriter::Options ScenarioWriterOptions(const sim::Scenario& scenario,
                                             const Eigen::Isometry3d& T_body_cam0) {
  DatasetWriter::Options options;
  options.T_body_cam0 = T_body_cam0;
  options.rate_hz = scenario.rate_hz;
  options.stamp_offset_ns = kSimulationEpochNs;  // EuRoC/TUM stamps: 19 digits from 2026-01-01
  options.write_rig = true;
  options.rig.forward_m = scenario.camera.forward_m;
  options.rig.height_m = scenario.camera.height_m;
  options.rig.pitch_deg = scenario.camera.pitch_deg;
  options.imu = scenario.imu;
  options.rig.has_imu = true;
  options.rig.imu_x_m = scenario.imu.x_m;
  options.rig.imu_y_m = scenario.imu.y_m;
  options.rig.imu_z_m = scenario.imu.z_m;
  options.rig.imu_roll_deg = scenario.imu.roll_deg;
  options.rig.imu_pitch_deg = scenario.imu.pitch_deg;
  options.rig.imu_yaw_deg = scenario.imu.yaw_deg;
  options.R_cam0_cam1 = ExportedRotationCam0Cam1(scenario);
  options.lens = scenario.camera.distortion;
  return options;
}

bool RenderScenario(const sim::Scenario& scenario, const std::string& out_dir,
                    const RenderOptions& options, RenderSummary* summary, std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<sim::Simulator> simulator = sim::Simulator::Create(scenario, error);
  if (!simulator) return false;
  DatasetWriter::Options wopt =
      ScenarioWriterOptions(scenario, simulator->calibration().T_body_cam0);
  // A lens or a rotated cam1: EuRoC's side gets the raw frames, the KITTI/TUM/bag side them
  // rectified by the exported calibration (DatasetWriter::Options::rectification).
  auto rectification = std::make_shared<StereoRectification>();
  if (!ExportedRectification(scenario, simulator->calibration(), rectification.get(), error))
    return false;
  if (!rectification->IsIdentity()) wopt.rectification = rectification;
  wopt.format = options.format;
  wopt.overwrite = options.overwrite;
  // EuRoC's body with the IMU: the cameras' T_BS relative to it, imu0/ from the frames' samples.
  wopt.T_body_imu = simulator->calibration().T_body_imu;
  DatasetWriter writer(wopt);
  if (!writer.Open(out_dir, ExportedStereoCamera(scenario, simulator->calibration()), error))
    return false;

  Progress progress("render " + scenario.name, simulator->EstimatedFrames(), options.progress);
  sim::StereoFrame frame;
  int n = 0;
  double camera_path_m = 0.0;  // the camera's 3-D path, as `run` measures it on the ground truth
  Eigen::Vector3d last_camera = Eigen::Vector3d::Zero();
  while (simulator->Next(&frame, error)) {
    if (n > 0) camera_path_m += (frame.T_world_cam0.translation() - last_camera).norm();
    last_camera = frame.T_world_cam0.translation();
    if (!writer.Add(ToDatasetFrame(frame), error)) return false;
    progress.Update(++n);
    summary->sim_time_s = frame.time_s;
    if (InterruptSignal() != 0) {  // SIGINT/SIGTERM: the writer removes its partial folder
      *error = InterruptedMessage(n, simulator->EstimatedFrames(), "frames", out_dir);
      return false;
    }
  }
  if (!error->empty()) return false;
  if (InterruptSignal() != 0) {
    *error = InterruptedMessage(n, n, "frames", out_dir);
    return false;
  }
  if (!writer.Finish(error)) return false;
  progress.Finish(n);

  summary->frames = n;
  summary->gl_renderer = simulator->gl_renderer();
  const auto& track = simulator->body_track();
  summary->path_length_m = camera_path_m;
  summary->base_path_length_m = 0.0;
  for (size_t i = 1; i < track.size(); ++i)
    summary->base_path_length_m += (track[i] - track[i - 1]).head<2>().norm();
  summary->wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary->frames_per_s = summary->wall_time_s > 0 ? n / summary->wall_time_s : 0.0;
  return true;
}

}  // namespace harness
