// Issue #35: a real gyro's turn-on bias in the simulator (imu.gyro_turn_on_bias_sigma_radps) and
// the samples of the robot standing before frame 0 (imu.pre_roll_s). The VO's standing start
// (vo/gyro_prior.h, ImuOptions::standing_start_s) learns the bias from them: through the
// L-hallway's corner with a turn-on bias of σ 0.05 rad/s per axis (2.9°/s; EuRoC's ADIS16448 read
// 0.078 rad/s about z) the run ends as it does without any bias. Without the pre-roll there is
// no standing start, the bias is beyond the online filter's bound (imu.max_bias_radps), and the
// gyro turns the estimate by degrees until the moving start has it (two 2 s stretches): what
// the standing start is for.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "harness/run.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "tests/sim/sim_test_util.h"
#include "vo/odometry.h"

namespace harness {
namespace {

using vobench_test::TempDir;
using vobench_test::WriteText;

// The L-hallway's corner (3 m, the 90° turn, 3 m) standing 1.2 s before frame 0, with `imu`
// keys added to the scenario's IMU.
std::string CornerYaml(const std::string& imu_keys) {
  return "name: corner\nscene: " + std::string(VOBENCH_SOURCE_DIR) +
         "/scenes/hallway_l.xml\nsettle_s: 1.2\npath:\n  - [5.0, 0.0]\n  - [8.0, 0.0]\n"
         "  - [8.0, 3.0]\nnoise:\n  pixel_sigma: 1.5\n  gain_sigma: 0.02\nimu:\n  rate_hz: 250\n" +
         imu_keys;
}

RunSummary RunCorner(const TempDir& dir, const std::string& name, const std::string& imu_keys) {
  WriteText(dir / (name + ".yaml"), CornerYaml(imu_keys));
  sim::Scenario scenario;
  std::string error;
  EXPECT_TRUE(sim::LoadScenario(dir / (name + ".yaml"), &scenario, &error)) << error;
  RunOptions run;
  run.out_dir = dir / name;
  run.progress = false;
  run.plots = false;
  RunSummary s;
  EXPECT_TRUE(RunScenario(scenario, vo::OdometryOptions(), run, &s, &error)) << error;
  return s;
}

TEST(GyroBiasTest, TheStandingStartLearnsASimulatedTurnOnBias) {
  TempDir dir("gyro_bias");
  const RunSummary none = RunCorner(dir, "none", "");
  const RunSummary standing =
      RunCorner(dir, "standing", "  gyro_turn_on_bias_sigma_radps: 0.05\n  pre_roll_s: 1.0\n");
  const RunSummary moving = RunCorner(dir, "moving", "  gyro_turn_on_bias_sigma_radps: 0.05\n");
  ASSERT_TRUE(none.has_ground_truth && standing.has_ground_truth && moving.has_ground_truth);
  EXPECT_EQ(none.lost_frames, 0);
  EXPECT_EQ(standing.lost_frames, 0);
  // Without a bias: 0.28° at the end (2026-12-06). With the bias and the standing start: the
  // same within 0.1°.
  EXPECT_LT(none.metrics.end_rotation_error_deg, 0.5);
  EXPECT_NEAR(standing.metrics.end_rotation_error_deg, none.metrics.end_rotation_error_deg, 0.1);
  EXPECT_NEAR(standing.metrics.end_pose_error_m, none.metrics.end_pose_error_m, 0.005);
  // Without the pre-roll the first two stretches carry the bias (4.75° at the end, 2026-12-06;
  // 11.9° before the moving start).
  EXPECT_GT(moving.metrics.end_rotation_error_deg, 3.0);
}

TEST(GyroBiasTest, PreRollSamplesComeWithFrameZeroAndTheBiasIsDrawnOnlyWhenAsked) {
  TempDir dir("gyro_bias");
  auto first_frames = [&](const std::string& imu_keys, std::vector<sim::ImuSample>* frame0,
                          std::vector<sim::ImuSample>* frame1) {
    WriteText(dir / "s.yaml", CornerYaml(imu_keys));
    sim::Scenario scenario;
    std::string error;
    ASSERT_TRUE(sim::LoadScenario(dir / "s.yaml", &scenario, &error)) << error;
    auto simulator = sim::Simulator::Create(scenario, &error);
    ASSERT_TRUE(simulator) << error;
    sim::StereoFrame f;
    ASSERT_TRUE(simulator->Next(&f, &error)) << error;
    *frame0 = f.imu;
    ASSERT_TRUE(simulator->Next(&f, &error)) << error;
    *frame1 = f.imu;
  };
  std::vector<sim::ImuSample> plain0, plain1, zero0, zero1, pre0, pre1, bias0, bias1;
  first_frames("", &plain0, &plain1);
  first_frames("  gyro_turn_on_bias_sigma_radps: 0\n  pre_roll_s: 0\n", &zero0, &zero1);
  first_frames("  pre_roll_s: 1.0\n", &pre0, &pre1);
  first_frames("  gyro_turn_on_bias_sigma_radps: 0.05\n", &bias0, &bias1);
  // Both keys at 0: the samples of a scenario without them, bit for bit.
  ASSERT_EQ(zero0.size(), plain0.size());
  ASSERT_EQ(zero1.size(), plain1.size());
  for (size_t i = 0; i < plain1.size(); ++i) EXPECT_EQ(zero1[i].gyro_radps, plain1[i].gyro_radps);
  // The pre-roll: 250 samples more with frame 0, from -1 s, the robot standing (true rate ~0).
  ASSERT_EQ(pre0.size(), plain0.size() + 250u);
  EXPECT_NEAR(pre0.front().time_s, -1.0, 1e-9);
  for (const sim::ImuSample& s : pre0) {
    EXPECT_LE(s.time_s, 1e-9);
    EXPECT_LT(s.gyro_true_radps.norm(), 1e-3) << s.time_s;
  }
  EXPECT_EQ(pre1.size(), plain1.size());
  // The turn-on bias: in the samples from the first on, a few hundredths of a rad/s.
  ASSERT_FALSE(bias0.empty());
  EXPECT_GT(bias0.front().gyro_bias_radps.norm(), 0.005);
  EXPECT_LT(bias0.front().gyro_bias_radps.norm(), 0.3);
  EXPECT_EQ(plain0.front().gyro_bias_radps.norm(), 0.0);
}

TEST(GyroBiasTest, BadKeysAreRefusedAtTheirLine) {
  TempDir dir("gyro_bias");
  const struct {
    std::string keys;
    std::string expect;
  } cases[] = {{"  pre_roll_s: 2.0\n", "imu.pre_roll_s"},
               {"  pre_roll_s: -1\n", "imu.pre_roll_s"},
               {"  gyro_turn_on_bias_sigma_radps: -0.1\n", "imu.gyro_turn_on_bias_sigma_radps"}};
  for (const auto& c : cases) {
    WriteText(dir / "bad.yaml", CornerYaml(c.keys));
    sim::Scenario scenario;
    std::string error;
    EXPECT_FALSE(sim::LoadScenario(dir / "bad.yaml", &scenario, &error)) << c.keys;
    EXPECT_NE(error.find(dir / "bad.yaml"), std::string::npos) << error;
    EXPECT_NE(error.find(c.expect), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace harness
