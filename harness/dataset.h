// Stereo datasets on disk: a writer for the KITTI odometry layout (optionally also EuRoC/ASL or
// a TUM-style stereo layout), and readers for the three layouts, so simulated and real sequences
// run through the same VO.
//
// KITTI layout written by DatasetWriter (DIR = the output folder):
//   image_0/%06d.png        left (cam0) images, 8-bit grayscale PNG
//   image_1/%06d.png        right (cam1) images
//   calib.txt               "P0: <12 numbers>" and "P1: <12 numbers>", row-major 3x4 projection
//                           matrices of the rectified pair; P1 has -fx * baseline_m in column 4
//   times.txt               one time stamp per frame (seconds)
//   poses.txt               [ground truth only] T_cam0first_cam0k, 12 numbers per frame
//                           (the left camera's pose in the FIRST left camera's frame, KITTI style)
//   groundtruth_tum.txt     [ground truth only] the same poses with their times, TUM format
//   T_world_cam0first.txt   [ground truth only] 12 numbers: the first left camera's pose in the
//                           world, so T_world_cam0k = T_world_cam0first * T_cam0first_cam0k
//   depth/%06d.png          [depth only] z-depth of the left view, 16-bit PNG, millimetres;
//                           0 = no depth (also for depths <= 0, not finite, or > 65.535 m)
// EuRoC/ASL layout, written in addition when Options::format is kEuroc:
//   mav0/cam0/data/<t_ns>.png, mav0/cam0/data.csv ("#timestamp [ns],filename"),
//   mav0/cam0/sensor.yaml (T_BS, intrinsics [fu, fv, cu, cv], zero radial-tangential distortion,
//   resolution, rate_hz, camera_model pinhole); the same for cam1 (T_BS = T_body_cam0 *
//   T_cam0_cam1); mav0/state_groundtruth_estimate0/data.csv [ground truth only]: the body pose
//   T_world_body in the world, finite-differenced velocity, zero biases.
// TUM-style stereo layout, written in addition when Options::format is kTum. The TUM RGB-D
// benchmark has no stereo layout; this one follows its conventions (rgb.txt, groundtruth.txt):
//   left.txt, right.txt     image lists in the form of TUM's rgb.txt: '#' comment lines, then
//                           "timestamp filename" per line (seconds; file name relative to DIR,
//                           e.g. "left/1305031102.175304000.png"). Left and right are paired by
//                           time stamp as associate.py pairs streams (TumReader::Options)
//   left/<t>.png, right/<t>.png   the images (<t> = the stamp with 9 decimals)
//   calib.txt               the KITTI calib.txt above (P0/P1 of the rectified pair)
//   groundtruth.txt         [ground truth only] TUM trajectory "t tx ty tz qx qy qz qw" of the
//                           LEFT camera in the world (T_world_cam0); any rate: readers associate
//                           it with the left stamps. The writer puts one pose at each frame stamp
// Time stamps in nanoseconds are int64: t_ns = llround(time_s * 1e9).
//
// Errors: functions return false and fill *error with the file (and line) and what was expected.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "harness/output_folder.h"
#include "harness/trajectory_io.h"
#include "vo/camera.h"

namespace harness {

// One stereo frame in memory.
struct DatasetFrame {
  double time_s = 0.0;  // time stamp (seconds)
  cv::Mat left;         // cam0 image, CV_8UC1
  cv::Mat right;        // cam1 image, CV_8UC1, same size as left
  cv::Mat depth_m;      // CV_32FC1 z-depth of the left view (metres), 0 = none; may be empty
  bool has_gt = false;  // true when T_world_cam0 holds the ground-truth pose
  Eigen::Isometry3d T_world_cam0 = Eigen::Isometry3d::Identity();  // left camera in the world
};

enum class DatasetFormat {
  kKitti,  // KITTI odometry layout only
  kEuroc,  // KITTI layout plus the EuRoC/ASL layout under mav0/
  kTum,    // KITTI layout plus the TUM-style stereo layout (left.txt, right.txt, left/, right/)
};
// "kitti" / "euroc" / "tum"; false for other names.
bool ParseDatasetFormat(const std::string& name, DatasetFormat* format);
const char* DatasetFormatName(DatasetFormat format);

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
                                                   // the TUM-style one
    bool overwrite = false;   // replace an existing DIR (on Finish) when it is a vobench
                              // dataset (.vobench.json kind "dataset"); otherwise refuse
    bool write_depth = true;  // write depth/%06d.png for frames that carry depth
    int png_compression = 3;  // zlib level of every PNG, 0 (none) .. 9 (smallest, slowest)
    // EuRoC body frame: the left camera's pose in the body (rotation, metres).
    Eigen::Isometry3d T_body_cam0 = Eigen::Isometry3d::Identity();
    double rate_hz = 0.0;  // rate written to sensor.yaml (Hz, >= 0); 0 = from the median
                           // frame interval, rounded to 1 mHz

