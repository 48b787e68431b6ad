// Ownership of output folders (issue #11, point 1; harness/output_folder.h): vobench replaces
// only folders it can prove it wrote (the .vobench.json marker), a second writer of the same
// folder fails at once, and stale work folders are removed only when they carry the marker.
// The OwnershipCliTest cases reproduce the defects as a user met them; they fail on the code
// before the marker (files deleted, a confusing write error).
#include "harness/output_folder.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using harness::FolderMarker;
using harness::OutputFolder;
using ::testing::HasSubstr;
using vobench_test::EntriesStartingWith;
using vobench_test::ReadAll;
using vobench_test::RunVobench;
using vobench_test::TempDir;
using vobench_test::WriteText;

// A pid that no process has: a child that has exited and been reaped.
pid_t DeadPid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  int status = 0;
  waitpid(pid, &status, 0);
  return pid;
}

std::string HostName() {
  char name[256] = {};
  gethostname(name, sizeof(name) - 1);
  return name;
}

// A marker as vobench writes it, for process `pid` of this host (`work`: of its work folder).
void WriteMarker(const std::string& dir, const std::string& kind, long pid, bool work = false) {
  nlohmann::json j;
  j["vobench_folder"] = harness::kFolderMarkerFormat;
  j["kind"] = kind;
  j["version"] = harness::VobenchVersion();
  j["command"] = {"vobench", "run"};
  j["created_utc"] = "2026-01-01T00:00:00Z";
  j["pid"] = pid;
  j["host"] = HostName();
  if (work) j[harness::kWorkFolderKey] = pid;
  WriteText(dir + "/" + harness::kFolderMarkerFile, j.dump(2) + "\n");
}

// --- The class --------------------------------------------------------------------------------

TEST(OutputFolderTest, WritesTheMarkerFirstAndPublishesUnderALock) {
  TempDir dir("of_publish");
  const std::string out = dir / "sub/run";  // parent folders are created
  OutputFolder folder;
  std::string error;
  ASSERT_TRUE(folder.Create(out, "run", &error)) << error;
  // The work folder: DIR.partial-<pid>-<random>, holding only its marker so far.
  EXPECT_THAT(folder.path(),
              ::testing::StartsWith(out + ".partial-" + std::to_string(getpid()) + "-"));
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(folder.path()))
    files.push_back(e.path().filename().string());
  EXPECT_EQ(files, std::vector<std::string>{".vobench.json"});
  FolderMarker work;
  ASSERT_TRUE(harness::ReadFolderMarker(folder.path(), &work, &error)) << error;
  EXPECT_EQ(work.work_folder_of_pid, getpid());  // "work folder of pid P"
  EXPECT_EQ(ReadAll(out + ".vobench-lock"),
            "vobench-lock pid=" + std::to_string(getpid()) + " host=" + HostName() + "\n");
  EXPECT_FALSE(fs::exists(out));
  WriteText(folder.path() + "/metrics.json", "{}");
  ASSERT_TRUE(folder.Publish(&error)) << error;

  FolderMarker marker;
  ASSERT_TRUE(harness::ReadFolderMarker(out, &marker, &error)) << error;
  EXPECT_EQ(marker.format, 1);
  EXPECT_EQ(marker.kind, "run");
  EXPECT_EQ(marker.version, harness::VobenchVersion());
  EXPECT_THAT(marker.version, ::testing::StartsWith("0."));
  ASSERT_FALSE(marker.command.empty());
  EXPECT_THAT(marker.command[0], HasSubstr("output_folder_test"));
  EXPECT_THAT(marker.created_utc,
              ::testing::MatchesRegex("[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9]{2}:[0-9]{2}:[0-9]{2}Z"));
  EXPECT_EQ(marker.pid, getpid());
  EXPECT_EQ(marker.host, HostName());
  EXPECT_EQ(marker.work_folder_of_pid, 0);  // published: no longer a work folder
  EXPECT_THAT(ReadAll(out + "/.vobench.json"), ::testing::Not(HasSubstr("work_folder_of_pid")));
  EXPECT_TRUE(fs::exists(out + "/metrics.json"));
  // Nothing else is left beside it: no work folder, no lock file.
  EXPECT_EQ(EntriesStartingWith(dir / "sub", "run"), std::vector<std::string>{"run"});
}

