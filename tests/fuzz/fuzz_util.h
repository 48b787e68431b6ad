// Shared by the libFuzzer targets: readers that take a path get the input through a file of
// their own (one per process and target, in $TMPDIR or /tmp), rewritten for every input.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace vobench_fuzz {

inline const std::string& InputPath(const char* target) {
  static const std::string path = [target] {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir != nullptr && *dir != '\0' ? dir : "/tmp") + "/vobench_" + target + "_" +
           std::to_string(::getpid()) + ".txt";
  }();
  return path;
}

// Writes the input to InputPath(target) and returns that path; aborts when it cannot (a broken
// harness must not pass for a clean run).
inline const std::string& WriteInput(const char* target, const uint8_t* data, size_t size) {
  const std::string& path = InputPath(target);
  FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror(path.c_str());
    std::abort();
  }
  return path;
}

}  // namespace vobench_fuzz
