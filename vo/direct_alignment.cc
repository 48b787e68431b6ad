#include "vo/direct_alignment.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <utility>

#include "vo/bilinear.h"
#include "vo/prior_motion.h"

namespace vo {

bool DirectAlignmentOptions::IsValid(std::string* error) const {
  std::string e;
  if (pyramid_levels < 1 || pyramid_levels > 6)
    e = "pyramid_levels must be in 1..6";
  else if (!(min_gradient > 0.0))
    e = "min_gradient must be > 0";
  else if (max_pixels < 1)
    e = "max_pixels must be >= 1";
  else if (max_iterations < 1)
    e = "max_iterations must be >= 1";
  else if (!(huber_k > 0.0))
    e = "huber_k must be > 0";
  else if (!(tukey_k >= 0.0))
    e = "tukey_k must be >= 0";
  else if (min_pixels < 1)
    e = "min_pixels must be >= 1";
  else if (!(max_yaw_sigma_deg > 0.0))
    e = "max_yaw_sigma_deg must be > 0";
  else if (!(max_forward_sigma_m > 0.0))
    e = "max_forward_sigma_m must be > 0";
  else if (!(max_yaw_change_deg > 0.0))
    e = "max_yaw_change_deg must be > 0";
  else if (!(max_forward_change_m > 0.0))
    e = "max_forward_change_m must be > 0";
  else if (!(min_depth_m > 0.0) || !(max_depth_m > min_depth_m))
    e = "need 0 < min_depth_m < max_depth_m";
  if (!e.empty() && error != nullptr) *error = e;
  return e.empty();
}

ScenePlane TransformPlane(const ScenePlane& plane_a, const Eigen::Isometry3d& T_a_b) {
  // n·(R p_b + t) = d  ⇔  (Rᵀ n)·p_b = d − n·t.
  ScenePlane b = plane_a;
  b.normal = T_a_b.linear().transpose() * plane_a.normal;
  b.distance_m = plane_a.distance_m - plane_a.normal.dot(T_a_b.translation());
  return b;
}

namespace {

// A pyramid level: the image (float, lightly smoothed at level 0) and its gradients, with the
// camera's intrinsics at that scale.
struct Level {
  cv::Mat image, gx, gy;  // CV_32F
  double fx, fy, cx, cy;
};

std::vector<Level> Pyramid(const cv::Mat& image8, const StereoCamera& camera, int levels) {
  std::vector<Level> pyramid(levels);
  cv::Mat f;
  image8.convertTo(f, CV_32F);
  cv::GaussianBlur(f, pyramid[0].image, cv::Size(3, 3), 0.8, 0.8, cv::BORDER_REPLICATE);
  for (int l = 1; l < levels; ++l) cv::pyrDown(pyramid[l - 1].image, pyramid[l].image);
  for (int l = 0; l < levels; ++l) {
    Level& L = pyramid[l];
    // Central differences: (I(x+1) − I(x−1)) / 2.
    cv::Sobel(L.image, L.gx, CV_32F, 1, 0, 1, 0.5, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(L.image, L.gy, CV_32F, 0, 1, 1, 0.5, 0.0, cv::BORDER_REPLICATE);
    const double s = 1.0 / static_cast<double>(1 << l);
    L.fx = camera.fx_px * s;
    L.fy = camera.fy_px * s;
    L.cx = camera.cx_px * s;  // pyrDown's pixel j is centred on pixel 2j of the level below
    L.cy = camera.cy_px * s;
  }
  return pyramid;
}

// Bilinear sample of a CV_32F image; false outside [0, size − 1).
bool Sample(const cv::Mat& m, double x, double y, double* value) {
  if (!(x >= 0.0 && y >= 0.0 && x < m.cols - 1.0 && y < m.rows - 1.0)) return false;
  *value = Bilinear(m, x, y);
  return true;
}

struct PlanePixel {
  Eigen::Vector3d p_prev;  // the pixel's point on the plane (previous camera frame)
  double intensity;        // previous image's grey level
};

// The previous level's pixels with a gradient, on the plane within the depth range.
std::vector<PlanePixel> SelectPixels(const Level& L, const std::vector<ScenePlane>& planes,
                                     const DirectAlignmentOptions& o) {
  std::vector<PlanePixel> pixels;
  const int border = 2;
  const double g2 = o.min_gradient * o.min_gradient;
  for (int v = border; v < L.image.rows - border; ++v) {
    const float* gx = L.gx.ptr<float>(v);
    const float* gy = L.gy.ptr<float>(v);
    const float* im = L.image.ptr<float>(v);
    for (int u = border; u < L.image.cols - border; ++u) {
      if (static_cast<double>(gx[u]) * gx[u] + static_cast<double>(gy[u]) * gy[u] < g2) continue;
      const Eigen::Vector3d ray((u - L.cx) / L.fx, (v - L.cy) / L.fy, 1.0);
      // The nearest plane in front along the ray: the surface seen from inside a convex room.
      double z = std::numeric_limits<double>::infinity();
      for (const ScenePlane& plane : planes) {
        const double denominator = plane.normal.dot(ray);
        if (denominator > 1e-9) z = std::min(z, plane.distance_m / denominator);
      }
      if (!(z >= o.min_depth_m && z <= o.max_depth_m)) continue;
      pixels.push_back(PlanePixel{z * ray, im[u]});
    }
  }
  if (static_cast<int>(pixels.size()) > o.max_pixels) {  // evenly thinned, deterministic
    std::vector<PlanePixel> thinned;
    thinned.reserve(o.max_pixels);
    const double step = static_cast<double>(pixels.size()) / o.max_pixels;
    for (int k = 0; k < o.max_pixels; ++k) thinned.push_back(pixels[static_cast<size_t>(k * step)]);
    pixels.swap(thinned);
  }
  return pixels;
}

bool Project(const Level& L, const Eigen::Isometry3d& T_curr_prev, const Eigen::Vector3d& p_prev,
             Eigen::Vector2d* uv) {
  const Eigen::Vector3d p = T_curr_prev * p_prev;
  if (!(p.z() > 1e-3)) return false;
  *uv = Eigen::Vector2d(L.fx * p.x() / p.z() + L.cx, L.fy * p.y() / p.z() + L.cy);
  return true;
}

// The pixels that the motion T_prev_curr moves at least 3 pixels inside the current image: the
// level's fixed set (a pixel that leaves the view later costs as an outlier, Linearise).
std::vector<PlanePixel> InView(const Level& curr_level, std::vector<PlanePixel> pixels,
                               const Eigen::Isometry3d& T_prev_curr) {
  const Eigen::Isometry3d T = T_prev_curr.inverse();
  const double margin = 3.0;
  std::vector<PlanePixel> kept;
  for (const PlanePixel& px : pixels) {
    Eigen::Vector2d uv;
    if (Project(curr_level, T, px.p_prev, &uv) && uv.x() >= margin && uv.y() >= margin &&
        uv.x() <= curr_level.image.cols - 1 - margin &&
        uv.y() <= curr_level.image.rows - 1 - margin) {
      kept.push_back(px);
    }
  }
  return kept;
}

double RobustSigma(std::vector<double> abs_residuals) {
  if (abs_residuals.empty()) return 1.0;
  const size_t mid = abs_residuals.size() / 2;
  std::nth_element(abs_residuals.begin(), abs_residuals.begin() + mid, abs_residuals.end());
  return std::max(1.0, 1.4826 * abs_residuals[mid]);  // at least one grey level
}

// A motion model of N parameters: Motion(theta) is T_prev_curr. The vehicle's (yaw, forward);
// the free platform's (ω, t): T_prev_curr = [R_start · Exp(ω) | t].
template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;

// One level's residuals, optionally with Jacobians (forward differences of step 1e-5 in each
// parameter). gain_index >= 0: θ(gain_index) is α, the log of the current image's gain over the
// previous image's, r = I_curr − e^α · I_prev (the motion does not read it); -1: r = I_curr −
// I_prev.
template <int N>
struct Linearisation {
  int n = 0;
  double cost = 0.0;  // Σ ρ
  Mat<N> H = Mat<N>::Zero();
  Vec<N> g = Vec<N>::Zero();
  std::vector<double> abs_residuals;
};

template <int N, typename Motion>
Linearisation<N> Linearise(const Level& curr_level, const std::vector<PlanePixel>& pixels,
                           const Motion& motion, const Vec<N>& theta, double threshold, bool tukey,
                           bool jacobians, int gain_index) {
  const double gain = gain_index >= 0 ? std::exp(theta(gain_index)) : 1.0;
  Linearisation<N> lin;
  const Eigen::Isometry3d T = motion(theta).inverse();
  constexpr double kEps = 1e-5;
  std::array<Eigen::Isometry3d, N> T_k;
  if (jacobians) {
    for (int k = 0; k < N; ++k) {
      if (k == gain_index) continue;
      Vec<N> moved = theta;
      moved(k) += kEps;
      T_k[k] = motion(moved).inverse();
    }
  }
  lin.abs_residuals.reserve(pixels.size());
  for (const PlanePixel& px : pixels) {
    Eigen::Vector2d uv;
    double value = 0.0;
    if (!Project(curr_level, T, px.p_prev, &uv) ||
        !Sample(curr_level.image, uv.x(), uv.y(), &value)) {
      // Out of view: the cost of a residual of 3 thresholds (Tukey: its ceiling), so that a step
      // gains nothing by pushing badly matched pixels out of the image.
      lin.cost += tukey ? threshold * threshold / 6.0 : threshold * (3.0 - 0.5) * threshold;
      continue;
    }
    const double r = value - gain * px.intensity;
    const double a = std::abs(r);
    double w = 0.0;
    if (tukey) {  // Tukey's biweight: residuals beyond the threshold have no weight
      const double q = a < threshold ? 1.0 - (r / threshold) * (r / threshold) : 0.0;
      w = q * q;
      lin.cost += threshold * threshold / 6.0 * (1.0 - q * q * q);
    } else {  // Huber
      w = a <= threshold ? 1.0 : threshold / a;
      lin.cost += a <= threshold ? 0.5 * r * r : threshold * (a - 0.5 * threshold);
    }
    lin.abs_residuals.push_back(a);
    ++lin.n;
    if (!jacobians) continue;
    std::array<Eigen::Vector2d, N> uv_k;
    bool projected = true;
    for (int k = 0; k < N && projected; ++k) {
      if (k == gain_index) continue;  // the motion does not read α: its derivative is analytic
      projected = Project(curr_level, T_k[k], px.p_prev, &uv_k[k]);
    }
    double gx = 0.0, gy = 0.0;
    if (!projected || !Sample(curr_level.gx, uv.x(), uv.y(), &gx) ||
        !Sample(curr_level.gy, uv.x(), uv.y(), &gy)) {
      continue;
    }
    const Eigen::Vector2d grad(gx, gy);
    Vec<N> J;
    for (int k = 0; k < N; ++k) {
      J(k) = k == gain_index ? -gain * px.intensity : grad.dot(uv_k[k] - uv) / kEps;  // ∂r/∂α
    }
    lin.H += w * J * J.transpose();
    lin.g += w * J * r;
  }
  return lin;
}

// What the coarse-to-fine Gauss-Newton found: the parameters, and on the finest level the
// support, the robust residual σ and the covariance (zero when the finest level had no pixel in
// view, infinite when its information was singular).
template <int N>
struct Alignment {
  Vec<N> theta;
  int pixels = 0;
  int iterations = 0;
  double residual_sigma = 0.0;
  Mat<N> covariance = Mat<N>::Zero();
};

// Σ ρ(r) over the previous image's pixels on the planes (unit normals), coarse to fine from
// theta0, with the prior ½ w_k (θ_k − θ0_k)² for each parameter whose prior_sigma_k > 0 (w_k in
// the grey levels' units: the level's robust residual variance over σ_k²); gain_index as
// Linearise's.
template <int N, typename Motion>
Alignment<N> AlignCoarseToFine(const StereoCamera& camera, const cv::Mat& prev, const cv::Mat& curr,
                               const std::vector<ScenePlane>& unit_planes, const Motion& motion,
                               const Vec<N>& theta0, const Vec<N>& prior_sigma,
                               const DirectAlignmentOptions& options, int gain_index) {
  Alignment<N> result;
  // Levels that keep at least 40 pixels across.
  int levels = options.pyramid_levels;
  while (levels > 1 && (std::min(camera.width, camera.height) >> (levels - 1)) < 40) --levels;
  const std::vector<Level> P = Pyramid(prev, camera, levels);
  const std::vector<Level> C = Pyramid(curr, camera, levels);

  Vec<N> theta = theta0;
  bool any_prior = false;
  for (int k = 0; k < N; ++k) {
    any_prior = any_prior || (prior_sigma(k) > 0.0 && std::isfinite(prior_sigma(k)));
  }
  Vec<N> prior_weight = Vec<N>::Zero();
  auto AddPrior = [&](const Vec<N>& at, Linearisation<N>* lin) {
    for (int k = 0; k < N; ++k) {
      if (!(prior_weight(k) > 0.0)) continue;
      const double d = at(k) - theta0(k);
      lin->cost += 0.5 * prior_weight(k) * d * d;
      lin->H(k, k) += prior_weight(k);
      lin->g(k) += prior_weight(k) * d;
    }
  };
  for (int l = levels - 1; l >= 0; --l) {
    const std::vector<PlanePixel> pixels =
        InView(C[l], SelectPixels(P[l], unit_planes, options), motion(theta));
    if (pixels.empty()) continue;
    // Huber weights on every level; on the finest, then Tukey's biweight (tukey_k > 0), which
    // gives the pixels off the plane (the floor below a wall) no weight at all.
    const int passes = l == 0 && options.tukey_k > 0.0 ? 2 : 1;
    double threshold = 0.0;
    bool tukey = false;
    for (int pass = 0; pass < passes; ++pass) {
      tukey = pass == 1;
      const double sigma = RobustSigma(
          Linearise<N>(C[l], pixels, motion, theta, 1e300, false, false, gain_index).abs_residuals);
      threshold = (tukey ? options.tukey_k : options.huber_k) * sigma;
      for (int k = 0; k < N; ++k) {
        const double s = prior_sigma(k);
        prior_weight(k) = s > 0.0 && std::isfinite(s) ? sigma * sigma / (s * s) : 0.0;
      }
      bool converged = false;
      for (int it = 0; it < options.max_iterations && !converged; ++it) {
        ++result.iterations;
        Linearisation<N> lin =
            Linearise<N>(C[l], pixels, motion, theta, threshold, tukey, true, gain_index);
        if (any_prior) AddPrior(theta, &lin);
        if (lin.n < 3 || !(lin.H.determinant() > 0.0)) break;
        Vec<N> step = -lin.H.ldlt().solve(lin.g);
        if (!step.allFinite()) break;
        bool improved = false;
        for (int halving = 0; halving < 6 && !improved; ++halving, step *= 0.5) {
          Linearisation<N> trial =
              Linearise<N>(C[l], pixels, motion, theta + step, threshold, tukey, false, gain_index);
          if (any_prior) AddPrior(theta + step, &trial);
          if (trial.cost < lin.cost) {
            theta += step;
            improved = true;
          }
        }
        converged = !improved || step.cwiseAbs().maxCoeff() < 1e-7;
      }
    }
    if (l > 0) continue;
    // The finest level: the measurement's support and uncertainty.
    Linearisation<N> final_lin =
        Linearise<N>(C[0], pixels, motion, theta, threshold, tukey, true, gain_index);
    if (any_prior) AddPrior(theta, &final_lin);
    result.pixels = final_lin.n;
    result.residual_sigma = RobustSigma(final_lin.abs_residuals);
    if (final_lin.n >= 3 && final_lin.H.determinant() > 0.0) {
      // The robustly weighted information, the robust residual variance.
      result.covariance = result.residual_sigma * result.residual_sigma * final_lin.H.inverse();
    } else {
      result.covariance.setConstant(std::numeric_limits<double>::infinity());
    }
  }
  result.theta = theta;
  return result;
}

// The finest level's robust costs of two results a and b of the same alignment, on the same
// pixels (those in view of both) with the same threshold (tukey_k, else huber_k, times the
// larger of the two robust σ): which of two basins fits the images better.
template <int N, typename Motion>
std::pair<double, double> CompareAtFinest(const StereoCamera& camera, const cv::Mat& prev,
                                          const cv::Mat& curr,
                                          const std::vector<ScenePlane>& unit_planes,
                                          const Motion& motion, const Vec<N>& a, const Vec<N>& b,
                                          const DirectAlignmentOptions& options, int gain_index) {
  const std::vector<Level> P = Pyramid(prev, camera, 1);
  const std::vector<Level> C = Pyramid(curr, camera, 1);
  const std::vector<PlanePixel> pixels =
      InView(C[0], InView(C[0], SelectPixels(P[0], unit_planes, options), motion(a)), motion(b));
  const double sigma = std::max(
      RobustSigma(
          Linearise<N>(C[0], pixels, motion, a, 1e300, false, false, gain_index).abs_residuals),
      RobustSigma(
          Linearise<N>(C[0], pixels, motion, b, 1e300, false, false, gain_index).abs_residuals));
  const bool tukey = options.tukey_k > 0.0;
  const double threshold = (tukey ? options.tukey_k : options.huber_k) * sigma;
  return {Linearise<N>(C[0], pixels, motion, a, threshold, tukey, false, gain_index).cost,
          Linearise<N>(C[0], pixels, motion, b, threshold, tukey, false, gain_index).cost};
}

// The options, the images (8-bit grey of the camera's size) and the planes (finite, in front),
// the planes with unit normals; false with *message otherwise.
bool CheckInput(const StereoCamera& camera, const DirectAlignmentOptions& options,
                const cv::Mat& prev, const cv::Mat& curr, const std::vector<ScenePlane>& planes,
                std::vector<ScenePlane>* unit, std::string* message) {
  std::string error;
  if (!options.IsValid(&error)) {
    *message = "invalid options: " + error;
    return false;
  }
  if (prev.empty() || curr.empty() || prev.type() != CV_8UC1 || curr.type() != CV_8UC1 ||
      prev.size() != curr.size() || prev.cols != camera.width || prev.rows != camera.height) {
    *message = "images must be 8-bit grey of the camera's size";
    return false;
  }
  for (const ScenePlane& plane : planes) {
    if (!plane.normal.allFinite() || !(plane.normal.norm() > 0.5) || !(plane.distance_m > 0.0) ||
        !std::isfinite(plane.distance_m)) {
      *message = "invalid plane";
      return false;
    }
    unit->push_back(plane);
    unit->back().distance_m /= plane.normal.norm();
    unit->back().normal.normalize();
  }
  return true;
}

}  // namespace

DirectAlignmentResult AlignVehicleDirect(const StereoCamera& camera, const cv::Mat& prev,
                                         const cv::Mat& curr, const std::vector<ScenePlane>& planes,
                                         const Eigen::Vector3d& up_prev,
                                         double axle_behind_camera_m, double yaw0_rad,
                                         double forward0_m, const DirectAlignmentOptions& options,
                                         double yaw_prior_sigma_rad) {
  DirectAlignmentResult result;
  result.yaw_rad = yaw0_rad;
  result.forward_m = forward0_m;
  std::vector<ScenePlane> unit;
  if (!CheckInput(camera, options, prev, curr, planes, &unit, &result.message)) return result;
  if (unit.empty() || !up_prev.allFinite() || !(up_prev.norm() > 0.0) || !std::isfinite(yaw0_rad) ||
      !std::isfinite(forward0_m)) {
    result.message = "no plane, or an invalid up or start";
    return result;
  }
  const Eigen::Vector3d up = up_prev.normalized();
  auto motion = [&](const Vec<2>& theta) {
    return VehicleMotion(up, axle_behind_camera_m, theta.x(), theta.y());
  };
  const Alignment<2> a =
      AlignCoarseToFine<2>(camera, prev, curr, unit, motion, Vec<2>(yaw0_rad, forward0_m),
                           Vec<2>(yaw_prior_sigma_rad, 0.0), options, /*gain_index=*/-1);
  const Eigen::Vector2d theta = a.theta;
  result.iterations = a.iterations;
  result.pixels = a.pixels;
  result.residual_sigma = a.residual_sigma;
  result.yaw_sigma_rad = std::sqrt(std::max(0.0, a.covariance(0, 0)));
  result.forward_sigma_m = std::sqrt(std::max(0.0, a.covariance(1, 1)));
  if (!theta.allFinite()) {
    result.message = "did not converge";
    return result;
  }
  std::ostringstream why;
  if (result.pixels < options.min_pixels) {
    why << result.pixels << " pixels in view (need " << options.min_pixels << ")";
  } else if (result.yaw_sigma_rad > options.max_yaw_sigma_deg * M_PI / 180.0 ||
             result.forward_sigma_m > options.max_forward_sigma_m) {
    why << "uncertain: sigma(yaw) " << result.yaw_sigma_rad * 180.0 / M_PI
        << " deg, sigma(forward) " << result.forward_sigma_m << " m";
  } else if (std::abs(theta.x() - yaw0_rad) > options.max_yaw_change_deg * M_PI / 180.0 ||
             std::abs(theta.y() - forward0_m) > options.max_forward_change_m) {
    why << "moved too far from the start (yaw " << (theta.x() - yaw0_rad) * 180.0 / M_PI
        << " deg, forward " << theta.y() - forward0_m << " m)";
  }
  result.message = why.str();
  result.ok = result.message.empty();
  if (result.ok) {
    result.yaw_rad = theta.x();
    result.forward_m = theta.y();
  }
  return result;
}

FreeDirectAlignmentResult AlignFreeDirect(const StereoCamera& camera, const cv::Mat& prev,
                                          const cv::Mat& curr,
                                          const std::vector<ScenePlane>& planes,
                                          const Eigen::Isometry3d& T_prev_curr0,
                                          const DirectAlignmentOptions& options,
                                          double rotation_prior_sigma_rad, bool standing_start) {
  FreeDirectAlignmentResult result;
  result.T_prev_curr = T_prev_curr0;
  std::vector<ScenePlane> unit;
  if (!CheckInput(camera, options, prev, curr, planes, &unit, &result.message)) return result;
  if (unit.empty() || !T_prev_curr0.matrix().allFinite()) {
    result.message = "no plane, or an invalid start";
    return result;
  }
  if (!(rotation_prior_sigma_rad > 0.0) || !std::isfinite(rotation_prior_sigma_rad)) {
    result.message = "no gyro rotation (its sigma must be > 0)";
    return result;
  }
  const Eigen::Matrix3d R0 = T_prev_curr0.linear();
  // θ = (t, α): the translation, and the log of the current image's gain over the previous
  // image's (r = I_curr − e^α · I_prev): a camera's exposure and analogue gain change from frame
  // to frame (auto-exposure; l_hallway's camera.gain_sigma 0.02 is ±3 grey levels on its walls),
  // and on a wall with one edge a translation that moves the edge is the cheaper way to explain a
  // brighter image (texture seed 3, frame 212: 5 cm wrong with σ 1.3 mm without α; 1 mm with
  // it). The affine brightness of DSO (Engel et al. 2018), without its offset: a gain alone is
  // the simulated camera's model, and one parameter fewer on a nearly blank wall.
  constexpr int kGain = 3;
  auto motion = [&](const Vec<4>& theta) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R0;
    T.translation() = theta.head<3>();
    return T;
  };
  // One alignment from the translation `start` (gain 1) and its checks (as AlignVehicleDirect's).
  auto align_from = [&](const Eigen::Vector3d& start) {
    FreeDirectAlignmentResult r;
    r.T_prev_curr = T_prev_curr0;
    Vec<4> theta0;
    theta0 << start, 0.0;
    const Alignment<4> a = AlignCoarseToFine<4>(camera, prev, curr, unit, motion, theta0,
                                                Vec<4>::Zero(), options, kGain);
    const Eigen::Matrix3d covariance = a.covariance.topLeftCorner<3, 3>();
    r.iterations = a.iterations;
    r.pixels = a.pixels;
    r.residual_sigma = a.residual_sigma;
    r.rotation_sigma_rad = rotation_prior_sigma_rad;
    // σ along the worst axis: the square root of the covariance's largest eigenvalue.
    if (covariance.allFinite()) {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(covariance, Eigen::EigenvaluesOnly);
      r.translation_sigma_m = std::sqrt(std::max(0.0, eig.eigenvalues()(2)));
    } else {
      r.translation_sigma_m = std::numeric_limits<double>::infinity();
    }
    if (!a.theta.allFinite()) {
      r.message = "did not converge";
      return r;
    }
    const double translation_change = (a.theta.head<3>() - start).norm();
    std::ostringstream why;
    if (r.pixels < options.min_pixels) {
      why << r.pixels << " pixels in view (need " << options.min_pixels << ")";
    } else if (r.translation_sigma_m > options.max_forward_sigma_m) {
      why << "uncertain: sigma(translation) " << r.translation_sigma_m << " m";
    } else if (translation_change > options.max_forward_change_m) {
      why << "moved too far from the start (translation " << translation_change << " m)";
    }
    r.message = why.str();
    r.ok = r.message.empty();
    r.log_gain = a.theta(kGain);
    if (r.ok) r.T_prev_curr = motion(a.theta);
    return r;
  };
  const Eigen::Vector3d t0 = T_prev_curr0.translation();
  FreeDirectAlignmentResult result_from_start = align_from(t0);
  if (!standing_start || t0.isZero(0.0)) return result_from_start;
  // The second start, standing still (the translation 0): a robot that brakes in front of the
  // wall leaves the constant velocity's start behind, out of the basin; where both converge,
  // the result whose grey levels fit better (the same pixels and threshold) is the measurement.
  FreeDirectAlignmentResult result_standing = align_from(Eigen::Vector3d::Zero());
  result_standing.from_standing = true;
  result_standing.iterations += result_from_start.iterations;
  result_from_start.iterations = result_standing.iterations;
  if (!result_standing.ok) return result_from_start;
  if (!result_from_start.ok) return result_standing;
  Vec<4> a, b;
  a << result_from_start.T_prev_curr.translation(), result_from_start.log_gain;
  b << result_standing.T_prev_curr.translation(), result_standing.log_gain;
  const std::pair<double, double> costs =
      CompareAtFinest<4>(camera, prev, curr, unit, motion, a, b, options, kGain);
  return costs.second < costs.first ? result_standing : result_from_start;
}

namespace {

// RANSAC over triples of `f` (deterministic), refined by least squares on the inliers: the
// plane and its inliers (indices into f). False when fewer than max(3, min_inliers) lie on the
// best plane or its inliers spread less than min_spread_m across their second principal axis.
bool FitPlane(const StereoCamera& camera, const std::vector<const Feature*>& f, double tolerance_px,
              int min_inliers, double min_spread_m, ScenePlane* plane, std::vector<int>* inliers) {
  const int n = static_cast<int>(f.size());
  if (n < std::max(3, min_inliers)) return false;
  const double fb = camera.fx_px * camera.baseline_m;
  // Disparity of the plane n·X = d at a feature's pixel: fb / z with z = d / (n·ray).
  auto on_plane = [&](const Eigen::Vector3d& normal, double d, const Feature& x) {
    const Eigen::Vector3d ray = x.p_cam0 / x.p_cam0.z();
    const double denominator = normal.dot(ray);
    if (!(d > 0.0) || !(denominator > 1e-9)) return false;
    return std::abs(fb * denominator / d - x.disparity_px) <= tolerance_px;
  };
  std::mt19937 rng(12345u);
  std::uniform_int_distribution<int> pick(0, n - 1);
  // At most 200 triples, fewer once the best plane's share w makes a triple of its inliers
  // drawn with probability 0.999 (the usual adaptive count log(0.001) / log(1 − w³)).
  const int64_t triples = static_cast<int64_t>(n) * (n - 1) * (n - 2) / 6;
  int trials = static_cast<int>(std::min<int64_t>(200, 2 * triples));
  int best = 0;
  Eigen::Vector3d best_normal = Eigen::Vector3d::UnitZ();
  double best_d = 0.0;
  for (int t = 0; t < trials; ++t) {
    const int a = pick(rng), b = pick(rng), c = pick(rng);
    if (a == b || b == c || a == c) continue;
    Eigen::Vector3d normal = (f[b]->p_cam0 - f[a]->p_cam0).cross(f[c]->p_cam0 - f[a]->p_cam0);
    if (!(normal.norm() > 1e-9)) continue;
    normal.normalize();
    double d = normal.dot(f[a]->p_cam0);
    if (d < 0.0) {
      normal = -normal;
      d = -d;
    }
    int count = 0;
    for (const Feature* x : f) count += on_plane(normal, d, *x) ? 1 : 0;
    if (count > best) {
      best = count;
      best_normal = normal;
      best_d = d;
      const double w = static_cast<double>(best) / n;
      const double miss = 1.0 - w * w * w;
      if (miss < 1e-12) break;
      if (miss < 1.0) {  // (miss == 1 when w³ underflows: no bound)
        const double needed = std::ceil(std::log(1e-3) / std::log(miss));  // may exceed an int
        if (needed < trials) trials = static_cast<int>(needed);
      }
    }
  }
  if (best < std::max(3, min_inliers)) return false;
  inliers->clear();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    if (!on_plane(best_normal, best_d, *f[i])) continue;
    inliers->push_back(i);
    mean += f[i]->p_cam0;
  }
  mean /= static_cast<double>(inliers->size());
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (int i : *inliers) S += (f[i]->p_cam0 - mean) * (f[i]->p_cam0 - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(S);  // ascending eigenvalues
  Eigen::Vector3d normal = eig.eigenvectors().col(0);
  double d = normal.dot(mean);
  if (d < 0.0) {
    normal = -normal;
    d = -d;
  }
  const double spread =
      std::sqrt(std::max(0.0, eig.eigenvalues()(1)) / static_cast<double>(inliers->size()));
  if (!(spread >= min_spread_m) || !(d > 0.0) || !normal.allFinite()) return false;
  plane->normal = normal;
  plane->distance_m = d;
  plane->inliers = static_cast<int>(inliers->size());
  return true;
}

std::vector<const Feature*> WithDepth(const std::vector<Feature>& features) {
  std::vector<const Feature*> f;
  for (const Feature& x : features) {
    if (x.has_depth() && x.p_cam0.allFinite() && x.uv_px.allFinite() && x.p_cam0.z() > 0.0)
      f.push_back(&x);
  }
  return f;
}

}  // namespace

bool FitDominantPlane(const StereoCamera& camera, const std::vector<Feature>& features,
                      double tolerance_px, int min_inliers, double min_fraction,
                      double min_spread_m, ScenePlane* plane) {
  const std::vector<const Feature*> f = WithDepth(features);
  std::vector<int> inliers;
  ScenePlane fitted;
  if (plane == nullptr ||
      !FitPlane(camera, f, tolerance_px, min_inliers, min_spread_m, &fitted, &inliers) ||
      fitted.inliers < min_fraction * static_cast<double>(f.size())) {
    return false;
  }
  *plane = fitted;
  return true;
}

bool FitScenePlanes(const StereoCamera& camera, const std::vector<Feature>& features,
                    double tolerance_px, int min_inliers, double min_fraction, double min_spread_m,
                    int max_planes, std::vector<ScenePlane>* planes) {
  if (planes == nullptr) return false;
  std::vector<const Feature*> remaining = WithDepth(features);
  const double total = static_cast<double>(remaining.size());
  std::vector<ScenePlane> found;
  int on_planes = 0;
  while (static_cast<int>(found.size()) < max_planes) {
    ScenePlane plane;
    std::vector<int> inliers;
    if (!FitPlane(camera, remaining, tolerance_px, min_inliers, min_spread_m, &plane, &inliers))
      break;
    found.push_back(plane);
    on_planes += plane.inliers;
    std::vector<bool> used(remaining.size(), false);
    for (int i : inliers) used[i] = true;
    std::vector<const Feature*> rest;
    for (size_t i = 0; i < remaining.size(); ++i) {
      if (!used[i]) rest.push_back(remaining[i]);
    }
    remaining.swap(rest);
  }
  if (found.empty() || on_planes < min_fraction * total) return false;
  *planes = found;
  return true;
}

}  // namespace vo
