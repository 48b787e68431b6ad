// Helpers for tests that run the `vobench` command and read the files it writes.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

namespace vobench_test {

struct CommandResult {
  int exit_code;       // the command's exit status (-1 when it did not exit normally)
  std::string output;  // stdout and stderr together
};

// Runs `vobench ARGS` (the build's binary, VOBENCH_BINARY) through the shell, in the folder
// `dir` when one is given.
inline CommandResult RunVobench(const std::string& args, const std::string& dir = "") {
  const std::string cmd = (dir.empty() ? std::string() : "cd '" + dir + "' && ") +
                          VOBENCH_BINARY + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (pipe && fgets(buf, sizeof(buf), pipe)) out += buf;
  const int status = pipe ? pclose(pipe) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// The whole file as bytes ("" when it cannot be read).
inline std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace vobench_test
