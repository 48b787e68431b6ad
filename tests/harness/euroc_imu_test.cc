// EuRoC's imu0 (harness/dataset/euroc_imu.h): written with the ground truth at the IMU rate,
// read back frame by frame, the real V1_01 file read, malformed files refused at file:line.
#include "harness/dataset/euroc_imu.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "harness/dataset.h"

namespace harness {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class EurocImuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::path(::testing::TempDir()) /
            ("vobench_euroc_imu_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  // Writes `text` as root_/imu.csv and reads it; returns the error ("" when read).
  std::string Read(const std::string& text, std::vector<sim::ImuSample>* samples = nullptr) {
    const std::string path = (root_ / "imu.csv").string();
    std::ofstream(path) << text;
    std::vector<int64_t> t_ns;
    std::vector<sim::ImuSample> local;
    std::string error;
    if (ReadEurocImu(path, &t_ns, samples ? samples : &local, &error)) return "";
    return error.empty() ? "(empty message)" : error;
  }
  fs::path root_;
};

const char* kHeader =
    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
    "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";

TEST_F(EurocImuTest, AGoodFileIsRead) {
  std::vector<sim::ImuSample> s;
  ASSERT_EQ(
      Read(std::string(kHeader) + "1000,0.1,-0.2,0.3,9.8,0,-1e-3\n2000, 1, 2, 3, 4, 5, 6\n", &s),
      "");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].time_s, 1e-6);
  EXPECT_EQ(s[0].gyro_radps, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(s[0].accel_mps2, Eigen::Vector3d(9.8, 0, -1e-3));
  EXPECT_EQ(s[1].accel_mps2, Eigen::Vector3d(4, 5, 6));
  EXPECT_FALSE(s[1].has_gt);
}

TEST_F(EurocImuTest, MalformedFilesAreRefusedNamingFileAndLine) {
  const std::string file = (root_ / "imu.csv").string();
  const std::string columns = Read(std::string(kHeader) + "1000,0,0,0,0,0,0\n2000,0,0,0,0,0\n");
  EXPECT_THAT(columns, HasSubstr(file + ":3: expected 6 numbers, got 5")) << columns;
  const std::string nan = Read(std::string(kHeader) + "1000,0,0,nan,0,0,0\n");
  EXPECT_THAT(nan, HasSubstr(file + ":2:")) << nan;
  EXPECT_THAT(nan, HasSubstr("finite")) << nan;
  const std::string inf = Read(std::string(kHeader) + "1000,0,0,0,0,0,inf\n");
  EXPECT_THAT(inf, HasSubstr(file + ":2:")) << inf;
  const std::string repeat =
      Read(std::string(kHeader) + "1000,0,0,0,0,0,0\n2000,0,0,0,0,0,0\n2000,0,0,0,0,0,0\n");
  EXPECT_THAT(repeat, HasSubstr(file + ":4: time stamp 2000 repeats")) << repeat;
  const std::string back = Read(std::string(kHeader) + "3000,0,0,0,0,0,0\n2000,0,0,0,0,0,0\n");
  EXPECT_THAT(back, HasSubstr(file + ":3: time stamp 2000 is before")) << back;
  const std::string stamp = Read(std::string(kHeader) + "1e9,0,0,0,0,0,0\n");
  EXPECT_THAT(stamp, HasSubstr(file + ":2: expected '<timestamp ns>")) << stamp;
  EXPECT_THAT(Read(kHeader), HasSubstr("no IMU samples"));
}

TEST_F(EurocImuTest, TheRealV101ImuIsRead) {
  const std::string path =
      std::string(VOBENCH_SHARED_DATA_DIR) + "/euroc_v101_clip/mav0/imu0/data.csv";
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
  std::vector<int64_t> t_ns;
  std::vector<sim::ImuSample> s;
  std::string error;
  ASSERT_TRUE(ReadEurocImu(path, &t_ns, &s, &error)) << error;
  ASSERT_GT(s.size(), 1000u);
  EXPECT_EQ(t_ns.front(), 1403715273262142976);
  EXPECT_EQ(s.front().gyro_radps.x(), -0.0020943951023931952);
  EXPECT_EQ(s.front().accel_mps2.x(), 9.0874956666666655);
  // 200 Hz, and gravity's magnitude on average.
  EXPECT_NEAR((s.size() - 1) / (s.back().time_s - s.front().time_s), 200.0, 1.0);
  double g = 0.0;
  for (const auto& x : s) g += x.accel_mps2.norm() / s.size();
  EXPECT_NEAR(g, 9.81, 0.2);
}

