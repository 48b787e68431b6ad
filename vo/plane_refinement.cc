#include "vo/plane_refinement.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "vo/bilinear.h"

namespace vo {

bool PlaneRefinementOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (max_iterations < 1)
    msg << "max_iterations must be >= 1, got " << max_iterations;
  else if (!(converged_px > 0.0) || !std::isfinite(converged_px))
    msg << "converged_px must be finite and > 0, got " << converged_px;
  else if (!(huber_sigmas > 0.0) || !std::isfinite(huber_sigmas))
    msg << "huber_sigmas must be finite and > 0, got " << huber_sigmas;
  else if (huber_iterations < 0 || huber_iterations >= max_iterations)
    msg << "huber_iterations must be in [0, max_iterations), got " << huber_iterations;
  else if (!(tukey_sigmas > 0.0) || !std::isfinite(tukey_sigmas))
    msg << "tukey_sigmas must be finite and > 0, got " << tukey_sigmas;
  else if (region_radius_px < 1 || region_radius_px > 50)
    msg << "region_radius_px must be in [1, 50], got " << region_radius_px;
  else if (!(region_outlier_ratio > 1.0) || !std::isfinite(region_outlier_ratio))
    msg << "region_outlier_ratio must be finite and > 1, got " << region_outlier_ratio;
  else if (!(min_sigma_grey > 0.0) || !std::isfinite(min_sigma_grey))
    msg << "min_sigma_grey must be finite and > 0, got " << min_sigma_grey;
  else if (min_pixels < 5)
    msg << "min_pixels must be >= 5, got " << min_pixels;
  else if (!(max_tilt_change_deg > 0.0) || !std::isfinite(max_tilt_change_deg))
    msg << "max_tilt_change_deg must be finite and > 0, got " << max_tilt_change_deg;
  else if (!(max_offset_change > 0.0) || !std::isfinite(max_offset_change))
    msg << "max_offset_change must be finite and > 0, got " << max_offset_change;
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

Eigen::Vector3d PlaneDisparityCoefficients(const StereoCamera& camera, const Plane& plane) {
  const Eigen::Vector3d m = plane.normal_cam0 / plane.offset_m;
  const double B = camera.baseline_m;
  return Eigen::Vector3d(-B * m.x(), -(camera.fx_px / camera.fy_px) * B * m.y(),
                         -camera.fx_px * B * m.z());
}

bool PlaneFromDisparityCoefficients(const StereoCamera& camera, const Eigen::Vector3d& abc,
                                    Plane* plane) {
  const double B = camera.baseline_m;
  const Eigen::Vector3d m(-abc.x() / B, -abc.y() * camera.fy_px / (camera.fx_px * B),
                          -abc.z() / (camera.fx_px * B));
  const double norm = m.norm();
  if (!m.allFinite() || !(norm > 0.0) || !std::isfinite(1.0 / norm)) return false;
  plane->normal_cam0 = m / norm;
  plane->offset_m = 1.0 / norm;
  return true;
}

namespace {

// (grey levels per pixel)²: a region whose matched right-image pixels have a smaller mean squared
// horizontal gradient cannot fix the disparity (a flat or saturated area).
constexpr double kMinMeanSquaredGradient = 0.01;

double Median(std::vector<double>* v) {
  auto mid = v->begin() + static_cast<std::ptrdiff_t>(v->size() / 2);
  std::nth_element(v->begin(), mid, v->end());
  return *mid;
}

PlaneRefinementResult Fail(PlaneRefinementResult r, const std::string& message) {
  r.ok = false;
  r.message = message;
  return r;
}

}  // namespace

PlaneRefinementResult RefinePlanePhotometric(const cv::Mat& left, const cv::Mat& right,
                                             const StereoCamera& camera, const Plane& initial,
                                             const std::vector<cv::Point>& pixels,
                                             const PlaneRefinementOptions& options) {
  PlaneRefinementResult result;
  result.plane = initial;
  std::string error;
  if (!options.IsValid(&error)) return Fail(result, "invalid options: " + error);
  if (!camera.IsValid(&error)) return Fail(result, "invalid camera: " + error);
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size() ||
      left.cols != camera.width || left.rows != camera.height) {
    return Fail(result, "images must be 8-bit grey (CV_8UC1) of the camera's size");
  }
  if (!initial.normal_cam0.allFinite() || !(initial.normal_cam0.norm() > 0.5) ||
      !(initial.offset_m > 0.0) || !std::isfinite(initial.offset_m)) {
    return Fail(result, "the initial plane needs a finite unit normal and a distance > 0");
  }
  if (static_cast<int>(pixels.size()) < options.min_pixels) {
    std::ostringstream msg;
    msg << "too few pixels (" << pixels.size() << ", need " << options.min_pixels << ")";
    return Fail(result, msg.str());
  }

