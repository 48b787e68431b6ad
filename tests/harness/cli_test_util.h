// Helpers for tests that run the `vobench` command and read the files it writes.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace vobench_test {

struct CommandResult {
  int exit_code;       // the command's exit status (-1 when it did not exit normally)
  std::string output;  // stdout and stderr together
};

// Runs `vobench ARGS` (the build's binary, VOBENCH_BINARY) through the shell, in the folder
// `dir` when one is given.
inline CommandResult RunVobench(const std::string& args, const std::string& dir = "") {
  const std::string cmd = (dir.empty() ? std::string() : "cd '" + dir + "' && ") + VOBENCH_BINARY +
                          " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (pipe && fgets(buf, sizeof(buf), pipe)) out += buf;
  const int status = pipe ? pclose(pipe) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// Starts `vobench ARGS...` (VOBENCH_BINARY) in the background with stdout and stderr into
// `log`; its pid, or -1 when it could not start. The caller waits for it (waitpid).
inline pid_t StartVobench(const std::vector<std::string>& args, const std::string& log) {
  std::vector<std::string> argv = {VOBENCH_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> c_argv;
  for (auto& a : argv) c_argv.push_back(a.data());
  c_argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, c_argv[0], &actions, nullptr, c_argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

// Names of the entries of `dir` that start with `prefix` (none when `dir` cannot be read).
inline std::vector<std::string> EntriesStartingWith(const std::string& dir,
                                                    const std::string& prefix) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().filename().string().rfind(prefix, 0) == 0)
      names.push_back(e.path().filename().string());
  return names;
}

// The whole file as bytes ("" when it cannot be read).
inline std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Two trajectories as text (trajectory_kitti.txt: 12 numbers a frame) agree number by number
// within `tolerance`, with the same count of numbers (`frames` × 12).
inline void ExpectTrajectoriesNear(const std::string& got_text, const std::string& want_text,
                                   int frames, double tolerance, const std::string& what) {
  std::istringstream got(got_text), want(want_text);
  double g = 0.0, w = 0.0;
  int numbers = 0;
  while (want >> w) {
    ASSERT_TRUE(got >> g) << what << ": fewer numbers than the reference's " << numbers;
    EXPECT_NEAR(g, w, tolerance) << what << ": number " << numbers;
    ++numbers;
  }
  EXPECT_FALSE(got >> g) << what << ": more numbers than the reference's " << numbers;
  EXPECT_EQ(numbers, 12 * frames) << what;
}

}  // namespace vobench_test
