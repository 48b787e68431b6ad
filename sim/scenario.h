// A scenario: which scene, which path the robot drives, the stereo rig, noise, seeds.
// Loaded from YAML (see scenes/l_hallway.yaml for a documented example).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "sim/lens.h"

namespace sim {

// Differential-drive robot and its path-tracking controller (pure pursuit).
struct RobotOptions {
  double speed_mps = 0.4;       // commanded cruise speed (m/s), > 0 (Pioneer 2DX ≈ 0.3–0.5)
  double max_accel_mps2 = 0.5;  // linear acceleration/deceleration limit (m/s²), > 0
  double turn_rate_dps = 30.0;  // max angular rate when turning in place (deg/s), > 0
  double lookahead_m = 0.5;     // pure-pursuit look-ahead distance (m), > 0
  std::string corner_mode = "in_place";  // "in_place": stop and rotate at corners; "arc": cut
                                         // corners on an arc (pure pursuit over the polyline)
  double goal_tolerance_m = 0.02;  // a waypoint counts as reached within this distance (m), > 0
  // in_place corners: stand still this long at each corner before turning (s), in [0, 600].
  double stop_s = 0.0;
  // At the last waypoint: turn in place to this yaw (deg, counter-clockwise from +x); NaN (the
  // default): stop facing along the last segment.
  double final_heading_deg = std::numeric_limits<double>::quiet_NaN();
  double wheel_radius_m = 0.095;  // driven-wheel radius (m), as in the MJCF robot
  double track_m = 0.33;          // distance between the driven wheels (m), as in the MJCF robot
};

// A waypoint's own goals (issue #34): a path entry written as a map
// {at: [x, y], turn: in_place | arc, radius_m: R, stop_s: S, speed_mps: V}; what it leaves out is
// the robot's (RobotOptions). sim/path_follower.h resolves them (ResolveWaypoints) and says how
// each is driven; scenes/README.md documents the keys.
struct WaypointOptions {
  std::string turn;  // "" (the robot's corner_mode), "in_place" or "arc"; inner waypoints only
  // turn arc: a circular arc of this radius tangent to both legs (m), > 0; NaN: the pure-pursuit
  // corner cut of corner_mode arc
  double radius_m = std::numeric_limits<double>::quiet_NaN();
  // Stand still here this long (s), [0, 600], where the robot stops (an in-place corner, the
  // first or the last waypoint); NaN: robot.stop_s at in-place corners, none at the ends
  double stop_s = std::numeric_limits<double>::quiet_NaN();
  // Cruise speed of the leg that starts here (m/s), (0, 3]; NaN: robot.speed_mps
  double speed_mps = std::numeric_limits<double>::quiet_NaN();
  bool any() const {
    return !turn.empty() || !std::isnan(radius_m) || !std::isnan(stop_s) || !std::isnan(speed_mps);
  }
};

// Plausible ranges, shared by the scenario reader and the dataset readers (harness/dataset/):
// a stereo rig from a phone's 1 mm to a car's or a tower's 5 m, and a field of view a pinhole
// model describes (the reader also checks the focal length that gives).
constexpr double kMinBaselineM = 0.001;  // 1 mm
constexpr double kMaxBaselineM = 5.0;    // 5 m
constexpr double kMinFovDeg = 1.0;       // exclusive
constexpr double kMaxFovDeg = 170.0;     // exclusive
// Renders averaged over a motion-blur exposure, at most (each one is a full stereo render).
constexpr int kMaxMotionBlurSamples = 1000;

// Auto-exposure (camera.auto_exposure, sim/lighting.h): a first-order loop that scales the
// rendered grey levels by a gain g (before the noise model). At each frame k the gain wanted is
// target_mean / mean_k (mean_k: the mean grey level of the left render at gain 1); the gain
// moves toward it as g_k = g_{k-1} + (1 - exp(-T / time_constant_s)) (wanted_k - g_{k-1}), T the
// frame period, so a step in the scene's brightness is followed with that time constant. Frame 0
// starts converged (g_0 = wanted_0). Gains are kept in [1/16, 16]. Both cameras get the same gain.
struct AutoExposureOptions {
  bool enabled = false;
  double target_mean = 110.0;    // grey level the loop steers the mean to, (0, 255)
  double time_constant_s = 0.5;  // (s), > 0 and <= 60
};

// Rectified stereo pair on the robot (the paper's Videre head by default).
struct CameraOptions {
  int width = 320;           // image width (pixels), 16..4096
  int height = 240;          // image height (pixels), 16..4096
  double fovy_deg = 55.0;    // vertical field of view (degrees), (1, 170)
  double baseline_m = 0.09;  // stereo baseline (m), [kMinBaselineM, kMaxBaselineM] = 1 mm .. 5 m
  double height_m = 1.0;     // optical centre height above the floor (m), > 0
  double forward_m = 0.15;   // optical centre ahead of the wheel axle (m)
  double pitch_deg = 0.0;    // downward tilt of the optical axis (degrees), (-80, 80)
  // The lens (sim/lens.h): none by default (an ideal pinhole). Scenario keys
  // camera.distortion.model (radtan | equidistant) and camera.distortion.coeffs (4 numbers);
  // the images are then the raw, distorted ones, rendered wider and remapped.
  LensDistortion distortion;
  AutoExposureOptions auto_exposure;  // camera.auto_exposure.*: off by default
};

// Camera noise models; each is off at 0.
struct NoiseOptions {
  double pixel_sigma = 0.0;  // additive Gaussian pixel noise (grey levels, 0..255 scale)
  double gain_sigma = 0.0;   // per-image multiplicative gain: gain ~ N(1, gain_sigma²)
  double bias_sigma = 0.0;   // per-image exposure offset ~ N(0, bias_sigma²) (grey levels)
  double motion_blur_exposure_s = 0.0;  // exposure time for motion blur (s); 0 = no blur;
                                        // at most the frame period minus 2 physics steps (the
                                        // exposures of consecutive frames must not overlap)
  int motion_blur_samples = 5;          // renders averaged over the exposure, 1..1000
                                        // (kMaxMotionBlurSamples), >= 2 when blur is on
};

// Procedural textures of the scene (sim/textures.h).
struct TextureSettings {
  uint64_t seed = 1;  // texture generator seed; the same seed gives the same hallway
};

// The robot's IMU (sim/imu.h): MuJoCo gyro and accelerometer sensors on site "imu", sampled every
// 1 / rate_hz, with the noise model of a Kalibr imu.yaml. Defaults: a TDK InvenSense ICM-20602
// (datasheet DS-000176: gyro rate noise spectral density 0.004 deg/s/sqrt(Hz), accelerometer
// noise spectral density 100 ug/sqrt(Hz); output data rates 1 kHz / n, so 250 Hz). Datasheets give
// no bias random walk: those two are the EuRoC MAV's imu0/sensor.yaml (ADIS16448), the usual
// order for a MEMS part. 250 Hz rather than EuRoC's 200 Hz: samples are taken on physics steps,
// and 200 Hz is 2.5 steps of the bench's 0.002 s.
struct ImuOptions {
  double rate_hz = 250.0;  // sample rate (Hz): the period a whole number of physics steps
  double gyro_noise_density = 0.004 * M_PI / 180.0;  // rad/s/sqrt(Hz), >= 0 (6.98e-5)
  double gyro_random_walk = 1.9393e-05;              // rad/s^2/sqrt(Hz), >= 0
  double accel_noise_density = 100e-6 * 9.80665;     // m/s^2/sqrt(Hz), >= 0 (9.81e-4)
  double accel_random_walk = 3.0e-3;                 // m/s^3/sqrt(Hz), >= 0
  // Pose on the robot body (x forward, y left, z up, origin at the wheel axle): by default on
  // top of the chassis above the axle, axes of the body.
  double x_m = 0.0, y_m = 0.0, z_m = 0.19;                // position (m)
  double roll_deg = 0.0, pitch_deg = 0.0, yaw_deg = 0.0;  // R = Rz(yaw) Ry(pitch) Rx(roll)
  // A real gyro's turn-on bias (a MEMS gyro's is 0.1-5 deg/s; EuRoC's ADIS16448 read 0.078
  // rad/s about z standing): σ per axis of the gyro's bias at the first sample (rad/s, >= 0),
  // drawn from the IMU's noise stream; 0 = the bias starts at 0 (and the stream is as before).
  double gyro_turn_on_bias_sigma_radps = 0.0;
  // IMU samples this long before frame 0 (s, 0 .. settle_s), taken while the robot stands
  // (settling): frame 0 carries them, at negative times, as a recording started before the
  // robot moved does (the VO's standing start learns the gyro's bias from them,
  // vo/gyro_prior.h). 0 = samples from frame 0 on.
  double pre_roll_s = 0.0;
};

// Calibration error (issue #34): the calibration vobench EXPORTS (render's calib.txt and EuRoC
// sensor.yaml, the camera the VO receives in `vobench run`) differs from the true one that
// rendered the images, to measure a VO's sensitivity to a bad calibration. The images do not
// change. baseline_pct scales the stereo baseline by (1 + baseline_pct / 100), focal_pct both
// focal lengths by (1 + focal_pct / 100) (the principal point stays); rotation_deg turns the
// right camera about its own y axis (image down: a toe-in/out "yaw" between the cameras, the
// error that biases disparity most) in EuRoC's cam1 T_BS. A rotation between the cameras has no
// place in a rectified calibration (KITTI's calib.txt, the VO's vo::StereoCamera): there the
// frames are rectified by the wrong calibration (ExportedRectification, harness/sim_adapter.h).
// All 0 = the true calibration, byte for byte.
struct CalibrationErrorOptions {
  double baseline_pct = 0.0;  // baseline error (% of the true baseline), > -100
  double focal_pct = 0.0;     // focal length error (% of the true fx, fy), > -100
  double rotation_deg = 0.0;  // right camera turned about its y axis (degrees), |.| < 45
  bool any() const { return baseline_pct != 0.0 || focal_pct != 0.0 || rotation_deg != 0.0; }
};

// Frame timing faults (issue #34), seeded by the scenario's seed, deterministic, each off at 0:
// frame k is dropped when u_k < drop_rate, u_k uniform in [0, 1) from DeriveSeed(seed, k, 3)
// (the kept frames are the very frames of the undropped sequence; their stamps keep the gaps),
// and a kept frame's stamp is the capture time plus a jitter UNIFORM in [-time_jitter_s,
// +time_jitter_s] from the same stream (bounded, so stamps stay in order: time_jitter_s below
// half the frame period). The images and ground truth stay those of the capture time; only the
// stamp is wrong, as with a camera driver's clock.
struct FrameOptions {
  double drop_rate = 0.0;      // fraction of frames dropped, [0, 1)
  double time_jitter_s = 0.0;  // stamp jitter half-width (s), [0, 0.5 / rate_hz)
  bool any() const { return drop_rate != 0.0 || time_jitter_s != 0.0; }
};

// People (issue #34): kinematic (mocap) bodies of human proportions (sim/people.h), each walking
// its own path back and forth at speed_mps: in a floor-plan scene between two of the plan's
// named places (PlanPath), in an MJCF scene (or a plan with fewer than two places) along a line
// beside the robot's path, clear of the walls and of the robot. They do not collide (no contacts,
// never wall contacts). Deterministic from `seed`; count 0 (the default) adds nothing.
constexpr int kMaxPeople = 20;
struct PeopleOptions {
  int count = 0;           // people in the scene, [0, kMaxPeople]
  uint64_t seed = 1;       // their paths, phases and clothes' textures
  double speed_mps = 1.2;  // walking speed (m/s), (0, 3]
  double height_m = 1.75;  // body height (m), [1, 2.3]
};

// A lamp switched at a time (lights.switch): light `light` (index in the scene's lights, model
// order, or its name) turned on or off at at_s (s from frame 0) and kept so until the next switch.
struct LightSwitch {
  double at_s = 0.0;  // >= 0
  int light = -1;     // index into the scene's lights (the name resolved when read)
  std::string name;   // the light's name as given ("" when given by index)
  bool on = false;
};

// Lights (issue #34, sim/lighting.h), each off by default, applied to MuJoCo's light and material
// properties before every render, at the render's time t (s from frame 0):
//   brightness(t) = max(0, 1 + brightness_drift * t / 60)
//                   * (1 - flicker_depth * (1 - cos(2 pi flicker_hz t)) / 2)
// scales every light's diffuse, ambient and specular colour and every material's emission (the
// scenes light their surfaces mostly by emission, the building's even ambient light), and a lamp
// switched off gives no light (its colours 0; sim/lighting.h SceneLighting).
struct LightsOptions {
  std::vector<LightSwitch> switches;  // in time order
  double brightness_drift = 0.0;      // fraction of the initial brightness gained per minute,
                                      // [-1, 1] (negative: dimming; clamped at 0)
  double flicker_hz = 0.0;            // flicker frequency (Hz), [0, 1000]; 0 = none
  double flicker_depth = 0.0;         // the dip of the flicker, [0, 1]: brightness 1 .. 1 - depth
  bool any() const {
    return !switches.empty() || brightness_drift != 0.0 || (flicker_hz > 0 && flicker_depth > 0);
  }
};

struct Scenario {
  std::string name;             // scenario name (file stem unless given)
  std::string source_path;      // the YAML file it was read from (empty if built in code)
  std::string scene_path;       // MJCF scene, or a floor plan (.yaml, sim/floor_plan.h) the
                                // scene is generated from; resolved to an absolute path
  uint64_t seed = 1;            // noise seed
  double rate_hz = 10.0;        // camera frame rate (Hz), > 0, at most 1 / physics_dt_s, and
                                // the frame period a whole number of physics steps (frames are
                                // taken on steps: 10 Hz at 0.002 s = every 50th step)
  double physics_dt_s = 0.002;  // physics time step (s), (0, 0.01]
  double max_duration_s = 300;  // safety limit on simulated time (s)
  double settle_s = 0.5;        // robot stands still this long before frame 0 (s), >= 0
  std::vector<Eigen::Vector2d> path;       // waypoints (x, y) in the world frame (m), >= 2
  std::vector<WaypointOptions> waypoints;  // each waypoint's own goals: empty, or one per waypoint
  RobotOptions robot;
  CameraOptions camera;
  NoiseOptions noise;
  TextureSettings textures;
  ImuOptions imu;
  // What the path follower steers on (sim/navigation.h): "ground_truth" (the true pose) or "vo"
  // (the VO's estimate, frame by frame: the closed loop).
  std::string navigation = "ground_truth";
  CalibrationErrorOptions calibration_error;
  FrameOptions frames;
  PeopleOptions people;
  LightsOptions lights;

