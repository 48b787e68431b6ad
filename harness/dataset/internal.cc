#include "harness/dataset/internal.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "harness/dataset/common.h"
#include "sim/scenario.h"

namespace harness::dataset_internal {
namespace fs = std::filesystem;

bool Fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

std::string Where(const std::string& path, int line) {
  return path + ":" + std::to_string(line) + ": ";
}

std::string Join(const std::string& a, const std::string& b) { return (fs::path(a) / b).string(); }

std::string FrameName(size_t index, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu%s", index, extension);
  return name;
}

std::string SizeText(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

std::string RigProblem(const vo::StereoCamera& c) {
  std::ostringstream e;
  if (!(c.baseline_m >= sim::kMinBaselineM && c.baseline_m <= sim::kMaxBaselineM)) {
    e << "baseline " << FormatDouble(c.baseline_m) << " m is outside the plausible range "
      << FormatDouble(sim::kMinBaselineM) << " .. " << FormatDouble(sim::kMaxBaselineM)
      << " m (1 mm to 5 m)";
    return e.str();
  }
  if (c.width <= 0 || c.height <= 0) return "";
  const double fov_deg[2] = {2.0 * std::atan(c.width / (2.0 * c.fx_px)) * 180.0 / M_PI,
                             2.0 * std::atan(c.height / (2.0 * c.fy_px)) * 180.0 / M_PI};
  for (int k = 0; k < 2; ++k) {
    if (!(fov_deg[k] > sim::kMinFovDeg && fov_deg[k] < sim::kMaxFovDeg)) {
      e << (k == 0 ? "fx " : "fy ") << FormatDouble(k == 0 ? c.fx_px : c.fy_px) << " px gives a "
        << (k == 0 ? "horizontal" : "vertical") << " field of view of " << fov_deg[k]
        << " deg over " << (k == 0 ? c.width : c.height) << " px; expected " << sim::kMinFovDeg
        << " .. " << sim::kMaxFovDeg << " deg";
      return e.str();
    }
  }
  return "";
}

bool IsRotation(const Eigen::Matrix3d& R, double tolerance) {
  if (!R.allFinite()) return false;
  const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  return err <= tolerance && R.determinant() > 0.0;
}

std::string NormalizeDir(const std::string& dir) {
  fs::path p = fs::path(dir).lexically_normal();
  std::string s = p.string();
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}

double NsToSeconds(int64_t t_ns) { return static_cast<double>(t_ns) / 1e9; }

bool CheckFrameIndex(const std::string& dir, size_t index, size_t size, std::string* error) {
  if (index < size) return true;
  return Fail(error, dir + ": frame " + std::to_string(index) + " out of range (" +
                         std::to_string(size) + " frames)");
}

bool ReadGreyImage(const std::string& path, const cv::Size& expected, const std::string& origin,
                   cv::Mat* image, std::string* error) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Fail(error, path + ": missing image file");
  *image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image->empty()) return Fail(error, path + ": cannot decode the image");
  if (image->size() != expected)
    return Fail(error, path + ": image size " + SizeText(*image) + " differs from " +
                           std::to_string(expected.width) + "x" + std::to_string(expected.height) +
                           " (" + origin + ")");
  return true;
}

bool TakeImageSizeFromFirstPair(const std::string& left_path, const std::string& right_path,
                                const std::string& calib_path, vo::StereoCamera* camera,
                                std::string* error) {
  const cv::Mat left = cv::imread(left_path, cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(right_path, cv::IMREAD_GRAYSCALE);
  if (left.empty()) return Fail(error, left_path + ": cannot decode the image");
  if (right.empty()) return Fail(error, right_path + ": cannot decode the image");
  if (left.size() != right.size())
    return Fail(error, right_path + ": size " + SizeText(right) +
                           " differs from the left image's " + SizeText(left) + " (" + left_path +
                           ")");
  camera->width = left.cols;
  camera->height = left.rows;
  std::string why;
  if (!camera->IsValid(&why)) return Fail(error, calib_path + ": " + why);
  if (const std::string problem = RigProblem(*camera); !problem.empty())
    return Fail(error, calib_path + ": " + problem);
  return true;
}

size_t CountAssociated(const std::vector<long>& index) {
  return static_cast<size_t>(
      std::count_if(index.begin(), index.end(), [](long i) { return i >= 0; }));
}

namespace {

// Error for a ground truth that no frame associates with (different clocks, wrong file).
std::string NoAssociationMessage(const std::string& gt_path, const std::vector<double>& frame_s,
                                 const std::vector<StampedPose>& gt, double max_difference_s) {
  std::string m = gt_path + ": no ground-truth pose within " + FormatDouble(max_difference_s) +
                  " s of any of the " + std::to_string(frame_s.size()) + " frames";
  if (!gt.empty() && !frame_s.empty()) {
    const auto [lo, hi] = std::minmax_element(frame_s.begin(), frame_s.end());
    m += " (frames " + FormatDouble(*lo) + " .. " + FormatDouble(*hi) + " s, ground truth " +
         FormatDouble(gt.front().time_s) + " .. " + FormatDouble(gt.back().time_s) +
         " s): a different clock or the wrong file?";
  } else if (gt.empty()) {
    m += " (the file has no poses)";
  }
  return m;
}

}  // namespace

bool AssociateWithFrames(const std::string& gt_path, const std::vector<double>& frame_s,
                         const std::vector<StampedPose>& gt, double max_difference_s,
                         std::vector<long>* index, std::string* error) {
  *index = AssociateGroundTruth(frame_s, gt, max_difference_s);
  if (CountAssociated(*index) == 0)
    return Fail(error, NoAssociationMessage(gt_path, frame_s, gt, max_difference_s));
  return true;
}

}  // namespace harness::dataset_internal
