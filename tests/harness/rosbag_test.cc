// ROS bags (harness/dataset/rosbag.h): the bag `vobench render --format rosbag` writes, read back
// by RosbagReader frame for frame against the KITTI export beside it; `eval --format rosbag` on
// it against `eval --format kitti` on the same frames (metrics.json bit for bit); --calib; bad
// bags refused naming the bag and the topic, nothing written. (Debian's python3-rosbag reads the
// same export in rosbag_check.py, ctest rosbag_python_check.) Skipped in a build without
// VOBENCH_ROSBAG, where the format's refusal is tested instead.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/dataset.h"
#include "harness/dataset/euroc_imu.h"
#include "harness/dataset/kalibr.h"
#include "harness/trajectory_io.h"
#include "sim/simulator.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

#ifdef VOBENCH_ROSBAG
#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#endif

namespace harness {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using vobench_test::RunVobench;

#ifdef VOBENCH_ROSBAG

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// metrics.json less its wall-clock timings (the only keys two runs of the same frames differ in).
nlohmann::json WithoutTimings(nlohmann::json j) {
  for (const char* k : {"vo_ms_median", "vo_ms_p95", "stage_ms_median"}) {
    EXPECT_TRUE(j.contains(k)) << k;
    j.erase(k);
  }
  return j;
}

// The short hallway (0.5 m, 19 frames at 10 Hz, the default IMU), rendered once per process as
// a bag (with the KITTI layout beside it) and in the EuRoC layout (for --calib).
class RosbagTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ =
        new fs::path(fs::temp_directory_path() / ("vobench_rosbag_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    const std::string scenario = (*root_ / "short.yaml").string();
    vobench_test::WriteText(scenario, "name: short\nscene: " + std::string(VOBENCH_SOURCE_DIR) +
                                          "/scenes/hallway_l.xml\npath:\n  - [0, 0]\n"
                                          "  - [0.5, 0]\nnoise:\n  pixel_sigma: 1.5\n");
    for (const char* format : {"rosbag", "euroc"}) {
      const auto r = RunVobench("render " + scenario + " --format " + format + " -q --out " +
                                (*root_ / (std::string("short_") + format)).string());
      ASSERT_EQ(r.exit_code, 0) << r.output;
    }
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  void SetUp() override {
    ASSERT_TRUE(fs::exists(Bag())) << "suite set-up failed";
    dir_ = *root_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string Kitti() { return (*root_ / "short_rosbag").string(); }
  static std::string Bag() { return Kitti() + "/short_rosbag.bag"; }
  static std::string Euroc() { return (*root_ / "short_euroc").string(); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // A copy of the rendered bag's messages into `path`: `keep` says which topics, `edit` may
  // change an image before it is written.
  void CopyBag(const std::string& path, const std::function<bool(const std::string&)>& keep,
               const std::function<void(const std::string&, sensor_msgs::Image*)>& edit = {}) {
    rosbag::Bag in(Bag(), rosbag::bagmode::Read);
    rosbag::Bag out(path, rosbag::bagmode::Write);
    for (const rosbag::MessageInstance& m : rosbag::View(in)) {
      if (!keep(m.getTopic())) continue;
      const auto image = m.instantiate<sensor_msgs::Image>();
      if (image && edit) {
        sensor_msgs::Image copy = *image;
        edit(m.getTopic(), &copy);
        out.write(m.getTopic(), m.getTime(), copy);
      } else {
        out.write(m.getTopic(), m.getTime(), m);
      }
    }
  }

  // `eval --format rosbag` on `bag` is refused (exit 2) with a message naming the bag and
  // `topic` and saying `problem`; no run folder.
  void ExpectRefused(const std::string& bag, const std::string& topic, const std::string& problem,
                     const std::string& flags = "") {
    const std::string out = Path("out");
    const auto r = RunVobench("eval --format rosbag --dataset " + bag + " --out " + out +
                              " --no-plots -q " + flags);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(bag)) << r.output;
    EXPECT_THAT(r.output, HasSubstr(topic)) << r.output;
    EXPECT_THAT(r.output, HasSubstr(problem)) << r.output;
    EXPECT_FALSE(fs::exists(out));
  }

  static fs::path* root_;
  fs::path dir_;
};

fs::path* RosbagTest::root_ = nullptr;

TEST_F(RosbagTest, FramesEqualTheKittiExportFrameForFrame) {
  KittiReader kitti;
  std::string error;
  ASSERT_TRUE(kitti.Open(Kitti(), &error)) << error;
  RosbagReader bag;
  ASSERT_TRUE(bag.Open(Bag(), RosbagReader::Options(), &error)) << error;
  ASSERT_EQ(bag.size(), kitti.size());
  EXPECT_EQ(bag.size(), 19u);
  EXPECT_EQ(bag.unpaired_frames(), 0u);
  EXPECT_TRUE(bag.rectification().IsIdentity());
  const vo::StereoCamera& a = bag.rectification().camera;
  const vo::StereoCamera& b = kitti.camera();
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.fx_px, b.fx_px);  // the same doubles: camera_info holds float64
  EXPECT_EQ(a.fy_px, b.fy_px);
  EXPECT_EQ(a.cx_px, b.cx_px);
  EXPECT_EQ(a.cy_px, b.cy_px);
  EXPECT_EQ(a.baseline_m, b.baseline_m);
  EXPECT_EQ(bag.ground_truth_frames(), bag.size());
  ASSERT_TRUE(bag.has_imu());
  EXPECT_DOUBLE_EQ(bag.imu().rate_hz, 250.0);  // the scenario's default IMU
  EXPECT_NEAR(bag.imu().gyro_noise_density, sim::ImuOptions().gyro_noise_density, 1e-15);
  EXPECT_NEAR(bag.imu().accel_noise_density, sim::ImuOptions().accel_noise_density, 1e-15);
  size_t imu_samples = 0;
  for (size_t i = 0; i < bag.size(); ++i) {
    DatasetFrame f, k;
    ASSERT_TRUE(bag.ReadFrame(i, &f, &error)) << error;
    ASSERT_TRUE(kitti.ReadFrame(i, &k, &error)) << error;
    EXPECT_EQ(cv::norm(f.left, k.left, cv::NORM_INF), 0.0) << "frame " << i;
    EXPECT_EQ(cv::norm(f.right, k.right, cv::NORM_INF), 0.0) << "frame " << i;
    ASSERT_FALSE(f.depth_m.empty());
    EXPECT_EQ(cv::norm(f.depth_m, k.depth_m, cv::NORM_INF), 0.0) << "frame " << i;
    // The EuRoC export's stamp: the simulation epoch + the frame time in ns.
    EXPECT_EQ(TimeToNs(f.time_s), kSimulationEpochNs + TimeToNs(k.time_s)) << "frame " << i;
    ASSERT_TRUE(f.has_gt && k.has_gt);
    // The bag holds a quaternion: the same pose to rounding.
    EXPECT_LT((f.T_world_cam0.matrix() - k.T_world_cam0.matrix()).cwiseAbs().maxCoeff(), 1e-12);
    // IMU samples in (previous frame, this frame] (250 Hz, frames at 10 Hz: 25 each).
    if (i > 0) {
      EXPECT_EQ(f.imu.size(), 25u) << "frame " << i;
    }
    for (const sim::ImuSample& s : f.imu) EXPECT_LE(s.time_s, f.time_s);
    imu_samples += f.imu.size();
  }
  EXPECT_GT(imu_samples, 18u * 25u);
}

TEST_F(RosbagTest, EvalGivesTheKittiEvalMetricsBitForBit) {
  // The bag's ground truth as a TUM file on the KITTI layout's clock (times.txt), the doubles
  // as they are in the messages: `eval --format kitti --gt` then sees the same poses as
  // `eval --format rosbag` (poses.txt holds matrices, the bag quaternions: last bits differ).
  std::vector<double> times;
  ASSERT_TRUE(ReadKittiTimes(Kitti() + "/times.txt", &times, nullptr));
  std::string tum;
  {
    rosbag::Bag in(Bag(), rosbag::bagmode::Read);
    size_t i = 0;
    for (const rosbag::MessageInstance& m :
         rosbag::View(in, rosbag::TopicQuery(RosbagTopics().ground_truth))) {
      const auto g = m.instantiate<geometry_msgs::TransformStamped>();
      ASSERT_TRUE(g);
      ASSERT_LT(i, times.size());
      tum += FormatDouble(times[i++]);
      for (double x : {g->transform.translation.x, g->transform.translation.y,
                       g->transform.translation.z, g->transform.rotation.x, g->transform.rotation.y,
                       g->transform.rotation.z, g->transform.rotation.w})
        tum += " " + FormatDouble(x);
      tum += "\n";
    }
    ASSERT_EQ(i, times.size());
  }
  vobench_test::WriteText(Path("gt.txt"), tum);
  // The KITTI layout has no IMU: the bag's run without its gyro (imu.gyro_prior: false).
  vobench_test::WriteText(Path("no_gyro.yaml"), "imu:\n  gyro_prior: false\n");
  const auto bag = RunVobench("eval --format rosbag --dataset " + Bag() + " --out " + Path("bag") +
                              " --config " + Path("no_gyro.yaml") + " --no-plots -q");
  ASSERT_EQ(bag.exit_code, 0) << bag.output;
  EXPECT_THAT(bag.output, HasSubstr("19 of 19 frames associated"));
  const auto kitti = RunVobench("eval --format kitti --dataset " + Kitti() + " --gt " +
                                Path("gt.txt") + " --out " + Path("kitti") + " --no-plots -q");
  ASSERT_EQ(kitti.exit_code, 0) << kitti.output;
  const nlohmann::json a = WithoutTimings(ReadJson(Path("bag") + "/metrics.json"));
  const nlohmann::json b = WithoutTimings(ReadJson(Path("kitti") + "/metrics.json"));
  EXPECT_EQ(a.dump(), b.dump());  // every key, every digit
  EXPECT_EQ(a["frames"], 19);
  EXPECT_TRUE(a.contains("match_precision"));  // the depth topic: matches scored as on KITTI
  EXPECT_EQ(a["platform"], "ground_vehicle");  // rig.yaml beside the bag
  // Against the KITTI layout's own poses.txt: the same to rounding.
  const auto own = RunVobench("eval --format kitti --dataset " + Kitti() + " --out " + Path("own") +
                              " --no-plots -q");
  ASSERT_EQ(own.exit_code, 0) << own.output;
  const nlohmann::json c = WithoutTimings(ReadJson(Path("own") + "/metrics.json"));
  for (const auto& [key, value] : c.items()) {
    ASSERT_TRUE(a.contains(key)) << key;
    if (value.is_number_float())
      EXPECT_NEAR(a[key].get<double>(), value.get<double>(), 1e-12) << key;
    else
      EXPECT_EQ(a[key], value) << key;
  }
}

TEST_F(RosbagTest, CalibrationFromEurocSensorYamlFiles) {
  RosbagReader::Options options;
  options.calib_left = Euroc() + "/mav0/cam0/sensor.yaml";
  options.calib_right = Euroc() + "/mav0/cam1/sensor.yaml";
  RosbagReader bag;
  std::string error;
  ASSERT_TRUE(bag.Open(Bag(), options, &error)) << error;
  KittiReader kitti;
  ASSERT_TRUE(kitti.Open(Kitti(), &error)) << error;
  EXPECT_TRUE(bag.rectification().IsIdentity());  // an ideal pair: images used as they are
  EXPECT_NEAR(bag.rectification().camera.baseline_m, kitti.camera().baseline_m, 1e-12);
  EXPECT_EQ(bag.rectification().camera.fx_px, kitti.camera().fx_px);
  // Only one file: refused.
  options.calib_right.clear();
  EXPECT_FALSE(bag.Open(Bag(), options, &error));
  EXPECT_THAT(error, HasSubstr("--calib needs two"));
}

// The bag's gyro (issue #35): render writes Kalibr's camchain-imucam.yaml beside the bag (the
// IMU's mounting, which camera_info cannot hold); eval reads it there, or from --imu-extrinsics,
// or takes the --calib files' T_BS, and the VO then runs as `vobench run` does on the scenario
// with its gyro (to 1e-5: the bag's stamps are nanoseconds since the simulation's epoch, as
// EuRoC's). Without a mounting the gyro is not used: the run is the one without the gyro, bit
// for bit.
TEST_F(RosbagTest, TheBagsGyroIsUsedWithTheImuMountingBesideTheBagOrGiven) {
  const std::string scenario = (*root_ / "short.yaml").string();
  const auto run = RunVobench("run " + scenario + " --out " + Path("run") + " --no-plots -q");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  vobench_test::WriteText(Path("no_gyro.yaml"), "imu:\n  gyro_prior: false\n");
  const auto run_no_gyro = RunVobench("run " + scenario + " --config " + Path("no_gyro.yaml") +
                                      " --out " + Path("run_no_gyro") + " --no-plots -q");
  ASSERT_EQ(run_no_gyro.exit_code, 0) << run_no_gyro.output;
  const std::string with_gyro = vobench_test::ReadAll(Path("run") + "/trajectory_kitti.txt");
  const std::string without_gyro =
      vobench_test::ReadAll(Path("run_no_gyro") + "/trajectory_kitti.txt");
  ASSERT_NE(with_gyro, without_gyro);

  // The mounting render wrote is the simulated rig's (the IMU on the chassis, cam0 on the body).
  ASSERT_TRUE(fs::exists(Kitti() + "/camchain-imucam.yaml"));
  Eigen::Isometry3d T_imu_cam0;
  std::string error;
  ASSERT_TRUE(ReadKalibrImuExtrinsics(Kitti() + "/camchain-imucam.yaml", &T_imu_cam0, &error))
      << error;
  sim::Scenario s;
  ASSERT_TRUE(sim::LoadScenario(scenario, &s, &error)) << error;
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  const Eigen::Isometry3d expected =
      CameraInImuFrame(simulator->calibration().T_body_cam0, simulator->calibration().T_body_imu);
  EXPECT_LT((T_imu_cam0.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12);

  // Beside the bag: read by itself.
  const auto beside = RunVobench("eval --format rosbag --dataset " + Bag() + " --out " +
                                 Path("beside") + " -q --no-plots");
  ASSERT_EQ(beside.exit_code, 0) << beside.output;
  EXPECT_THAT(beside.output,
              HasSubstr("the VO uses its gyro (imu.gyro_prior), cam0 on the IMU from " + Kitti() +
                        "/camchain-imucam.yaml"));
  const int frames = 19;
  vobench_test::ExpectTrajectoriesNear(
      vobench_test::ReadAll(Path("beside") + "/trajectory_kitti.txt"), with_gyro, frames, 1e-5,
      "beside");

  // A copy of the bag alone (with its rig.yaml): the mounting unknown, the gyro not used.
  fs::create_directories(Path("alone"));
  fs::copy_file(Bag(), Path("alone/short.bag"));
  fs::copy_file(Kitti() + "/rig.yaml", Path("alone/rig.yaml"));
  const auto alone = RunVobench("eval --format rosbag --dataset " + Path("alone/short.bag") +
                                " --out " + Path("alone_out") + " -q --no-plots");
  ASSERT_EQ(alone.exit_code, 0) << alone.output;
  EXPECT_THAT(alone.output, HasSubstr("its mounting unknown: the gyro not used"));
  EXPECT_EQ(vobench_test::ReadAll(Path("alone_out") + "/trajectory_kitti.txt"), without_gyro);

  // --imu-extrinsics names the file.
  const auto given = RunVobench("eval --format rosbag --dataset " + Path("alone/short.bag") +
                                " --imu-extrinsics " + Kitti() + "/camchain-imucam.yaml --out " +
                                Path("given") + " -q --no-plots");
  ASSERT_EQ(given.exit_code, 0) << given.output;
  EXPECT_EQ(vobench_test::ReadAll(Path("given") + "/trajectory_kitti.txt"),
            vobench_test::ReadAll(Path("beside") + "/trajectory_kitti.txt"));

  // --calib: the EuRoC files' cam0 T_BS (EuRoC's body frame is its IMU's).
  const auto calib = RunVobench("eval --format rosbag --dataset " + Path("alone/short.bag") +
                                " --calib " + Euroc() + "/mav0/cam0/sensor.yaml " + Euroc() +
                                "/mav0/cam1/sensor.yaml --out " + Path("calib") + " -q --no-plots");
  ASSERT_EQ(calib.exit_code, 0) << calib.output;
  EXPECT_THAT(calib.output,
              HasSubstr("cam0 on the IMU from " + Euroc() + "/mav0/cam0/sensor.yaml"));
  vobench_test::ExpectTrajectoriesNear(
      vobench_test::ReadAll(Path("calib") + "/trajectory_kitti.txt"), with_gyro, frames, 1e-5,
      "calib");
}

TEST_F(RosbagTest, BadImuExtrinsicsAreRefused) {
  // Not a rigid transform: exit 2, the file and key named, nothing written.
  vobench_test::WriteText(Path("bad.yaml"),
                          "cam0:\n  T_cam_imu:\n  - [2, 0, 0, 0]\n  - [0, 1, 0, 0]\n"
                          "  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n");
  const auto bad = RunVobench("eval --format rosbag --dataset " + Bag() + " --imu-extrinsics " +
                              Path("bad.yaml") + " --out " + Path("out") + " -q --no-plots");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_THAT(bad.output, HasSubstr(Path("bad.yaml")));
  EXPECT_THAT(bad.output, HasSubstr("T_cam_imu"));
  EXPECT_FALSE(fs::exists(Path("out")));
  // A file that is not there.
  const auto missing = RunVobench("eval --format rosbag --dataset " + Bag() + " --imu-extrinsics " +
                                  Path("none.yaml") + " --out " + Path("out") + " -q --no-plots");
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr(Path("none.yaml")));
  EXPECT_FALSE(fs::exists(Path("out")));
  // A bag without IMU messages on the topic: the mounting of nothing.
  const auto no_imu =
      RunVobench("eval --format rosbag --dataset " + Bag() + " --imu /none" + " --imu-extrinsics " +
                 Kitti() + "/camchain-imucam.yaml --out " + Path("out") + " -q --no-plots");
  EXPECT_EQ(no_imu.exit_code, 2) << no_imu.output;
  EXPECT_THAT(no_imu.output, HasSubstr("no IMU messages on /none"));
  EXPECT_FALSE(fs::exists(Path("out")));
  // Not a bag: the flag is the bag's.
  const auto kitti = RunVobench("eval --format kitti --dataset " + Kitti() + " --imu-extrinsics " +
                                Kitti() + "/camchain-imucam.yaml --out " + Path("out") + " -q");
  EXPECT_EQ(kitti.exit_code, 2) << kitti.output;
  EXPECT_THAT(kitti.output, HasSubstr("--imu-extrinsics: only with --format rosbag"));
  EXPECT_FALSE(fs::exists(Path("out")));
}

TEST_F(RosbagTest, SwappedImageTopicsAreRefused) {
  // --left/--right choose the topics (camera_info beside them): swapped, the right camera_info's
  // P says the "right" camera is to the left (a negative baseline).
  ExpectRefused(Bag(), "/cam1/camera_info", "baseline",
                "--left /cam1/image_raw --right /cam0/image_raw");
}

TEST_F(RosbagTest, RosbagFlagsOnlyWithTheRosbagFormat) {
  const auto r = RunVobench("eval --format kitti --dataset " + Kitti() + " --left /cam0/x --out " +
                            Path("out") + " -q");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--left: only with --format rosbag"));
  EXPECT_FALSE(fs::exists(Path("out")));
}

TEST_F(RosbagTest, NotABagIsRefused) {
  vobench_test::WriteText(Path("text.bag"), "this is not a bag\n");
  const auto r = RunVobench("eval --format rosbag --dataset " + Path("text.bag") + " --out " +
                            Path("out") + " -q");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(Path("text.bag") + ": not a readable ROS bag"));
  EXPECT_FALSE(fs::exists(Path("out")));
  const auto missing = RunVobench("eval --format rosbag --dataset " + Path("none.bag") + " --out " +
                                  Path("out") + " -q");
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr(Path("none.bag")));
}