  bool IsValid(std::string* error) const;
};

// Reads and validates a scenario file. On failure returns false and *error names the file,
// the key (and line where known) and what was expected. Unknown keys are errors.
// About how many frames the scenario renders (the path at speed_mps, in-place turns at
// turn_rate_dps, at rate_hz, at most max_duration_s): an estimate for refusing a stride or frame
// limit that cannot leave the VO two frames, before anything is simulated.
int EstimatedFrames(const Scenario& scenario);

bool LoadScenario(const std::string& path, Scenario* scenario, std::string* error);

// Parses a scenario from YAML text; `source_name` is used in messages and `base_dir` to
// resolve a relative scene path.
bool ParseScenario(const std::string& yaml_text, const std::string& source_name,
                   const std::string& base_dir, Scenario* scenario, std::string* error);

// Writes the effective scenario as YAML (every field, defaults included).
std::string ScenarioToYaml(const Scenario& scenario);

// Every key a scenario may have, as YAML (the values meaningless): ScenarioToYaml of `scenario`
// with each optional section (robot.stop_s and final_heading_deg, camera.distortion and
// auto_exposure, calibration_error, frames, people, lights) filled in, which it writes only where
// set. A suite checks its scenario overrides' keys against it (harness/suite/spec.cc).
std::string ScenarioKeysYaml(const Scenario& scenario);

// Path of a scenario shipped in scenes/ by name ("l_hallway" -> <data dir>/scenes/l_hallway.yaml,
// sim/data_dir.h: the source tree, or <prefix>/share/vobench when installed).
std::string BuiltinScenarioPath(const std::string& name);

}  // namespace sim