TEST_F(EurocImuTest, TheRealV101SensorYamlIsReadAndABadOneRefused) {
  const std::string path =
      std::string(VOBENCH_SHARED_DATA_DIR) + "/euroc_v101_clip/mav0/imu0/sensor.yaml";
  sim::ImuOptions imu;
  std::string error;
  if (fs::exists(path)) {
    ASSERT_TRUE(ReadEurocImuSensorYaml(path, &imu, &error)) << error;
    EXPECT_EQ(imu.rate_hz, 200.0);  // the ADIS16448's numbers
    EXPECT_EQ(imu.gyro_noise_density, 1.6968e-04);
    EXPECT_EQ(imu.gyro_random_walk, 1.9393e-05);
    EXPECT_EQ(imu.accel_noise_density, 2.0e-3);
    EXPECT_EQ(imu.accel_random_walk, 3.0e-3);
  }
  const std::string bad = (root_ / "sensor.yaml").string();
  std::ofstream(bad) << "%YAML:1.0\nrate_hz: 200\ngyroscope_noise_density: -1\n";
  EXPECT_FALSE(ReadEurocImuSensorYaml(bad, &imu, &error));
  EXPECT_THAT(error, HasSubstr(bad + ":3: key 'gyroscope_noise_density': expected >= 0, got -1"))
      << error;
  std::ofstream(bad) << "%YAML:1.0\nrate_hz: 0\n";
  EXPECT_FALSE(ReadEurocImuSensorYaml(bad, &imu, &error));
  EXPECT_THAT(error, HasSubstr(bad + ":2: key 'rate_hz': expected > 0 Hz")) << error;
  std::ofstream(bad) << "rate_hz: 200\n";
  EXPECT_FALSE(ReadEurocImuSensorYaml(bad, &imu, &error));
  EXPECT_THAT(error, HasSubstr("key 'gyroscope_noise_density': required")) << error;
}

TEST(EurocImuFrames, CameraInImuFrameIsTheCameraSeenFromTheImu) {
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity(), T_body_imu = T_body_cam;
  T_body_cam.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T_body_cam.translation() = Eigen::Vector3d(0.15, 0.045, 0.9);
  T_body_imu.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_body_imu.translation() = Eigen::Vector3d(0, 0, 0.19);
  const Eigen::Isometry3d T = CameraInImuFrame(T_body_cam, T_body_imu);
  // The offset (0.15, 0.045, 0.71) in the body, seen from axes turned 90 deg about z.
  EXPECT_LT((T.translation() - Eigen::Vector3d(0.045, -0.15, 0.71)).norm(), 1e-12);
  EXPECT_TRUE((T_body_imu * T).isApprox(T_body_cam, 1e-12));
}

TEST(EurocImuFrames, SamplesBetweenTwoStamps) {
  const std::vector<int64_t> t = {10, 20, 30, 40};
  std::vector<sim::ImuSample> s(4);
  for (int i = 0; i < 4; ++i) s[i].time_s = i;
  std::vector<sim::ImuSample> out;
  ImuSamplesBetween(t, s, 10, 30, &out);  // (10, 30]
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].time_s, 1.0);
  EXPECT_EQ(out[1].time_s, 2.0);
  out.clear();
  ImuSamplesBetween(t, s, INT64_MIN, 10, &out);
  EXPECT_EQ(out.size(), 1u);
}

// The 32x24 stereo camera of the writer tests (f 30 px, baseline 0.1 m).
vo::StereoCamera SmallCamera() {
  vo::StereoCamera camera;
  camera.width = 32;
  camera.height = 24;
  camera.fx_px = camera.fy_px = 30;
  camera.cx_px = 15.5;
  camera.cy_px = 11.5;
  camera.baseline_m = 0.1;
  return camera;
}

