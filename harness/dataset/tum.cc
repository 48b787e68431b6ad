#include "harness/dataset/tum.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "harness/dataset/internal.h"
#include "harness/dataset/kitti.h"

namespace harness {
namespace fs = std::filesystem;
namespace {

using dataset_internal::AssociateWithFrames;
using dataset_internal::CheckFrameIndex;
using dataset_internal::CountAssociated;
using dataset_internal::Fail;
using dataset_internal::Join;
using dataset_internal::NormalizeDir;
using dataset_internal::ReadGreyImage;
using dataset_internal::TakeImageSizeFromFirstPair;
using dataset_internal::Where;

// Reads a TUM rgb.txt-style list: "timestamp filename" lines, '#' comments.
bool ReadTumImageList(const std::string& path, const std::string& dir, std::vector<double>* times_s,
                      std::vector<std::string>* files, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) {
    if (error) *error += " (expected the image list: 'timestamp filename' per line)";
    return false;
  }
  IncreasingStamps<double> order(path);
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsBlankOrComment(lines[i])) continue;
    const int line_no = static_cast<int>(i) + 1;
    std::istringstream in(lines[i]);
    std::string stamp, file, extra;
    double t = 0.0;
    if (!(in >> stamp >> file) || (in >> extra) || !ParseDouble(stamp, &t) || !std::isfinite(t))
      return Fail(error, Where(path, line_no) +
                             "expected 'timestamp filename' (seconds, a path relative to " + dir +
                             ")");
    if (!order.Next(t, stamp, line_no, error)) return false;
    times_s->push_back(t);
    files->push_back(Join(dir, file));
  }
  if (times_s->empty()) return Fail(error, path + ": no images listed");
  return true;
}

}  // namespace

bool TumReader::Open(const std::string& dir, const Options& options, std::string* error) {
  *this = TumReader();
  options_ = options;
  dir_ = NormalizeDir(dir);
  if (!(options_.gt_max_difference_s > 0.0) || !std::isfinite(options_.gt_max_difference_s) ||
      !(options_.stereo_max_difference_s > 0.0) || !std::isfinite(options_.stereo_max_difference_s))
    return Fail(error,
                "TumReader options: gt_max_difference_s and stereo_max_difference_s must "
                "be finite and > 0");
  std::error_code ec;
  if (!fs::is_directory(dir_, ec)) return Fail(error, dir_ + ": dataset folder not found");
  if (!ReadKittiCalib(Join(dir_, "calib.txt"), &camera_, error)) return false;
  std::vector<double> t[2];
  std::vector<std::string> files[2];
  const std::string lists[2] = {Join(dir_, "left.txt"), Join(dir_, "right.txt")};
  for (int cam = 0; cam < 2; ++cam)
    if (!ReadTumImageList(lists[cam], dir_, &t[cam], &files[cam], error)) return false;

  // Stereo frames: left and right associated by stamp; a frame's time is its left stamp.
  AssociateOptions stereo;
  stereo.max_difference_s = options_.stereo_max_difference_s;
  const double t0 = std::min(*std::min_element(t[0].begin(), t[0].end()),
                             *std::min_element(t[1].begin(), t[1].end()));
  std::vector<double> rel[2];
  for (int cam = 0; cam < 2; ++cam)
    for (double x : t[cam]) rel[cam].push_back(x - t0);
  for (const AssociatedPair& p : AssociateStamps(rel[0], rel[1], stereo)) {
    times_s_.push_back(t[0][p.first]);
    files_[0].push_back(files[0][p.first]);
    files_[1].push_back(files[1][p.second]);
  }
  unpaired_ = t[0].size() + t[1].size() - 2 * times_s_.size();
  if (times_s_.empty())
    return Fail(error, lists[0] + ": no left stamp within " +
                           FormatDouble(options_.stereo_max_difference_s) + " s of a stamp in " +
                           lists[1]);
  for (size_t i = 0; i < times_s_.size(); ++i)
    for (int cam = 0; cam < 2; ++cam)
      if (!fs::is_regular_file(files_[cam][i], ec))
        return Fail(error, files_[cam][i] + ": missing image file (listed in " + lists[cam] + ")");
  if (!TakeImageSizeFromFirstPair(files_[0][0], files_[1][0], Join(dir_, "calib.txt"), &camera_,
                                  &bits_, error))
    return false;

  // Ground truth (optional).
  gt_index_.assign(times_s_.size(), -1);
  gt_path_ = options_.gt_path;
  if (gt_path_.empty() && fs::exists(Join(dir_, "groundtruth.txt"), ec))
    gt_path_ = Join(dir_, "groundtruth.txt");
  if (gt_path_.empty()) return true;
  if (!ReadTum(gt_path_, &gt_, error)) return false;
  return AssociateWithFrames(gt_path_, times_s_, gt_, options_.gt_max_difference_s, &gt_index_,
                             error);
}

size_t TumReader::ground_truth_frames() const { return CountAssociated(gt_index_); }

bool TumReader::ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const {
  if (!CheckFrameIndex(dir_, index, size(), error)) return false;
  const cv::Size size(camera_.width, camera_.height);
  cv::Mat images[2];
  for (int cam = 0; cam < 2; ++cam) {
    if (!ReadGreyImage(files_[cam][index], size, "the size of the first pair", bits_, &images[cam],
                       error))
      return false;
  }
  frame->time_s = times_s_[index];
  frame->left = images[0];
  frame->right = images[1];
  frame->depth_m = cv::Mat();
  const long gt = gt_index_[index];
  frame->has_gt = gt >= 0;
  frame->T_world_cam0 = frame->has_gt ? gt_[gt].T_world_cam : Eigen::Isometry3d::Identity();
  return true;
}

}  // namespace harness