TEST(OutputFolderTest, DestroyedBeforePublishLeavesNothing) {
  TempDir dir("of_discard");
  const std::string out = dir / "run";
  {
    OutputFolder folder;
    std::string error;
    ASSERT_TRUE(folder.Create(out, "run", &error)) << error;
    WriteText(folder.path() + "/metrics.json", "{}");
  }
  EXPECT_TRUE(EntriesStartingWith(dir.str(), "run").empty());
}

TEST(OutputFolderTest, ReplacesItsOwnFolderOfTheSameKindAndAnEmptyOne) {
  TempDir dir("of_replace");
  const std::string out = dir / "run";
  for (int k = 0; k < 2; ++k) {
    OutputFolder folder;
    std::string error;
    ASSERT_TRUE(folder.Create(out, "run", &error)) << error;
    WriteText(folder.path() + "/n.txt", std::to_string(k));
    ASSERT_TRUE(folder.Publish(&error)) << error;
  }
  EXPECT_EQ(ReadAll(out + "/n.txt"), "1");
  EXPECT_EQ(EntriesStartingWith(dir.str(), "run"), std::vector<std::string>{"run"});

  const std::string empty = dir / "empty";
  fs::create_directories(empty);
  OutputFolder folder;
  std::string error;
  ASSERT_TRUE(folder.Create(empty, "run", &error)) << error;
  ASSERT_TRUE(folder.Publish(&error)) << error;
  EXPECT_TRUE(harness::HasFolderMarker(empty, "run"));
}

TEST(OutputFolderTest, RefusesFoldersVobenchDidNotWriteOrWroteAsAnotherKind) {
  TempDir dir("of_refuse");
  std::string error;
  // No marker: a stray metrics.json proves nothing.
  const std::string mine = dir / "m";
  fs::create_directories(mine);
  WriteText(mine + "/metrics.json", "{}");
  WriteText(mine + "/thesis.tex", "t");
  OutputFolder folder;
  EXPECT_FALSE(folder.Create(mine, "run", &error));
  EXPECT_EQ(error, mine +
                       ": exists and was not written by vobench (no .vobench.json), so it is not "
                       "a vobench run folder; remove it yourself or choose another --out");
  EXPECT_EQ(ReadAll(mine + "/thesis.tex"), "t");
  EXPECT_EQ(EntriesStartingWith(dir.str(), "m"), std::vector<std::string>{"m"});  // no lock left

  // A marker of another kind: a dataset is not replaced by a run.
  const std::string dataset = dir / "d";
  fs::create_directories(dataset);
  WriteMarker(dataset, "dataset", 1);
  WriteText(dataset + "/calib.txt", "x");
  OutputFolder run;
  EXPECT_FALSE(run.Create(dataset, "run", &error));
  EXPECT_THAT(error, HasSubstr(dataset + ": holds a vobench dataset folder (.vobench.json kind "
                                         "'dataset'), not a vobench run folder; remove it "
                                         "yourself or choose another --out"));
  EXPECT_TRUE(fs::exists(dataset + "/calib.txt"));

  // A marker that is not one, and a file in the way.
  WriteText(mine + "/.vobench.json", "{\"kind\": ");
  EXPECT_FALSE(harness::CheckReplaceable(mine, "run", &error));
  EXPECT_THAT(error, HasSubstr("not a vobench folder marker"));
  WriteText(dir / "file", "x");
  EXPECT_FALSE(harness::CheckReplaceable(dir / "file", "run", &error));
  EXPECT_THAT(error, HasSubstr("exists and is not a folder"));

  // Without replace_existing, even vobench's own folder stays (render without --overwrite).
  OutputFolder::Options keep;
  keep.replace_existing = false;
  keep.replace_flag = "--overwrite";
  WriteMarker(mine, "run", 1);
  OutputFolder again;
  EXPECT_FALSE(again.Create(mine, "run", keep, &error));
  EXPECT_EQ(error, mine + ": output folder already exists (pass --overwrite to replace it)");
}

TEST(OutputFolderTest, SecondWriterOfTheSameFolderFailsAtOnce) {
  TempDir dir("of_lock");
  const std::string out = dir / "run";
  OutputFolder first;
  std::string error;
  ASSERT_TRUE(first.Create(out, "run", &error)) << error;
  OutputFolder second;
  EXPECT_FALSE(second.Create(out, "run", &error));
  EXPECT_EQ(error, out + ": another vobench (pid " + std::to_string(getpid()) +
                       ") is writing this folder; wait for it to end or choose another --out");
  EXPECT_EQ(EntriesStartingWith(dir.str(), "run.partial-").size(), 1u);  // the first's only
  ASSERT_TRUE(first.Publish(&error)) << error;
  OutputFolder third;  // the lock is free again
  ASSERT_TRUE(third.Create(out, "run", &error)) << error;
  ASSERT_TRUE(third.Publish(&error)) << error;
}

