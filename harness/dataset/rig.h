// The stereo camera's mounting on a ground vehicle, written beside a dataset as rig.yaml by
// `vobench render` and read by `vobench run --dataset` / `eval` when present: a KITTI, EuRoC or
// TUM folder otherwise carries no rig, and a ground-vehicle run (vehicle.enabled) needs the wheel
// axle's distance behind the camera (vehicle.axle_behind_camera_m, vo::ResolvePlatform).
//
//   # rig.yaml (metres, degrees)
//   camera_forward_m: 0.15   # optical centre ahead of the wheel axle
//   camera_height_m: 0.4     # optical centre above the floor
//   camera_pitch_deg: 0      # downward tilt of the optical axis
//   imu_x_m: 0               # the IMU on the vehicle (optional: all six or none; render writes
//   imu_y_m: 0               #   them): position on the body (x forward, y left, z up, origin
//   imu_z_m: 0.19            #   at the wheel axle) and axes R = Rz(yaw) Ry(pitch) Rx(roll) of
//   imu_roll_deg: 0          #   the body's, as the scenario's imu keys (sim/scenario.h)
//   imu_pitch_deg: 0
//   imu_yaw_deg: 0
#pragma once

#include <string>

namespace harness {

struct RigMounting {
  double forward_m = 0.0;  // optical centre ahead of the wheel axle (m), finite; a camera
                           // behind the axle (< 0) is recorded, not applied (vo::ResolvePlatform)
  double height_m = 0.0;   // optical centre above the floor (m), > 0
  double pitch_deg = 0.0;  // downward tilt of the optical axis (degrees), (-90, 90)
  bool has_imu = false;    // the IMU's pose below is known (finite)
  double imu_x_m = 0.0, imu_y_m = 0.0, imu_z_m = 0.0;
  double imu_roll_deg = 0.0, imu_pitch_deg = 0.0, imu_yaw_deg = 0.0;

  bool IsValid(std::string* error) const;
};

// The file name inside a dataset folder.
inline constexpr const char* kRigFileName = "rig.yaml";

// rig.yaml's text for `rig` (round-trips exactly through ReadRigYaml).
std::string RigYaml(const RigMounting& rig);

// Reads `path` with sim::YamlReader ("PATH:LINE: key 'K': ..."). False when it cannot be read,
// is not a YAML map of the three camera keys with finite numbers, and optionally all six imu_
// keys (unknown and duplicate keys are refused), or the height or pitch is out of range.
bool ReadRigYaml(const std::string& path, RigMounting* rig, std::string* error);

}  // namespace harness
