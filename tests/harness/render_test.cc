// `vobench render`: the dataset on disk equals what the simulator rendered, is byte-identical
// run after run, and bad input ends with a message, a non-zero exit and no output folder.
#include "harness/render.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <sstream>
#include <tuple>
#include <utility>

#include "harness/dataset.h"
#include "harness/dataset/rectification.h"
#include "harness/dataset/rig.h"
#include "harness/pipeline.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

using vobench_test::ExpectTrajectoriesNear;
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

// calibration_error (issue #34): the exported calibration differs from the true one exactly as
// configured (baseline and focal scaled, cam1's T_BS turned about its y axis); the images are
// the same bytes; the in-memory sequence's camera has the same error; the rotation, which a
// rectified calibration cannot hold, is refused for KITTI and `run`, nothing written.
// The KITTI side of a render with a lens or a rotated cam1 (`dir`, rendered --format euroc)
// holds the EuRoC side's raw frames rectified exactly as `eval --format euroc` rectifies them:
// the same camera in calib.txt, the same images bit for bit, the rectified left camera's ground
// truth, no depth. Returns the rectified camera.
vo::StereoCamera ExpectKittiSideIsEvalsRectification(const std::string& dir) {
  std::string error;
  harness::EurocReader euroc;
  harness::KittiReader kitti;
  EXPECT_TRUE(euroc.Open(dir, &error)) << error;
  EXPECT_TRUE(kitti.Open(dir, &error)) << error;
  harness::StereoRectification rectification;
  EXPECT_TRUE(euroc.Rectification(&rectification, &error)) << error;
  EXPECT_FALSE(rectification.IsIdentity());
  const vo::StereoCamera& c = rectification.camera;
  EXPECT_EQ(kitti.camera().fx_px, c.fx_px);
  EXPECT_EQ(kitti.camera().cx_px, c.cx_px);
  EXPECT_EQ(kitti.camera().cy_px, c.cy_px);
  EXPECT_NEAR(kitti.camera().baseline_m, c.baseline_m, 1e-15);  // calib.txt holds -fx b
  EXPECT_FALSE(fs::exists(fs::path(dir) / "depth"));
  EXPECT_EQ(kitti.size(), euroc.size());
  harness::DatasetFrame raw, rectified;
  for (size_t i = 0; i < euroc.size(); i += 7) {
    EXPECT_TRUE(euroc.ReadFrame(i, &raw, &error)) << error;
    EXPECT_TRUE(kitti.ReadFrame(i, &rectified, &error)) << error;
    harness::RectifyFrame(rectification, &raw);
    EXPECT_EQ(cv::norm(raw.left, rectified.left, cv::NORM_INF), 0.0) << "frame " << i;
    EXPECT_EQ(cv::norm(raw.right, rectified.right, cv::NORM_INF), 0.0) << "frame " << i;
    // The ground truth of the rectified left camera, as eval's rectification turns it.
    EXPECT_LT((rectified.T_world_cam0.matrix() - raw.T_world_cam0.matrix()).cwiseAbs().maxCoeff(),
              1e-9)
        << "frame " << i;
  }
  return c;
}

