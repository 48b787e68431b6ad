// Reliability, second round (issue #31): the defects found by probing vobench from outside as a
// careless or hostile user would, one test per defect (the numbers are the issue's). Each test
// failed on the code before the fix. Nothing a user keeps is ever touched; every impossible
// input is refused where it is read, with exit status 2 and `file:line: key 'a.b': what`.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "harness/check.h"
#include "harness/output_folder.h"
#include "harness/plots/plots.h"
#include "harness/suite/folder.h"
#include "harness/trajectory_io.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using ::testing::HasSubstr;
using ::testing::Not;
using vobench_test::EntriesStartingWith;
using vobench_test::ReadAll;
using vobench_test::RunVobench;
using vobench_test::TempDir;
using vobench_test::WriteText;

// A scenario in the L-hallway (corridor y in [-1, 1], x from -1.5) with `body` after the scene
// line (default: a 0.8 m straight path, a few frames).
std::string ShortScenario(const TempDir& dir,
                          const std::string& body = "path:\n  - [0, 0]\n  - [0.8, 0]\n",
                          const std::string& file = "short.yaml") {
  const std::string path = dir / file;
  WriteText(path, "name: short\nscene: " + std::string(VOBENCH_SOURCE_DIR) +
                      "/scenes/hallway_l.xml\n" + body);
  return path;
}

// --- 1. Moved-aside results are never deleted ------------------------------------------------

// `vobench run … --out r; mv r r.old-1; vobench run … --out r` left only r: every finished
// folder's marker names a process that has exited, and the next writer removed DIR.old-* and
// DIR.partial-* folders with such a marker.
TEST(ReliabilityTest, MovedAsideResultsAreKept) {
  TempDir dir("rel_moved");
  const std::string scenario = ShortScenario(dir);
  const std::string r = dir / "r";
  const std::string run = "run " + scenario + " --max-frames 3 --no-plots -q --out " + r;
  ASSERT_EQ(RunVobench(run).exit_code, 0);
  fs::rename(r, r + ".old-1");  // mv r r.old-1
  // cp -a r.old-1 r.partial-<a pid that has exited>-abcdef: a copy under a work folder's name
  const std::string marker = ReadAll(r + ".old-1/.vobench.json");
  const std::string pid = marker.substr(marker.find("\"pid\": ") + 7);
  const std::string copy = r + ".partial-" + pid.substr(0, pid.find_first_of(",\n")) + "-abcdef";
  fs::copy(r + ".old-1", copy, fs::copy_options::recursive);
  ASSERT_EQ(RunVobench(run).exit_code, 0);
  EXPECT_TRUE(fs::exists(r + ".old-1/metrics.json"));
  EXPECT_TRUE(fs::exists(copy + "/metrics.json"));
  EXPECT_TRUE(fs::exists(r + "/metrics.json"));
  // The same with render (a dataset folder).
  const std::string d = dir / "d";
  ASSERT_EQ(RunVobench("render " + scenario + " -q --out " + d).exit_code, 0);
  fs::rename(d, d + ".old-1");
  ASSERT_EQ(RunVobench("render " + scenario + " -q --out " + d).exit_code, 0);
  EXPECT_TRUE(fs::exists(d + ".old-1/times.txt"));
}

// --- 2. A user's DIR.lock is not vobench's -----------------------------------------------------

// An empty `o.lock` or one holding a number was overwritten with vobench's pid and deleted at
// the end; `flock o.lock vobench run … --out o` was refused ("another vobench (pid unknown)").
TEST(ReliabilityTest, AUsersLockFileIsNeitherTakenOverNorRemoved) {
  TempDir dir("rel_lock");
  const std::string scenario = ShortScenario(dir);
  const std::string o = dir / "o";
  WriteText(o + ".lock", "");
  const int fd = ::open((o + ".lock").c_str(), O_RDONLY);  // flock o.lock vobench run …
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  const auto r = RunVobench("run " + scenario + " --max-frames 3 --no-plots -q --out " + o);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(o + "/metrics.json"));
  EXPECT_EQ(ReadAll(o + ".lock"), "");
  ::close(fd);
  WriteText(o + ".lock", "1234\n");
  EXPECT_EQ(RunVobench("run " + scenario + " --max-frames 3 --no-plots -q --out " + o).exit_code,
            0);
  EXPECT_EQ(ReadAll(o + ".lock"), "1234\n");
  EXPECT_FALSE(fs::exists(o + ".vobench-lock"));
}

