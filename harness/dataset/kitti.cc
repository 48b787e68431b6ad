#include "harness/dataset/kitti.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <utility>

#include "harness/dataset/internal.h"

namespace harness {
namespace fs = std::filesystem;
namespace {

using dataset_internal::CheckFrameIndex;
using dataset_internal::Fail;
using dataset_internal::FrameName;
using dataset_internal::Join;
using dataset_internal::NormalizeDir;
using dataset_internal::ReadGreyImage;
using dataset_internal::RigProblem;
using dataset_internal::SizeText;
using dataset_internal::TakeImageSizeFromFirstPair;
using dataset_internal::Where;

}  // namespace

bool ReadKittiCalib(const std::string& path, vo::StereoCamera* camera, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) {
    if (error) *error += " (expected the KITTI calibration with P0: and P1: lines)";
    return false;
  }
  std::vector<double> P[2];
  int P_line[2] = {0, 0};
  std::string what;
  std::set<std::string> seen;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const int line_no = static_cast<int>(i) + 1;
    if (IsBlankOrComment(line)) continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos)
      return Fail(error, Where(path, line_no) + "not a 'KEY: numbers' line (expected P0:, P1:, " +
                             "P2:, P3:, Tr: ...)");
    const std::string key = line.substr(0, colon);
    if (!seen.insert(key).second)
      return Fail(error, Where(path, line_no) + "key '" + key +
                             "': given twice (a second line would silently replace the first)");
    const int k = key == "P0" ? 0 : key == "P1" ? 1 : -1;
    if (k < 0) continue;  // P2, P3, Tr, ...: not used
    if (!ParseNumbers(std::string_view(line).substr(colon + 1), 12, &P[k], &what))
      return Fail(error, Where(path, line_no) + key + ": " + what +
                             " (expected 12 finite numbers, row-major 3x4 projection matrix)");
    P_line[k] = line_no;
  }
  for (int k = 0; k < 2; ++k)
    if (P[k].empty())
      return Fail(error, path + ": no P" + std::to_string(k) + ": line (expected 'P" +
                             std::to_string(k) + ": ' and 12 numbers)");
  // A rectified camera's projection matrix: K [I | t] with K = [fx 0 cx; 0 fy cy; 0 0 1] and t
  // along x only, so entries (1,2), (2,1), (2,4), (3,1), (3,2), (3,4) are 0 and (3,3) is 1.
  for (int k = 0; k < 2; ++k) {
    const std::string key = "P" + std::to_string(k);
    const double tolerance = 1e-9 * std::max(1.0, std::abs(P[k][0]));
    if (std::abs(P[k][1]) > tolerance)
      return Fail(error, Where(path, P_line[k]) + "key '" + key + "': skew " +
                             FormatDouble(P[k][1]) +
                             " (entry 2) must be 0: a rectified camera has none");
    for (const auto& [idx, want] : {std::pair{4, 0.0}, std::pair{7, 0.0}, std::pair{8, 0.0},
                                    std::pair{9, 0.0}, std::pair{10, 1.0}, std::pair{11, 0.0}})
      if (std::abs(P[k][idx] - want) > tolerance)
        return Fail(error, Where(path, P_line[k]) + "key '" + key + "': entry " +
                               std::to_string(idx + 1) + " is " + FormatDouble(P[k][idx]) +
                               ", expected " + FormatDouble(want) +
                               " (a rectified pair's P is [fx 0 cx tx; 0 fy cy 0; 0 0 1 0])");
  }
  // Rectified pair: same intrinsics, only the x offset differs.
  for (int idx : {0, 1, 2, 5, 6, 10}) {
    if (std::abs(P[0][idx] - P[1][idx]) > 1e-9 * std::max(1.0, std::abs(P[0][idx])))
      return Fail(error, path + ": P0 and P1 differ in entry " + std::to_string(idx + 1) +
                             " (expected a rectified pair with equal intrinsics)");
  }
  camera->width = 0;
  camera->height = 0;
  camera->fx_px = P[0][0];
  camera->fy_px = P[0][5];
  camera->cx_px = P[0][2];
  camera->cy_px = P[0][6];
  if (!(camera->fx_px > 0.0) || !(camera->fy_px > 0.0))
    return Fail(error, Where(path, P_line[0]) + "key 'P0': focal lengths must be > 0");
  camera->baseline_m = (P[0][3] - P[1][3]) / camera->fx_px;
  if (!(camera->baseline_m > 0.0))
    return Fail(error, path +
                           ": baseline (P0[3] - P1[3]) / fx = " + FormatDouble(camera->baseline_m) +
                           " m, expected > 0 (P1 column 4 holds -fx * baseline)");
  if (const std::string problem = RigProblem(*camera); !problem.empty())
    return Fail(error, path + ": " + problem + " (baseline = (P0[3] - P1[3]) / fx)");
  return true;
}

std::string KittiReader::ImagePath(int cam, size_t index) const {
  return Join(dir_, "image_" + std::to_string(cam) + "/" + FrameName(index, ".png"));
}

