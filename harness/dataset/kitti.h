// The KITTI odometry layout: its calib.txt and a reader. DatasetWriter (writer.h) writes it for
// every sequence (DIR = the dataset folder):
//   image_0/%06d.png        left (cam0) images, 8-bit grayscale PNG
//   image_1/%06d.png        right (cam1) images
//   calib.txt               "P0: <12 numbers>" and "P1: <12 numbers>", row-major 3x4 projection
//                           matrices of the rectified pair; P1 has -fx * baseline_m in column 4;
//                           the writer adds P2 (= P0), P3 (= P1) and Tr (identity 3x4), the
//                           keys KITTI's odometry calib.txt has (pykitti needs them; the reader
//                           reads P0/P1 only)
//   times.txt               one time stamp per frame (seconds)
//   poses.txt               [ground truth only] T_cam0first_cam0k, 12 numbers per frame
//                           (the left camera's pose in the FIRST left camera's frame, KITTI style)
//   groundtruth_tum.txt     [ground truth only] the same poses with their times, TUM format
//   T_world_cam0first.txt   [ground truth only] 12 numbers: the first left camera's pose in the
//                           world, so T_world_cam0k = T_world_cam0first * T_cam0first_cam0k
//   depth/%06d.png          [depth only] z-depth of the left view, 16-bit PNG, millimetres;
//                           0 = no depth (also for depths <= 0, not finite, or > 65.535 m)
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "harness/dataset/common.h"
#include "harness/trajectory_io.h"
#include "vo/camera.h"

namespace harness {

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
  int bits_ = 8;  // the images' bit depth (dataset_internal::FirstPairBits)
  std::vector<double> times_s_;
  std::vector<Eigen::Isometry3d> T_cam0first_cam0_;
  Eigen::Isometry3d T_world_cam0first_ = Eigen::Isometry3d::Identity();
  bool has_depth_ = false;
};

// Parses a KITTI calib.txt: P0 and P1 (other keys ignored) into a camera without image size
// (width/height left at 0). Fails on a missing key, a malformed line, non-finite numbers,
// P0/P1 with different intrinsics, or a baseline <= 0.
bool ReadKittiCalib(const std::string& path, vo::StereoCamera* camera, std::string* error);

}  // namespace harness
