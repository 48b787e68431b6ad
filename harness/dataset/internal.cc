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

std::string IntrinsicsProblem(int width, int height, double fx, double fy, double cx, double cy,
                              bool equidistant) {
  std::ostringstream e;
  if (width <= 0 || height <= 0) return "";
  // A pinhole (radial-tangential) camera sees 2 atan(w / 2f); an equidistant (fisheye) one
  // r = f theta, so w / f radians, and may see past 180 degrees.
  const double max_fov_deg = equidistant ? kMaxFisheyeFovDeg : sim::kMaxFovDeg;
  const double size[2] = {static_cast<double>(width), static_cast<double>(height)};
  const double f[2] = {fx, fy};
  for (int k = 0; k < 2; ++k) {
    const double fov_deg =
        (equidistant ? size[k] / f[k] : 2.0 * std::atan(size[k] / (2.0 * f[k]))) * 180.0 / M_PI;
    if (!(fov_deg > sim::kMinFovDeg && fov_deg < max_fov_deg)) {
      e << (k == 0 ? "fx " : "fy ") << FormatDouble(f[k]) << " px gives a "
        << (k == 0 ? "horizontal" : "vertical") << " field of view of " << fov_deg << " deg over "
        << size[k] << " px; expected " << sim::kMinFovDeg << " .. " << max_fov_deg << " deg";
      return e.str();
    }
  }
  if (!(cx >= 0.0 && cx <= width && cy >= 0.0 && cy <= height)) {
    e << "principal point (" << FormatDouble(cx) << ", " << FormatDouble(cy)
      << ") px lies outside the " << width << "x" << height << " image";
    return e.str();
  }
  return "";
}

std::string RigProblem(const vo::StereoCamera& c) {
  std::ostringstream e;
  if (!(c.baseline_m >= sim::kMinBaselineM && c.baseline_m <= sim::kMaxBaselineM)) {
    e << "baseline " << FormatDouble(c.baseline_m) << " m is outside the plausible range "
      << FormatDouble(sim::kMinBaselineM) << " .. " << FormatDouble(sim::kMaxBaselineM)
      << " m (1 mm to 5 m)";
    return e.str();
  }
  return IntrinsicsProblem(c.width, c.height, c.fx_px, c.fy_px, c.cx_px, c.cy_px, false);
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

namespace {

// The bits a 16-bit image's values use: its largest value rounded up to 8, 10, 12, 14 or 16 bits
// (8-bit data stored in 16 bits, a 10- or 12-bit sensor's LSB-aligned data, full 16 bits).
int SignificantBits(const cv::Mat& image16) {
  double max_value = 0.0;
  cv::minMaxLoc(image16, nullptr, &max_value);
  for (int bits = 8; bits < 16; bits += 2)
    if (max_value < static_cast<double>(1 << bits)) return bits;
  return 16;
}

// imread keeping a 16-bit depth (colour converted to grey).
cv::Mat ReadAnyDepthGrey(const std::string& path) {
  return cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
}

}  // namespace

bool ReadGreyImage(const std::string& path, const cv::Size& expected, const std::string& origin,
                   int bits, cv::Mat* image, std::string* error) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Fail(error, path + ": missing image file");
  const cv::Mat raw = ReadAnyDepthGrey(path);
  if (raw.empty()) return Fail(error, path + ": cannot decode the image");
  if (raw.size() != expected)
    return Fail(error, path + ": image size " + SizeText(raw) + " differs from " +
                           std::to_string(expected.width) + "x" + std::to_string(expected.height) +
                           " (" + origin + ")");
  if (raw.depth() == CV_8U) {
    if (bits != 8)
      return Fail(error, path + ": an 8-bit image in a sequence of " + std::to_string(bits) +
                             "-bit images (its first pair)");
    *image = raw;
    return true;
  }
  if (raw.depth() != CV_16U)
    return Fail(error, path + ": unsupported pixel type (expected an 8- or 16-bit grey image)");
  if (bits == 8 && SignificantBits(raw) > 8)
    return Fail(error, path + ": a 16-bit image in a sequence of 8-bit images (its first pair)");
  if (SignificantBits(raw) > bits) {
    double max_value = 0.0;
    cv::minMaxLoc(raw, nullptr, &max_value);
    return Fail(error, path + ": pixel value " + std::to_string(static_cast<int>(max_value)) +
                           " exceeds the " + std::to_string(bits) +
                           "-bit range of the sequence (0 .. " + std::to_string((1 << bits) - 1) +
                           ", from the largest value of its first pair)");
  }
  // value >> (bits - 8): the same scale for every frame of the sequence.
  const int shift = bits - 8;
  image->create(raw.size(), CV_8UC1);
  for (int y = 0; y < raw.rows; ++y) {
    const uint16_t* in = raw.ptr<uint16_t>(y);
    uint8_t* out = image->ptr<uint8_t>(y);
    for (int x = 0; x < raw.cols; ++x) out[x] = static_cast<uint8_t>(in[x] >> shift);
  }
  return true;
}

bool FirstPairBits(const std::string& left_path, const std::string& right_path, int* bits,
                   std::string* error) {
  const cv::Mat left = ReadAnyDepthGrey(left_path), right = ReadAnyDepthGrey(right_path);
  if (left.empty()) return Fail(error, left_path + ": cannot decode the image");
  if (right.empty()) return Fail(error, right_path + ": cannot decode the image");
  if (left.depth() != right.depth())
    return Fail(error, right_path + ": pixel depth differs from the left image's (" + left_path +
                           "): one is 8-bit, the other 16-bit");
  *bits = left.depth() == CV_16U ? std::max(SignificantBits(left), SignificantBits(right)) : 8;
  return true;
}

bool TakeImageSizeFromFirstPair(const std::string& left_path, const std::string& right_path,
                                const std::string& calib_path, vo::StereoCamera* camera, int* bits,
                                std::string* error) {
  const cv::Mat left = ReadAnyDepthGrey(left_path);
  const cv::Mat right = ReadAnyDepthGrey(right_path);
  if (left.empty()) return Fail(error, left_path + ": cannot decode the image");
  if (right.empty()) return Fail(error, right_path + ": cannot decode the image");
  if (left.size() != right.size())
    return Fail(error, right_path + ": size " + SizeText(right) +
                           " differs from the left image's " + SizeText(left) + " (" + left_path +
                           ")");
  if (!FirstPairBits(left_path, right_path, bits, error)) return false;
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
