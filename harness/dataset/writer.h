// DatasetWriter: a stereo sequence onto disk in the KITTI odometry layout (kitti.h), and when
// asked also in the EuRoC/ASL layout (euroc.h) or the TUM-style stereo layout (tum.h), so
// simulated sequences (`vobench render`) run through the same readers as real ones, and other
// systems' readers take them as they are:
//   - every YAML file starts with OpenCV's "%YAML:1.0" line (cv::FileStorage needs it; EuRoC's
//     own files have it; vobench's yaml-cpp readers skip it), but the bag's
//     camchain-imucam.yaml: Kalibr's files are plain YAML, read by PyYAML, which refuses
//     OpenCV's directive;
//   - calib.txt holds P0..P3 (P2 = P0, P3 = P1: the grey pair stands in for the colour pair) and
//     an identity Tr, as pykitti and cv::datasets::SLAM_kitti expect of the odometry calib.txt;
//   - kRosbag: one ROS bag DIR/<DIR's name>.bag in the layout of EuRoC's bags (rosbag.h), its
//     stamps the EuRoC export's; with IMU samples also DIR/camchain-imucam.yaml (Kalibr's:
//     the cameras' poses relative to the IMU, which camera_info cannot hold; kalibr.h);
//   - the EuRoC, TUM and bag stamps are Options::stamp_offset_ns + the frame time in nanoseconds;
//     all stamps of a sequence have the same number of digits, so the file names sort in time
//     order (`vobench render` starts the simulator's clock at kSimulationEpochNs: 19 digits).
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "harness/dataset/common.h"
#include "harness/dataset/rectification.h"
#include "harness/dataset/rig.h"
#include "harness/dataset/rosbag.h"
#include "harness/output_folder.h"
#include "vo/camera.h"

namespace harness {

// Where `vobench render` puts the simulator's time 0 on the EuRoC/TUM stamps:
// 2026-01-01T00:00:00Z in nanoseconds since the Unix epoch. Fixed (never the wall clock), so
// the same scenario gives the same bytes; 19 digits, like EuRoC's 1403636579763555584.
constexpr int64_t kSimulationEpochNs = 1767225600000000000;

// Writes a sequence atomically: everything goes into a marked, locked work folder
// "DIR.partial-<pid>-<random>" (an OutputFolder of kind "dataset", output_folder.h) that is
// renamed to DIR only by Finish(). Destroying the writer before Finish() (error, exception)
// removes the partial folder, so a half-written DIR never exists. A process killed outright
// (SIGKILL, Ctrl-C without a handler) leaves the ".partial-" folder, never DIR; Open() removes
// such leftovers of dead processes when they carry vobench's marker. Identical input gives
// byte-identical files (fixed PNG parameters, FormatDouble numbers, no "now" anywhere), except
// the marker .vobench.json (command line, time, pid).
//
// Usage:  DatasetWriter writer(options);
//         if (!writer.Open(dir, camera, &error)) ...;
//         for (...) if (!writer.Add(frame, &error)) ...;
//         if (!writer.Finish(&error)) ...;
class DatasetWriter {
 public:
  struct Options {
    DatasetFormat format = DatasetFormat::kKitti;  // kEuroc also writes the mav0/ layout, kTum
                                                   // the TUM-style one, kRosbag DIR/<name>.bag
    bool overwrite = false;   // replace an existing DIR (on Finish) when it is a vobench
                              // dataset (.vobench.json kind "dataset"); otherwise refuse
    bool write_depth = true;  // write depth/%06d.png for frames that carry depth
    int png_compression = 3;  // zlib level of every PNG, 0 (none) .. 9 (smallest, slowest)
    // EuRoC body frame: the left camera's pose in the body (rotation, metres).
    Eigen::Isometry3d T_body_cam0 = Eigen::Isometry3d::Identity();
    double rate_hz = 0.0;    // rate written to sensor.yaml (Hz, >= 0); 0 = from the median
                             // frame interval, rounded to 1 mHz
    bool write_rig = false;  // write rig.yaml (the camera's mounting, harness/dataset/rig.h)
    RigMounting rig;         // with write_rig
    // Added to every frame time (as whole nanoseconds) for the EuRoC and TUM stamps, >= 0. 0 =
    // the frame times are the stamps already (a recorded sequence); the simulator's clock starts
    // at 0, so render gives kSimulationEpochNs. times.txt and the KITTI-side files keep the frame
    // times.
    int64_t stamp_offset_ns = 0;
    // EuRoC with an IMU: when the frames carry IMU samples (DatasetFrame::imu), kEuroc writes
    // imu0/ (its sensor.yaml with these rate and noise numbers) and the ground truth at the IMU
    // rate, and EuRoC's body frame is the IMU's: the cameras' T_BS are CameraInImuFrame(
    // T_body_cam0, T_body_imu) (dataset/euroc_imu.h), T_body_imu the IMU on the same body.
    sim::ImuOptions imu;
    Eigen::Isometry3d T_body_imu = Eigen::Isometry3d::Identity();
    // EuRoC: cam1's orientation in cam0 written in its T_BS (a rotation matrix). The identity
    // for a rectified pair; a scenario's calibration_error.rotation_deg otherwise
    // (ExportedRotationCam0Cam1, harness/sim_adapter.h). The KITTI-side files cannot hold it.
    Eigen::Matrix3d R_cam0_cam1 = Eigen::Matrix3d::Identity();
    // EuRoC: both cameras' lens in sensor.yaml (distortion_model, distortion_coefficients); the
    // images are then the raw ones of that lens. None: radial-tangential [0, 0, 0, 0].
    sim::LensDistortion lens;
    // Raw frames of a lens or of a pair whose calibration holds a rotation (null or identity:
    // the frames are rectified already). The EuRoC side writes the frames as they are with the
    // raw calibration (Open's camera, `lens`, R_cam0_cam1); every other side (the KITTI layout,
    // TUM, the bag) writes them rectified by this (RectifyFrame: the images remapped, the ground
    // truth of the rectified left camera, no depth), with its rectified camera in calib.txt, as
    // `vobench eval --format euroc` rectifies that EuRoC side (the same maps: the exported
    // numbers read back exactly). Made by ExportedRectification (harness/sim_adapter.h).
    std::shared_ptr<const StereoRectification> rectification;