// The writer's hook: frames that carry IMU samples give imu0/, body.yaml and the ground truth
// at the IMU rate; the reader gives each frame its samples again.
TEST_F(EurocImuTest, WrittenAndReadBackWithTheDatasetWriterAndReader) {
  const vo::StereoCamera camera = SmallCamera();
  std::vector<DatasetFrame> frames(3);
  int k = 0;
  for (int i = 0; i < 3; ++i) {
    DatasetFrame& f = frames[i];
    f.time_s = 0.1 * i;
    f.left = cv::Mat(24, 32, CV_8UC1, cv::Scalar(10 * i));
    f.right = f.left.clone();
    f.has_gt = true;
    f.T_world_cam0.translation() = Eigen::Vector3d(0.1 * i, 0, 1);
    for (; k * 0.02 <= f.time_s + 1e-9; ++k) {  // 50 Hz: samples in (previous, this frame]
      sim::ImuSample s;
      s.time_s = k * 0.02;
      s.gyro_radps = Eigen::Vector3d(0.01 * k, -0.5, 1.0 / 3.0);
      s.accel_mps2 = Eigen::Vector3d(0.1, 0.2, 9.81 + 1e-3 * k);
      s.has_gt = true;
      s.T_world_imu.translation() = Eigen::Vector3d(0.02 * k, 0, 0.19);
      s.v_world_mps = Eigen::Vector3d(1, 0, 0);
      s.gyro_bias_radps = Eigen::Vector3d(1e-5 * k, 0, 0);
      s.accel_bias_mps2 = Eigen::Vector3d(0, 0, -2e-4 * k);
      f.imu.push_back(s);
    }
  }
  DatasetWriter::Options options;
  options.format = DatasetFormat::kEuroc;
  options.stamp_offset_ns = 1000000000;  // 1 s: stamps of one width (names that sort)
  options.imu.rate_hz = 50;
  options.imu.gyro_noise_density = 1.5e-4;
  // The rig on the robot's body; the files' body is the IMU.
  options.T_body_cam0.translation() = Eigen::Vector3d(0.15, 0.045, 0.905);
  options.T_body_imu.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  options.T_body_imu.translation() = Eigen::Vector3d(0, 0, 0.19);
  const std::string dir = (root_ / "euroc").string();
  DatasetWriter writer(options);
  std::string error;
  ASSERT_TRUE(writer.Open(dir, camera, &error)) << error;
  for (const DatasetFrame& f : frames) ASSERT_TRUE(writer.Add(f, &error)) << error;
  ASSERT_TRUE(writer.Finish(&error)) << error;

  const std::string data = ReadAll(dir + "/mav0/imu0/data.csv");
  EXPECT_THAT(
      data, StartsWith(std::string(kHeader) + "1000000000,0,-0.5,0.3333333333333333,0.1,0.2,9.81\n"
                                              "1020000000,0.01,-0.5,"));
  const std::string yaml = ReadAll(dir + "/mav0/imu0/sensor.yaml");
  EXPECT_THAT(yaml, StartsWith("%YAML:1.0\n"));
  EXPECT_THAT(yaml, HasSubstr("rate_hz: 50\n"));
  EXPECT_THAT(yaml, HasSubstr("gyroscope_noise_density: 0.00015 "));
  EXPECT_THAT(yaml, HasSubstr("accelerometer_random_walk: 0.003 "));
  EXPECT_THAT(yaml, HasSubstr("data: [1.0, 0.0, 0.0, 0.0,"));
  EXPECT_THAT(ReadAll(dir + "/mav0/body.yaml"), StartsWith("%YAML:1.0\n"));
  EXPECT_THAT(ReadAll(dir + "/mav0/state_groundtruth_estimate0/sensor.yaml"),
              StartsWith("%YAML:1.0\n"));
  const std::string gt = ReadAll(dir + "/mav0/state_groundtruth_estimate0/data.csv");
  EXPECT_EQ(std::count(gt.begin(), gt.end(), '\n'), 1 + k);  // header + one line a sample
  EXPECT_THAT(gt, HasSubstr("\n1020000000,0.02,0,0.19,1,0,0,0,1,0,0,1e-05,0,0,0,0,-2e-04\n"));

  EurocReader reader;
  ASSERT_TRUE(reader.Open(dir, &error)) << error;
  EXPECT_TRUE(reader.has_imu());
  EXPECT_EQ(reader.imu().rate_hz, 50.0);  // imu0/sensor.yaml read back
  EXPECT_EQ(reader.imu().gyro_noise_density, 1.5e-4);
  EXPECT_EQ(reader.imu().accel_random_walk, sim::ImuOptions().accel_random_walk);
  EXPECT_TRUE(reader.cam0().T_body_cam.isApprox(
      CameraInImuFrame(options.T_body_cam0, options.T_body_imu), 1e-12));
  EXPECT_EQ(reader.ground_truth_body().size(), static_cast<size_t>(k));
  for (size_t i = 0; i < frames.size(); ++i) {
    DatasetFrame f;
    ASSERT_TRUE(reader.ReadFrame(i, &f, &error)) << error;
    ASSERT_EQ(f.imu.size(), frames[i].imu.size()) << i;
    for (size_t j = 0; j < f.imu.size(); ++j) {
      EXPECT_NEAR(f.imu[j].time_s - 1.0, frames[i].imu[j].time_s, 1e-12);  // the 1 s offset
      EXPECT_EQ(f.imu[j].gyro_radps, frames[i].imu[j].gyro_radps);
      EXPECT_EQ(f.imu[j].accel_mps2, frames[i].imu[j].accel_mps2);
    }
  }
}

