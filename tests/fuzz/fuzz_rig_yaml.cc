// libFuzzer target: a dataset's rig.yaml reader (harness::ReadRigYaml).
#include <cstddef>
#include <cstdint>
#include <string>

#include "harness/dataset.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = vobench_fuzz::WriteInput("fuzz_rig_yaml", data, size);
  harness::RigMounting rig;
  std::string error;
  harness::ReadRigYaml(path, &rig, &error);
  return 0;
}
