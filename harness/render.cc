#include "harness/render.h"

#include <chrono>
#include <filesystem>

#include "harness/interrupt.h"
#include "harness/progress.h"

namespace harness {

namespace fs = std::filesystem;

bool RenderScenario(const sim::Scenario& scenario, const std::string& out_dir,
                    const RenderOptions& options, RenderSummary* summary, std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<sim::Simulator> simulator = sim::Simulator::Create(scenario, error);
  if (!simulator) return false;
  DatasetWriter::Options wopt;
  wopt.format = options.format;
  wopt.overwrite = options.overwrite;
  wopt.T_body_cam0 = simulator->calibration().T_body_cam0;
  wopt.T_body_imu = simulator->calibration().T_body_imu;  // EuRoC's body with the IMU
  wopt.imu = scenario.imu;
  wopt.rate_hz = scenario.rate_hz;
  wopt.write_rig = true;
  wopt.rig.forward_m = scenario.camera.forward_m;
  wopt.rig.height_m = scenario.camera.height_m;
  wopt.rig.pitch_deg = scenario.camera.pitch_deg;
  wopt.rig.has_imu = true;
  wopt.rig.imu_x_m = scenario.imu.x_m;
  wopt.rig.imu_y_m = scenario.imu.y_m;
  wopt.rig.imu_z_m = scenario.imu.z_m;
  wopt.rig.imu_roll_deg = scenario.imu.roll_deg;
  wopt.rig.imu_pitch_deg = scenario.imu.pitch_deg;
  wopt.rig.imu_yaw_deg = scenario.imu.yaw_deg;
  DatasetWriter writer(wopt);
  if (!writer.Open(out_dir, ToStereoCamera(simulator->calibration()), error)) return false;

  Progress progress("render " + scenario.name, simulator->EstimatedFrames(), options.progress);
  sim::StereoFrame frame;
  int n = 0;
  while (simulator->Next(&frame, error)) {
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
  summary->path_length_m = 0.0;
  for (size_t i = 1; i < track.size(); ++i)
    summary->path_length_m += (track[i] - track[i - 1]).head<2>().norm();
  summary->wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary->frames_per_s = summary->wall_time_s > 0 ? n / summary->wall_time_s : 0.0;
  return true;
}

}  // namespace harness