  cv::Mat R;
  right.convertTo(R, CV_32F);
  cv::Mat gx(R.size(), CV_32F, cv::Scalar(0.0f));
  for (int y = 0; y < R.rows; ++y) {
    const float* r = R.ptr<float>(y);
    float* g = gx.ptr<float>(y);
    for (int x = 1; x + 1 < R.cols; ++x) g[x] = 0.5f * (r[x + 1] - r[x - 1]);
  }

  Plane start = initial;
  start.normal_cam0.normalize();
  Eigen::Vector3d abc = PlaneDisparityCoefficients(camera, start);
  double gain = 0.0;
  double bias = 0.0;
  const double cx = camera.cx_px;
  const double cy = camera.cy_px;
  const double max_x = R.cols - 2;  // keep the 2×2 neighbourhood inside the image
  const double max_y = R.rows - 2;

  std::vector<double> residuals;
  std::vector<double> deviations;
  residuals.reserve(pixels.size());
  deviations.reserve(pixels.size());
  bool converged = false;
  for (int it = 0; it < options.max_iterations && !converged; ++it) {
    // Residuals of the pixels whose match lies inside the right image.
    struct Sample {
      int x, y;
      double du, dv, r, grad, intensity;
      bool outlier;  // in a neighbourhood that does not fit the plane (Tukey phase)
    };
    std::vector<Sample> samples;
    samples.reserve(pixels.size());
    for (const cv::Point& p : pixels) {
      if (p.x < 0 || p.y < 0 || p.x >= left.cols || p.y >= left.rows) continue;
      const double du = p.x - cx;
      const double dv = p.y - cy;
      const double d = abc.x() * du + abc.y() * dv + abc.z();
      const double xr = p.x - d;
      if (!(d > 0.0) || !(xr >= 0.0) || !(xr < max_x) || p.y > max_y) continue;
      const double intensity = Bilinear(R, xr, p.y);
      const double r = (1.0 + gain) * intensity + bias - left.at<uint8_t>(p.y, p.x);
      samples.push_back({p.x, p.y, du, dv, r, Bilinear(gx, xr, p.y), intensity, false});
    }
    result.pixels = static_cast<int>(samples.size());
    if (result.pixels < options.min_pixels) {
      std::ostringstream msg;
      msg << "too few pixels inside the right image (" << result.pixels << ", need "
          << options.min_pixels << ")";
      return Fail(result, msg.str());
    }
    const bool huber = it < options.huber_iterations;
    if (!huber) {
      // Neighbourhoods off the plane: the mean |r| over a (2·radius+1)² window of the region's
      // pixels, against its median over the region. Noise averages out in a window, a surface
      // that is not the plane does not.
      cv::Mat abs_r(left.size(), CV_32F, cv::Scalar(0.0f));
      cv::Mat count(left.size(), CV_32F, cv::Scalar(0.0f));
      for (const Sample& s : samples) {
        abs_r.at<float>(s.y, s.x) = static_cast<float>(std::abs(s.r));
        count.at<float>(s.y, s.x) = 1.0f;
      }
      const cv::Size window(2 * options.region_radius_px + 1, 2 * options.region_radius_px + 1);
      cv::boxFilter(abs_r, abs_r, -1, window, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
      cv::boxFilter(count, count, -1, window, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
      std::vector<double> local_mean;
      local_mean.reserve(samples.size());
      for (const Sample& s : samples) {
        local_mean.push_back(abs_r.at<float>(s.y, s.x) / count.at<float>(s.y, s.x));
      }
      std::vector<double> sorted = local_mean;  // Median reorders
      const double limit = options.region_outlier_ratio * Median(&sorted);
      for (size_t i = 0; i < samples.size(); ++i) samples[i].outlier = local_mean[i] > limit;
    }
    residuals.clear();
    for (const Sample& s : samples) {
      if (!s.outlier) residuals.push_back(s.r);
    }
    const double med = Median(&residuals);
    deviations.clear();
    for (const Sample& s : samples) {
      if (!s.outlier) deviations.push_back(std::abs(s.r - med));
    }
    const double sigma = std::max(1.4826 * Median(&deviations), options.min_sigma_grey);
    result.residual_sigma = sigma;
    const double k = options.huber_sigmas * sigma;
    const double tukey = options.tukey_sigmas * sigma;

    // Weighted normal equations of (a, b, c, g, β).
    Eigen::Matrix<double, 5, 5> A = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> rhs = Eigen::Matrix<double, 5, 1>::Zero();
    for (const Sample& s : samples) {
      if (s.outlier) continue;
      double w;
      if (huber) {
        w = std::abs(s.r) <= k ? 1.0 : k / std::abs(s.r);
      } else {
        const double x = s.r / tukey;
        w = std::abs(x) < 1.0 ? (1.0 - x * x) * (1.0 - x * x) : 0.0;
      }
      const double gd = -(1.0 + gain) * s.grad;  // ∂r/∂d
      Eigen::Matrix<double, 5, 1> J;
      J << gd * s.du, gd * s.dv, gd, s.intensity, 1.0;
      A.selfadjointView<Eigen::Lower>().rankUpdate(J, w);
      rhs.noalias() += w * s.r * J;
    }
    A.triangularView<Eigen::StrictlyUpper>() = A.transpose();
    if (!(A(2, 2) > kMinMeanSquaredGradient * samples.size())) {
      return Fail(result, "no texture in the region (no horizontal image gradient)");
    }
    const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> ldlt(A);
    if (ldlt.info() != Eigen::Success) return Fail(result, "degenerate normal equations");
    const Eigen::Matrix<double, 5, 1> step = -ldlt.solve(rhs);
    if (!step.allFinite()) return Fail(result, "degenerate normal equations");
    abc += step.head<3>();
    gain += step(3);
    bias += step(4);
    result.iterations = it + 1;
    // Largest change of disparity over the pixels (an affine function: at the extremes).
    double moved = 0.0;
    for (const Sample& s : samples) {
      moved = std::max(moved, std::abs(step(0) * s.du + step(1) * s.dv + step(2)));
    }
    converged = !huber && moved < options.converged_px;
  }

  Plane refined = initial;
  if (!PlaneFromDisparityCoefficients(camera, abc, &refined)) {
    return Fail(result, "the refined disparity describes no plane in front of the camera");
  }
  const double tilt_deg =
      std::acos(std::clamp(refined.normal_cam0.dot(start.normal_cam0), -1.0, 1.0)) * 180.0 / M_PI;
  const double offset_change = std::abs(refined.offset_m - start.offset_m) / start.offset_m;
  if (!(tilt_deg <= options.max_tilt_change_deg) || !(offset_change <= options.max_offset_change)) {
    std::ostringstream msg;
    msg << "refined plane implausibly far from the initial one (" << tilt_deg << " deg, "
        << 100.0 * offset_change << " % of the distance)";
    return Fail(result, msg.str());
  }
  result.ok = true;
  result.plane = refined;
  result.disparity_coefficients = abc;
  result.gain = gain;
  result.bias = bias;
  return result;
}

}  // namespace vo
