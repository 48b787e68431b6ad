// Kalibr's camchain-imucam.yaml (harness/dataset/kalibr.h): what render writes beside a bag reads
// back to the same mounting; the file as Kalibr writes it (its own keys and layout, a real
// camera-IMU calibration's numbers) reads; bad files are refused naming the file, line and key.
#include "harness/dataset/kalibr.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <string>

#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace harness {
namespace {

using ::testing::HasSubstr;
using vobench_test::TempDir;
using vobench_test::WriteText;

vo::StereoCamera Camera() {
  vo::StereoCamera c;
  c.width = 320;
  c.height = 240;
  c.fx_px = 230.51785523653993;
  c.fy_px = 230.51785523653993;
  c.cx_px = 159.5;
  c.cy_px = 119.5;
  c.baseline_m = 0.09;
  return c;
}

// A camera 0.2 m ahead of and 0.5 m above an IMU turned 10° about its z axis, looking along
// the IMU's x (camera z forward, x right, y down).
Eigen::Isometry3d SomeMounting() {
  Eigen::Matrix3d R_imu_cam;
  R_imu_cam << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
               R_imu_cam;
  T.translation() = Eigen::Vector3d(0.2, 0.045, 0.5);
  return T;
}

TEST(KalibrTest, WrittenCamchainReadsBackTheMounting) {
  TempDir dir("kalibr");
  const Eigen::Isometry3d T = SomeMounting();
  const std::string text = KalibrCamchainYaml(Camera(), T, "/cam0/image_raw", "/cam1/image_raw");
  // Kalibr's keys, cam1 at the baseline to the right of cam0.
  for (const char* key :
       {"cam0:", "cam1:", "T_cam_imu:", "T_cn_cnm1:", "camera_model: pinhole",
        "intrinsics: [230.51785523653993, 230.51785523653993, 159.5, 119.5]",
        "distortion_model: radtan", "resolution: [320, 240]", "rostopic: /cam1/image_raw",
        "timeshift_cam_imu: 0.0", "- [1, 0, 0, -0.09]"})
    EXPECT_THAT(text, HasSubstr(key));
  WriteText(dir / "camchain-imucam.yaml", text);
  Eigen::Isometry3d read;
  std::string error;
  ASSERT_TRUE(ReadKalibrImuExtrinsics(dir / "camchain-imucam.yaml", &read, &error)) << error;
  EXPECT_LT((read.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(KalibrTest, ReadsAFileAsKalibrWritesIt) {
  // The layout and keys of kalibr_calibrate_imu_camera's camchain-imucam.yaml (numbers of a
  // camera-IMU rig: a small rotation between the axes, a time shift of 0).
  TempDir dir("kalibr");
  WriteText(dir / "camchain-imucam.yaml",
            "cam0:\n"
            "  T_cam_imu:\n"
            "  - [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975]\n"
            "  - [0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768]\n"
            "  - [-0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949]\n"
            "  - [0.0, 0.0, 0.0, 1.0]\n"
            "  cam_overlaps: [1]\n"
            "  camera_model: pinhole\n"
            "  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n"
            "  distortion_model: radtan\n"
            "  intrinsics: [458.654, 457.296, 367.215, 248.375]\n"
            "  resolution: [752, 480]\n"
            "  rostopic: /cam0/image_raw\n"
            "  timeshift_cam_imu: 0.0\n");
  Eigen::Isometry3d T_imu_cam0;
  std::string error;
  ASSERT_TRUE(ReadKalibrImuExtrinsics(dir / "camchain-imucam.yaml", &T_imu_cam0, &error)) << error;
  // The inverse: cam0's centre in the IMU frame is -R^T t.
  Eigen::Matrix4d T_cam_imu;
  T_cam_imu << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975, 0.999557249008,
      0.0149672133247, 0.025715529948, -0.064676986768, -0.0257744366974, 0.00375618835797,
      0.999660727178, 0.00981073058949, 0, 0, 0, 1;
  EXPECT_LT((T_imu_cam0.matrix() * T_cam_imu - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(),
            1e-12);
}

TEST(KalibrTest, BadFilesAreRefusedNamingTheFileAndKey) {
  TempDir dir("kalibr");
  const std::string rows =
      "  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n";
  const struct {
    std::string text;
    std::string expect;
  } cases[] = {
      {"cam1:\n  T_cam_imu:\n" + rows, "required"},
      {"cam0:\n  T_cam_imu:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n",
       "4 rows of 4 numbers"},
      {"cam0:\n  T_cam_imu:\n  - [1, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n",
       "cam0.T_cam_imu[0]"},
      {"cam0:\n  T_cam_imu:\n  - [2, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, "
       "1]\n",
       "rigid transform"},
      {"cam0:\n  T_cam_imu:\n" + rows + "  timeshift_cam_imu: 0.004\n", "time shift"},
      {"cam0:\n  T_cam_imu:\n  - [1, 0, 0, x]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, "
       "1]\n",
       "number"},
      {"- just a list\n", "mapping"},
  };
  for (const auto& c : cases) {
    const std::string path = dir / "bad.yaml";
    WriteText(path, c.text);
    Eigen::Isometry3d T;
    std::string error;
    EXPECT_FALSE(ReadKalibrImuExtrinsics(path, &T, &error)) << c.text;
    EXPECT_THAT(error, HasSubstr(path)) << c.text;
    EXPECT_THAT(error, HasSubstr(c.expect)) << c.text;
  }
  Eigen::Isometry3d T;
  std::string error;
  EXPECT_FALSE(ReadKalibrImuExtrinsics(dir / "missing.yaml", &T, &error));
  EXPECT_THAT(error, HasSubstr("missing.yaml"));
}

}  // namespace
}  // namespace harness