TEST(OutputFolderTest, AFileNamedLikeTheLockThatIsNotOneIsKept) {
  TempDir dir("of_lockfile");
  const std::string out = dir / "run";
  for (const std::string text : {"my notes\n", "", "4242\n"}) {  // empty, a bare pid: not ours
    WriteText(out + ".vobench-lock", text);
    OutputFolder folder;
    std::string error;
    EXPECT_FALSE(folder.Create(out, "run", &error));
    EXPECT_THAT(error, HasSubstr(out + ".vobench-lock: exists and is not a vobench lock file"));
    EXPECT_EQ(ReadAll(out + ".vobench-lock"), text);
  }
}

// A lock file is created, locked and then written: a second vobench that finds it still empty
// and locked waits for the text (it is the first one's, not a user's file).
TEST(OutputFolderTest, ALockFileBeingWrittenIsAnotherVobenchs) {
  TempDir dir("of_lock_race");
  const std::string out = dir / "run";
  const std::string lock_path = out + ".vobench-lock";
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  if (child == 0) {  // FolderLock::Acquire's steps, with a pause before the text
    const int fd = open(lock_path.c_str(), O_RDWR | O_CREAT | O_EXCL, 0644);
    const char ok = fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0 ? '1' : '0';
    (void)!write(ready[1], &ok, 1);
    usleep(300 * 1000);
    const std::string text = "vobench-lock pid=" + std::to_string(getpid()) + " host=h\n";
    (void)!pwrite(fd, text.data(), text.size(), 0);
    pause();  // until SIGKILL
    _exit(0);
  }
  char ok = 0;
  ASSERT_EQ(read(ready[0], &ok, 1), 1);
  ASSERT_EQ(ok, '1');
  OutputFolder blocked;
  std::string error;
  EXPECT_FALSE(blocked.Create(out, "run", &error));
  EXPECT_THAT(error, HasSubstr("another vobench (pid " + std::to_string(child) + ")"));
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  close(ready[0]);
  close(ready[1]);
}

TEST(OutputFolderTest, LockOfAKilledWriterIsTakenOver) {
  TempDir dir("of_killed");
  const std::string out = dir / "run";
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  if (child == 0) {
    harness::FolderLock lock;
    std::string error;
    const char ok = lock.Acquire(out + ".vobench-lock", out, &error) ? '1' : '0';
    (void)!write(ready[1], &ok, 1);
    pause();  // until SIGKILL: no destructor runs
    _exit(0);
  }
  char ok = 0;
  ASSERT_EQ(read(ready[0], &ok, 1), 1);
  ASSERT_EQ(ok, '1');
  OutputFolder blocked;
  std::string error;
  EXPECT_FALSE(blocked.Create(out, "run", &error));
  EXPECT_THAT(error, HasSubstr("another vobench (pid " + std::to_string(child) + ")"));
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_TRUE(fs::exists(out + ".vobench-lock"));  // left behind, but no longer locked
  OutputFolder folder;
  ASSERT_TRUE(folder.Create(out, "run", &error)) << error;
  ASSERT_TRUE(folder.Publish(&error)) << error;
  EXPECT_FALSE(fs::exists(out + ".vobench-lock"));
  close(ready[0]);
  close(ready[1]);
}

