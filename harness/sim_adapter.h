// The seam between the simulator (sim/) and the VO and harness types: the one place that knows
// both. sim/ never includes vo/ (tests/gates/include_boundaries.sh); what a simulated frame or
// calibration becomes on the VO side is written here, once.
//
//   ResolveScenario(arg)      a scenario file, or the name of one shipped in scenes/
//   ToStereoCamera(calib)     sim::StereoCalibration -> vo::StereoCamera (pinhole, rectified)
//   ExportedStereoCamera(...)  the camera vobench exports: with the scenario's calibration_error
//   ExportedRotationCam0Cam1   cam1's orientation in cam0 as exported (EuRoC's T_BS)
//   ToDatasetFrame(frame)     sim::StereoFrame -> DatasetFrame (images, depth, ground truth,
//                             the IMU samples since the previous frame)
//
// Pose conventions are already the VO's on the sim side (T_world_cam0, camera x right, y down,
// z forward: the simulator converts from MuJoCo's cameras), so nothing is re-expressed here.
#pragma once

#include <Eigen/Core>
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

// The camera vobench exports for a scenario (calib.txt, EuRoC sensor.yaml, the camera `vobench
// run` gives the VO): the true one with the scenario's calibration_error applied (sim/scenario.h
// CalibrationErrorOptions: baseline and both focal lengths scaled, the principal point kept).
// Without an error it is ToStereoCamera(calibration), bit for bit.
vo::StereoCamera ExportedStereoCamera(const sim::Scenario& scenario,
                                      const sim::StereoCalibration& calibration);

// cam1's orientation in cam0 as exported: calibration_error.rotation_deg about cam1's y axis
// (the identity without it). Only EuRoC's sensor.yaml (cam1's T_BS) can hold it.
Eigen::Matrix3d ExportedRotationCam0Cam1(const sim::Scenario& scenario);

// "" when the scenario's calibration error can be exported where it goes, else why not:
// calibration_error.rotation_deg needs EuRoC's T_BS, camera.distortion's raw images EuRoC's
// sensor.yaml (`where` names the destination, e.g.
// "--format kitti", "vobench run"; euroc = true: it goes to a EuRoC sequence).
std::string CalibrationErrorProblem(const sim::Scenario& scenario, bool euroc,
                                    const std::string& where);

// A simulated frame as a dataset frame (with ground truth and depth).
DatasetFrame ToDatasetFrame(const sim::StereoFrame& frame);

}  // namespace harness