// The ground truth at the IMU rate read back into imu0's samples (as the strided copies of a
// suite's external sequences do, harness/suite/external.h): positions, velocities and biases
// exactly, the rotation to 1e-15; a file that does not match imu0 line for line is refused,
// naming file:line.
TEST_F(EurocImuTest, TheGroundTruthAtTheImuRateIsReadBackIntoTheSamples) {
  std::vector<sim::ImuSample> written;
  for (int k = 0; k < 4; ++k) {
    sim::ImuSample s;
    s.time_s = 0.005 * k;
    s.gyro_radps = Eigen::Vector3d(0.1 * k, -0.2, 1.0 / 3.0);
    s.accel_mps2 = Eigen::Vector3d(0.1, 0.2, 9.81 + 1e-3 * k);
    s.has_gt = true;
    s.T_world_imu.linear() =
        Eigen::AngleAxisd(0.3 + 0.1 * k, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    s.T_world_imu.translation() = Eigen::Vector3d(0.1 * k, 1.0 / 7.0, 0.19);
    s.v_world_mps = Eigen::Vector3d(1.0 / 3.0, 0, k);
    s.gyro_bias_radps = Eigen::Vector3d(1e-5 * k, 0, 2.5e-6);
    s.accel_bias_mps2 = Eigen::Vector3d(0, -1e-4, -2e-4 * k);
    written.push_back(s);
  }
  const std::string mav0 = (root_ / "mav0").string();
  bool wrote_gt = false;
  std::string error;
  ASSERT_TRUE(WriteEurocImu(mav0, written, sim::ImuOptions(), 1000000000, &wrote_gt, &error))
      << error;
  ASSERT_TRUE(wrote_gt);
  std::vector<int64_t> t_ns;
  std::vector<sim::ImuSample> read;
  ASSERT_TRUE(ReadEurocImu(mav0 + "/imu0/data.csv", &t_ns, &read, &error)) << error;
  const std::string gt_path = mav0 + "/state_groundtruth_estimate0/data.csv";
  ASSERT_TRUE(ReadEurocImuGroundTruth(gt_path, t_ns, &read, &error)) << error;
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_TRUE(read[i].has_gt) << i;
    EXPECT_EQ(read[i].T_world_imu.translation(), written[i].T_world_imu.translation()) << i;
    EXPECT_TRUE(read[i].T_world_imu.linear().isApprox(written[i].T_world_imu.linear(), 1e-15)) << i;
    EXPECT_EQ(read[i].v_world_mps, written[i].v_world_mps) << i;
    EXPECT_EQ(read[i].gyro_bias_radps, written[i].gyro_bias_radps) << i;
    EXPECT_EQ(read[i].accel_bias_mps2, written[i].accel_bias_mps2) << i;
    EXPECT_EQ(read[i].gyro_radps, written[i].gyro_radps) << i;  // imu0's, untouched
  }

  const std::string gt = ReadAll(gt_path);
  const auto refused = [&](const std::string& text) {
    std::ofstream(gt_path) << text;
    std::vector<sim::ImuSample> samples = read;
    std::string why;
    EXPECT_FALSE(ReadEurocImuGroundTruth(gt_path, t_ns, &samples, &why));
    return why;
  };
  const std::string short_file = refused(gt.substr(0, gt.rfind('\n', gt.size() - 2) + 1));
  EXPECT_THAT(short_file, HasSubstr(gt_path + ": 3 lines for 4 IMU samples")) << short_file;
  std::string other_stamp = gt;
  other_stamp.replace(other_stamp.find("\n1005000000,"), 12, "\n1005000001,");
  const std::string stamp = refused(other_stamp);
  EXPECT_THAT(stamp, HasSubstr(gt_path + ":3: time stamp 1005000001 is not the IMU sample's "
                                         "1005000000"))
      << stamp;
  std::string fewer = gt;
  fewer.erase(fewer.find(",", fewer.find("\n1000000000,") + 1), 2);  // ",0" of x
  const std::string fields = refused(fewer);
  EXPECT_THAT(fields, HasSubstr(gt_path + ":2: expected 16 numbers, got 15")) << fields;
}

