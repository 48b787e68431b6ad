// SIGINT / SIGTERM on the long commands, and a suite's children (issue #11): a stopped command
// says how far it got, leaves nothing behind and exits with 128 + the signal; a suite's
// children lead their own process groups and die with the suite, also on SIGKILL.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using vobench_test::EntriesStartingWith;
using vobench_test::ReadAll;
using vobench_test::TempDir;
using vobench_test::WriteText;

constexpr auto kStartTimeout = std::chrono::seconds(60);  // until the command is under way
constexpr auto kStopTimeout = std::chrono::seconds(30);   // until it has stopped

// Starts `vobench ARGS...` with stdout and stderr into `log`.
pid_t Start(const std::vector<std::string>& args, const std::string& log) {
  return vobench_test::StartVobench(args, log);
}

// Waits for `pid` to end; its wait status, or -1 on timeout (then it is killed).
int Wait(pid_t pid) {
  const auto end = Clock::now() + kStopTimeout;
  int status = 0;
  while (Clock::now() < end) {
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return -1;
}

// Waits until `dir` holds an entry starting with `prefix` (the command's work folder).
bool WaitForEntry(const fs::path& dir, const std::string& prefix) {
  const auto end = Clock::now() + kStartTimeout;
  while (Clock::now() < end) {
    if (!EntriesStartingWith(dir.string(), prefix).empty()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// /proc/PID/stat: state and parent.
bool ProcStat(pid_t pid, char* state, pid_t* ppid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t close = text.rfind(')');
  if (close == std::string::npos) return false;
  std::istringstream rest(text.substr(close + 2));
  return static_cast<bool>(rest >> *state >> *ppid);
}

bool Alive(pid_t pid) {
  char state = 0;
  pid_t ppid = 0;
  return ProcStat(pid, &state, &ppid) && state != 'Z' && state != 'X';
}

std::vector<pid_t> ChildrenOf(pid_t parent) {
  std::vector<pid_t> children;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    char state = 0;
    pid_t ppid = 0;
    const pid_t pid = std::stoi(name);
    if (ProcStat(pid, &state, &ppid) && ppid == parent && state != 'Z') children.push_back(pid);
  }
  return children;
}

std::vector<pid_t> WaitForChildren(pid_t parent) {
  const auto end = Clock::now() + kStartTimeout;
  while (Clock::now() < end) {
    const std::vector<pid_t> children = ChildrenOf(parent);
    if (!children.empty()) return children;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return {};
}

// `run` on the whole L path (400 frames, many seconds), stopped with SIGTERM once under way.
TEST(InterruptTest, RunStoppedBySigtermSaysSoLeavesNothingAndExits143) {
  TempDir dir("interrupt_run");
  const std::string out = dir / "run";
  const pid_t pid = Start({"run", "l_hallway", "--out", out, "--no-plots"}, dir / "log.txt");
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(WaitForEntry(dir.str(), "run.")) << ReadAll(dir / "log.txt");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // into the frame loop
  kill(pid, SIGTERM);
  const int status = Wait(pid);
  const std::string log = ReadAll(dir / "log.txt");
  ASSERT_TRUE(WIFEXITED(status)) << "status " << status << ": " << log;
  EXPECT_EQ(WEXITSTATUS(status), 143) << log;
  EXPECT_NE(log.find("vobench run: interrupted after "), std::string::npos) << log;
  EXPECT_NE(log.find(" frames; nothing was written to " + out + "\n"), std::string::npos) << log;
  EXPECT_TRUE(EntriesStartingWith(dir.str(), "run").empty()) << "left behind in " << dir.str();
}

TEST(InterruptTest, RenderStoppedBySigintSaysSoLeavesNothingAndExits130) {
  TempDir dir("interrupt_render");
  const std::string out = dir / "seq";
  const pid_t pid = Start({"render", "l_hallway", "--out", out, "-q"}, dir / "log.txt");
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(WaitForEntry(dir.str(), "seq.")) << ReadAll(dir / "log.txt");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  kill(pid, SIGINT);
  const int status = Wait(pid);
  const std::string log = ReadAll(dir / "log.txt");
  ASSERT_TRUE(WIFEXITED(status)) << "status " << status << ": " << log;
  EXPECT_EQ(WEXITSTATUS(status), 130) << log;
  EXPECT_NE(log.find("vobench render: interrupted after "), std::string::npos) << log;
  EXPECT_NE(log.find(" frames; nothing was written to " + out + "\n"), std::string::npos) << log;
  EXPECT_TRUE(EntriesStartingWith(dir.str(), "seq").empty()) << "left behind in " << dir.str();
}

// One long run (the whole L path), so that its child is still running when the suite stops.
void WriteLongSuite(const TempDir& dir) {
  WriteText(dir / "long.yaml",
            "name: long\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: paper\n");
}

TEST(InterruptTest, SuiteChildrenLeadTheirOwnGroupAndDieWithAKilledSuite) {
  TempDir dir("interrupt_suite_kill");
  WriteLongSuite(dir);
  const pid_t suite =
      Start({"suite", dir / "long.yaml", "-j", "1", "-q", "--out", dir / "out"}, dir / "log.txt");
  ASSERT_GT(suite, 0);
  const std::vector<pid_t> children = WaitForChildren(suite);
  ASSERT_FALSE(children.empty()) << ReadAll(dir / "log.txt");
  // Its own process group (set by parent and child right after fork; the child may be seen
  // in the instant before, so this waits briefly).
  for (const pid_t child : children) {
    const auto until = Clock::now() + std::chrono::seconds(2);
    while (getpgid(child) != child && Clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    EXPECT_EQ(getpgid(child), child) << "own process group";
  }
  kill(suite, SIGKILL);
  int status = 0;
  waitpid(suite, &status, 0);
  // The kernel kills the children with the parent (PR_SET_PDEATHSIG): none runs on to race a
  // resumed suite in the same work folder.
  const auto end = Clock::now() + std::chrono::seconds(10);
  bool any_alive = true;
  while (any_alive && Clock::now() < end) {
    any_alive = false;
    for (const pid_t child : children) any_alive |= Alive(child);
    if (any_alive) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (const pid_t child : children) {
    EXPECT_FALSE(Alive(child)) << "child " << child << " outlived its killed suite";
    if (Alive(child)) kill(child, SIGKILL);
  }
}

TEST(InterruptTest, SuiteStoppedBySigintStopsItsChildrenAndExits130) {
  TempDir dir("interrupt_suite_int");
  WriteLongSuite(dir);
  const std::string out = dir / "out";
  const pid_t suite =
      Start({"suite", dir / "long.yaml", "-j", "1", "-q", "--out", out}, dir / "log.txt");
  ASSERT_GT(suite, 0);
  const std::vector<pid_t> children = WaitForChildren(suite);
  ASSERT_FALSE(children.empty()) << ReadAll(dir / "log.txt");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  kill(suite, SIGINT);
  const int status = Wait(suite);
  const std::string log = ReadAll(dir / "log.txt");
  ASSERT_TRUE(WIFEXITED(status)) << "status " << status << ": " << log;
  EXPECT_EQ(WEXITSTATUS(status), 130) << log;
  EXPECT_NE(log.find("interrupted by signal 2 after 0 of 1 runs"), std::string::npos) << log;
  for (const pid_t child : children) EXPECT_FALSE(Alive(child)) << child;
  EXPECT_FALSE(fs::exists(fs::path(out) / "tmp")) << "work folder left behind";
  EXPECT_TRUE(fs::exists(fs::path(out) / "suite.json"));  // resumable
}

}  // namespace