TEST(OutputFolderTest, StaleWorkFoldersAreRemovedOnlyWhenMarked) {
  TempDir dir("of_stale");
  const std::string out = dir / "run";
  const pid_t dead = DeadPid();
  // A vobench killed outright left its marked work folder: removed.
  const std::string stale = out + ".partial-" + std::to_string(dead) + "-xAbC12";
  fs::create_directories(stale + "/sub");
  WriteMarker(stale, "run", dead, /*work=*/true);
  // A folder of the same pattern without a marker: not vobench's to remove.
  const std::string foreign = out + ".partial-" + std::to_string(dead) + "-yAbC12";
  fs::create_directories(foreign);
  WriteText(foreign + "/notes.txt", "keep");
  // A marked work folder of a process that still runs (this one): left alone.
  const std::string live = out + ".partial-" + std::to_string(getpid()) + "-zAbC12";
  fs::create_directories(live);
  WriteMarker(live, "run", getpid(), /*work=*/true);
  // A finished folder of that dead process renamed to the pattern (a user's backup): kept.
  const std::string backup = out + ".partial-" + std::to_string(dead) + "-bAcKuP";
  fs::create_directories(backup);
  WriteMarker(backup, "run", dead);
  // A work marker whose pid is not the one in the name, and a name that is not exactly the
  // pattern: kept.
  const std::string other_pid = out + ".partial-1-qAbC12";
  fs::create_directories(other_pid);
  WriteMarker(other_pid, "run", dead, /*work=*/true);
  const std::string inexact = out + ".partial-" + std::to_string(dead) + "-x";
  fs::create_directories(inexact);
  WriteMarker(inexact, "run", dead, /*work=*/true);

  OutputFolder folder;
  std::string error;
  ASSERT_TRUE(folder.Create(out, "run", &error)) << error;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_EQ(ReadAll(foreign + "/notes.txt"), "keep");
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(backup));
  EXPECT_TRUE(fs::exists(other_pid));
  EXPECT_TRUE(fs::exists(inexact));
  ASSERT_TRUE(folder.Publish(&error)) << error;
}

TEST(OutputFolderTest, AdoptFolderMarksANewOrEmptyFolderAndKeepsItsOwn) {
  TempDir dir("of_adopt");
  std::string error;
  ASSERT_TRUE(harness::AdoptFolder(dir / "new/suite", "suite", &error)) << error;
  EXPECT_TRUE(harness::HasFolderMarker(dir / "new/suite", "suite"));
  WriteText(dir / "new/suite/suite.json", "{}");
  ASSERT_TRUE(harness::AdoptFolder(dir / "new/suite", "suite", &error)) << error;
  EXPECT_TRUE(fs::exists(dir / "new/suite/suite.json"));
  EXPECT_EQ(EntriesStartingWith(dir / "new", "suite"), std::vector<std::string>{"suite"});
  fs::create_directories(dir / "empty");
  ASSERT_TRUE(harness::AdoptFolder(dir / "empty", "suite", &error)) << error;
  EXPECT_TRUE(harness::HasFolderMarker(dir / "empty", "suite"));
  fs::create_directories(dir / "mine");
  WriteText(dir / "mine/notes.txt", "keep");
  EXPECT_FALSE(harness::AdoptFolder(dir / "mine", "suite", &error));
  EXPECT_THAT(error, HasSubstr("not a vobench suite folder"));
  EXPECT_FALSE(harness::AdoptFolder(dir / "new/suite", "run", &error));
}

TEST(OutputFolderTest, ReplaceFolderSwapsInTheNewFolder) {
  TempDir dir("of_swap");
  const std::string to = dir / "to", from = dir / "from";
  fs::create_directories(to);
  WriteMarker(to, "run", 1);
  WriteText(to + "/old.txt", "old");
  fs::create_directories(from);
  WriteMarker(from, "run", 1);
  WriteText(from + "/new.txt", "new");
  std::string error;
  ASSERT_TRUE(harness::ReplaceFolder(from, to, "run", &error)) << error;
  EXPECT_EQ(ReadAll(to + "/new.txt"), "new");
  EXPECT_FALSE(fs::exists(to + "/old.txt"));
  EXPECT_FALSE(fs::exists(from));
  // Refused onto a folder vobench did not write; both stay as they are.
  fs::create_directories(from);
  fs::create_directories(dir / "mine");
  WriteText(dir / "mine/notes.txt", "keep");
  EXPECT_FALSE(harness::ReplaceFolder(from, dir / "mine", "run", &error));
  EXPECT_TRUE(fs::exists(from));
  EXPECT_EQ(ReadAll(dir / "mine/notes.txt"), "keep");
}

// --- The commands, as a user met the defects -------------------------------------------------

// A short scenario in the real hallway (0.8 m straight).
std::string ShortScenario(const TempDir& dir) {
  const std::string path = dir / "short.yaml";
  WriteText(path, "name: short\nscene: " + std::string(VOBENCH_SOURCE_DIR) +
                      "/scenes/hallway_l.xml\npath:\n  - [0, 0]\n  - [0.8, 0]\n");
  return path;
}

