// The EuRoC/ASL layout: sensor.yaml and a reader of the raw pair (rectification.h makes it the
// rectified pair the VO expects). DatasetWriter (writer.h) writes it in addition to the KITTI
// layout when Options::format is kEuroc:
//   mav0/cam0/data/<t_ns>.png, mav0/cam0/data.csv ("#timestamp [ns],filename"),
//   mav0/cam0/sensor.yaml (T_BS, intrinsics [fu, fv, cu, cv], zero radial-tangential distortion,
//   resolution, rate_hz, camera_model pinhole); the same for cam1 (T_BS = T_body_cam0 *
//   T_cam0_cam1); mav0/state_groundtruth_estimate0/data.csv [ground truth only]: the body pose
//   T_world_body in the world, finite-differenced velocity, zero biases, and its sensor.yaml
//   (T_BS identity). With IMU samples in the frames: mav0/imu0/, body.yaml and that ground truth
//   at the IMU rate (euroc_imu.h). Every yaml starts with "%YAML:1.0" (cv::FileStorage needs
//   it); stamps have one number of digits (writer.h: stamp_offset_ns), so names sort in time
//   order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "harness/dataset/common.h"
#include "harness/dataset/rectification.h"
#include "harness/trajectory_io.h"

namespace harness {

// Reads an EuRoC sensor.yaml. Keys read: T_BS (rows, cols, data: 16 numbers), intrinsics
// [fu, fv, cu, cv], resolution [width, height], camera_model, distortion_model,
// distortion_coefficients, and rate_hz when present. Other keys are ignored, so the variants in
// circulation read too (Kimera-VIO's sensorLeft.yaml has camera_id instead of sensor_type and
// comment). A leading OpenCV "%YAML:1.0" line is accepted.
bool ReadEurocSensorYaml(const std::string& path, EurocCameraCalibration* calibration,
                         std::string* error);

class EurocReader {
 public:
  struct Options {
    double gt_max_difference_s = 0.003;  // ground-truth stamp must lie within this of the frame
                                         // (seconds, > 0); EuRoC ground truth runs at 200 Hz
    // Ground truth: a TUM trajectory ("t tx ty tz qx qy qz qw") of the BODY (IMU) frame in the
    // world, as EuRoC's ground truth is; T_world_cam0 = T_world_body * T_BS(cam0). Empty = the
    // first that exists of mav0/state_groundtruth_estimate0/data.csv (EuRoC's own),
    // DIR/groundtruth_tum.txt, DIR/groundtruth.txt (the last two: TUM format, body frame).
    std::string gt_path;
  };

  // Reads DIR/mav0/cam{0,1}/{data.csv,sensor.yaml} and the ground truth (see Options::gt_path).
  // Stereo frames are the stamps present in both cameras (the others are counted in
  // unpaired_frames()). A ground truth that no frame associates with is an error (a clock or
  // file mix-up); frames without an associated pose have has_gt = false.
  bool Open(const std::string& dir, std::string* error) { return Open(dir, Options(), error); }
  bool Open(const std::string& dir, const Options& options, std::string* error);

  const EurocCameraCalibration& cam0() const { return cam_[0]; }
  const EurocCameraCalibration& cam1() const { return cam_[1]; }
  size_t size() const { return t_ns_.size(); }
  const std::vector<int64_t>& times_ns() const { return t_ns_; }
  size_t unpaired_frames() const { return unpaired_; }
  // Ground-truth body poses T_world_body as in the file (empty when none).
  const std::vector<StampedPose>& ground_truth_body() const { return gt_body_; }
  const std::string& ground_truth_path() const { return gt_path_; }  // "" when none
  size_t ground_truth_frames() const;  // frames with an associated ground-truth pose
  // mav0/imu0/data.csv when present (euroc_imu.h): ReadFrame gives each frame its samples;
  // imu() the rate and noise numbers of imu0/sensor.yaml (sim::ImuOptions' defaults without it).
  bool has_imu() const { return !imu_.empty(); }
  const sim::ImuOptions& imu() const { return imu_options_; }

  // The rectification of the pair (ComputeStereoRectification on cam0, cam1).
  bool Rectification(StereoRectification* rectification, std::string* error) const {
    return Rectification(RectificationOptions(), rectification, error);
  }
  bool Rectification(const RectificationOptions& options, StereoRectification* rectification,
                     std::string* error) const;

  // Raw images of frame `index` (grayscale, checked against the yaml resolution);
  // has_gt and T_world_cam0 = T_world_body * T_body_cam0 when a ground-truth stamp is close
  // enough. depth_m stays empty. RectifyFrame turns it into the rectified frame.
  bool ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const;

 private:
  Options options_;
  std::string dir_;
  EurocCameraCalibration cam_[2];
  int bits_ = 8;  // the images' bit depth (dataset_internal::FirstPairBits)
  std::vector<int64_t> t_ns_;
  std::vector<std::string> files_[2];  // image paths per camera, aligned with t_ns_
  std::vector<StampedPose> gt_body_;
  std::string gt_path_;
  std::vector<long> gt_index_;  // per frame: index into gt_body_, -1 = none
  size_t unpaired_ = 0;
  std::vector<int64_t> imu_ns_;      // imu0 stamps
  std::vector<sim::ImuSample> imu_;  // imu0 samples
  sim::ImuOptions imu_options_;      // imu0/sensor.yaml
};

}  // namespace harness