    bool IsValid(std::string* error) const;
  };

  DatasetWriter() = default;
  explicit DatasetWriter(Options options) : options_(std::move(options)) {}
  ~DatasetWriter();  // removes the partial folder unless Finish() succeeded
  DatasetWriter(const DatasetWriter&) = delete;
  DatasetWriter& operator=(const DatasetWriter&) = delete;

  // Checks options and camera, refuses an existing DIR unless options.overwrite (and then any
  // DIR vobench did not write as a dataset), creates the partial folder (and DIR's parent
  // folders) under the lock DIR.lock.
  bool Open(const std::string& dir, const vo::StereoCamera& camera, std::string* error);
  // Writes the frame's images at once. Frames must come in strictly increasing time (distinct
  // t_ns); images must be CV_8UC1 of the camera's size, depth empty or CV_32FC1 of that size.
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
  bool WriteEurocText(std::string* error) const;
  bool WriteTumText(std::string* error) const;

  Options options_;
  vo::StereoCamera camera_;
  std::string dir_;
  OutputFolder folder_;      // the marked, locked work folder and its publishing
  std::string partial_dir_;  // folder_.path() while open
  bool finished_ = false;
  bool has_gt_ = false;
  bool has_depth_ = false;
  std::vector<double> times_s_;
  std::vector<int64_t> times_ns_;
  std::vector<Eigen::Isometry3d> T_world_cam0_;  // one per frame when has_gt_
  std::vector<int> compression_params_;
};

// Time stamp in nanoseconds as written to EuRoC files.
int64_t TimeToNs(double time_s);

// --- KITTI odometry reader. Images load lazily, one frame at a time, as grayscale.
class KittiReader {
 public:
  struct Options {
    std::string poses_path;  // ground-truth file (KITTI poses); empty = DIR/poses.txt if it exists
                             // (the KITTI benchmark keeps it apart: poses/NN.txt)
    bool require_poses = false;  // fail Open() when there is no ground truth
    bool load_depth = true;      // read depth/%06d.png when the folder exists
  };

  // Reads calib.txt (P0/P1 -> camera; baseline_m = (P0[3] - P1[3]) / fx, i.e. -P1[3]/fx for
  // KITTI), times.txt, the ground truth and T_world_cam0first.txt when present; checks that
  // every image file exists and reads frame 0 for the image size.
  bool Open(const std::string& dir, std::string* error) { return Open(dir, Options(), error); }
  bool Open(const std::string& dir, const Options& options, std::string* error);

  const vo::StereoCamera& camera() const { return camera_; }
  size_t size() const { return times_s_.size(); }
  const std::vector<double>& times_s() const { return times_s_; }
  bool has_ground_truth() const { return !T_cam0first_cam0_.empty(); }
  // Ground truth in the first camera's frame (poses.txt), one per frame; empty when none.
  const std::vector<Eigen::Isometry3d>& poses() const { return T_cam0first_cam0_; }
  // From T_world_cam0first.txt; identity when absent (the world is the first camera).
  const Eigen::Isometry3d& T_world_cam0first() const { return T_world_cam0first_; }
  // Ground truth as a TUM-style trajectory in the world (empty when none).
  std::vector<StampedPose> GroundTruth() const;

  // Loads frame `index`: images (checked against the camera size), depth when present, and
  // T_world_cam0 = T_world_cam0first * T_cam0first_cam0k when there is ground truth.
  bool ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const;

 private:
  std::string ImagePath(int cam, size_t index) const;

  Options options_;
  std::string dir_;
  vo::StereoCamera camera_;
  std::vector<double> times_s_;
  std::vector<Eigen::Isometry3d> T_cam0first_cam0_;
  Eigen::Isometry3d T_world_cam0first_ = Eigen::Isometry3d::Identity();
  bool has_depth_ = false;
};

// Parses a KITTI calib.txt: P0 and P1 (other keys ignored) into a camera without image size
// (width/height left at 0). Fails on a missing key, a malformed line, non-finite numbers,
// P0/P1 with different intrinsics, or a baseline <= 0.
bool ReadKittiCalib(const std::string& path, vo::StereoCamera* camera, std::string* error);