// `render --overwrite` removed any existing folder, dataset or not.
TEST(OwnershipCliTest, RenderOverwriteKeepsAFolderVobenchDidNotWrite) {
  TempDir dir("own_render");
  const std::string d = dir / "d";
  fs::create_directories(d);
  WriteText(d + "/important.txt", "x");
  const auto r = RunVobench("render l_hallway --out " + d + " --overwrite -q");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("vobench render: " + d +
                                  ": exists and was not written by vobench (no .vobench.json)"));
  EXPECT_THAT(r.output, HasSubstr("remove it yourself or choose another --out"));
  EXPECT_EQ(ReadAll(d + "/important.txt"), "x");
  EXPECT_EQ(EntriesStartingWith(dir.str(), "d"), std::vector<std::string>{"d"});

  // vobench's own dataset is replaced with --overwrite, refused without; a run folder is not a
  // dataset and is not replaced by one.
  const std::string scenario = ShortScenario(dir);
  const std::string seq = dir / "seq";
  ASSERT_EQ(RunVobench("render " + scenario + " --out " + seq + " -q").exit_code, 0);
  EXPECT_TRUE(harness::HasFolderMarker(seq, "dataset"));
  const auto again = RunVobench("render " + scenario + " --out " + seq + " -q");
  EXPECT_NE(again.exit_code, 0);
  EXPECT_THAT(again.output, HasSubstr(seq + ": output folder already exists (pass --overwrite "
                                            "to replace it)"));
  EXPECT_EQ(RunVobench("render " + scenario + " --out " + seq + " -q --overwrite").exit_code, 0)
      << "its own dataset is replaced";
  const std::string run = dir / "run";
  ASSERT_EQ(RunVobench("run " + scenario + " --max-frames 4 --no-plots -q --out " + run).exit_code,
            0);
  const auto onto_run = RunVobench("render " + scenario + " --out " + run + " -q --overwrite");
  EXPECT_NE(onto_run.exit_code, 0);
  EXPECT_THAT(onto_run.output, HasSubstr("holds a vobench run folder"));
  EXPECT_TRUE(fs::exists(run + "/metrics.json"));
}

// `run` replaced any folder holding a file named metrics.json, other files included.
TEST(OwnershipCliTest, RunKeepsAFolderThatOnlyHoldsAStrayMetricsJson) {
  TempDir dir("own_run");
  const std::string m = dir / "m";
  fs::create_directories(m);
  WriteText(m + "/metrics.json", "{}");
  WriteText(m + "/thesis.tex", "t");
  const auto r =
      RunVobench("run " + ShortScenario(dir) + " --max-frames 5 --no-plots -q --out " + m);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("vobench run: " + m +
                                  ": exists and was not written by vobench (no .vobench.json), so "
                                  "it is not a vobench run folder; remove it yourself or choose "
                                  "another --out"));
  EXPECT_EQ(ReadAll(m + "/thesis.tex"), "t");
  EXPECT_EQ(ReadAll(m + "/metrics.json"), "{}");
  EXPECT_EQ(EntriesStartingWith(dir.str(), "m"), std::vector<std::string>{"m"});
}

// Re-running into vobench's own earlier run folder replaces it, as before the marker.
TEST(OwnershipCliTest, RerunningIntoItsOwnRunFolderReplacesIt) {
  TempDir dir("own_rerun");
  const std::string scenario = ShortScenario(dir), out = dir / "r";
  const auto first = RunVobench("run " + scenario + " --max-frames 5 --no-plots -q --out " + out);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  FolderMarker marker;
  std::string error;
  ASSERT_TRUE(harness::ReadFolderMarker(out, &marker, &error)) << error;
  EXPECT_EQ(marker.kind, "run");
  EXPECT_EQ(marker.command.back(), out);
  const long first_pid = marker.pid;
  const auto second = RunVobench("run " + scenario + " --max-frames 4 --no-plots -q --out " + out);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  ASSERT_TRUE(harness::ReadFolderMarker(out, &marker, &error)) << error;
  EXPECT_NE(marker.pid, first_pid);
  EXPECT_THAT(ReadAll(out + "/metrics.json"), HasSubstr("\"frames\": 4"));
  EXPECT_EQ(EntriesStartingWith(dir.str(), "r"), std::vector<std::string>{"r"});
}

