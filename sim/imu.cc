#include "sim/imu.h"

#include <cmath>

namespace sim {

uint64_t ImuNoiseSeed(uint64_t scenario_seed) {
  // Camera noise: DeriveSeed(seed, frame, 0 or 1). Index b = 2 is the IMU's alone.
  constexpr uint64_t kImuStream = 0x494D55;  // "IMU"
  return DeriveSeed(scenario_seed, kImuStream, 2);
}

ImuNoiseModel::ImuNoiseModel(const ImuOptions& options, uint64_t seed)
    : options_(options), rng_(seed), dt_s_(1.0 / options.rate_hz) {
  // The turn-on bias: three draws first, only when asked for (otherwise the stream is the one
  // of a scenario without the key).
  if (options.gyro_turn_on_bias_sigma_radps > 0.0)
    for (int i = 0; i < 3; ++i)
      gyro_bias_[i] = options.gyro_turn_on_bias_sigma_radps * rng_.Normal();
}

void ImuNoiseModel::Apply(ImuSample* s) {
  const double white_g = options_.gyro_noise_density / std::sqrt(dt_s_);
  const double white_a = options_.accel_noise_density / std::sqrt(dt_s_);
  const double walk_g = options_.gyro_random_walk * std::sqrt(dt_s_);
  const double walk_a = options_.accel_random_walk * std::sqrt(dt_s_);
  // Fixed draw order (gyro xyz, accel xyz, then the bias steps): the stream depends only on the
  // sample count.
  for (int i = 0; i < 3; ++i)
    s->gyro_radps[i] = s->gyro_true_radps[i] + gyro_bias_[i] + white_g * rng_.Normal();
  for (int i = 0; i < 3; ++i)
    s->accel_mps2[i] = s->accel_true_mps2[i] + accel_bias_[i] + white_a * rng_.Normal();
  s->gyro_bias_radps = gyro_bias_;
  s->accel_bias_mps2 = accel_bias_;
  for (int i = 0; i < 3; ++i) gyro_bias_[i] += walk_g * rng_.Normal();
  for (int i = 0; i < 3; ++i) accel_bias_[i] += walk_a * rng_.Normal();
}

Eigen::Isometry3d ImuPoseOnBody(const ImuOptions& o) {
  constexpr double kDeg = M_PI / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(o.yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(o.pitch_deg * kDeg, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(o.roll_deg * kDeg, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(o.x_m, o.y_m, o.z_m);
  return T;
}

double AllanDeviation(const std::vector<double>& x, double dt_s, int m) {
  const size_t n = x.size();
  if (m < 1 || n < 2 * static_cast<size_t>(m) + 1) return 0.0;
  // theta_k = dt * sum_{i<k} x_i, k = 0..n (in long double: millions of samples).
  std::vector<long double> theta(n + 1, 0.0L);
  for (size_t i = 0; i < n; ++i) theta[i + 1] = theta[i] + static_cast<long double>(x[i]) * dt_s;
  const size_t mm = static_cast<size_t>(m);
  long double sum = 0.0L;
  for (size_t k = 0; k + 2 * mm <= n; ++k) {
    const long double d = theta[k + 2 * mm] - 2.0L * theta[k + mm] + theta[k];
    sum += d * d;
  }
  const double tau = m * dt_s;
  const size_t terms = n + 1 - 2 * mm;
  return std::sqrt(static_cast<double>(sum / (2.0L * tau * tau * terms)));
}

}  // namespace sim
