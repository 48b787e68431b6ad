// ROS 1 bags in and out (Debian's librosbag-dev, libsensor-msgs-dev, libgeometry-msgs-dev), in
// the layout of EuRoC's bags, so a simulated sequence plays into a ROS system as a recording
// would, and a recorded EuRoC-style bag runs through the VO (`vobench eval --format rosbag`).
//
// The layout RosbagWriter writes (DatasetWriter with DatasetFormat::kRosbag: DIR/<DIR's name>.bag
// beside the KITTI layout, inside the writer's partial folder, so it is published whole or not
// at all). Every message's header.stamp and bag time are the EuRoC export's nanosecond stamps
// (writer.h: stamp_offset_ns + the frame time; the IMU's as WriteEurocImu's):
//   /cam0/image_raw, /cam1/image_raw   sensor_msgs/Image, mono8, frame_id cam0 / cam1 (EuRoC's)
//   /cam0/camera_info, /cam1/camera_info   sensor_msgs/CameraInfo with every image: the rectified
//                          pinhole, distortion_model plumb_bob with D = 0 (5 zeros), R = I,
//                          K = [fx 0 cx; 0 fy cy; 0 0 1], P = [K | 0] (cam1: P[3] = -fx * baseline)
//   /cam0/depth/image_raw  sensor_msgs/Image 16UC1 (REP 118: millimetres, 0 = none), the left
//                          view's z-depth, where the frames carry it: the KITTI layout's depth/
//                          PNGs (`eval` scores the VO's matches on it)
//   /imu0                  sensor_msgs/Imu (frames with IMU samples), frame_id imu4 (EuRoC's):
//                          angular_velocity, linear_acceleration (specific force) in the IMU frame;
//                          no orientation (orientation_covariance[0] = -1, REP 145); covariances
//                          diagonal, the discrete-time white noise of the noise model:
//                          density^2 * rate_hz (gyro and accelerometer)
//   /groundtruth/cam0      geometry_msgs/TransformStamped at every frame stamp: the left camera's
//                          exact pose in the simulator's gravity-aligned world (frame_id world,
//                          child_frame_id cam0). A transform, as EuRoC's Vicon ground truth
//                          (/vicon/firefly_sbx/firefly_sbx) is, with the child frame naming what
//                          it is the pose of; of the camera, not the body, because that is what the
//                          VO is scored on, at the frame stamps (no association, no extrinsic
//                          needed); the body (IMU) pose at the IMU rate is the next topic:
//   /groundtruth/imu0      geometry_msgs/TransformStamped at every IMU sample (simulated samples
//                          only): the IMU's pose in the world (child_frame_id imu4), as the EuRoC
//                          export's state_groundtruth_estimate0 (there also velocity and biases).
//
// RosbagReader reads EuRoC-style bags: two image topics (mono8 or 8UC1; rgb8/bgr8 are turned
// grey), stereo frames the stamps present on both; the depth topic (16UC1 mm or 32FC1 m) where a
// stamp matches; calibration from the topics' camera_info
// (sibling topic "<namespace>/camera_info", the first message of each: a rectified pinhole as
// above, used as it is; a raw one is refused, naming --calib) or from two EuRoC sensor.yaml files
// (euroc.h; EuRoC's own bags carry no camera_info), rectified as `eval --format euroc` does; the
// IMU topic's samples between frames (as EurocReader gives them); the ground-truth topic
// (TransformStamped of the left camera, its child_frame_id the left images' frame_id) associated
// with the frame stamps. Errors name the bag and the topic.
//
// Without VOBENCH_ROSBAG (the packages missing at configure time) every function here refuses
// with RosbagUnavailable()'s message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "harness/dataset/common.h"
#include "harness/dataset/rectification.h"
#include "vo/camera.h"

namespace harness {

// Whether this build reads and writes bags (CMake option VOBENCH_ROSBAG).
bool RosbagSupported();
// "this vobench was built without ROS bag support ..." (how to turn it on).
std::string RosbagUnavailable();

// The topics of the layout above.
struct RosbagTopics {
  std::string left = "/cam0/image_raw";
  std::string right = "/cam1/image_raw";
  std::string imu = "/imu0";
  std::string depth = "/cam0/depth/image_raw";
  std::string ground_truth = "/groundtruth/cam0";
  std::string imu_ground_truth = "/groundtruth/imu0";
};

// DIR/<DIR's name>.bag: where DatasetWriter puts the bag of a dataset folder DIR.
std::string RosbagPathInDataset(const std::string& dir);

// "<namespace>/camera_info" of an image topic ("/cam0/image_raw" -> "/cam0/camera_info").
std::string CameraInfoTopic(const std::string& image_topic);

// Writes one bag (used by DatasetWriter: the checks of its frames are DatasetWriter::Add's).
class RosbagWriter {
 public:
  RosbagWriter();
  ~RosbagWriter();  // closes the bag (a partial bag's folder is the caller's to remove)
  RosbagWriter(const RosbagWriter&) = delete;
  RosbagWriter& operator=(const RosbagWriter&) = delete;

  // imu: the noise numbers the IMU messages' covariances come from.
  bool Open(const std::string& path, const vo::StereoCamera& camera, const sim::ImuOptions& imu,
            std::string* error);
  // The frame's images, camera_info, depth (depth_mm: CV_16UC1 millimetres as the KITTI
  // layout's depth PNG, or empty), ground truth (frame.has_gt) and IMU samples (each stamped
  // stamp_offset_ns + TimeToNs(time_s)); stamp_ns: the frame's.
  bool Add(const DatasetFrame& frame, const cv::Mat& depth_mm, int64_t stamp_ns,
           int64_t stamp_offset_ns, std::string* error);
  bool Close(std::string* error);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class RosbagReader {
 public:
  struct Options {
    RosbagTopics topics;
    // Two EuRoC sensor.yaml files (cam0, cam1) instead of the camera_info topics; empty = read
    // camera_info.
    std::string calib_left, calib_right;
    double gt_max_difference_s = 0.003;  // ground-truth stamp within this of the frame's (s, > 0)
    RectificationOptions rectification;  // raw pairs (--calib files)
  };

  RosbagReader();
  ~RosbagReader();
  RosbagReader(const RosbagReader&) = delete;
  RosbagReader& operator=(const RosbagReader&) = delete;

  // Opens the bag, indexes the image topics (checks the first image of each: encoding and size),
  // reads the calibration, the IMU and the ground truth.
  bool Open(const std::string& path, const Options& options, std::string* error);

  size_t size() const;
  size_t unpaired_frames() const;
  // The rectified camera the frames are given in (the rectification's).
  const StereoRectification& rectification() const;
  bool has_imu() const;
  const sim::ImuOptions& imu() const;      // rate from the stamps, noise from the covariances
  std::string ground_truth_topic() const;  // "" when the bag has none
  size_t ground_truth_frames() const;
  // Frame `index`: grey images (rectified), time_s = stamp * 1e-9, the IMU samples since the
  // previous frame, the left camera's ground truth when associated.
  bool ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace harness