// --- Ground-truth association shared by the readers.

// For each frame stamp, the index into `ground_truth` of the pose associated with it as the TUM
// tools' associate.py does (AssociateStamps: |t_frame - t_gt| < max_difference_s, greedy by
// smallest difference, each pose used at most once), or -1 when none is close enough.
// Stamps are taken relative to frame_times_s.front() before comparing, so large absolute stamps
// (EuRoC: ~1.4e9 s) keep microsecond resolution. max_difference_s must be > 0.
std::vector<long> AssociateGroundTruth(const std::vector<double>& frame_times_s,
                                       const std::vector<StampedPose>& ground_truth,
                                       double max_difference_s);

// --- EuRoC/ASL.

// Calibration of one camera as sensor.yaml gives it (raw, possibly distorted).
struct EurocCameraCalibration {
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();  // T_BS: camera in the body
  double fu_px = 0.0;                                            // focal length x (pixels)
  double fv_px = 0.0;                                            // focal length y (pixels)
  double cu_px = 0.0;                                            // principal point x (pixels)
  double cv_px = 0.0;                                            // principal point y (pixels)
  std::string camera_model;                                      // "pinhole"
  std::string distortion_model;  // "radial-tangential" (k1 k2 p1 p2) or "equidistant"
                                 // (k1 k2 k3 k4, Kannala-Brandt as OpenCV's fisheye model)
  std::vector<double> distortion_coefficients;  // as listed in the file
  int width = 0;                                // resolution (pixels)
  int height = 0;
  double rate_hz = 0.0;  // nominal frame rate (Hz)
  std::string path;      // the file it was read from ("" when made in code); named in errors
};
// Reads an EuRoC sensor.yaml. Keys read: T_BS (rows, cols, data: 16 numbers), intrinsics
// [fu, fv, cu, cv], resolution [width, height], camera_model, distortion_model,
// distortion_coefficients, and rate_hz when present. Other keys are ignored, so the variants in
// circulation read too (Kimera-VIO's sensorLeft.yaml has camera_id instead of sensor_type and
// comment). A leading OpenCV "%YAML:1.0" line is accepted.
bool ReadEurocSensorYaml(const std::string& path, EurocCameraCalibration* calibration,
                         std::string* error);

// Maps a raw stereo pair onto the ideal rectified camera the VO expects (vo::StereoCamera:
// equal intrinsics, cam1 at +baseline_m along cam0's x, no distortion).
// Rectified frames: rect0 and rect1 are the raw camera frames turned by R_cam0_rect0 and
// R_cam1_rect1 (same origins), so that T_rect0_rect1 = [I | (baseline_m, 0, 0)]. A point seen by
// the VO in rect0 is p_cam0 = R_cam0_rect0 * p_rect0; the rectified left camera's pose in the
// world is T_world_rect0 = T_world_cam0 * [R_cam0_rect0 | 0].
struct StereoRectification {
  vo::StereoCamera camera;  // the rectified camera (output image size and intrinsics)
  Eigen::Matrix3d R_cam0_rect0 = Eigen::Matrix3d::Identity();  // rectified left frame in raw cam0
  Eigen::Matrix3d R_cam1_rect1 = Eigen::Matrix3d::Identity();  // rectified right frame in raw cam1
  cv::Mat map0_x, map0_y;  // CV_32FC1 (height x width): raw cam0 pixel of each rectified pixel;
                           // empty = identity (no remap needed)
  cv::Mat map1_x, map1_y;  // the same for cam1
  bool IsIdentity() const { return map0_x.empty() && map1_x.empty(); }
};

struct RectificationOptions {
  // Free scaling of the rectified view, in [0, 1] (cv::stereoRectify's alpha; the balance of
  // cv::fisheye::stereoRectify for equidistant cameras). 0 = zoomed so that every rectified
  // pixel has a raw source pixel (no black border, the VO sees no invalid area; OpenCV's zoom
  // is refined until that holds exactly); 1 = every raw pixel kept (black borders).
  double alpha = 0.0;
  // Pairs within these tolerances of an ideal rectified pair (pinhole, zero distortion, equal
  // intrinsics, same orientation, cam1 on +x of cam0) get the identity rectification: images
  // are used as they are, bit for bit (e.g. the simulator's exports).
  double identity_intrinsics_tolerance_px = 1e-6;  // |fu0 - fu1| etc. (pixels)
  double identity_rotation_tolerance = 1e-6;       // max |R_cam0_cam1 - I| entry
  double identity_offset_tolerance_m = 1e-6;       // |y|, |z| of cam1 in cam0 (metres)
  double identity_distortion_tolerance = 1e-12;    // max |distortion coefficient|

