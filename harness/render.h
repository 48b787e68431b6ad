// `vobench render`: simulate a scenario and write its stereo sequence as a dataset on disk.
#pragma once

#include <string>

#include "harness/dataset.h"
#include "harness/sim_adapter.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "vo/camera.h"

namespace harness {

struct RenderSummary {
  int frames = 0;
  double sim_time_s = 0.0;          // time of the last frame (s)
  double path_length_m = 0.0;       // length of the left camera's 3-D path over the frames (m):
                                    // `run`'s path_length_m for the same frames
  double base_path_length_m = 0.0;  // length of the robot base's 2-D track (m)
  double wall_time_s = 0.0;         // rendering + writing wall time (s)
  double frames_per_s = 0.0;        // stereo frames (with depth) rendered and written per second
  std::string gl_renderer;
};

struct RenderOptions {
  DatasetFormat format =
      DatasetFormat::kKitti;  // kEuroc / kTum also write the mav0/ / TUM-style layout
  bool overwrite = false;     // replace an existing output folder
  bool progress = true;       // progress line on stderr
};

// Renders `scenario` into `out_dir` (atomically: nothing is left at out_dir on failure).
// The dataset writer's options for frames simulated from `scenario` (every writer of simulated
// frames: render, a suite's sequence for an external estimator): the rig's mounting, the frame
// rate, and the EuRoC/TUM stamps on the simulation epoch (kSimulationEpochNs: 19 digits, names
// that sort). The caller sets the format (and overwrite, a stride's rate).
DatasetWriter::Options ScenarioWriterOptions(const sim::Scenario& scenario,
                                             const Eigen::Isometry3d& T_body_cam0);

bool RenderScenario(const sim::Scenario& scenario, const std::string& out_dir,
                    const RenderOptions& options, RenderSummary* summary, std::string* error);

}  // namespace harness