// --- 12. SIGHUP and SIGQUIT stop a command like SIGTERM -----------------------------------------

// A closed terminal or an ssh drop killed run/render outright, leaving DIR.lock and
// DIR.partial-*.
TEST(ReliabilityTest, SighupAndSigquitStopLikeSigtermLeavingNothing) {
  for (const int sig : {SIGHUP, SIGQUIT}) {
    TempDir dir("rel_hup");
    const std::string out = dir / "run";
    const pid_t pid = vobench_test::StartVobench({"run", "l_hallway", "--out", out, "--no-plots"},
                                                 dir / "log.txt");
    ASSERT_GT(pid, 0);
    const auto start_end = Clock::now() + std::chrono::seconds(60);
    while (EntriesStartingWith(dir.str(), "run.partial-").empty() && Clock::now() < start_end)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // into the frame loop
    kill(pid, sig);
    int status = 0;
    waitpid(pid, &status, 0);
    const std::string log = ReadAll(dir / "log.txt");
    ASSERT_TRUE(WIFEXITED(status)) << "signal " << sig << ", status " << status << ": " << log;
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig) << log;
    EXPECT_THAT(log, HasSubstr("vobench run: interrupted after "));
    EXPECT_TRUE(EntriesStartingWith(dir.str(), "run").empty()) << "left behind in " << dir.str();
  }
}

// --- 3. check --baseline FOLDER -------------------------------------------------------------

// `vobench check --baseline FOLDER` aborted with an uncaught std::ios_base::failure (exit 134);
// `--update` too.
TEST(ReliabilityTest, CheckBaselineThatIsAFolderIsRefused) {
  TempDir dir("rel_check");
  fs::create_directories(dir / "b");
  for (const std::string& extra : std::vector<std::string>{
           "", " --update --suite " + std::string(VOBENCH_SOURCE_DIR) + "/suites/ci.yaml"}) {
    const auto r = RunVobench("check --baseline " + (dir / "b") + extra + " -q");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(dir / "b" + ": is a folder, not a baseline file"));
  }
  harness::Baseline b;
  std::string error;
  EXPECT_FALSE(harness::LoadBaseline(dir / "b", &b, &error));
  EXPECT_THAT(error, HasSubstr("is a folder"));
}

// --- 5. Paths that leave the building --------------------------------------------------------

// A path at (30, 30) rendered 32 black frames with exit 0; a path whose camera ends 3 cm from a
// wall, or on the wall line, filmed through it; a segment through a wall gave exit 1 without a
// line number.
TEST(ReliabilityTest, PathsOutsideFreeSpaceAreRefusedAtTheirLine) {
  TempDir dir("rel_path");
  struct Case {
    std::string path, line, what;
  };
  const std::vector<Case> cases = {
      {"  - [30, 30]\n  - [31, 30]\n", ":4: key 'path[0]'", "leaves the building"},
      // the camera (0.15 m ahead of the axle) 3 cm from wall_south (y = -1): axle at y = -0.82
      {"  - [0, 0]\n  - [2, -0.82]\n", ":5: key 'path[1]'", "comes within"},
      {"  - [0, -1]\n  - [2, -1]\n", ":5: key 'path[1]'", "wall 'wall_south'"},
      {"  - [0, 0]\n  - [0, -2]\n", ":5: key 'path[1]'", "crosses wall 'wall_south'"},
      // an arc corner that cuts into the wall at the inside of the L
      {"robot: {corner_mode: arc, lookahead_m: 2.0}\npath:\n  - [0, 0]\n  - [8, 0]\n"
       "  - [8, 3]\n",
       ":6: key 'path[1]'", "the arc at path[1]"},
  };
  for (const Case& c : cases) {
    const bool has_path = c.path.rfind("robot", 0) == 0;
    const std::string scenario = ShortScenario(dir, has_path ? c.path : "path:\n" + c.path);
    const auto r = RunVobench("render " + scenario + " -q --out " + (dir / "d"));
    EXPECT_EQ(r.exit_code, 2) << c.path << r.output;
    EXPECT_THAT(r.output, HasSubstr(scenario + c.line)) << c.path;
    EXPECT_THAT(r.output, HasSubstr(c.what)) << c.path;
    EXPECT_FALSE(fs::exists(dir / "d"));
  }
  // The scenarios vobench ships stay valid.
  for (const char* name : {"l_hallway", "plain_corridor"}) {
    const auto r = RunVobench(std::string("run ") + name + " --max-frames 2 --no-plots -q --out " +
                              (dir / name));
    EXPECT_EQ(r.exit_code, 0) << name << r.output;
  }
}

