#include "sim/lens.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

namespace sim {

bool MakeDistortedView(const LensDistortion& lens, double fx_px, double fy_px, double cx_px,
                       double cy_px, int width, int height, DistortedView* view,
                       std::string* error) {
  const bool radtan = lens.model == kRadTan;
  if (!radtan && lens.model != kEquidistant) {
    *error = "distortion model '" + lens.model + "': expected '" + kRadTan + "' or '" +
             kEquidistant + "'";
    return false;
  }
  if (lens.coeffs.size() != 4 || !std::all_of(lens.coeffs.begin(), lens.coeffs.end(),
                                              [](double c) { return std::isfinite(c); })) {
    *error = "distortion coefficients: expected 4 finite numbers (" +
             std::string(radtan ? "k1 k2 p1 p2" : "k1 k2 k3 k4") + "), got " +
             std::to_string(lens.coeffs.size());
    return false;
  }
  const cv::Matx33d K(fx_px, 0, cx_px, 0, fy_px, cy_px, 0, 0, 1);
  const cv::Mat D(lens.coeffs, true);
  std::vector<cv::Point2f> pixels;
  pixels.reserve(static_cast<size_t>(width) * height);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u)
      pixels.emplace_back(static_cast<float>(u), static_cast<float>(v));
  std::vector<cv::Point2f> rays;  // normalised (x, y) of each pixel's ray
  const cv::TermCriteria until(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-10);
  if (radtan)
    cv::undistortPoints(pixels, rays, K, D, cv::noArray(), cv::noArray(), until);
  else
    cv::fisheye::undistortPoints(pixels, rays, K, D, cv::noArray(), cv::noArray(), until);
  double half_x = 0.0, half_y = 0.0;  // the widest ray (normalised)
  for (const cv::Point2f& r : rays) {
    if (!std::isfinite(r.x) || !std::isfinite(r.y)) {
      *error = "distortion coefficients: a pixel's ray does not undistort (too strong a lens)";
      return false;
    }
    half_x = std::max(half_x, static_cast<double>(std::abs(r.x)));
    half_y = std::max(half_y, static_cast<double>(std::abs(r.y)));
  }
  // 2 px of margin for bilinear sampling; the fov a pinhole render can hold.
  constexpr double kMarginPx = 2.0;
  constexpr double kMaxFovDeg = 170.0;
  const double fov_x = 2.0 * std::atan(half_x) * 180.0 / M_PI;
  const double fov_y = 2.0 * std::atan(half_y) * 180.0 / M_PI;
  if (!(fov_x < kMaxFovDeg && fov_y < kMaxFovDeg)) {
    *error = "distortion coefficients: the lens sees " + std::to_string(fov_x) + " x " +
             std::to_string(fov_y) + " degrees, more than a pinhole render holds (170)";
    return false;
  }
  DistortedView& w = *view;
  w.wide_fx_px = fx_px;
  w.wide_fy_px = fy_px;
  w.wide_width = 2 * static_cast<int>(std::ceil(half_x * fx_px + kMarginPx)) + 1;
  w.wide_height = 2 * static_cast<int>(std::ceil(half_y * fy_px + kMarginPx)) + 1;
  w.wide_cx_px = 0.5 * (w.wide_width - 1);
  w.wide_cy_px = 0.5 * (w.wide_height - 1);
  w.wide_fovy_deg = 2.0 * std::atan(0.5 * w.wide_height / w.wide_fy_px) * 180.0 / M_PI;
  w.map_x.create(height, width, CV_32FC1);
  w.map_y.create(height, width, CV_32FC1);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const cv::Point2f& r = rays[static_cast<size_t>(v) * width + u];
      w.map_x.at<float>(v, u) = static_cast<float>(w.wide_fx_px * r.x + w.wide_cx_px);
      w.map_y.at<float>(v, u) = static_cast<float>(w.wide_fy_px * r.y + w.wide_cy_px);
    }
  return true;
}

}  // namespace sim
