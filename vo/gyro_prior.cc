#include "vo/gyro_prior.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "vo/options_check.h"

namespace vo {
namespace {

// Exp of a rotation vector.
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// Log of a rotation: its rotation vector.
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// Samples farther than this from the interval do not bound it (a gap in the IMU's data).
constexpr double kMaxSampleGapS = 1.0;

}  // namespace

bool ImuOptions::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!(min_rotation_sigma_deg > 0.0) || !std::isfinite(min_rotation_sigma_deg)) {
    msg << "min_rotation_sigma_deg must be finite and > 0, got " << min_rotation_sigma_deg;
  } else if (!(max_weak_rotation_error_deg > 0.0) || !std::isfinite(max_weak_rotation_error_deg)) {
    msg << "max_weak_rotation_error_deg must be finite and > 0, got "
        << max_weak_rotation_error_deg;
  } else if (!(initial_bias_sigma_radps >= 0.0) || !std::isfinite(initial_bias_sigma_radps)) {
    msg << "initial_bias_sigma_radps must be finite and >= 0, got " << initial_bias_sigma_radps;
  } else if (!(bias_gain >= 0.0 && bias_gain <= 1.0)) {
    msg << "bias_gain must be in [0, 1], got " << bias_gain;
  } else if (!(bias_window_s > 0.0) || !std::isfinite(bias_window_s)) {
    msg << "bias_window_s must be finite and > 0, got " << bias_window_s;
  } else if (!(max_bias_radps > 0.0) || !std::isfinite(max_bias_radps)) {
    msg << "max_bias_radps must be finite and > 0, got " << max_bias_radps;
  } else if (!(standing_start_s >= 0.0) || !std::isfinite(standing_start_s)) {
    msg << "standing_start_s must be finite and >= 0, got " << standing_start_s;
  } else if (!(standing_max_std_radps > 0.0) || !std::isfinite(standing_max_std_radps)) {
    msg << "standing_max_std_radps must be finite and > 0, got " << standing_max_std_radps;
  } else if (!(max_standing_bias_radps > 0.0) || !std::isfinite(max_standing_bias_radps)) {
    msg << "max_standing_bias_radps must be finite and > 0, got " << max_standing_bias_radps;
  }
  return NoBrokenRule(msg, error);
}

bool GyroCalibration::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (!R_imu_cam.allFinite() ||
      !(R_imu_cam * R_imu_cam.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
      !(R_imu_cam.determinant() > 0.0)) {
    msg << "R_imu_cam must be a rotation";
  } else if (!(noise_density >= 0.0) || !std::isfinite(noise_density)) {
    msg << "noise_density must be finite and >= 0, got " << noise_density;
  } else if (!(random_walk >= 0.0) || !std::isfinite(random_walk)) {
    msg << "random_walk must be finite and >= 0, got " << random_walk;
  }
  return NoBrokenRule(msg, error);
}

