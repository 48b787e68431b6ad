// The seam between the simulator (sim/) and the VO and harness types: the one place that knows
// both. sim/ never includes vo/ (tests/gates/include_boundaries.sh); what a simulated frame or
// calibration becomes on the VO side is written here, once.
//
//   ResolveScenario(arg)      a scenario file, or the name of one shipped in scenes/
//   ToStereoCamera(calib)     sim::StereoCalibration -> vo::StereoCamera (pinhole, rectified)
//   ExportedStereoCamera(...)  the camera vobench exports: with the scenario's calibration_error
//   ExportedRotationCam0Cam1   cam1's orientation in cam0 as exported (EuRoC's T_BS)
//   ExportedRectification      what rectifies the raw frames of a lens or a rotated cam1 by
//                              the exported calibration (as `eval --format euroc` does)
//   ToDatasetFrame(frame)     sim::StereoFrame -> DatasetFrame (images, depth, ground truth,
//                             the IMU samples since the previous frame)
//
// Pose conventions are already the VO's on the sim side (T_world_cam0, camera x right, y down,
// z forward: the simulator converts from MuJoCo's cameras), so nothing is re-expressed here.
#pragma once

#include <Eigen/Core>
#include <string>

#include "harness/dataset.h"
#include "harness/dataset/rectification.h"
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

// The rectification of the scenario's raw frames by its exported calibration: the two cameras'
// sensor.yaml as render --format euroc writes them (ExportedStereoCamera's intrinsics,
// camera.distortion, cam1 at the exported baseline turned by ExportedRotationCam0Cam1) through
// ComputeStereoRectification with the default RectificationOptions, the rectification that
// `vobench eval --format euroc` computes from that export. The identity (the exported camera,
// no maps) for a pinhole pair without a rotation: the frames are rectified already. The frames
// the simulator renders are of the true rig, so a calibration error shows in the rectified
// images as it would on a real rig calibrated that wrongly.
bool ExportedRectification(const sim::Scenario& scenario, const sim::StereoCalibration& calibration,
                           StereoRectification* rectification, std::string* error);
// Whether the scenario's exported calibration needs that rectification: a lens
// (camera.distortion) or a rotated cam1 (calibration_error.rotation_deg).
bool ExportsRawFrames(const sim::Scenario& scenario);

// A simulated frame as a dataset frame (with ground truth and depth).
DatasetFrame ToDatasetFrame(const sim::StereoFrame& frame);

}  // namespace harness
