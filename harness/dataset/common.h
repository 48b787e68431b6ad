// What every dataset layout shares: the stereo frame in memory, the layout names, time stamps
// in nanoseconds and the association of ground truth with the frame stamps.
//
// The readers (kitti.h, euroc.h, tum.h) have one shape: Open(dir, options, error) reads the
// layout's text files and checks that every image is there; size() frames, each loaded lazily
// by ReadFrame(index, frame, error) as grayscale images, with the left camera's ground-truth
// pose where one is known (DatasetFrame::has_gt). Time stamps in nanoseconds are int64:
// t_ns = llround(time_s * 1e9).
//
// Errors: functions return false and fill *error with the file (and line) and what was expected.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "harness/trajectory_io.h"
#include "sim/imu.h"

namespace harness {

// One stereo frame in memory.
struct DatasetFrame {
  double time_s = 0.0;  // time stamp (seconds)
  cv::Mat left;         // cam0 image, CV_8UC1
  cv::Mat right;        // cam1 image, CV_8UC1, same size as left
  cv::Mat depth_m;      // CV_32FC1 z-depth of the left view (metres), 0 = none; may be empty
  bool has_gt = false;  // true when T_world_cam0 holds the ground-truth pose
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();  // left camera in the world
  // The IMU's samples since the previous frame (stamps in (previous time_s, time_s]; the first
  // frame: up to its time), empty without an IMU. Simulated samples carry their ground truth
  // (sim::ImuSample::has_gt); a dataset's (EuRoC imu0) the measurements only.
  std::vector<sim::ImuSample> imu;
};

enum class DatasetFormat {
  kKitti,   // KITTI odometry layout only
  kEuroc,   // KITTI layout plus the EuRoC/ASL layout under mav0/
  kTum,     // KITTI layout plus the TUM-style stereo layout (left.txt, right.txt, left/, right/)
  kRosbag,  // KITTI layout plus one ROS bag (rosbag.h); a reader of one bag file
};
// "kitti" / "euroc" / "tum" / "rosbag"; false for other names.
bool ParseDatasetFormat(const std::string& name, DatasetFormat* format);
const char* DatasetFormatName(DatasetFormat format);

// Time stamp in nanoseconds as written to EuRoC files.
int64_t TimeToNs(double time_s);

// For each frame stamp, the index into `ground_truth` of the pose associated with it as the TUM
// tools' associate.py does (AssociateStamps: |t_frame - t_gt| < max_difference_s, greedy by
// smallest difference, each pose used at most once), or -1 when none is close enough.
// Stamps are taken relative to frame_times_s.front() before comparing, so large absolute stamps
// (EuRoC: ~1.4e9 s) keep microsecond resolution. max_difference_s must be > 0.
std::vector<long> AssociateGroundTruth(const std::vector<double>& frame_times_s,
                                       const std::vector<StampedPose>& ground_truth,
                                       double max_difference_s);

}  // namespace harness
