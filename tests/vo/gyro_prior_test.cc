#include "vo/gyro_prior.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d Exp(const Eigen::Vector3d& w) {
  return w.norm() < 1e-15 ? Eigen::Matrix3d::Identity()
                          : Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
}

double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

// Samples of a constant rate every period_s from t0_s to t1_s (inclusive where it falls).
std::vector<GyroSample> ConstantRate(const Eigen::Vector3d& rate, double t0_s, double t1_s,
                                     double period_s) {
  std::vector<GyroSample> s;
  for (int k = 0;; ++k) {
    const double t = t0_s + k * period_s;
    if (t > t1_s + 1e-12) break;
    GyroSample g;
    g.time_s = t;
    g.rate_radps = rate;
    s.push_back(g);
  }
  return s;
}

// A mounting that is not the identity: the IMU turned 30° about x and 100° about z.
Eigen::Matrix3d Mounting() {
  return (Eigen::AngleAxisd(100.0 * kDeg, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(30.0 * kDeg, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TEST(GyroPriorTest, AConstantRateIntegratesToTheExactRotation) {
  const Eigen::Vector3d w(0.1, -0.2, 0.3);  // rad/s
  // Samples at 250 Hz with stamps that do not fall on the frames' times.
  const std::vector<GyroSample> s = ConstantRate(w, 0.0013, 2.0, 0.004);
  Eigen::Matrix3d R;
  ASSERT_TRUE(IntegrateGyro(s, 0.1, 0.6, Eigen::Vector3d::Zero(), &R));
  EXPECT_LT(AngleBetween(R, Exp(0.5 * w)), 1e-12);
  // A bias is subtracted from every sample.
  const Eigen::Vector3d b(0.01, 0.02, -0.03);
  ASSERT_TRUE(IntegrateGyro(s, 0.1, 0.6, b, &R));
  EXPECT_LT(AngleBetween(R, Exp(0.5 * (w - b))), 1e-12);
  // The camera frame: R_prev_curr = R_cam_imu · R_imu · R_imu_cam, frame after frame.
  GyroCalibration calibration;
  calibration.R_imu_cam = Mounting();
  GyroPrior gyro(ImuOptions(), calibration);
  gyro.AddSamples(s);
  EXPECT_FALSE(gyro.Next(0.1).ok);  // the first frame has no interval
  for (double t : {0.2, 0.35, 0.5}) {
    const GyroRotation r = gyro.Next(t);
    ASSERT_TRUE(r.ok) << t;
    const double dt = t == 0.2 ? 0.1 : 0.15;
    EXPECT_NEAR(r.dt_s, dt, 1e-12);
    const Eigen::Matrix3d expected = Mounting().transpose() * Exp(dt * w) * Mounting();
    EXPECT_LT(AngleBetween(r.R_prev_curr, expected), 1e-12) << t;
  }
}

TEST(GyroPriorTest, ALinearRateIntegratesByTheTrapezoid) {
  // A rate growing linearly about one axis: the angle is the integral, exactly.
  std::vector<GyroSample> s;
  for (int k = 0; k <= 100; ++k) {
    GyroSample g;
    g.time_s = 0.01 * k;
    g.rate_radps = Eigen::Vector3d(0.0, 0.0, 2.0 * g.time_s);  // ω = 2t
    s.push_back(g);
  }
  Eigen::Matrix3d R;
  ASSERT_TRUE(IntegrateGyro(s, 0.2, 0.7, Eigen::Vector3d::Zero(), &R));
  EXPECT_LT(AngleBetween(R, Exp(Eigen::Vector3d(0.0, 0.0, 0.7 * 0.7 - 0.2 * 0.2))), 1e-12);
}

TEST(GyroPriorTest, AGapInTheSamplesGivesNoRotation) {
  const std::vector<GyroSample> s = ConstantRate(Eigen::Vector3d(0.0, 0.0, 1.0), 0.0, 1.0, 0.004);
  Eigen::Matrix3d R;
  EXPECT_FALSE(IntegrateGyro(s, 5.0, 5.1, Eigen::Vector3d::Zero(), &R));
  EXPECT_FALSE(IntegrateGyro(s, 0.5, 0.5, Eigen::Vector3d::Zero(), &R));
  EXPECT_FALSE(IntegrateGyro({}, 0.1, 0.2, Eigen::Vector3d::Zero(), &R));
  GyroPrior gyro{ImuOptions(), GyroCalibration()};
  gyro.AddSamples(s);
  gyro.Next(4.0);
  EXPECT_FALSE(gyro.Next(4.1).ok);
  EXPECT_FALSE(gyro.Next(4.1).ok);  // a time that does not increase
}

TEST(GyroPriorTest, TheCovarianceGrowsWithTimeAsTheNoiseModelSays) {
  GyroCalibration calibration;
  calibration.noise_density = 7e-5;  // rad/s/√Hz
  calibration.random_walk = 2e-5;    // rad/s²/√Hz
  ImuOptions options;
  options.initial_bias_sigma_radps = 0.001;
  GyroPrior gyro(options, calibration);
  gyro.AddSamples(ConstantRate(Eigen::Vector3d::Zero(), 0.0, 10.0, 0.004));
  gyro.Next(0.0);
  // Σ = (σ_c² Δt + P Δt²) I, P = σ_b0² + σ_bc² · (time before the interval).
  double P = 0.001 * 0.001;
  double t = 0.0;
  double previous_sigma = 0.0;
  for (double dt : {0.05, 0.1, 0.2, 0.4}) {
    t += dt;
    const GyroRotation r = gyro.Next(t);
    ASSERT_TRUE(r.ok);
    const double expected = 7e-5 * 7e-5 * dt + P * dt * dt;
    EXPECT_NEAR(r.covariance(0, 0), expected, 1e-18) << dt;
    EXPECT_NEAR(r.covariance(2, 2), expected, 1e-18);
    EXPECT_EQ(r.covariance(0, 1), 0.0);
    EXPECT_NEAR(r.sigma_rad(), std::sqrt(expected), 1e-12);
    EXPECT_GT(r.sigma_rad(), previous_sigma);  // a longer interval, a larger σ
    previous_sigma = r.sigma_rad();
    P += 2e-5 * 2e-5 * dt;
    EXPECT_NEAR(gyro.bias_variance(), P, 1e-18);
  }
}

// The robot turns (a varying rate about all axes) for 60 s; the gyro reads the truth plus a
// constant bias (5.4e-3 rad/s), the VO measures the true rotation of each frame (30 Hz) with
// noise_deg of noise per axis. The bias estimate after it.
Eigen::Vector3d EstimatedBias(const Eigen::Vector3d& bias, double noise_deg, int* updates) {
  GyroCalibration calibration;
  calibration.R_imu_cam = Mounting();
  GyroPrior gyro(ImuOptions(), calibration);
  auto rate = [](double t) {
    return Eigen::Vector3d(0.2 * std::sin(0.5 * t), 0.1 * std::cos(0.3 * t), 0.4);
  };
  std::vector<GyroSample> samples;
  for (int k = 0; k <= 250 * 60; ++k) {
    GyroSample g;
    g.time_s = 0.004 * k;
    g.rate_radps = rate(g.time_s) + bias;
    samples.push_back(g);
  }
  gyro.AddSamples(samples);
  SplitMix64 rng(7);
  gyro.Next(0.0);
  const double dt = 1.0 / 30.0;
  for (int i = 1; i <= 30 * 60; ++i) {
    const double t0 = (i - 1) * dt, t1 = i * dt;
    const GyroRotation r = gyro.Next(t1);
    EXPECT_TRUE(r.ok);
    // The true rotation (the same integration without the bias, IMU frame), in the camera's,
    // with its noise.
    Eigen::Matrix3d R_true_imu;
    std::vector<GyroSample> truth;
    for (const GyroSample& s : samples) {
      if (s.time_s >= t0 - 0.01 && s.time_s <= t1 + 0.01) {
        GyroSample g = s;
        g.rate_radps -= bias;
        truth.push_back(g);
      }
    }
    EXPECT_TRUE(IntegrateGyro(truth, t0, t1, Eigen::Vector3d::Zero(), &R_true_imu));
    const Eigen::Vector3d noise(test::Normal(&rng), test::Normal(&rng), test::Normal(&rng));
    const Eigen::Matrix3d R_vo =
        Mounting().transpose() * R_true_imu * Mounting() * Exp(noise_deg * kDeg * noise);
    gyro.Observe(true, R_vo);
  }
  *updates = gyro.bias_updates();
  return gyro.bias_radps();
}

TEST(GyroPriorTest, TheBiasEstimateConvergesOnTheVosRotations) {
  const Eigen::Vector3d bias(0.003, -0.002, 0.004);  // rad/s, IMU frame
  int updates = 0;
  // Exact rotations from the VO: 30 stretches of 2 s, each taking 0.2 of the error away
  // (0.8^30 = 1.2e-3 of it left).
  Eigen::Vector3d b = EstimatedBias(bias, 0.0, &updates);
  EXPECT_EQ(updates, 30);
  EXPECT_LT((b - bias).norm(), 2e-5) << b.transpose();
  // With the noise of a bundle-adjusted motion (0.01° per axis and frame: 6.8e-4 rad/s per
  // stretch and axis, 2.3e-4 after the filter's gain): within 1e-3 rad/s (0.06°/s).
  b = EstimatedBias(bias, 0.01, &updates);
  EXPECT_EQ(updates, 30);
  EXPECT_LT((b - bias).norm(), 1e-3) << b.transpose();
}

TEST(GyroPriorTest, AStretchThatDisagreesGrosslyIsNotABias) {
  // The VO's rotation off by 10° over a stretch (a wrong motion): the bias stays.
  GyroPrior gyro{ImuOptions(), GyroCalibration()};
  gyro.AddSamples(ConstantRate(Eigen::Vector3d(0.0, 0.0, 0.5), 0.0, 10.0, 0.004));
  gyro.Next(0.0);
  for (int i = 1; i <= 90; ++i) {
    const GyroRotation r = gyro.Next(i / 30.0);
    gyro.Observe(true, r.R_prev_curr * Exp(Eigen::Vector3d(0.0, 0.0, 0.2 * kDeg)));
  }
  EXPECT_EQ(gyro.bias_radps(), Eigen::Vector3d::Zero());
  // A lost frame ends a stretch without an observation.
  GyroPrior other{ImuOptions(), GyroCalibration()};
  other.AddSamples(ConstantRate(Eigen::Vector3d(0.0, 0.0, 0.5), 0.0, 10.0, 0.004));
  other.Next(0.0);
  for (int i = 1; i <= 90; ++i) {
    const GyroRotation r = other.Next(i / 30.0);
    other.Observe(i % 30 != 0, r.R_prev_curr);
  }
  EXPECT_EQ(other.bias_updates(), 0);
}

// A gyro at 200 Hz reading rate(t) + a turn-on bias + noise of 0.015 rad/s per axis (the
// numbers of EuRoC V1_01's ADIS16448 standing still: 0.078 rad/s about z, 0.013-0.021 rad/s of
// noise and vibration) from `from_s` to 3 s; the frames start at 0.
const Eigen::Vector3d kTurnOnBias(-0.002, 0.021, 0.078);
template <typename Rate>
std::vector<GyroSample> NoisyGyro(const Rate& rate, double from_s, uint64_t seed) {
  SplitMix64 rng(seed);
  std::vector<GyroSample> samples;
  for (int k = 0; from_s + k * 0.005 <= 3.0 + 1e-9; ++k) {
    GyroSample g;
    g.time_s = from_s + k * 0.005;
    const Eigen::Vector3d noise(test::Normal(&rng), test::Normal(&rng), test::Normal(&rng));
    g.rate_radps = rate(g.time_s) + kTurnOnBias + 0.015 * noise;
    samples.push_back(g);
  }
  return samples;
}

// Standing still for 2 s before the first frame, then turning at 0.3 rad/s: the standing start
// gives the turn-on bias at the first frame (the mean of the last second's 201 samples, good to
// 0.015 / sqrt(201) = 1.1e-3 rad/s per axis), and the first frame's rotation is right to the
// noise of its 7 samples (0.015 rad/s · 1/30 s / sqrt(7): 0.011° per axis; asserted 0.05°)
// where a bias of 0 would be 0.15° off.
TEST(GyroPriorTest, AMovingStartTakesATurnOnBiasBeyondTheOnlineBound) {
  // No standing start (the samples start with the frames); the gyro reads a turn at 0.5 rad/s
  // about z plus EuRoC's turn-on bias (0.081 rad/s, four times max_bias_radps); the VO measures
  // the true rotations (30 Hz). The first 2 s stretch alone sets nothing; the second, agreeing
  // with it, gives the bias (the moving start); later stretches refine it online.
  const Eigen::Vector3d bias = kTurnOnBias;
  const Eigen::Vector3d rate(0.0, 0.0, 0.5);
  GyroPrior gyro{ImuOptions(), GyroCalibration()};
  gyro.AddSamples(ConstantRate(rate + bias, 0.0, 10.0, 0.004));
  gyro.Next(0.0);
  for (int i = 1; i <= 9 * 30; ++i) {
    const GyroRotation r = gyro.Next(i / 30.0);
    ASSERT_TRUE(r.ok);
    gyro.Observe(true, Exp(rate / 30.0));
    if (i == 60) {
      EXPECT_FALSE(gyro.moving_start());
      EXPECT_EQ(gyro.bias_radps(), Eigen::Vector3d::Zero());
    }
    if (i == 120) {
      // A stretch's observation is first order in the rotation: the bias's x and y parts,
      // seen from a frame that turns 1 rad over the stretch, come out 13 % short (0.0102 of
      // 0.081 rad/s left); z, the turn's axis, to 1e-4.
      EXPECT_TRUE(gyro.moving_start());
      EXPECT_LT((gyro.bias_radps() - bias).norm(), 0.15 * bias.norm())
          << gyro.bias_radps().transpose();
      EXPECT_NEAR(gyro.bias_radps().z(), bias.z(), 1e-4);
    }
  }
  EXPECT_FALSE(gyro.standing_start());
  // The online estimate takes part of the rest (0.0072 left after 9 s).
  EXPECT_LT((gyro.bias_radps() - bias).norm(), 0.1 * bias.norm());

  // Two large observations that do not agree (a VO off by +3 and then by -3 °/s about x): no
  // moving start, the bias stays 0.
  GyroPrior other{ImuOptions(), GyroCalibration()};
  other.AddSamples(ConstantRate(rate, 0.0, 10.0, 0.004));
  other.Next(0.0);
  for (int i = 1; i <= 9 * 30; ++i) {
    other.Next(i / 30.0);
    const double sign = ((i - 1) / 60) % 2 == 0 ? 1.0 : -1.0;
    other.Observe(true, Exp(rate / 30.0 + Eigen::Vector3d(sign * 0.1 * kDeg, 0.0, 0.0)));
  }
  EXPECT_FALSE(other.moving_start());
  EXPECT_EQ(other.bias_radps(), Eigen::Vector3d::Zero());
}

TEST(GyroPriorTest, AStandingStartGivesTheTurnOnBias) {
  auto rate = [](double t) {
    return t < 0.0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0, 0, 0.3);
  };
  const std::vector<GyroSample> samples = NoisyGyro(rate, -2.0, 21);
  GyroCalibration calibration;
  calibration.R_imu_cam = Mounting();
  GyroPrior gyro(ImuOptions(), calibration);
  gyro.AddSamples(samples);
  EXPECT_FALSE(gyro.Next(0.0).ok);  // the first frame
  ASSERT_TRUE(gyro.standing_start());
  EXPECT_LT((gyro.bias_radps() - kTurnOnBias).norm(), 0.004) << gyro.bias_radps().transpose();
  EXPECT_LT(gyro.bias_variance(), 0.002 * 0.002);
  const GyroRotation r = gyro.Next(1.0 / 30.0);
  ASSERT_TRUE(r.ok);
  const Eigen::Matrix3d R_true =
      Mounting().transpose() * Exp(Eigen::Vector3d(0, 0, 0.3 / 30.0)) * Mounting();
  EXPECT_LT(AngleBetween(r.R_prev_curr, R_true), 0.05 * kDeg);
  // Off (standing_start_s 0): the bias starts at 0 and the frame is off by the bias's turn.
  ImuOptions off;
  off.standing_start_s = 0.0;
  GyroPrior plain(off, calibration);
  plain.AddSamples(samples);
  plain.Next(0.0);
  EXPECT_FALSE(plain.standing_start());
  EXPECT_EQ(plain.bias_radps(), Eigen::Vector3d::Zero());
  EXPECT_GT(AngleBetween(plain.Next(1.0 / 30.0).R_prev_curr, R_true), 0.1 * kDeg);
}

// What is no standing start: turning before the first frame (the rate varies by more than
// standing_max_std_radps), a rate steadier than that but larger than max_standing_bias_radps
// (a steady turn), and too short a record (0.5 s of the 1 s window).
TEST(GyroPriorTest, TurningOrTooShortARecordIsNoStandingStart) {
  auto turning = [](double t) { return Eigen::Vector3d(0.0, 0.0, 0.3 * std::sin(3.0 * t)); };
  auto steady = [](double) { return Eigen::Vector3d(0.0, 0.0, 0.3); };
  auto still = [](double) { return Eigen::Vector3d::Zero(); };
  struct Case {
    const char* name;
    std::vector<GyroSample> samples;
  };
  const Case cases[] = {{"turning", NoisyGyro(turning, -2.0, 22)},
                        {"steady turn", NoisyGyro(steady, -2.0, 23)},
                        {"too short", NoisyGyro(still, -0.5, 24)}};
  for (const Case& c : cases) {
    GyroPrior gyro{ImuOptions(), GyroCalibration()};
    gyro.AddSamples(c.samples);
    gyro.Next(0.0);
    EXPECT_FALSE(gyro.standing_start()) << c.name;
    EXPECT_EQ(gyro.bias_radps(), Eigen::Vector3d::Zero()) << c.name;
  }
}

// After a standing start the online estimate corrects the standing one (max_bias_radps about
// it, not about 0): the VO's exact rotations over a 2 s stretch move it towards the truth, and
// it stays at the turn-on bias's size (0.078 rad/s, four times max_bias_radps).
TEST(GyroPriorTest, TheOnlineEstimateCorrectsTheStandingOne) {
  auto rate = [](double t) {
    return t < 0.0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0, 0, 0.3);
  };
  GyroPrior gyro{ImuOptions(), GyroCalibration()};
  gyro.AddSamples(NoisyGyro(rate, -2.0, 25));
  gyro.Next(0.0);
  ASSERT_TRUE(gyro.standing_start());
  const double before = (gyro.bias_radps() - kTurnOnBias).norm();
  for (int i = 1; i <= 61; ++i) {
    gyro.Next(i / 30.0);
    gyro.Observe(true, Exp(Eigen::Vector3d(0, 0, 0.3 / 30.0)));
  }
  EXPECT_EQ(gyro.bias_updates(), 1);
  EXPECT_GT(gyro.bias_radps().norm(), 0.07);
  EXPECT_LT((gyro.bias_radps() - kTurnOnBias).norm(), std::max(before, 0.004));
}

TEST(GyroPriorTest, OptionsRefuseBadFields) {
  test::ExpectOptionsRefuseBadFields<ImuOptions>({
      {"min_rotation_sigma_deg", [](ImuOptions* o) { o->min_rotation_sigma_deg = 0.0; }},
      {"max_weak_rotation_error_deg", [](ImuOptions* o) { o->max_weak_rotation_error_deg = 0.0; }},
      {"initial_bias_sigma_radps", [](ImuOptions* o) { o->initial_bias_sigma_radps = -1.0; }},
      {"bias_gain", [](ImuOptions* o) { o->bias_gain = 1.5; }},
      {"bias_window_s", [](ImuOptions* o) { o->bias_window_s = 0.0; }},
      {"max_bias_radps", [](ImuOptions* o) { o->max_bias_radps = NAN; }},
      {"standing_start_s", [](ImuOptions* o) { o->standing_start_s = -1.0; }},
      {"standing_max_std_radps", [](ImuOptions* o) { o->standing_max_std_radps = 0.0; }},
      {"max_standing_bias_radps", [](ImuOptions* o) { o->max_standing_bias_radps = NAN; }},
  });
  test::ExpectOptionsRefuseBadFields<GyroCalibration>({
      {"R_imu_cam", [](GyroCalibration* c) { c->R_imu_cam = 2.0 * Eigen::Matrix3d::Identity(); }},
      {"noise_density", [](GyroCalibration* c) { c->noise_density = -1.0; }},
      {"random_walk", [](GyroCalibration* c) { c->random_walk = INFINITY; }},
  });
}

TEST(GyroPriorTest, AWeakMotionTheGyroContradictsIsNoConsensus) {
  const ImuOptions options;  // max_weak_rotation_error_deg 0.5
  const Eigen::Matrix3d R_gyro(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()));
  auto ransac_at = [&](double off_deg, int inliers) {
    RansacResult r;
    r.status = RansacResult::Status::kOk;
    r.num_inliers = inliers;
    r.inlier_mask.assign(40, true);
    r.T_prev_curr = Eigen::Isometry3d::Identity();
    r.T_prev_curr.linear() =
        R_gyro * Eigen::AngleAxisd(off_deg * M_PI / 180.0, Eigen::Vector3d::UnitX());
    RejectWeakMotionAgainstGyro(options, 30, R_gyro, &r);
    return r;
  };
  const RansacResult far = ransac_at(0.8, 12);
  EXPECT_EQ(far.status, RansacResult::Status::kNoConsensus);
  EXPECT_EQ(far.num_inliers, 0);
  EXPECT_EQ(std::count(far.inlier_mask.begin(), far.inlier_mask.end(), true), 0);
  EXPECT_THAT(far.message, ::testing::HasSubstr("from the gyro's rotation"));
  EXPECT_TRUE(ransac_at(0.3, 12).ok());  // within the gate
  EXPECT_TRUE(ransac_at(5.0, 30).ok());  // reliable: never second-guessed
}

}  // namespace
}  // namespace vo
