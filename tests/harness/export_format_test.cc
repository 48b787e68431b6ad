// `vobench render`'s exports as other systems' tools read them (issue #33): every YAML file
// opens in OpenCV's cv::FileStorage (C++ EuRoC readers: Kimera, ORB-SLAM3, VINS) with the values
// written; EuRoC and TUM stamps are 19-digit nanoseconds from kSimulationEpochNs, so a sorted
// listing of every image folder is the stamp order; calib.txt parses as pykitti parses it (P0..P3,
// Tr); the run folder's KITTI trajectories start at the identity. vobench's own readers still read
// all of it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "harness/dataset.h"
#include "harness/dataset/euroc_imu.h"
#include "harness/dataset/rig.h"
#include "harness/sim_adapter.h"
#include "harness/trajectory_io.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "tests/harness/cli_test_util.h"

namespace {

namespace fs = std::filesystem;
using harness::DatasetFrame;
using vobench_test::ReadAll;
using vobench_test::RunVobench;

constexpr double kTol = 1e-12;  // values pass through text with 17 significant digits

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// File names in `dir`, sorted bytewise (what `LC_ALL=C ls` lists).
std::vector<std::string> SortedNames(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A FileStorage node's numbers (a sequence).
std::vector<double> Numbers(const cv::FileNode& node) {
  std::vector<double> v;
  for (const auto& n : node) v.push_back(static_cast<double>(n));
  return v;
}

// One short noisy scenario in the real hallway (0.4 m), rendered once by `vobench render` in the
// euroc and tum layouts (both hold the kitti layout too).
class ExportFormatTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() /
                         ("vobench_export_format_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    const std::string scenario_path = (*root_ / "short.yaml").string();
    std::ofstream(scenario_path) << "name: short\nscene: " << VOBENCH_SOURCE_DIR
                                 << "/scenes/hallway_l.xml\npath:\n  - [0, 0]\n  - [0.4, 0]\n"
                                    "noise:\n  pixel_sigma: 1.5\n  gain_sigma: 0.02\n";
    for (const char* format : {"euroc", "tum"}) {
      const auto r = RunVobench("render " + scenario_path + " --out " + Export(format) +
                                " -q --format " + format);
      ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    std::string error;
    scenario_ = new sim::Scenario;
    ASSERT_TRUE(sim::LoadScenario(scenario_path, scenario_, &error)) << error;
    auto simulator = sim::Simulator::Create(*scenario_, &error);
    ASSERT_TRUE(simulator) << error;
    calibration_ = new sim::StereoCalibration(simulator->calibration());
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
    delete scenario_;
    delete calibration_;
  }
  void SetUp() override {
    ASSERT_TRUE(calibration_ != nullptr && fs::exists(Export("tum"))) << "suite set-up failed";
  }

  static std::string Export(const std::string& format) {
    return (*root_ / ("export_" + format)).string();
  }
  // The frame times of times.txt (the simulator's clock, from 0).
  static std::vector<double> FrameTimes(const std::string& dir) {
    std::vector<double> times;
    std::string error;
    EXPECT_TRUE(harness::ReadKittiTimes(dir + "/times.txt", &times, &error)) << error;
    return times;
  }

  static fs::path* root_;
  static sim::Scenario* scenario_;
  static sim::StereoCalibration* calibration_;
};

fs::path* ExportFormatTest::root_ = nullptr;
sim::Scenario* ExportFormatTest::scenario_ = nullptr;
sim::StereoCalibration* ExportFormatTest::calibration_ = nullptr;

TEST_F(ExportFormatTest, EveryYamlStartsWithTheOpenCvDirectiveAndOpensInFileStorage) {
  // Every .yaml of both exports, whoever adds one: first line "%YAML:1.0", opened by OpenCV.
  int yaml_files = 0;
  for (const std::string format : {"euroc", "tum"}) {
    for (const auto& e : fs::recursive_directory_iterator(Export(format))) {
      if (e.path().extension() != ".yaml") continue;
      ++yaml_files;
      const std::string path = e.path().string();
      ASSERT_FALSE(Lines(path).empty()) << path;
      EXPECT_EQ(Lines(path).front(), "%YAML:1.0") << path;
      cv::FileStorage storage(path, cv::FileStorage::READ);
      EXPECT_TRUE(storage.isOpened()) << path;
    }
  }
  EXPECT_GE(yaml_files, 5);  // euroc: cam0, cam1, ground truth, rig; tum: rig

  // The values OpenCV reads are the calibration's.
  const std::string mav0 = Export("euroc") + "/mav0";
  Eigen::Isometry3d T_cam0_cam1 = Eigen::Isometry3d::Identity();
  T_cam0_cam1.translation().x() = calibration_->baseline_m;
  // EuRoC's body is the IMU (every simulated sequence carries one): the cameras relative to it.
  const Eigen::Isometry3d T_imu_cam0 =
      harness::CameraInImuFrame(calibration_->T_body_cam0, calibration_->T_body_imu);
  const Eigen::Isometry3d T_body_cam[2] = {T_imu_cam0, T_imu_cam0 * T_cam0_cam1};
  for (int cam = 0; cam < 2; ++cam) {
    const std::string path = mav0 + "/cam" + std::to_string(cam) + "/sensor.yaml";
    cv::FileStorage storage(path, cv::FileStorage::READ);
    ASSERT_TRUE(storage.isOpened()) << path;
    EXPECT_EQ(static_cast<std::string>(storage["sensor_type"]), "camera");
    EXPECT_EQ(static_cast<int>(storage["T_BS"]["rows"]), 4);
    EXPECT_EQ(static_cast<int>(storage["T_BS"]["cols"]), 4);
    const std::vector<double> T = Numbers(storage["T_BS"]["data"]);
    ASSERT_EQ(T.size(), 16u) << path;
    for (int i = 0; i < 16; ++i)
      EXPECT_NEAR(T[i], T_body_cam[cam].matrix()(i / 4, i % 4), kTol) << path << " T_BS " << i;
    const std::vector<double> k = Numbers(storage["intrinsics"]);
    ASSERT_EQ(k.size(), 4u);
    EXPECT_NEAR(k[0], calibration_->fx_px, kTol);
    EXPECT_NEAR(k[1], calibration_->fy_px, kTol);
    EXPECT_NEAR(k[2], calibration_->cx_px, kTol);
    EXPECT_NEAR(k[3], calibration_->cy_px, kTol);
    EXPECT_EQ(Numbers(storage["resolution"]),
              (std::vector<double>{static_cast<double>(calibration_->width),
                                   static_cast<double>(calibration_->height)}));
    EXPECT_EQ(static_cast<double>(storage["rate_hz"]), scenario_->rate_hz);
    EXPECT_EQ(static_cast<std::string>(storage["camera_model"]), "pinhole");
    EXPECT_EQ(static_cast<std::string>(storage["distortion_model"]), "radial-tangential");
    EXPECT_EQ(Numbers(storage["distortion_coefficients"]), (std::vector<double>{0, 0, 0, 0}));

    // vobench's own reader (yaml-cpp) reads the same file to the same values.
    harness::EurocCameraCalibration c;
    std::string error;
    ASSERT_TRUE(harness::ReadEurocSensorYaml(path, &c, &error)) << error;
    EXPECT_NEAR((c.T_body_cam.matrix() - T_body_cam[cam].matrix()).cwiseAbs().maxCoeff(), 0.0,
                kTol);
    EXPECT_EQ(c.fu_px, k[0]);
    EXPECT_EQ(c.width, calibration_->width);
    EXPECT_EQ(c.rate_hz, scenario_->rate_hz);
  }
  // The ground truth's sensor.yaml: the body itself (T_BS = identity).
  cv::FileStorage gt(mav0 + "/state_groundtruth_estimate0/sensor.yaml", cv::FileStorage::READ);
  ASSERT_TRUE(gt.isOpened());
  EXPECT_EQ(Numbers(gt["T_BS"]["data"]),
            (std::vector<double>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}));

  // rig.yaml in every layout: OpenCV and ReadRigYaml read the scenario's mounting.
  for (const std::string format : {"euroc", "tum"}) {
    const std::string path = Export(format) + "/rig.yaml";
    cv::FileStorage storage(path, cv::FileStorage::READ);
    ASSERT_TRUE(storage.isOpened()) << path;
    EXPECT_EQ(static_cast<double>(storage["camera_forward_m"]), scenario_->camera.forward_m);
    EXPECT_EQ(static_cast<double>(storage["camera_height_m"]), scenario_->camera.height_m);
    EXPECT_EQ(static_cast<double>(storage["camera_pitch_deg"]), scenario_->camera.pitch_deg);
    harness::RigMounting rig;
    std::string error;
    ASSERT_TRUE(harness::ReadRigYaml(path, &rig, &error)) << error;
    EXPECT_EQ(rig.forward_m, scenario_->camera.forward_m);
    EXPECT_EQ(rig.height_m, scenario_->camera.height_m);
    EXPECT_EQ(rig.pitch_deg, scenario_->camera.pitch_deg);
  }
}

TEST_F(ExportFormatTest, RigYamlReaderSkipsTheDirectiveAndKeepsLineNumbers) {
  const std::string path = (*root_ / "rig_bad.yaml").string();
  std::ofstream(path) << "%YAML:1.0\ncamera_forward_m: 0.1\ncamera_height_m: -1\n"
                         "camera_pitch_deg: 0\n";
  harness::RigMounting rig;
  std::string error;
  EXPECT_FALSE(harness::ReadRigYaml(path, &rig, &error));
  EXPECT_NE(error.find(path + ":3"), std::string::npos) << error;  // the file's own line
  EXPECT_NE(error.find("camera_height_m"), std::string::npos) << error;
}

TEST_F(ExportFormatTest, EurocStampsHave19DigitsAndListingsSortInStampOrder) {
  const std::vector<double> times = FrameTimes(Export("euroc"));
  ASSERT_GT(times.size(), 10u);
  const std::string mav0 = Export("euroc") + "/mav0";
  std::vector<int64_t> stamps;
  for (int cam = 0; cam < 2; ++cam) {
    const std::string base = mav0 + "/cam" + std::to_string(cam);
    const std::vector<std::string> csv = Lines(base + "/data.csv");
    ASSERT_EQ(csv.size(), times.size() + 1);
    EXPECT_EQ(csv[0], "#timestamp [ns],filename");
    std::vector<std::string> names;
    for (size_t i = 1; i < csv.size(); ++i) {
      const std::string stamp = csv[i].substr(0, csv[i].find(','));
      EXPECT_EQ(stamp.size(), 19u) << csv[i];
      EXPECT_EQ(csv[i], stamp + "," + stamp + ".png");
      const int64_t t_ns = std::stoll(stamp);
      // The simulator's time on the fixed epoch (2026-01-01T00:00:00Z), never the wall clock.
      EXPECT_EQ(t_ns, harness::kSimulationEpochNs + harness::TimeToNs(times[i - 1])) << i;
      if (cam == 0) stamps.push_back(t_ns);
      names.push_back(stamp + ".png");
    }
    EXPECT_EQ(stamps.front(), harness::kSimulationEpochNs);  // the simulator's first frame: t = 0
    EXPECT_TRUE(std::is_sorted(stamps.begin(), stamps.end()));
    // The sorted listing is data.csv's order, which is time order.
    EXPECT_EQ(SortedNames(base + "/data"), names) << base;
  }
  // The ground truth at the IMU rate on the same clock: 19-digit stamps, sorted, covering every
  // frame's stamp (the IMU rate is a multiple of the frame rate).
  const std::vector<std::string> gt = Lines(mav0 + "/state_groundtruth_estimate0/data.csv");
  ASSERT_GT(gt.size(), stamps.size() + 1);
  std::vector<int64_t> gt_stamps;
  for (size_t i = 1; i < gt.size(); ++i) {
    EXPECT_EQ(gt[i].find(','), 19u) << gt[i];
    gt_stamps.push_back(std::stoll(gt[i].substr(0, gt[i].find(','))));
  }
  EXPECT_TRUE(std::is_sorted(gt_stamps.begin(), gt_stamps.end()));
  for (int64_t t : stamps)
    EXPECT_TRUE(std::binary_search(gt_stamps.begin(), gt_stamps.end(), t)) << t;

  // Round trip: the EuRoC reader takes the same stamps and the frames equal the KITTI layout's.
  harness::EurocReader euroc;
  harness::KittiReader kitti;
  std::string error;
  ASSERT_TRUE(euroc.Open(Export("euroc"), &error)) << error;
  ASSERT_TRUE(kitti.Open(Export("euroc"), &error)) << error;
  EXPECT_EQ(euroc.times_ns(), stamps);
  EXPECT_EQ(euroc.ground_truth_frames(), stamps.size());
  for (size_t i : {size_t{0}, stamps.size() - 1}) {
    DatasetFrame e, k;
    ASSERT_TRUE(euroc.ReadFrame(i, &e, &error)) << error;
    ASSERT_TRUE(kitti.ReadFrame(i, &k, &error)) << error;
    EXPECT_EQ(cv::norm(e.left, k.left, cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(cv::norm(e.right, k.right, cv::NORM_INF), 0.0) << i;
    ASSERT_TRUE(e.has_gt && k.has_gt);
    EXPECT_LT((e.T_world_cam0.matrix() - k.T_world_cam0.matrix()).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST_F(ExportFormatTest, TumNamesAreFixedWidthAndSortInStampOrder) {
  const std::vector<double> times = FrameTimes(Export("tum"));
  ASSERT_GT(times.size(), 10u);
  std::vector<std::string> stamps;
  for (const std::string side : {"left", "right"}) {
    std::vector<std::string> names;
    for (const std::string& line : Lines(Export("tum") + "/" + side + ".txt")) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream in(line);
      std::string stamp, file;
      ASSERT_TRUE(in >> stamp >> file) << line;
      // Seconds with 9 decimals, the 19 digits of the nanosecond stamp: "1767225600.033333333".
      ASSERT_EQ(stamp.size(), 20u) << line;
      EXPECT_EQ(stamp[10], '.') << line;
      const int64_t t_ns = std::stoll(stamp.substr(0, 10) + stamp.substr(11));
      EXPECT_EQ(t_ns, harness::kSimulationEpochNs + harness::TimeToNs(times[names.size()]));
      EXPECT_EQ(file, side + "/" + stamp + ".png");
      names.push_back(stamp + ".png");
      if (side == "left") stamps.push_back(stamp);
    }
    ASSERT_EQ(names.size(), times.size());
    EXPECT_EQ(SortedNames(Export("tum") + "/" + side), names) << side;
  }
  // groundtruth.txt holds the same stamps' text.
  std::vector<std::string> gt_stamps;
  for (const std::string& line : Lines(Export("tum") + "/groundtruth.txt"))
    if (!line.empty() && line[0] != '#') gt_stamps.push_back(line.substr(0, line.find(' ')));
  EXPECT_EQ(gt_stamps, stamps);

  // Round trip: the TUM reader pairs every frame and associates every pose.
  harness::TumReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(Export("tum"), &error)) << error;
  EXPECT_EQ(reader.size(), times.size());
  EXPECT_EQ(reader.unpaired_frames(), 0u);
  EXPECT_EQ(reader.ground_truth_frames(), times.size());
  EXPECT_EQ(reader.times_s().front(), std::strtod(stamps.front().c_str(), nullptr));
}

// pykitti's odometry loader: read_calib_file splits each line at its first ':' and keeps the
// floats after it; _load_calib reshapes P0..P3 and Tr to 3x4, T_cam1_velo = T1 * T_cam0_velo with
// T1[0][3] = P1[0][3] / P1[0][0], and the baselines b_gray / b_rgb as the distances between the
// cameras' centres in the velodyne frame.
TEST_F(ExportFormatTest, CalibTxtLoadsAsPykittiLoadsIt) {
  std::map<std::string, std::vector<double>> data;
  for (const std::string& line : Lines(Export("euroc") + "/calib.txt")) {
    const size_t colon = line.find(':');
    ASSERT_NE(colon, std::string::npos) << line;
    std::istringstream in(line.substr(colon + 1));
    std::vector<double> v;
    for (std::string x; in >> x;) v.push_back(std::stod(x));
    data[line.substr(0, colon)] = v;
  }
  for (const char* key : {"P0", "P1", "P2", "P3", "Tr"}) {
    ASSERT_EQ(data.count(key), 1u) << key;
    ASSERT_EQ(data[key].size(), 12u) << key;
  }
  EXPECT_EQ(data.size(), 5u);
  using Mat34 = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;
  auto reshape = [&](const char* key) { return Eigen::Map<const Mat34>(data[key].data()); };
  const Mat34 P0 = reshape("P0"), P1 = reshape("P1"), P2 = reshape("P2"), P3 = reshape("P3");
  EXPECT_EQ(P2, P0);
  EXPECT_EQ(P3, P1);
  Eigen::Matrix3d K;
  K << calibration_->fx_px, 0, calibration_->cx_px, 0, calibration_->fy_px, calibration_->cy_px, 0,
      0, 1;
  EXPECT_LT((P0.leftCols<3>() - K).cwiseAbs().maxCoeff(), kTol);  // K_cam0
  EXPECT_EQ(P0.col(3), Eigen::Vector3d::Zero());
  Eigen::Matrix4d T_cam0_velo = Eigen::Matrix4d::Identity();
  T_cam0_velo.topRows<3>() = reshape("Tr");
  EXPECT_EQ(T_cam0_velo, Eigen::Matrix4d::Identity());
  auto camera_in_velo = [&](const Mat34& P) {
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T(0, 3) = P(0, 3) / P(0, 0);
    return ((T * T_cam0_velo).inverse() * Eigen::Vector4d(0, 0, 0, 1)).eval();
  };
  const double b_gray = (camera_in_velo(P1) - camera_in_velo(P0)).norm();
  const double b_rgb = (camera_in_velo(P3) - camera_in_velo(P2)).norm();
  EXPECT_NEAR(b_gray, calibration_->baseline_m, kTol);
  EXPECT_NEAR(b_rgb, calibration_->baseline_m, kTol);

  // vobench's KITTI reader still reads it.
  vo::StereoCamera camera;
  std::string error;
  ASSERT_TRUE(harness::ReadKittiCalib(Export("euroc") + "/calib.txt", &camera, &error)) << error;
  EXPECT_NEAR(camera.baseline_m, calibration_->baseline_m, kTol);
  EXPECT_NEAR(camera.fx_px, calibration_->fx_px, kTol);
}

// The run folder's KITTI files start at the identity and are the TUM (world) files relative to
// their first pose.
TEST_F(ExportFormatTest, RunFolderKittiTrajectoriesStartAtTheIdentity) {
  const std::string out = (*root_ / "eval").string();
  const auto r = RunVobench("eval --dataset " + Export("euroc") +
                            " --format euroc --max-frames 12 --no-plots -q --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const std::string& name : {std::string("trajectory"), std::string("groundtruth")}) {
    std::vector<Eigen::Isometry3d> kitti;
    std::vector<harness::StampedPose> world;
    std::string error;
    ASSERT_TRUE(harness::ReadKittiPoses(out + "/" + name + "_kitti.txt", &kitti, &error)) << error;
    ASSERT_TRUE(harness::ReadTum(out + "/" + name + "_world_tum.txt", &world, &error)) << error;
    ASSERT_EQ(kitti.size(), world.size()) << name;
    ASSERT_GT(kitti.size(), 5u) << name;
    EXPECT_EQ(Lines(out + "/" + name + "_kitti.txt").front(), "1 0 0 0 0 1 0 0 0 0 1 0") << name;
    if (name == "groundtruth") {  // the simulator's world: the first camera is not its origin
      EXPECT_GT(world.front().T_world_cam.translation().norm(), 0.1);
    }
    for (size_t i = 0; i < kitti.size(); ++i) {
      const Eigen::Isometry3d expected = world.front().T_world_cam.inverse() * world[i].T_world_cam;
      EXPECT_LT((kitti[i].matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-9)
          << name << " " << i;
    }
  }
}

// --- The writer's stamp rules on small synthetic frames (no rendering).

vo::StereoCamera SmallCamera() {
  vo::StereoCamera camera;
  camera.width = 16;
  camera.height = 12;
  camera.fx_px = camera.fy_px = 14.0;
  camera.cx_px = 7.5;
  camera.cy_px = 5.5;
  camera.baseline_m = 0.1;
  return camera;
}

DatasetFrame SmallFrame(double time_s) {
  DatasetFrame f;
  f.time_s = time_s;
  f.left = cv::Mat(12, 16, CV_8UC1, cv::Scalar(40));
  f.right = cv::Mat(12, 16, CV_8UC1, cv::Scalar(80));
  return f;
}

// Writes frames at `times` with `options` into a fresh folder; returns the first error ("" when
// all went well) and checks that a refused sequence leaves no folder.
std::string WriteFrames(const std::string& dir, harness::DatasetWriter::Options options,
                        const std::vector<double>& times) {
  fs::remove_all(dir);
  std::string error;
  {
    harness::DatasetWriter writer(options);
    if (!writer.Open(dir, SmallCamera(), &error)) return error;
    for (double t : times)
      if (!writer.Add(SmallFrame(t), &error)) break;
    if (error.empty()) writer.Finish(&error);
  }
  if (!error.empty()) {
    EXPECT_FALSE(fs::exists(dir)) << "a refused sequence left " << dir;
  }
  return error;
}

TEST(ExportWriterTest, StampsKeepOneWidthSoNamesSort) {
  const std::string dir =
      (fs::temp_directory_path() / ("vobench_export_writer_" + std::to_string(::getpid())))
          .string();
  harness::DatasetWriter::Options options;
  options.format = harness::DatasetFormat::kEuroc;
  // 9.9 s -> 10 digits, 10.0 s -> 11: names would sort 10000000000 before 9900000000.
  EXPECT_NE(WriteFrames(dir, options, {9.8, 9.9, 10.0})
                .find("frame 2: stamp 10000000000 ns has "
                      "another number of digits than frame "
                      "0's 9800000000"),
            std::string::npos);
  // The same times on the simulator's epoch: 19 digits throughout, names in time order.
  options.stamp_offset_ns = harness::kSimulationEpochNs;
  EXPECT_EQ(WriteFrames(dir, options, {9.8, 9.9, 10.0}), "");
  EXPECT_EQ(SortedNames(dir + "/mav0/cam0/data"),
            (std::vector<std::string>{"1767225609800000000.png", "1767225609900000000.png",
                                      "1767225610000000000.png"}));
  // The KITTI layout names frames by index: no stamp rule.
  options.format = harness::DatasetFormat::kKitti;
  options.stamp_offset_ns = 0;
  EXPECT_EQ(WriteFrames(dir, options, {9.8, 9.9, 10.0}), "");
  // Negative stamps name no file.
  options.format = harness::DatasetFormat::kTum;
  EXPECT_NE(
      WriteFrames(dir, options, {-0.2, -0.1}).find("frame 0: stamp -200000000 ns is negative"),
      std::string::npos);
  // TUM lists hold seconds: stamps 10 ns apart at 1.7e9 s read as the same double.
  options.stamp_offset_ns = harness::kSimulationEpochNs;
  EXPECT_NE(WriteFrames(dir, options, {0.0, 1e-8})
                .find("stamp 1767225600.000000010 s reads as the same number of seconds as the "
                      "previous frame's 1767225600.000000000"),
            std::string::npos);
  EXPECT_EQ(WriteFrames(dir, options, {0.0, 1e-6}), "");  // 1 us: distinct doubles
  // An offset out of range is refused before anything is written.
  options.stamp_offset_ns = -1;
  EXPECT_NE(WriteFrames(dir, options, {0.0}).find("stamp_offset_ns must be in [0, "),
            std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