    bool IsValid(std::string* error) const;
  };

  DatasetWriter() = default;
  explicit DatasetWriter(Options options) : options_(std::move(options)) {}
  ~DatasetWriter();  // removes the partial folder unless Finish() succeeded
  DatasetWriter(const DatasetWriter&) = delete;
  DatasetWriter& operator=(const DatasetWriter&) = delete;

  // Checks options and camera, refuses an existing DIR unless options.overwrite (and then any
  // DIR vobench did not write as a dataset), creates the partial folder (and DIR's parent
  // folders) under the lock DIR.vobench-lock.
  bool Open(const std::string& dir, const vo::StereoCamera& camera, std::string* error);
  // Writes the frame's images at once. Frames must come in strictly increasing time (distinct
  // t_ns); images must be CV_8UC1 of the camera's size, depth empty or CV_32FC1 of that size.
  // EuRoC and TUM: every stamp (stamp_offset_ns + t_ns) >= 0 with as many digits as the first
  // frame's (names that sort), and for TUM distinct as the seconds its lists hold (doubles).
  // Ground truth and depth are all-or-nothing: the first frame decides for the sequence.
  bool Add(const DatasetFrame& frame, std::string* error);
  // Writes the text files and renames the partial folder to DIR. At least one frame needed.
  bool Finish(std::string* error);

  bool is_open() const { return !partial_dir_.empty(); }
  bool finished() const { return finished_; }
  size_t num_frames() const { return times_s_.size(); }
  const std::string& partial_dir() const { return partial_dir_; }  // empty when not open

 private:
  void RemovePartial();
  // The mav0/ text files: WriteEurocSensorFolders writes each sensor's folder (data.csv,
  // sensor.yaml) by the functions below it; a new sensor (imu0/) and body.yaml go there.
  bool WriteEurocSensorFolders(std::string* error) const;
  // cam0 in EuRoC's body frame: the robot's body, or the IMU's when the frames carry samples.
  Eigen::Isometry3d EurocBodyCam0() const;
  bool WriteEurocCamera(int cam, double rate_hz, std::string* error) const;
  bool WriteEurocGroundTruth(std::string* error) const;
  bool WriteTumText(std::string* error) const;
  // Frame i's ground truth as the KITTI/TUM/bag side holds it: the rectified left camera's pose
  // with a rectification (RectifyFrame's), the frame's own otherwise.
  Eigen::Isometry3d LeftCameraPose(size_t i) const;

  Options options_;
  vo::StereoCamera camera_;            // the frames' camera (raw with a rectification)
  vo::StereoCamera rectified_camera_;  // the KITTI/TUM/bag side's: camera_ or the rectified one
  bool rectify_ = false;               // options_.rectification is not the identity
  std::string dir_;
  OutputFolder folder_;      // the marked, locked work folder and its publishing
  std::string partial_dir_;  // folder_.path() while open
  bool finished_ = false;
  bool has_gt_ = false;
  bool has_depth_ = false;
  std::vector<double> times_s_;
  std::vector<int64_t> stamps_ns_;               // the EuRoC/TUM stamps: stamp_offset_ns + t_ns
  std::vector<Eigen::Isometry3d> T_world_cam0_;  // one per frame when has_gt_ (raw camera's)
  std::vector<sim::ImuSample> imu_;              // the frames' IMU samples (kEuroc)
  std::vector<int> compression_params_;
  std::unique_ptr<RosbagWriter> bag_;  // kRosbag: the bag in the partial folder
  bool bag_has_imu_ = false;           // kRosbag: a frame carried IMU samples (Finish writes
                                       // camchain-imucam.yaml, kalibr.h)
};

}  // namespace harness
