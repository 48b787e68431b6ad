// libFuzzer target: Kalibr's camchain-imucam.yaml reader (harness::ReadKalibrImuExtrinsics).
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>

#include "harness/dataset/kalibr.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = vobench_fuzz::WriteInput("fuzz_kalibr", data, size);
  Eigen::Isometry3d T_imu_cam0;
  std::string error;
  harness::ReadKalibrImuExtrinsics(path, &T_imu_cam0, &error);
  return 0;
}