double GyroRotation::sigma_rad() const {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(covariance, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
}

bool IntegrateGyro(const std::vector<GyroSample>& samples_in, double t0_s, double t1_s,
                   const Eigen::Vector3d& bias_radps, Eigen::Matrix3d* R_imu0_imu1) {
  if (!(t1_s > t0_s) || !std::isfinite(t0_s) || !std::isfinite(t1_s)) return false;
  std::vector<GyroSample> s;
  for (const GyroSample& g : samples_in) {
    if (std::isfinite(g.time_s) && g.rate_radps.allFinite() && g.time_s >= t0_s - kMaxSampleGapS &&
        g.time_s <= t1_s + kMaxSampleGapS)
      s.push_back(g);
  }
  if (s.empty()) return false;
  std::stable_sort(s.begin(), s.end(),
                   [](const GyroSample& a, const GyroSample& b) { return a.time_s < b.time_s; });
  // The rate at time t: linear between the samples around it, held beyond the first and last.
  auto rate = [&s](double t) -> Eigen::Vector3d {
    if (t <= s.front().time_s) return s.front().rate_radps;
    if (t >= s.back().time_s) return s.back().rate_radps;
    const auto it = std::upper_bound(s.begin(), s.end(), t,
                                     [](double v, const GyroSample& g) { return v < g.time_s; });
    const GyroSample& b = *it;
    const GyroSample& a = *(it - 1);
    const double span = b.time_s - a.time_s;
    if (!(span > 0.0)) return b.rate_radps;
    const double f = (t - a.time_s) / span;
    return (1.0 - f) * a.rate_radps + f * b.rate_radps;
  };
  // The pieces: t0, the sample times inside (t0, t1), t1.
  std::vector<double> knots{t0_s};
  for (const GyroSample& g : s) {
    if (g.time_s > t0_s && g.time_s < t1_s && g.time_s > knots.back()) knots.push_back(g.time_s);
  }
  knots.push_back(t1_s);
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  for (size_t k = 0; k + 1 < knots.size(); ++k) {
    const double dt = knots[k + 1] - knots[k];
    const Eigen::Vector3d w = 0.5 * (rate(knots[k]) + rate(knots[k + 1])) - bias_radps;
    R = R * ExpSO3(w * dt);
  }
  *R_imu0_imu1 = R;
  return R.allFinite();
}

GyroPrior::GyroPrior(const ImuOptions& options, const GyroCalibration& calibration)
    : options_(options), calibration_(calibration) {
  Reset();
}

void GyroPrior::Reset() {
  samples_.clear();
  have_time_ = false;
  last_time_s_ = 0.0;
  bias_.setZero();
  bias_origin_.setZero();
  standing_start_ = false;
  bias_variance_ = options_.initial_bias_sigma_radps * options_.initial_bias_sigma_radps;
  bias_updates_ = 0;
  moving_start_ = false;
  have_large_ = false;
  large_.setZero();
  last_ = GyroRotation();
  stretch_s_ = 0.0;
  stretch_gyro_.setIdentity();
  stretch_vo_.setIdentity();
}

void GyroPrior::AddSamples(const std::vector<GyroSample>& samples) {
  samples_.insert(samples_.end(), samples.begin(), samples.end());
}

void GyroPrior::EstimateStandingBias(double t_s) {
  const double window = options_.standing_start_s;
  if (!(window > 0.0) || !std::isfinite(t_s)) return;
  std::vector<Eigen::Vector3d> rates;  // the window's samples
  double first = t_s, last = t_s - window;
  for (const GyroSample& g : samples_) {
    if (!(g.time_s >= t_s - window && g.time_s <= t_s) || !g.rate_radps.allFinite()) continue;
    first = std::min(first, g.time_s);
    last = std::max(last, g.time_s);
    rates.push_back(g.rate_radps);
  }
  const int n = static_cast<int>(rates.size());
  if (n < 10 || !(last - first >= 0.9 * window)) return;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& w : rates) mean += w;
  mean /= n;
  Eigen::Vector3d variance = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& w : rates) variance += (w - mean).cwiseAbs2();
  variance /= std::max(1, n - 1);
  const double max_std = options_.standing_max_std_radps;
  if (!(variance.maxCoeff() <= max_std * max_std) ||
      !(mean.norm() <= options_.max_standing_bias_radps)) {
    return;  // turning (or shaking) before the first frame: no standing start
  }
  bias_ = mean;
  bias_origin_ = mean;
  bias_variance_ = variance.maxCoeff() / n;
  standing_start_ = true;
}

GyroRotation GyroPrior::Next(double t_s) {
  if (!have_time_) EstimateStandingBias(t_s);
  GyroRotation r;
  if (have_time_ && t_s > last_time_s_) {
    const double dt = t_s - last_time_s_;
    Eigen::Matrix3d R_imu = Eigen::Matrix3d::Identity();
    if (IntegrateGyro(samples_, last_time_s_, t_s, bias_, &R_imu)) {
      const Eigen::Matrix3d& R_ic = calibration_.R_imu_cam;
      r.ok = true;
      r.dt_s = dt;
      r.R_prev_curr = R_ic.transpose() * R_imu * R_ic;
      const double sc = calibration_.noise_density;
      r.covariance = (sc * sc * dt + bias_variance_ * dt * dt) * Eigen::Matrix3d::Identity();
    }
    bias_variance_ += calibration_.random_walk * calibration_.random_walk * dt;
  }
  if (!have_time_ || t_s > last_time_s_) {
    // Keep the last sample at or before t_s (it bounds the next interval) and the later ones.
    size_t keep = 0;
    for (size_t i = 0; i < samples_.size(); ++i) {
      if (samples_[i].time_s <= t_s) keep = i;
    }
    samples_.erase(samples_.begin(), samples_.begin() + static_cast<std::ptrdiff_t>(keep));
    last_time_s_ = t_s;
    have_time_ = true;
  }
  last_ = r;
  return r;
}

