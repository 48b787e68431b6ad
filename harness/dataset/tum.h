// The TUM-style stereo layout and its reader. DatasetWriter (writer.h) writes it in addition to
// the KITTI layout when Options::format is kTum. The TUM RGB-D benchmark has no stereo layout;
// this one follows its conventions (rgb.txt, groundtruth.txt):
//   left.txt, right.txt     image lists in the form of TUM's rgb.txt: '#' comment lines, then
//                           "timestamp filename" per line (seconds; file name relative to DIR,
//                           e.g. "left/1305031102.175304000.png"). Left and right are paired by
//                           time stamp as associate.py pairs streams (TumReader::Options)
//   left/<t>.png, right/<t>.png   the images (<t> = the stamp with 9 decimals; the writer's
//                           stamps have one width, so names sort in time order)
//   calib.txt               the KITTI calib.txt (kitti.h: P0/P1 of the rectified pair)
//   groundtruth.txt         [ground truth only] TUM trajectory "t tx ty tz qx qy qz qw" of the
//                           LEFT camera in the world (T_world_cam0); any rate: readers associate
//                           it with the left stamps. The writer puts one pose at each frame stamp
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "harness/dataset/common.h"
#include "harness/trajectory_io.h"
#include "vo/camera.h"

namespace harness {

// --- TUM-style stereo reader (the layout: the top of this file). Images load lazily, as
// grayscale.
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
  int bits_ = 8;  // the images' bit depth (dataset_internal::FirstPairBits)
  std::vector<double> times_s_;
  std::vector<std::string> files_[2];  // image paths (left, right), aligned with times_s_
  std::vector<StampedPose> gt_;
  std::string gt_path_;
  std::vector<long> gt_index_;  // per frame: index into gt_, -1 = none
  size_t unpaired_ = 0;
};

}  // namespace harness
