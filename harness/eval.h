// `vobench eval`: the VO on a recorded stereo sequence in the KITTI, EuRoC/ASL or TUM-style
// layout (dataset.h), with the same run folder, table and metrics as `vobench run`.
//
//   kitti  calib.txt, times.txt, image_0/, image_1/; ground truth: poses.txt (one per frame,
//          with T_world_cam0first.txt when present) or --gt (TUM, left camera, associated; or
//          KITTI poses such as the benchmark's poses/NN.txt).
//   euroc  mav0/cam{0,1}/{data.csv,sensor.yaml,data/}; the raw pair is undistorted and
//          rectified from the two sensor.yaml files (ComputeStereoRectification) before the VO
//          sees it; ground truth: the body pose (EuRoC's data.csv, or TUM groundtruth_tum.txt /
//          groundtruth.txt in DIR, or --gt), turned into the rectified left camera's pose
//          T_world_rect0 = T_world_body * T_BS(cam0) * R_cam0_rect0.
//   tum    left.txt, right.txt, calib.txt; ground truth: groundtruth.txt (left camera) or --gt.
//   rosbag one ROS bag (dataset/rosbag.h: RosbagReader) in EuRoC's layout: the image topics,
//          their camera_info or two EuRoC sensor.yaml files, the IMU topic, the ground-truth
//          topic (the left camera, TransformStamped); rig.yaml beside the bag when present.
//
// Ground truth recorded at another rate is associated with the frame stamps as the TUM tools'
// associate.py does (max_difference_s). Frames without an associated pose are run and logged,
// but the metrics use only the frames with ground truth (RunSummary::ground_truth_frames says
// how many). Without any ground truth the run folder still has the trajectory, the per-frame log
// and metrics.json (without the accuracy metrics).
#pragma once

#include <cstddef>
#include <string>

#include "harness/dataset.h"
#include "harness/run.h"
#include "vo/camera.h"
#include "vo/odometry.h"

namespace harness {

struct EvalOptions {
  DatasetFormat format = DatasetFormat::kKitti;  // layout of the dataset folder
  std::string gt_path;  // ground truth, TUM format ("t tx ty tz qx qy qz qw"): the left camera
                        // for kitti/tum, the body (IMU) frame for euroc (a .csv name: EuRoC's
                        // state_groundtruth_estimate0 format). For kitti also a KITTI poses file
                        // (12 numbers per line, one per frame, in the first camera's frame),
                        // told by its field count. "" = the layout's own, if any
  double max_difference_s = 0.0;        // largest |t_frame - t_gt| associated (seconds), >= 0;
                                        // 0 = DefaultMaxDifference(format)
  RectificationOptions rectification;   // EuRoC raw pairs (and raw bags)
  RosbagTopics rosbag_topics;           // rosbag: the topics read
  std::string calib_left, calib_right;  // rosbag: EuRoC sensor.yaml files instead of camera_info
  std::string imu_extrinsics;  // rosbag: Kalibr camchain-imucam.yaml, cam0's pose on the IMU (for
                               // the VO's gyro); "" = camchain-imucam.yaml beside the bag, else
                               // the --calib files' T_BS, else unknown (the gyro is not used)

  bool IsValid(std::string* error) const;
};

// 0.02 s (associate.py's default) for kitti and tum, 0.003 s for euroc and rosbag (200 Hz
// ground truth).
double DefaultMaxDifference(DatasetFormat format);

// What the dataset held, for the report.
struct EvalInfo {
  size_t dataset_frames = 0;        // stereo frames in the dataset (before --max-frames)
  size_t unpaired_frames = 0;       // images without a partner in the other camera (euroc, tum)
  std::string ground_truth_path;    // "" when there is none
  size_t ground_truth_frames = 0;   // dataset frames with an associated ground-truth pose
  double max_difference_s = 0.0;    // the association tolerance used (seconds)
  bool rectified = false;           // the raw pair was remapped (euroc with a real raw pair)
  vo::StereoCamera camera;          // the camera the VO ran with (rectified for euroc)
  std::string imu_extrinsics_path;  // where the IMU's mounting came from ("" = unknown or no IMU)
};

// Opens `dir` in `options.format`, runs the VO over its frames (run_options.max_frames caps
// them) and writes the run folder run_options.out_dir (RunOdometry). The run's name is the
// dataset folder's name. Errors name the file and the problem; nothing is left at out_dir then.
// The dataset folder `dir` in `options.format` as a sequence (frames rectified where the layout
// needs it, ground truth associated), and what `eval` reports of it. One opener per layout;
// every caller (eval, run --dataset) goes through this one.
bool OpenDataset(const std::string& dir, const EvalOptions& options, StereoSequence* sequence,
                 EvalInfo* info, std::string* error);

bool EvalDataset(const std::string& dir, const EvalOptions& options,
                 const vo::OdometryOptions& vo_options, const RunOptions& run_options,
                 RunSummary* summary, EvalInfo* info, std::string* error);

// The dataset folder's name ("data/seq01/" -> "seq01").
std::string DatasetName(const std::string& dir);

}  // namespace harness
