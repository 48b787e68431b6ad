// libFuzzer target: the KITTI calib.txt reader (harness::ReadKittiCalib).
#include <cstddef>
#include <cstdint>
#include <string>

#include "harness/dataset.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = vobench_fuzz::WriteInput("fuzz_kitti_calib", data, size);
  vo::StereoCamera camera;
  std::string error;
  harness::ReadKittiCalib(path, &camera, &error);
  return 0;
}
