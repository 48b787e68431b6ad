// The simulator: a MuJoCo scene with a differential-drive robot that drives a scenario's path
// through the physics, and a stereo rig on it rendered offscreen (OSMesa) at the scenario's
// frame rate, with ground-truth pose and depth.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sim/imu.h"
#include "sim/navigation.h"
#include "sim/scenario.h"

namespace sim {

// Rectified stereo calibration the simulator renders with. Pixel centres at integer
// coordinates (OpenCV); cam1 = cam0 shifted by +baseline_m along cam0's x axis.
struct StereoCalibration {
  int width = 0;       // image width (pixels)
  int height = 0;      // image height (pixels)
  double fx_px = 0.0;  // focal lengths (pixels)
  double fy_px = 0.0;
  double cx_px = 0.0;  // principal point (pixels)
  double cy_px = 0.0;
  double baseline_m = 0.0;  // stereo baseline (m)
  LensDistortion lens;      // both cameras' lens (none: the images are the rectified pinhole's)
  Eigen::Isometry3d T_body_cam0 = Eigen::Isometry3d::Identity();  // cam0 on the robot base
  Eigen::Isometry3d T_body_imu = Eigen::Isometry3d::Identity();   // the IMU on the robot base
};

// One stereo frame and its ground truth.
struct StereoFrame {
  int index = 0;        // frame number from 0
  double time_s = 0.0;  // frame time from the first frame (s); mid-exposure with blur
  cv::Mat left;         // CV_8UC1 grey, cam0
  cv::Mat right;        // CV_8UC1 grey, cam1
  cv::Mat depth_m;      // CV_32FC1 z-depth of the left view (m), noise-free
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();  // computer-vision axes
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();  // robot base (x forward, z up)
  // The IMU's samples since the previous frame: times in (previous frame's time, time_s]; frame 0
  // has the sample at time 0. With the noise model applied and their ground truth (sim/imu.h).
  std::vector<ImuSample> imu;
};

class Simulator {
 public:
  // Loads the scene, places the robot at the path's start, builds textures and the renderer.
  // Returns nullptr and fills *error (naming the scene file) on failure.
  static std::unique_ptr<Simulator> Create(const Scenario& scenario, std::string* error);
  ~Simulator();

  // Advances the physics to the next frame and renders it. Returns false at the end of the
  // path (then *error is empty) or on a failure (then *error says what happened). With the
  // scenario's frames.drop_rate, dropped frames are captured and discarded (their IMU samples go
  // with the next frame kept; a kept frame keeps its index and time, so the stamps have gaps);
  // with frames.time_jitter_s the frame's time_s is its capture time plus the jitter
  // (sim/scenario.h FrameOptions; FrameFate gives both).
  bool Next(StereoFrame* frame, std::string* error);

  const StereoCalibration& calibration() const { return calibration_; }
  const Scenario& scenario() const { return scenario_; }
  const std::string& gl_renderer() const;
  // Rough number of frames the path will take (for progress displays).
  int EstimatedFrames() const;
  // Robot base position (x, y, z in the world, m) after every physics step since frame 0.
  const std::vector<Eigen::Vector3d>& body_track() const { return body_track_; }
  // The people (people.count, sim/people.h): where each one's body origin (on the floor, below
  // the torso) was at the time of the frame Next() gave last.
  const std::vector<Eigen::Vector3d>& people_at_last_frame() const { return people_at_frame_; }
  // The auto-exposure's gain of the frame Next() gave last (1 without camera.auto_exposure).
  double exposure_gain() const { return exposure_gain_; }

  // Closed loop (navigation: vo; sim/navigation.h). What the follower believed at the time of
  // the frame Next() gave last, before any fix of it.
  PlanarPose BeliefAtLastFrame() const;
  // An estimate of the body pose at the time of the frame Next() gave last: it becomes the
  // belief, with the commands issued since that time replayed on it. Ignored with
  // navigation: ground_truth.
  void FixAtLastFrame(const PlanarPose& body);
  // An estimator consulted at every control step with the true pose: its answer is the belief
  // of that step (a perfect or a biased sensor, for tests). navigation: vo only.
  using StepEstimator = std::function<PlanarPose(const PlanarPose& truth)>;
  void SetStepEstimator(StepEstimator estimator);
  // What the robot did so far (complete once Next() returned false without an error).
  const NavigationReport& navigation() const;

 private:
  struct Impl;
  explicit Simulator(const Scenario& scenario);
  bool Capture(StereoFrame* frame, std::string* error);  // the next frame, none dropped
  Scenario scenario_;
  StereoCalibration calibration_;
  std::vector<Eigen::Vector3d> body_track_;
  std::vector<Eigen::Vector3d> people_at_frame_;
  double exposure_gain_ = 1.0;
  std::unique_ptr<Impl> impl_;
};

// What frames.drop_rate and frames.time_jitter_s do to frame `index` of a scenario with `seed`:
// whether it is dropped, and the jitter added to its stamp (s; 0 when time_jitter_s is 0). One
// stream per frame, DeriveSeed(seed, index, 3): first draw the drop, second the jitter; frame 0
// (the clock's origin) has none.
struct FrameFate {
  bool dropped = false;
  double jitter_s = 0.0;
};
FrameFate FrameFateOf(const FrameOptions& options, uint64_t seed, int index);

// Intrinsics of a MuJoCo camera with vertical field of view `fovy_deg` rendered at
// width x height: square pixels, principal point at the image centre.
void IntrinsicsFromFovy(double fovy_deg, int width, int height, double* fx_px, double* fy_px,
                        double* cx_px, double* cy_px);

}  // namespace sim
