// libFuzzer target: the KITTI times.txt reader (harness::ReadKittiTimes).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "harness/trajectory_io.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = vobench_fuzz::WriteInput("fuzz_kitti_times", data, size);
  std::vector<double> times_s;
  std::string error;
  harness::ReadKittiTimes(path, &times_s, &error);
  return 0;
}