TEST_F(RosbagTest, EmptyBagIsRefused) {
  { rosbag::Bag empty(Path("empty.bag"), rosbag::bagmode::Write); }
  ExpectRefused(Path("empty.bag"), "/cam0/image_raw", "the bag has no messages at all");
}

TEST_F(RosbagTest, MissingTopicIsRefused) {
  CopyBag(Path("no_right.bag"), [](const std::string& t) { return t != "/cam1/image_raw"; });
  ExpectRefused(Path("no_right.bag"), "topic /cam1/image_raw: no messages", "--left / --right");
  ExpectRefused(Bag(), "topic /left: no messages", "topics in the bag: /cam0/camera_info",
                "--left /left");
  CopyBag(Path("no_info.bag"), [](const std::string& t) { return t != "/cam1/camera_info"; });
  ExpectRefused(Path("no_info.bag"), "topic /cam1/camera_info: no messages", "--calib");
}

TEST_F(RosbagTest, WrongTypeOrEncodingIsRefused) {
  ExpectRefused(Bag(), "topic /imu0: type sensor_msgs/Imu", "expected sensor_msgs/Image",
                "--right /imu0");
  CopyBag(
      Path("rgb16.bag"), [](const std::string&) { return true; },
      [](const std::string& topic, sensor_msgs::Image* m) {
        if (topic == "/cam1/image_raw") m->encoding = "rgb16";
      });
  ExpectRefused(Path("rgb16.bag"), "topic /cam1/image_raw: image stamped 1767225600000000000 ns",
                "encoding 'rgb16', expected mono8");
  CopyBag(
      Path("short.bag"), [](const std::string&) { return true; },
      [](const std::string& topic, sensor_msgs::Image* m) {
        if (topic == "/cam0/image_raw") m->data.resize(m->data.size() / 2);
      });
  ExpectRefused(Path("short.bag"), "topic /cam0/image_raw", "data bytes do not hold");
  // A raw (distorted) camera_info: read with --calib instead.
  {
    rosbag::Bag in(Bag(), rosbag::bagmode::Read);
    rosbag::Bag out(Path("raw.bag"), rosbag::bagmode::Write);
    for (const rosbag::MessageInstance& m : rosbag::View(in)) {
      const auto info = m.instantiate<sensor_msgs::CameraInfo>();
      if (!info) {
        out.write(m.getTopic(), m.getTime(), m);
        continue;
      }
      sensor_msgs::CameraInfo raw = *info;
      raw.D[0] = -0.28;
      out.write(m.getTopic(), m.getTime(), raw);
    }
  }
  ExpectRefused(Path("raw.bag"), "topic /cam0/camera_info", "not a rectified pinhole");
}

TEST_F(RosbagTest, RenderLeavesNothingHalfWritten) {
  // An output folder that exists and is not a vobench dataset: refused, the folder untouched,
  // no partial folder left.
  fs::create_directories(Path("taken"));
  vobench_test::WriteText(Path("taken/mine.txt"), "keep\n");
  const auto r = RunVobench("render " + (*root_ / "short.yaml").string() +
                            " --format rosbag -q --overwrite --out " + Path("taken"));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(Path("taken/mine.txt")));
  EXPECT_FALSE(fs::exists(Path("taken/taken.bag")));
  EXPECT_TRUE(vobench_test::EntriesStartingWith(dir_.string(), "taken.partial").empty());
}

#else  // built without VOBENCH_ROSBAG

TEST(RosbagTest, RefusedWithoutTheBuildOption) {
  EXPECT_FALSE(RosbagSupported());
  const auto r = RunVobench("eval --format rosbag --dataset x.bag --out /tmp/none -q");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("built without ROS bag support"));
  DatasetWriter::Options options;
  options.format = DatasetFormat::kRosbag;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("VOBENCH_ROSBAG"));
}

#endif  // VOBENCH_ROSBAG

}  // namespace
}  // namespace harness