// Frames whose IMU samples carry no ground truth (a dataset's, re-written) keep the frames'
// ground truth at the frame rate; imu0/ is written all the same.
TEST_F(EurocImuTest, SamplesWithoutGroundTruthLeaveTheFramesGroundTruth) {
  const vo::StereoCamera camera = SmallCamera();
  DatasetWriter::Options options;
  options.format = DatasetFormat::kEuroc;
  options.stamp_offset_ns = harness::kSimulationEpochNs;  // as render: stamps of one width
  const std::string dir = (root_ / "euroc").string();
  DatasetWriter writer(options);
  std::string error;
  ASSERT_TRUE(writer.Open(dir, camera, &error)) << error;
  for (int i = 0; i < 2; ++i) {
    DatasetFrame f;
    f.time_s = 0.1 * i;
    f.left = cv::Mat(24, 32, CV_8UC1, cv::Scalar(0));
    f.right = f.left.clone();
    f.has_gt = true;
    sim::ImuSample s;
    s.time_s = f.time_s;
    f.imu.push_back(s);
    ASSERT_TRUE(writer.Add(f, &error)) << error;
  }
  ASSERT_TRUE(writer.Finish(&error)) << error;
  EXPECT_TRUE(fs::exists(dir + "/mav0/imu0/data.csv"));
  const std::string gt = ReadAll(dir + "/mav0/state_groundtruth_estimate0/data.csv");
  EXPECT_EQ(std::count(gt.begin(), gt.end(), '\n'), 3);  // header + the 2 frames
}

// rig.yaml carries the IMU's pose on the vehicle (render writes it): read back exactly; a
// rig.yaml without it (older renders) reads with has_imu false; some of the six keys only are
// refused naming the first missing one at file:line.
TEST_F(EurocImuTest, RigFileCarriesTheImuPose) {
  RigMounting rig;
  rig.forward_m = 0.15;
  rig.height_m = 1.0;
  rig.has_imu = true;
  rig.imu_x_m = -0.1;
  rig.imu_z_m = 0.19;
  rig.imu_yaw_deg = 1.0 / 3.0;
  const std::string path = (root_ / "rig.yaml").string();
  std::ofstream(path) << RigYaml(rig);
  RigMounting back;
  std::string error;
  ASSERT_TRUE(ReadRigYaml(path, &back, &error)) << error;
  EXPECT_TRUE(back.has_imu);
  EXPECT_EQ(back.imu_x_m, rig.imu_x_m);
  EXPECT_EQ(back.imu_z_m, rig.imu_z_m);
  EXPECT_EQ(back.imu_yaw_deg, rig.imu_yaw_deg);
  const std::string camera = "camera_forward_m: 0.2\ncamera_height_m: 0.4\ncamera_pitch_deg: 0\n";
  std::ofstream(path) << camera;
  ASSERT_TRUE(ReadRigYaml(path, &back, &error)) << error;
  EXPECT_FALSE(back.has_imu);
  std::ofstream(path) << camera << "imu_x_m: 0\nimu_y_m: 0\n";
  EXPECT_FALSE(ReadRigYaml(path, &back, &error));
  EXPECT_THAT(error, HasSubstr(path + ":1: key 'imu_z_m': required")) << error;
  std::ofstream(path) << camera << "imu_x_m: 0\nimu_y_m: 0\nimu_z_m: 0\nimu_roll_deg: 0\n"
                      << "imu_pitch_deg: 0\nimu_yaw_deg: .inf\n";
  EXPECT_FALSE(ReadRigYaml(path, &back, &error));
  EXPECT_THAT(error, HasSubstr(path + ":9: key 'imu_yaw_deg': expected a finite number")) << error;
}

}  // namespace
}  // namespace harness