  bool IsValid(std::string* error) const;
};

// Rectification of a raw pair from its two calibrations (cam0 = left, cam1 = right):
//   T_cam1_cam0 = T_BS1^-1 * T_BS0 (both from sensor.yaml);
//   radial-tangential (k1 k2 p1 p2 -> OpenCV distCoeffs (k1, k2, p1, p2)):
//     cv::stereoRectify(CALIB_ZERO_DISPARITY, options.alpha) + cv::initUndistortRectifyMap;
//   equidistant (k1..k4): cv::fisheye::stereoRectify + cv::fisheye::initUndistortRectifyMap;
//   the rectified camera: fx = fy, cx, cy from P1; baseline_m = -P2[0][3] / P2[0][0]; the same
//   image size as the raw one; R_cam0_rect0 = R1^T, R_cam1_rect1 = R2^T. With alpha 0 the focal
//   length is raised in steps of 0.1 % until every map entry lies inside the raw images.
// Already-rectified pairs get the identity rectification (see RectificationOptions).
// Fails, naming the calibration files, on an unknown camera or distortion model, a wrong number
// of distortion coefficients, different resolutions, cam1 not to the right of cam0 (the VO needs
// the baseline along +x), or a degenerate result.
bool ComputeStereoRectification(const EurocCameraCalibration& cam0,
                                const EurocCameraCalibration& cam1,
                                const RectificationOptions& options,
                                StereoRectification* rectification, std::string* error);

// Remaps frame->left / frame->right onto the rectified pair (bilinear interpolation, black
// outside the raw image) and turns the ground truth into the rectified left camera's pose
// (T_world_rect0 = T_world_cam0 * R_cam0_rect0). Depth is dropped (it belongs to the raw view).
// Identity rectification: the frame is left as it is. The images must have the raw size the
// maps were made for (the readers check that); aborts otherwise (a programmer error).
void RectifyFrame(const StereoRectification& rectification, DatasetFrame* frame);

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
  std::vector<int64_t> t_ns_;
  std::vector<std::string> files_[2];  // image paths per camera, aligned with t_ns_
  std::vector<StampedPose> gt_body_;
  std::string gt_path_;
  std::vector<long> gt_index_;  // per frame: index into gt_body_, -1 = none
  size_t unpaired_ = 0;
};

// --- TUM-style stereo layout (see the top of this file). Images load lazily, as grayscale.
class TumReader {
 public:
  struct Options {
    // Ground truth: TUM trajectory of the left camera (T_world_cam0), any rate. Empty =
    // DIR/groundtruth.txt when it exists.
    std::string gt_path;
    double gt_max_difference_s = 0.02;      // ground-truth stamp within this of the left stamp
                                            // (seconds, > 0); associate.py's default
    double stereo_max_difference_s = 0.02;  // right stamp within this of the left stamp
                                            // (seconds, > 0); associate.py's default
  };

  // Reads calib.txt (ReadKittiCalib), left.txt, right.txt and the ground truth; pairs left and
  // right images by stamp (the others are counted in unpaired_frames()); checks that every
  // image file exists and reads the first pair for the image size (left and right must agree).
  // A ground truth that no frame associates with is an error.
  bool Open(const std::string& dir, std::string* error) { return Open(dir, Options(), error); }
  bool Open(const std::string& dir, const Options& options, std::string* error);

  const vo::StereoCamera& camera() const { return camera_; }
  size_t size() const { return times_s_.size(); }
  const std::vector<double>& times_s() const { return times_s_; }  // the left stamps
  size_t unpaired_frames() const { return unpaired_; }
  const std::vector<StampedPose>& ground_truth() const { return gt_; }  // as in the file
  const std::string& ground_truth_path() const { return gt_path_; }     // "" when none
  size_t ground_truth_frames() const;  // frames with an associated ground-truth pose

  // Loads frame `index` (images checked against the size of the first pair); has_gt and
  // T_world_cam0 when a ground-truth pose is associated with the frame's left stamp.
  bool ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const;

 private:
  Options options_;
  std::string dir_;
  vo::StereoCamera camera_;
  std::vector<double> times_s_;
  std::vector<std::string> files_[2];  // image paths (left, right), aligned with times_s_
  std::vector<StampedPose> gt_;
  std::string gt_path_;
  std::vector<long> gt_index_;  // per frame: index into gt_, -1 = none
  size_t unpaired_ = 0;
};

}  // namespace harness
