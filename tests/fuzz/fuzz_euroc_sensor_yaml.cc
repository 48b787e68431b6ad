// libFuzzer target: the EuRoC sensor.yaml reader (harness::ReadEurocSensorYaml).
#include <cstddef>
#include <cstdint>
#include <string>

#include "harness/dataset.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = vobench_fuzz::WriteInput("fuzz_euroc_sensor_yaml", data, size);
  harness::EurocCameraCalibration calibration;
  std::string error;
  harness::ReadEurocSensorYaml(path, &calibration, &error);
  return 0;
}
