// `vobench render`: the dataset on disk equals what the simulator rendered, is byte-identical
// run after run, and bad input ends with a message, a non-zero exit and no output folder.
#include "harness/render.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "harness/dataset.h"
#include "harness/dataset/rig.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

using vobench_test::ReadAll;
using vobench_test::RunVobench;

namespace fs = std::filesystem;
using vobench_test::TempDir;
using vobench_test::WriteText;

constexpr double kPoseTol = 1e-9;  // poses pass through text with 17 significant digits

// A short scenario in the real hallway (0.8 m straight), noise on.
std::string ShortScenario(const TempDir& dir, const std::string& extra = "") {
  const std::string path = dir / "short.yaml";
  WriteText(path, "name: short\nscene: " + std::string(VOBENCH_SOURCE_DIR) +
                      "/scenes/hallway_l.xml\npath:\n  - [0, 0]\n  - [0.8, 0]\n"
                      "noise:\n  pixel_sigma: 1.5\n  gain_sigma: 0.02\n" +
                      extra);
  return path;
}

TEST(RenderTest, DatasetOnDiskEqualsTheSimulationAndIsDeterministic) {
  TempDir dir("render");
  const std::string scenario_path = ShortScenario(dir);
  const auto a =
      RunVobench("render " + scenario_path + " --out " + (dir / "a") + " -q --format euroc");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const auto b =
      RunVobench("render " + scenario_path + " --out " + (dir / "b") + " -q --format euroc");
  ASSERT_EQ(b.exit_code, 0) << b.output;

  // Byte-identical trees, but for the marker (its command line, time and pid differ).
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir / "a"))
    if (e.is_regular_file() && e.path().filename() != ".vobench.json")
      files.push_back(fs::relative(e.path(), dir / "a").string());
  EXPECT_TRUE(fs::exists(fs::path(dir / "a") / ".vobench.json"));
  ASSERT_GT(files.size(), 20u);
  for (const auto& f : files)
    EXPECT_EQ(ReadAll(fs::path(dir / "b") / f), ReadAll(fs::path(dir / "a") / f)) << f;
  // The camera's mounting, as the scenario gives it (the defaults: 0.15 m ahead of the axle).
  harness::RigMounting rig;
  std::string rig_error;
  ASSERT_TRUE(harness::ReadRigYaml((fs::path(dir / "a") / "rig.yaml").string(), &rig, &rig_error))
      << rig_error;
  EXPECT_EQ(rig.forward_m, sim::CameraOptions().forward_m);
  EXPECT_EQ(rig.height_m, sim::CameraOptions().height_m);
  EXPECT_EQ(rig.pitch_deg, sim::CameraOptions().pitch_deg);
  EXPECT_TRUE(rig.has_imu);  // and the IMU's, as the scenario's imu keys give it
  EXPECT_EQ(rig.imu_z_m, sim::ImuOptions().z_m);
  for (const char* f :
       {"calib.txt", "times.txt", "poses.txt", "groundtruth_tum.txt", "image_0/000000.png",
        "image_1/000000.png", "depth/000000.png", "mav0/cam0/data.csv", "mav0/cam0/sensor.yaml",
        "mav0/cam1/sensor.yaml", "mav0/state_groundtruth_estimate0/data.csv", "mav0/imu0/data.csv",
        "mav0/imu0/sensor.yaml", "mav0/body.yaml"})
    EXPECT_TRUE(fs::exists(fs::path(dir / "a") / f)) << f;

  // Read back and compare with a fresh simulation of the same scenario.
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(scenario_path, &s, &error)) << error;
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  harness::KittiReader reader;
  ASSERT_TRUE(reader.Open(dir / "a", &error)) << error;
  const vo::StereoCamera cam = reader.camera();
  const sim::StereoCalibration& cal = simulator->calibration();
  EXPECT_NEAR(cam.fx_px, cal.fx_px, 1e-9);
  EXPECT_NEAR(cam.cx_px, cal.cx_px, 1e-9);
  EXPECT_NEAR(cam.baseline_m, cal.baseline_m, 1e-9);
  EXPECT_EQ(cam.width, cal.width);
  ASSERT_TRUE(reader.has_ground_truth());
  sim::StereoFrame f;
  size_t n = 0;
  Eigen::Isometry3d T_world_first;
  while (simulator->Next(&f, &error)) {
    ASSERT_LT(n, reader.size());
    harness::DatasetFrame d;
    ASSERT_TRUE(reader.ReadFrame(n, &d, &error)) << error;
    EXPECT_EQ(cv::norm(d.left, f.left, cv::NORM_INF), 0) << n;
    EXPECT_EQ(cv::norm(d.right, f.right, cv::NORM_INF), 0) << n;
    EXPECT_NEAR(d.time_s, f.time_s, 1e-9);
    if (n == 0) T_world_first = f.T_world_cam0;
    const Eigen::Isometry3d expected = T_world_first.inverse() * f.T_world_cam0;
    EXPECT_LT((reader.poses()[n].matrix() - expected.matrix()).cwiseAbs().maxCoeff(), kPoseTol)
        << n;
    EXPECT_LT((d.T_world_cam0.matrix() - f.T_world_cam0.matrix()).cwiseAbs().maxCoeff(), kPoseTol)
        << n;
    // Depth to the millimetre (16-bit PNG in mm).
    const float z_gt = f.depth_m.at<float>(120, 160);
    EXPECT_NEAR(d.depth_m.at<float>(120, 160), z_gt, 0.0005 + 1e-6) << n;
    ++n;
  }
  EXPECT_EQ(n, reader.size());
}