bool KittiReader::Open(const std::string& dir, const Options& options, std::string* error) {
  *this = KittiReader();
  options_ = options;
  dir_ = NormalizeDir(dir);
  std::error_code ec;
  if (!fs::is_directory(dir_, ec)) return Fail(error, dir_ + ": dataset folder not found");
  if (!ReadKittiCalib(Join(dir_, "calib.txt"), &camera_, error)) return false;
  const std::string times_path = Join(dir_, "times.txt");
  if (!ReadKittiTimes(times_path, &times_s_, error)) return false;
  if (times_s_.empty()) return Fail(error, times_path + ": no frames (expected one time per line)");
  // As many images as times: a times.txt cut short would silently drop the rest of the sequence.
  for (int cam = 0; cam < 2; ++cam) {
    const std::string folder = Join(dir_, "image_" + std::to_string(cam));
    size_t images = 0;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
      if (it->path().extension() == ".png") ++images;
    if (images > times_s_.size())
      return Fail(error, times_path + ": lists " + std::to_string(times_s_.size()) +
                             " frames but " + folder + "/ holds " + std::to_string(images) +
                             " images (expected one time per image): times.txt is incomplete");
  }

  // Ground truth.
  std::string poses_path = options_.poses_path;
  if (poses_path.empty() && fs::exists(Join(dir_, "poses.txt"), ec))
    poses_path = Join(dir_, "poses.txt");
  if (!poses_path.empty()) {
    if (!ReadKittiPoses(poses_path, &T_cam0first_cam0_, error)) return false;
    if (T_cam0first_cam0_.size() < times_s_.size())
      return Fail(error, poses_path + ": has " + std::to_string(T_cam0first_cam0_.size()) +
                             " poses but " + times_path + " lists " +
                             std::to_string(times_s_.size()) +
                             " frames (expected one pose per frame): fewer poses than frames");
    if (T_cam0first_cam0_.size() > times_s_.size())
      return Fail(error, poses_path + ": has " + std::to_string(T_cam0first_cam0_.size()) +
                             " poses but " + times_path + " lists only " +
                             std::to_string(times_s_.size()) +
                             " frames (expected one pose per frame): more poses than frames");
  } else if (options_.require_poses) {
    return Fail(error, Join(dir_, "poses.txt") + ": ground truth required but not found");
  }
  const std::string world_path = Join(dir_, "T_world_cam0first.txt");
  if (fs::exists(world_path, ec)) {
    std::vector<Eigen::Isometry3d> T;
    if (!ReadKittiPoses(world_path, &T, error)) return false;
    if (T.size() != 1)
      return Fail(error, world_path + ": expected exactly one pose (12 numbers), got " +
                             std::to_string(T.size()));
    T_world_cam0first_ = T[0];
  }

  // Every image must be there; frame 0 gives the image size.
  for (size_t i = 0; i < times_s_.size(); ++i)
    for (int cam = 0; cam < 2; ++cam)
      if (!fs::is_regular_file(ImagePath(cam, i), ec))
        return Fail(error, ImagePath(cam, i) + ": missing image file (frame " + std::to_string(i) +
                               " of " + std::to_string(times_s_.size()) + " in times.txt)");
  if (!TakeImageSizeFromFirstPair(ImagePath(0, 0), ImagePath(1, 0), Join(dir_, "calib.txt"),
                                  &camera_, &bits_, error))
    return false;
  has_depth_ = options_.load_depth && fs::is_directory(Join(dir_, "depth"), ec);
  return true;
}

std::vector<StampedPose> KittiReader::GroundTruth() const {
  std::vector<StampedPose> gt;
  for (size_t i = 0; i < T_cam0first_cam0_.size(); ++i)
    gt.push_back({times_s_[i], T_world_cam0first_ * T_cam0first_cam0_[i]});
  return gt;
}

bool KittiReader::ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const {
  if (!CheckFrameIndex(dir_, index, size(), error)) return false;
  const cv::Size size(camera_.width, camera_.height);
  cv::Mat images[2];
  for (int cam = 0; cam < 2; ++cam) {
    if (!ReadGreyImage(ImagePath(cam, index), size, "the size of frame 0", bits_, &images[cam],
                       error))
      return false;
  }
  std::error_code ec;
  cv::Mat depth_m;
  if (has_depth_) {
    const std::string path = Join(dir_, "depth/" + FrameName(index, ".png"));
    if (!fs::is_regular_file(path, ec)) return Fail(error, path + ": missing depth image");
    const cv::Mat mm = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (mm.empty() || mm.type() != CV_16UC1)
      return Fail(error, path + ": expected a 16-bit single-channel PNG (depth in millimetres)");
    if (mm.size() != size)
      return Fail(error, path + ": depth size " + SizeText(mm) + " differs from the image size");
    mm.convertTo(depth_m, CV_32FC1, 1e-3);
  }
  frame->time_s = times_s_[index];
  frame->left = images[0];
  frame->right = images[1];
  frame->depth_m = depth_m;
  frame->has_gt = has_ground_truth();
  frame->T_world_cam0 =
      frame->has_gt ? T_world_cam0first_ * T_cam0first_cam0_[index] : Eigen::Isometry3d::Identity();
  return true;
}

}  // namespace harness