void GyroPrior::Observe(bool measured, const Eigen::Matrix3d& R_prev_curr_vo) {
  if (!measured || !last_.ok || !R_prev_curr_vo.allFinite()) {
    stretch_s_ = 0.0;
    stretch_gyro_.setIdentity();
    stretch_vo_.setIdentity();
    return;
  }
  const Eigen::Matrix3d& R_ic = calibration_.R_imu_cam;
  stretch_gyro_ = stretch_gyro_ * (R_ic * last_.R_prev_curr * R_ic.transpose());
  stretch_vo_ = stretch_vo_ * (R_ic * R_prev_curr_vo * R_ic.transpose());
  stretch_s_ += last_.dt_s;
  if (stretch_s_ < options_.bias_window_s) return;
  // gyro ≈ vo · Exp((b − b_est) T): the estimate's error is −Log(gyro⁻¹ vo) / T.
  const Eigen::Vector3d error = -LogSO3(stretch_gyro_.transpose() * stretch_vo_) / stretch_s_;
  if (error.allFinite() && error.norm() > options_.max_bias_radps && !standing_start_ &&
      !moving_start_ && bias_updates_ == 0 && error.norm() <= options_.max_standing_bias_radps) {
    // The moving start: a turn-on bias beyond max_bias_radps without a standing start shows as
    // the same large observation stretch after stretch; two in a row that agree within
    // max_bias_radps give the bias their mean, as a standing start would (a VO's bad stretch
    // does not repeat itself so).
    if (have_large_ && (error - large_).norm() <= options_.max_bias_radps) {
      const Eigen::Vector3d mean = 0.5 * (error + large_);
      bias_ += mean;
      bias_origin_ = bias_;
      bias_variance_ = std::max(bias_variance_, (0.5 * (error - large_)).squaredNorm());
      moving_start_ = true;
    } else {
      large_ = error;
      have_large_ = true;
    }
  } else if (error.allFinite() && error.norm() <= options_.max_bias_radps) {
    have_large_ = false;
    const double k = options_.bias_gain;
    bias_ += k * error;
    const Eigen::Vector3d online = bias_ - bias_origin_;
    if (online.norm() > options_.max_bias_radps) {
      bias_ = bias_origin_ + online * (options_.max_bias_radps / online.norm());
    }
    bias_variance_ *= (1.0 - k);
    ++bias_updates_;
  }
  stretch_s_ = 0.0;
  stretch_gyro_.setIdentity();
  stretch_vo_.setIdentity();
}

void RejectWeakMotionAgainstGyro(const ImuOptions& options, int reliable_min_inliers,
                                 const Eigen::Matrix3d& R_prior, RansacResult* ransac) {
  if (!ransac->ok() || ransac->num_inliers >= reliable_min_inliers ||
      !ransac->T_prev_curr.matrix().allFinite())
    return;
  const double error_rad =
      Eigen::AngleAxisd(R_prior.transpose() * ransac->T_prev_curr.linear()).angle();
  if (error_rad <= options.max_weak_rotation_error_deg * M_PI / 180.0) return;
  std::ostringstream msg;
  msg << "a weak motion (" << ransac->num_inliers << " inliers) turns " << error_rad * 180.0 / M_PI
      << " deg from the gyro's rotation";
  ransac->status = RansacResult::Status::kNoConsensus;
  ransac->message = msg.str();
  ransac->num_inliers = 0;
  ransac->inlier_mask.assign(ransac->inlier_mask.size(), false);
}

}  // namespace vo
