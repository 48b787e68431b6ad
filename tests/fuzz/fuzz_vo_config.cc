// libFuzzer target: the VO configuration reader (harness::ParseVoConfig).
#include <cstddef>
#include <cstdint>
#include <string>

#include "harness/vo_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  vo::OdometryOptions options;
  std::string error;
  harness::ParseVoConfig(text, "fuzz.yaml", &options, &error);
  return 0;
}