// Two runs with the same --out shared one ".partial" folder: the second removed the first's work
// and then failed with a confusing write error.
TEST(OwnershipCliTest, SecondConcurrentWriterFailsFastAndTheFirstCompletes) {
  TempDir dir("own_concurrent");
  const std::string out = dir / "o";
  const std::string log = dir / "first.log";
  const pid_t first = vobench_test::StartVobench(
      {"run", "l_hallway", "--max-frames", "80", "--no-plots", "-q", "--out", out}, log);
  ASSERT_GT(first, 0);
  // Once the first holds the folder (its work folder exists), start the second.
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (EntriesStartingWith(dir.str(), "o.partial-").empty() &&
         std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_FALSE(EntriesStartingWith(dir.str(), "o.partial-").empty()) << ReadAll(log);
  // The first is held still while the second runs: on a loaded machine the first's 80 frames can
  // otherwise end before the second even starts (CI saw the second find no writer at all).
  ASSERT_EQ(kill(first, SIGSTOP), 0);
  const bool first_still_writing = !EntriesStartingWith(dir.str(), "o.partial-").empty();
  const auto start = std::chrono::steady_clock::now();
  const auto second = first_still_writing
                          ? RunVobench("run l_hallway --max-frames 5 --no-plots -q --out " + out)
                          : vobench_test::CommandResult{};
  const double second_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(kill(first, SIGCONT), 0);
  ASSERT_TRUE(first_still_writing) << "the first published before it was held";
  EXPECT_EQ(second.exit_code, 1) << second.output;
  EXPECT_THAT(second.output, HasSubstr("vobench run: " + out + ": another vobench (pid " +
                                       std::to_string(first) + ") is writing this folder"));
  EXPECT_LT(second_s, 30.0) << "fails fast, without running the VO";
  int status = 0;
  ASSERT_EQ(waitpid(first, &status, 0), first);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << ReadAll(log);
  EXPECT_THAT(ReadAll(out + "/metrics.json"), HasSubstr("\"frames\": 80"));
  FolderMarker marker;
  std::string error;
  ASSERT_TRUE(harness::ReadFolderMarker(out, &marker, &error)) << error;
  EXPECT_EQ(marker.pid, first);
  EXPECT_EQ(EntriesStartingWith(dir.str(), "o"), (std::vector<std::string>{"o"}));
}

// A stale work folder of a killed vobench is removed by the next run of the same --out; one
// without the marker is never touched.
TEST(OwnershipCliTest, RunCleansOnlyMarkedStaleWorkFolders) {
  TempDir dir("own_stale");
  const std::string out = dir / "o";
  const pid_t dead = DeadPid();
  const std::string stale = out + ".partial-" + std::to_string(dead) + "-xAbC12";
  fs::create_directories(stale);
  WriteMarker(stale, "run", dead, /*work=*/true);
  const std::string foreign = out + ".partial-" + std::to_string(dead) + "-yAbC12";
  fs::create_directories(foreign);
  WriteText(foreign + "/data.bin", "mine");
  const auto r =
      RunVobench("run " + ShortScenario(dir) + " --max-frames 4 --no-plots -q --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_EQ(ReadAll(foreign + "/data.bin"), "mine");
}

// A suite folder: marked on creation; a second call on the same shard fails at once, while a
// folder vobench did not write is not used.
TEST(OwnershipCliTest, SuiteLocksItsShardAndRefusesAFolderItDidNotWrite) {
  TempDir dir("own_suite");
  WriteText(dir / "s.yaml",
            "name: s\nscenarios:\n  - scenario: l_hallway\n    max_frames: 2\nconfigs:\n"
            "  - name: a\n");
  const std::string out = dir / "out";
  std::string error;
  ASSERT_TRUE(harness::AdoptFolder(out, "suite", &error)) << error;
  harness::FolderLock shard;  // as a running `suite --shard 1/1` holds it
  ASSERT_TRUE(shard.Acquire(out + "/.shard1of1.lock", out + " (shard shard1of1)", &error)) << error;
  const auto busy = RunVobench("suite " + (dir / "s.yaml") + " -q --out " + out);
  EXPECT_EQ(busy.exit_code, 1) << busy.output;
  EXPECT_THAT(busy.output, HasSubstr(out + " (shard shard1of1): another vobench (pid " +
                                     std::to_string(getpid()) + ") is writing this folder"));
  EXPECT_FALSE(fs::exists(out + "/runs"));

  fs::create_directories(dir / "mine");
  WriteText(dir / "mine/suite.json", "{}");
  const auto mine = RunVobench("suite " + (dir / "s.yaml") + " -q --out " + (dir / "mine"));
  EXPECT_EQ(mine.exit_code, 1) << mine.output;
  EXPECT_THAT(mine.output, HasSubstr("exists and was not written by vobench (no .vobench.json)"));
  EXPECT_EQ(ReadAll(dir / "mine/suite.json"), "{}");
}

}  // namespace