class RenderBadInputTest : public ::testing::Test {
 protected:
  RenderBadInputTest() : dir_("badrender") {}
  // Runs render on `yaml`; expects failure, a message naming `expect_in_message`, no output.
  void ExpectRefused(const std::string& yaml, const std::string& expect_in_message) {
    const std::string path = dir_ / "bad.yaml";
    WriteText(path, yaml);
    const std::string out = dir_ / "out";
    const auto r = RunVobench("render " + path + " --out " + out + " -q");
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(expect_in_message), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out)) << "a failed render must leave no output folder";
    for (const auto& e : fs::directory_iterator(dir_.str()))
      EXPECT_EQ(e.path().filename().string().find("out"), std::string::npos) << e.path();
  }
  TempDir dir_;
};

const std::string kScene = std::string("scene: ") + VOBENCH_SOURCE_DIR + "/scenes/hallway_l.xml\n";

TEST_F(RenderBadInputTest, MissingScenario) {
  const auto r = RunVobench("render " + (dir_ / "none.yaml") + " --out " + (dir_ / "out") + " -q");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("none.yaml"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}
TEST_F(RenderBadInputTest, MalformedYaml) {
  ExpectRefused(kScene + "path: [[0, 0], [1, 0]\n", "malformed YAML");
}
TEST_F(RenderBadInputTest, UnknownKey) {
  ExpectRefused(kScene + "path: [[0, 0], [1, 0]]\nspeed: 3\n", "'speed'");
}
TEST_F(RenderBadInputTest, WrongType) {
  ExpectRefused(kScene + "path: [[0, 0], [1, 0]]\nrate_hz: [1]\n", "'rate_hz'");
}
TEST_F(RenderBadInputTest, NegativeBaseline) {
  ExpectRefused(kScene + "path: [[0, 0], [1, 0]]\ncamera:\n  baseline_m: -1\n",
                "'camera.baseline_m'");
}
TEST_F(RenderBadInputTest, NaN) {
  ExpectRefused(kScene + "path: [[0, 0], [1, 0]]\nrate_hz: .nan\n", "'rate_hz'");
}
TEST_F(RenderBadInputTest, ShortPath) {
  ExpectRefused(kScene + "path: [[0, 0]]\n", "at least 2 waypoints");
}
TEST_F(RenderBadInputTest, MalformedMjcf) {
  WriteText(dir_ / "broken.xml", "<mujoco><worldbody><body></worldbody></mujoco>");
  ExpectRefused("scene: broken.xml\npath: [[0, 0], [1, 0]]\n", "broken.xml");
}
TEST_F(RenderBadInputTest, PathLeavesTheHallway) {
  // The robot drives into a wall... walls are visual-only, so instead: an unreachable time limit.
  ExpectRefused(kScene + "path: [[0, 0], [3, 0]]\nmax_duration_s: 1\n", "max_duration_s");
}
TEST_F(RenderBadInputTest, ExistingOutputIsRefused) {
  fs::create_directories(dir_ / "exists");
  WriteText(dir_ / "exists/keep.txt", "x");
  const auto r =
      RunVobench("render " + ShortScenario(dir_) + " --out " + (dir_ / "exists") + " -q");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(fs::exists(dir_ / "exists/keep.txt"));
}

}  // namespace
