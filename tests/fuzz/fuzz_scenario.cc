// libFuzzer target: the scenario YAML reader (sim::ParseScenario).
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/data_dir.h"
#include "sim/scenario.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  sim::Scenario scenario;
  std::string error;
  sim::ParseScenario(text, "fuzz.yaml", sim::DataDir() + "/scenes", &scenario, &error);
  return 0;
}
