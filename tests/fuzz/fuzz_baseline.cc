// libFuzzer target: the regression baseline reader (harness::LoadBaseline, results/baseline.json):
// malformed JSON, duplicate keys, nulls, non-finite and wrong-typed values.
#include <cstddef>
#include <cstdint>
#include <string>

#include "harness/check.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = vobench_fuzz::WriteInput("fuzz_baseline", data, size);
  harness::Baseline baseline;
  std::string error;
  harness::LoadBaseline(path, &baseline, &error);
  return 0;
}