// --- 8. Suite ids that are too long together ---------------------------------------------------

// Scenario and configuration names that each pass the 255-byte check combined into a file name
// too long: exit 1 after the suite folder and tmp/ were written.
TEST(ReliabilityTest, SuiteRunIdsThatCannotNameAFileAreRefusedBeforeAnythingIsWritten) {
  TempDir dir("rel_ids");
  const std::string long_name(120, 'a');
  WriteText(dir / "s.yaml", "name: s\nscenarios:\n  - scenario: " + ShortScenario(dir) +
                                "\n    name: " + long_name +
                                "\nconfigs:\n  - name: " + std::string(120, 'b') + "\n");
  const auto r = RunVobench("suite " + (dir / "s.yaml") + " -q --out " + (dir / "out"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr((dir / "s.yaml") + ":4: key 'scenarios[0].name': run id '"));
  EXPECT_THAT(r.output, HasSubstr("shorten the scenario or configuration name"));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// --- 9. A full disk ----------------------------------------------------------------------------

// Half-written runs/<id>.failed.txt.tmp<pid> and <baseline>.tmp<pid> stayed behind, messages
// said "write error" instead of the reason, and a plot that failed printed a Python traceback.
TEST(ReliabilityTest, FailedWritesNameTheReasonAndLeaveNoTemporaryFile) {
  std::string error;
  // /dev/full: every write fails with ENOSPC; the device itself is never removed.
  EXPECT_FALSE(harness::WriteTextFile("/dev/full", "x", &error));
  EXPECT_THAT(error, HasSubstr("/dev/full: cannot write: No space left on device"));
  EXPECT_TRUE(fs::exists("/dev/full"));
  // A file size limit (as a full disk, the write stops part-way): the atomic write leaves
  // neither the file nor its temporary.
  TempDir dir("rel_full");
  const std::string path = dir / "baseline.json";
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  const pid_t child = fork();
  if (child == 0) {
    signal(SIGXFSZ, SIG_IGN);
    const rlimit limit = {1024, 1024};
    setrlimit(RLIMIT_FSIZE, &limit);
    std::string why;
    const bool ok = harness::WriteFileAtomically(path, std::string(4096, 'x'), &why);
    const std::string reply = (ok ? "1" : "0") + why;
    (void)!write(pipe_fds[1], reply.data(), reply.size());
    _exit(0);
  }
  close(pipe_fds[1]);
  char buf[512] = {};
  const ssize_t n = read(pipe_fds[0], buf, sizeof(buf) - 1);
  close(pipe_fds[0]);
  waitpid(child, nullptr, 0);
  ASSERT_GT(n, 0);
  EXPECT_EQ(buf[0], '0');
  EXPECT_THAT(std::string(buf + 1), HasSubstr("cannot write: File too large"));
  EXPECT_TRUE(fs::is_empty(dir.str())) << "left behind in " << dir.str();
  // A plot that fails is one line with Python's reason, never its traceback.
  EXPECT_FALSE(harness::RunPlot({"timing", "/no/such/run", (dir / "t.png")}, &error));
  EXPECT_THAT(error, HasSubstr("plot.py timing failed: "));
  EXPECT_THAT(error, Not(HasSubstr("Traceback")));
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

// --- 10. Baselines ------------------------------------------------------------------------------

// `check --update` on a symlinked baseline replaced the link with a file (the target kept the old
// values); duplicate run keys: the last won silently; "value": null made a metric always pass.
TEST(ReliabilityTest, BaselineEdgeCasesAreRefusedOrChecked) {
  TempDir dir("rel_baseline");
  const std::string suite = ShortScenario(dir);
  WriteText(dir / "s.yaml", "name: s\nscenarios:\n  - scenario: " + suite +
                                "\n    max_frames: 3\nconfigs:\n  - name: a\n");
  const std::string metric = "\"ate_rmse_m\": {\"value\": 0.1, \"tolerance\": 0.01}";
  WriteText(dir / "dup.json", "{\"suite\": \"s.yaml\", \"runs\": {\"short__a__s0__k1\": {" +
                                  metric + "}, \"short__a__s0__k1\": {" + metric + "}}}\n");
  harness::Baseline b;
  std::string error;
  EXPECT_FALSE(harness::LoadBaseline(dir / "dup.json", &b, &error));
  EXPECT_THAT(error, HasSubstr("dup.json: key 'short__a__s0__k1': appears twice"));

  // null: the run is expected to give no value; a value now fails.
  WriteText(dir / "null.json",
            "{\"suite\": \"s.yaml\", \"runs\": {\"x\": {\"ate_rmse_m\": "
            "{\"value\": null, \"tolerance\": 0.01}}}}\n");
  ASSERT_TRUE(harness::LoadBaseline(dir / "null.json", &b, &error)) << error;
  harness::SuiteResult result;
  harness::SuiteRow row;
  row.run.id = "x";
  row.status = "ok";
  row.metrics["ate_rmse_m"] = 0.05;
  result.rows.push_back(row);
  const harness::CheckReport report = harness::CompareToBaseline(b, result);
  ASSERT_EQ(report.rows.size(), 1u);
  EXPECT_EQ(report.rows[0].verdict, "WORSE");
  EXPECT_EQ(report.worse, 1);

  // --update through a symbolic link writes the target; the link stays a link.
  WriteText(dir / "target.json",
            "{\"suite\": \"s.yaml\", \"runs\": {\"old\": {" + metric + "}}}\n");
  fs::create_symlink(dir / "target.json", dir / "link.json");
  const auto r = RunVobench("check --baseline " + (dir / "link.json") + " --update --suite " +
                            (dir / "s.yaml") + " -q --out " + (dir / "c"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_symlink(dir / "link.json"));
  EXPECT_THAT(ReadAll(dir / "target.json"), HasSubstr("\"short__a__s1__k1\""));
}

// --- 11. Exit codes and line numbers as the README says -------------------------------------

// rate_hz, max_duration_s, physics_dt_s, settle_s, motion_blur_samples and a repeated waypoint
// were refused without a line number; `run --out ""` wrote out/run/<name>; --stride 1000,
// max_frames: 1 and goal_tolerance_m: 100 passed validation and failed later.
TEST(ReliabilityTest, ScenarioValuesAreRefusedAtTheirLineWithExit2) {
  TempDir dir("rel_lines");
  const std::string path = "path:\n  - [0, 0]\n  - [0.8, 0]\n";
  struct Case {
    std::string body, where;
  };
  const std::vector<Case> cases = {
      {"rate_hz: 0\n" + path, ":3: key 'rate_hz': expected > 0"},
      {"max_duration_s: -1\n" + path, ":3: key 'max_duration_s': expected > 0"},
      {"physics_dt_s: 0.5\n" + path, ":3: key 'physics_dt_s': expected in (0, 0.01]"},
      {"settle_s: -1\n" + path, ":3: key 'settle_s': expected >= 0"},
      {"noise: {motion_blur_exposure_s: 0.01, motion_blur_samples: 1}\n" + path,
       ":3: key 'noise.motion_blur_samples'"},
      {"path:\n  - [0, 0]\n  - [0.8, 0]\n  - [0.8, 0]\n", ":6: key 'path[2]': repeats"},
      {"robot: {goal_tolerance_m: 100}\n" + path,
       ":3: key 'robot.goal_tolerance_m': 100 m is not below the shortest path segment"},
  };
  for (const Case& c : cases) {
    const std::string scenario = ShortScenario(dir, c.body);
    const auto r = RunVobench("run " + scenario + " --no-plots -q --out " + (dir / "o"));
    EXPECT_EQ(r.exit_code, 2) << c.body << r.output;
    EXPECT_THAT(r.output, HasSubstr(scenario + c.where)) << c.body;
  }
  const std::string scenario = ShortScenario(dir);
  const auto empty_out = RunVobench("run " + scenario + " --no-plots -q --out ''", dir.str());
  EXPECT_EQ(empty_out.exit_code, 2) << empty_out.output;
  EXPECT_THAT(empty_out.output, HasSubstr("--out"));
  EXPECT_FALSE(fs::exists(dir / "out"));
  const auto stride =
      RunVobench("run " + scenario + " --stride 1000 --no-plots -q --out " + (dir / "o"));
  EXPECT_EQ(stride.exit_code, 2) << stride.output;
  EXPECT_THAT(stride.output, HasSubstr("--stride 1000: the sequence has about "));
  const auto one =
      RunVobench("run " + scenario + " --max-frames 1 --no-plots -q --out " + (dir / "o"));
  EXPECT_EQ(one.exit_code, 2) << one.output;
  EXPECT_THAT(one.output, HasSubstr("--max-frames 1: the VO needs at least 2 frames"));
  EXPECT_FALSE(fs::exists(dir / "o"));
  // A suite of runs that would all fail is refused before the first starts.
  WriteText(dir / "s.yaml", "name: s\nscenarios:\n  - scenario: " + scenario +
                                "\n    max_frames: 1\nconfigs:\n  - name: a\n");
  const auto suite = RunVobench("suite " + (dir / "s.yaml") + " -q --out " + (dir / "so"));
  EXPECT_EQ(suite.exit_code, 2) << suite.output;
  EXPECT_THAT(suite.output, HasSubstr((dir / "s.yaml") + ":4: key 'scenarios[0]': max_frames 1"));
  EXPECT_FALSE(fs::exists(dir / "so"));
}

// --- 13. Silent acceptances ---------------------------------------------------------------------

// A ground-truth pose 1e300 m away ran to exit 0 with ATE null; a merged suite could be written
// inside one of its shard folders. (times.txt shorter than the image list: dataset_test.cc,
// KittiMalformedTest.TimesShorterThanTheImagesIsRefused.)
TEST(ReliabilityTest, ImpossiblePosesAndAMergeInsideAShardAreRefused) {
  TempDir dir("rel_silent");
  WriteText(dir / "gt.txt", "0 0 0 0 0 0 0 1\n1 1e300 0 0 0 0 0 1\n");
  std::vector<harness::StampedPose> poses;
  std::string error;
  EXPECT_FALSE(harness::ReadTum(dir / "gt.txt", &poses, &error));
  EXPECT_THAT(error, HasSubstr((dir / "gt.txt") + ":2: position 1e+300 m from the origin"));
  WriteText(dir / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1e300 0 1 0 0 0 0 1 0\n");
  std::vector<Eigen::Isometry3d> kitti;
  EXPECT_FALSE(harness::ReadKittiPoses(dir / "poses.txt", &kitti, &error));
  EXPECT_THAT(error, HasSubstr((dir / "poses.txt") + ":2: position"));

  WriteText(dir / "s.yaml", "name: s\nscenarios:\n  - scenario: " + ShortScenario(dir) +
                                "\n    max_frames: 2\nconfigs:\n  - name: a\n  - name: b\n");
  for (const char* shard : {"1/2", "2/2"}) {
    const auto r = RunVobench("suite " + (dir / "s.yaml") + " --shard " + shard + " -q --out " +
                              (dir / ("shard" + std::string(1, shard[0]))));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const auto merge = RunVobench("suite merge --out " + (dir / "shard1/merged") + " " +
                                (dir / "shard1") + " " + (dir / "shard2"));
  EXPECT_EQ(merge.exit_code, 2) << merge.output;
  EXPECT_THAT(merge.output, HasSubstr("must not be inside the shard folder"));
  EXPECT_FALSE(fs::exists(dir / "shard1/merged"));
}

}  // namespace