TEST(RenderTest, CalibrationErrorChangesOnlyTheExportedCalibration) {
  TempDir dir("render");
  const std::string truth = ShortScenario(dir);
  const std::string wrong = dir / "wrong.yaml";
  WriteText(wrong, ReadAll(truth) +
                       "calibration_error:\n  baseline_pct: 2\n  focal_pct: -1.5\n"
                       "  rotation_deg: 0.7\n");
  const std::string scaled = dir / "scaled.yaml";
  WriteText(scaled, ReadAll(truth) + "calibration_error:\n  baseline_pct: 2\n  focal_pct: -1.5\n");
  for (const auto& [yaml, out] :
       {std::pair{truth, dir / "a"}, std::pair{wrong, dir / "b"}, std::pair{scaled, dir / "s"}}) {
    const auto r = RunVobench("render " + yaml + " --out " + out + " -q --format euroc");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  // The images are the true rig's: every PNG of the scaled render, and the raw (EuRoC) ones of
  // the rotated render, equal the true calibration's.
  size_t images = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir / "a"))
    if (e.is_regular_file() && e.path().extension() == ".png") {
      const std::string f = fs::relative(e.path(), dir / "a").string();
      EXPECT_EQ(ReadAll(fs::path(dir / "s") / f), ReadAll(e.path().string())) << f;
      if (f.rfind("mav0/", 0) == 0) {
        EXPECT_EQ(ReadAll(fs::path(dir / "b") / f), ReadAll(e.path().string())) << f;
      }
      ++images;
    }
  EXPECT_GT(images, 20u);
  std::string error;
  harness::KittiReader a, s;
  ASSERT_TRUE(a.Open(dir / "a", &error)) << error;
  ASSERT_TRUE(s.Open(dir / "s", &error)) << error;
  EXPECT_NEAR(s.camera().baseline_m, a.camera().baseline_m * 1.02, 1e-12);
  EXPECT_NEAR(s.camera().fx_px, a.camera().fx_px * 0.985, 1e-9);
  EXPECT_NEAR(s.camera().fy_px, a.camera().fy_px * 0.985, 1e-9);
  EXPECT_EQ(s.camera().cx_px, a.camera().cx_px);
  EXPECT_EQ(s.camera().cy_px, a.camera().cy_px);
  harness::EurocCameraCalibration a0, a1, b0, b1;
  for (const auto& [folder, cam, calib] :
       {std::tuple{dir / "a", "cam0", &a0}, std::tuple{dir / "a", "cam1", &a1},
        std::tuple{dir / "b", "cam0", &b0}, std::tuple{dir / "b", "cam1", &b1}})
    ASSERT_TRUE(harness::ReadEurocSensorYaml(
        (fs::path(folder) / "mav0" / cam / "sensor.yaml").string(), calib, &error))
        << error;
  EXPECT_NEAR(b1.fu_px, a1.fu_px * 0.985, 1e-9);
  EXPECT_LT((b0.T_body_cam.matrix() - a0.T_body_cam.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  const Eigen::Isometry3d a01 = a0.T_body_cam.inverse() * a1.T_body_cam;
  const Eigen::Isometry3d b01 = b0.T_body_cam.inverse() * b1.T_body_cam;
  EXPECT_LT((a01.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(b01.translation().x(), a01.translation().x() * 1.02, 1e-12);
  const Eigen::AngleAxisd turn(b01.linear());
  EXPECT_NEAR(turn.angle(), 0.7 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(std::abs(turn.axis().y()), 1.0, 1e-12);  // about the camera's y axis

  // The rotation has no place in a rectified calibration: the KITTI side holds the raw frames
  // rectified by the wrong calibration, as a real rig calibrated that wrongly would give them.
  const vo::StereoCamera rectified = ExpectKittiSideIsEvalsRectification(dir / "b");

  // `run`'s sequence in memory: the same rectified camera; without the rotation the scaled
  // camera itself, and the frames as rendered.
  sim::Scenario scenario;
  ASSERT_TRUE(sim::LoadScenario(wrong, &scenario, &error)) << error;
  harness::StereoSequence sequence;
  ASSERT_TRUE(harness::OpenScenarioSequence(scenario, &sequence, &error)) << error;
  EXPECT_EQ(sequence.camera.fx_px, rectified.fx_px);
  EXPECT_EQ(sequence.camera.baseline_m, rectified.baseline_m);
  scenario.calibration_error.rotation_deg = 0.0;
  ASSERT_TRUE(harness::OpenScenarioSequence(scenario, &sequence, &error)) << error;
  EXPECT_EQ(sequence.camera.baseline_m, s.camera().baseline_m);
  EXPECT_EQ(sequence.camera.fx_px, s.camera().fx_px);

  // --format kitti writes the same rectified frames as the EuRoC render's KITTI side.
  const auto k = RunVobench("render " + wrong + " --out " + (dir / "k") + " -q --format kitti");
  ASSERT_EQ(k.exit_code, 0) << k.output;
  const fs::path k_dir = dir / "k", b_dir = dir / "b";
  EXPECT_EQ(ReadAll(k_dir / "calib.txt"), ReadAll(b_dir / "calib.txt"));
  for (const char* f : {"image_0/000000.png", "image_1/000000.png", "image_0/000020.png"})
    EXPECT_EQ(ReadAll(k_dir / f), ReadAll(b_dir / f)) << f;
  EXPECT_FALSE(fs::exists(k_dir / "mav0"));
}

TEST(RenderTest, ALensIsRawInEurocAndRectifiedElsewhereAsEvalRectifiesIt) {
  TempDir dir("render_lens");
  for (const char* lens : {"{model: radtan, coeffs: [-0.28, 0.07, 0.0002, 0.00002]}",
                           "{model: equidistant, coeffs: [0.05, -0.01, 0.002, -0.0005]}"}) {
    const std::string yaml =
        ShortScenario(dir, std::string("camera:\n  distortion: ") + lens + "\n");
    const std::string euroc = dir / "euroc";
    fs::remove_all(euroc);
    const auto r = RunVobench("render " + yaml + " --out " + euroc + " -q --format euroc");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ExpectKittiSideIsEvalsRectification(euroc);
    // `vobench run` gives the VO those frames: its trajectory is eval's on the EuRoC side (the
    // same images and camera). Both give the VO the gyro (imu.gyro_prior, the default): EuRoC's
    // samples are stamped in nanoseconds since the simulation's epoch (1.77e9 s), whose
    // differences read back as seconds carry ~1e-7 s of rounding, so the two agree to ~1e-6.
    WriteText(dir / "free.yaml", "platform: free\n");
    const std::string config = " --config " + (dir / "free.yaml") + " -q --no-plots --out ";
    fs::remove_all(dir / "run");
    fs::remove_all(dir / "eval");
    const auto run = RunVobench("run " + yaml + config + (dir / "run"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const auto eval =
        RunVobench("eval --format euroc --dataset " + euroc + config + (dir / "eval"));
    ASSERT_EQ(eval.exit_code, 0) << eval.output;
    const std::string trajectory = ReadAll(fs::path(dir / "run") / "trajectory_kitti.txt");
    EXPECT_GT(trajectory.size(), 100u);
    ExpectTrajectoriesNear(ReadAll(fs::path(dir / "eval") / "trajectory_kitti.txt"), trajectory,
                           static_cast<int>(std::count(trajectory.begin(), trajectory.end(), '\n')),
                           1e-5, lens);
  }
}

// Issue #34: everything that goes wrong in a real building at once (two people walking, a
// flickering tube, a 1 % baseline error in the exported calibration, a radtan lens) rendered as
// EuRoC; `vobench eval --format euroc` rectifies the raw images with the exported calibration and
// the VO (defaults) measures every frame of a short straight path (2 m).
TEST(RenderTest, PeopleFlickerCalibrationErrorAndALensRenderAsEurocAndEvalLosesNoFrame) {
  TempDir dir("render_realism");
  // A 2 m straight path: people walk lines of 1.5 m beside it (sim/people.h).
  std::string yaml = ShortScenario(
      dir,
      "people:\n  count: 2\n  seed: 4\n"
      "lights:\n  flicker_hz: 2.7\n  flicker_depth: 0.3\n"
      "calibration_error:\n  baseline_pct: 1.0\n"
      "camera:\n  distortion: {model: radtan, coeffs: [-0.28, 0.07, 0.0002, 0.00002]}\n");
  std::string text = ReadAll(yaml);
  const std::string short_path = "  - [0.8, 0]\n";
  ASSERT_NE(text.find(short_path), std::string::npos);
  text.replace(text.find(short_path), short_path.size(), "  - [2.0, 0]\n");
  WriteText(yaml, text);
  const std::string euroc = dir / "euroc";
  const auto r = RunVobench("render " + yaml + " --out " + euroc + " -q --format euroc");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const vo::StereoCamera rectified = ExpectKittiSideIsEvalsRectification(euroc);
  std::string error;
  sim::Scenario scenario;
  ASSERT_TRUE(sim::LoadScenario(yaml, &scenario, &error)) << error;
  EXPECT_NEAR(rectified.baseline_m, 1.01 * scenario.camera.baseline_m, 1e-9);  // the error
  EXPECT_EQ(scenario.people.count, 2);
  harness::EurocReader reader;
  ASSERT_TRUE(reader.Open(euroc, &error)) << error;
  ASSERT_GE(reader.size(), 10u);

  const auto eval = RunVobench("eval --format euroc --dataset " + euroc + " -q --no-plots --out " +
                               (dir / "eval"));
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  std::ifstream in(fs::path(dir / "eval") / "metrics.json");
  const nlohmann::json m = nlohmann::json::parse(in);
  EXPECT_EQ(m["frames"], static_cast<int>(reader.size()));
  EXPECT_EQ(m["frames_not_initialised"], 0);
  EXPECT_EQ(m["lost_frames"], 0) << m.dump(1);
  EXPECT_EQ(m["ground_truth_frames"], static_cast<int>(reader.size()));
  EXPECT_LT(m["end_pose_error_m"].get<double>(), 0.05) << m.dump(1);  // of a 2 m path
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
