// libFuzzer target: the trajectory readers, KITTI poses (harness::ReadKittiPoses) and TUM
// (harness::ReadTum), both on every input.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "harness/trajectory_io.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = vobench_fuzz::WriteInput("fuzz_poses", data, size);
  std::string error;
  std::vector<Eigen::Isometry3d> kitti;
  harness::ReadKittiPoses(path, &kitti, &error);
  std::vector<harness::StampedPose> tum;
  harness::ReadTum(path, &tum, &error);
  return 0;
}
