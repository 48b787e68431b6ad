// The seam between the simulator (sim/) and the VO and harness types: the one place that knows
// both. sim/ never includes vo/ (tests/gates/include_boundaries.sh); what a simulated frame or
// calibration becomes on the VO side is written here, once.
//
//   ResolveScenario(arg)      a scenario file, or the name of one shipped in scenes/
//   ToStereoCamera(calib)     sim::StereoCalibration -> vo::StereoCamera (pinhole, rectified)
//   ToDatasetFrame(frame)     sim::StereoFrame -> DatasetFrame (images, depth, ground truth,
//                             the IMU samples since the previous frame)
//
// Pose conventions are already the VO's on the sim side (T_world_cam0, camera x right, y down,
// z forward: the simulator converts from MuJoCo's cameras), so nothing is re-expressed here.
#pragma once

#include <string>

#include "harness/dataset.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "vo/camera.h"

namespace harness {

// Resolves a scenario argument: an existing file, or the name of a scenario shipped in
// scenes/ ("l_hallway"). Loads and validates it.
bool ResolveScenario(const std::string& arg, sim::Scenario* scenario, std::string* error);

// The simulator's calibration as the VO's camera model.
vo::StereoCamera ToStereoCamera(const sim::StereoCalibration& calibration);

// A simulated frame as a dataset frame (with ground truth and depth).
DatasetFrame ToDatasetFrame(const sim::StereoFrame& frame);

}  // namespace harness
