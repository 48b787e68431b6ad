// `vobench suite`: suite files (strict), the run matrix and its ids, shards, resume after an
// interruption, shard-and-merge equal to the unsharded suite, failed runs.
#include "harness/suite.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "harness/dataset/writer.h"
#include "harness/output_folder.h"
#include "harness/sim_adapter.h"
#include "harness/suite/folder.h"
#include "harness/trajectory_io.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

using vobench_test::ReadAll;
using vobench_test::RunVobench;

namespace fs = std::filesystem;
using vobench_test::TempDir;
using vobench_test::WriteText;

// summary.csv without the timing columns (the last ones), which vary between identical runs.
std::string WithoutTimingColumns(const std::string& csv) {
  std::istringstream in(csv);
  std::string out, line;
  const size_t timing = harness::SuiteTimingColumns().size();
  while (std::getline(in, line)) {
    for (size_t k = 0; k < timing; ++k) line = line.substr(0, line.rfind(','));
    out += line + "\n";
  }
  return out;
}

fs::file_time_type MTime(const fs::path& p) { return fs::last_write_time(p); }

// A small suite: both scenes, two configs, strides 1 and 2, 6 source frames per run (8 runs).
// The corridor runs get a scenario override.
constexpr char kTinySuite[] = R"(name: tiny
max_frames: 6
scenarios:
  - scenario: l_hallway
  - name: corridor
    scenario: plain_corridor
    set: {noise.pixel_sigma: 3.0}
configs:
  - name: paper
  - name: ncc
    set: {tracker.matcher.type: ncc_mutual}
strides: [1, 2]
)";

// --------------------------------------------------------------------------------------------
// Suite files.

TEST(SuiteFileTest, ExpandsTheMatrixInAFixedOrderWithStableIds) {
  harness::Suite suite;
  std::string error;
  const std::string text = std::string(kTinySuite) + "seeds: [3, 4]\n";
  ASSERT_TRUE(harness::ParseSuite(text, "tiny.yaml", VOBENCH_SOURCE_DIR, &suite, &error)) << error;
  EXPECT_EQ(suite.name, "tiny");
  ASSERT_EQ(suite.scenarios.size(), 2u);
  EXPECT_EQ(suite.scenarios[0].name, "l_hallway");  // default: the scenario's own name
  EXPECT_EQ(suite.scenarios[1].scenario.noise.pixel_sigma, 3.0);
  EXPECT_EQ(suite.scenarios[1].max_frames, 6);
  EXPECT_EQ(suite.configs[1].options.tracker.matcher.type, vo::MatcherType::kNccMutual);

  const std::vector<harness::SuiteRun> runs = harness::ExpandSuite(suite);
  ASSERT_EQ(runs.size(), 2u * 2u * 2u * 2u);
  EXPECT_EQ(runs[0].id, "l_hallway__paper__s3__k1");
  EXPECT_EQ(runs[1].id, "l_hallway__paper__s3__k2");  // stride varies fastest
  EXPECT_EQ(runs[2].id, "l_hallway__paper__s4__k1");
  EXPECT_EQ(runs[4].id, "l_hallway__ncc__s3__k1");
  EXPECT_EQ(runs[15].id, "corridor__ncc__s4__k2");
  std::set<std::string> ids, hashes;
  for (size_t i = 0; i < runs.size(); ++i) {
    EXPECT_EQ(runs[i].index, static_cast<int>(i));
    ids.insert(runs[i].id);
    hashes.insert(runs[i].spec_hash);
    EXPECT_EQ(runs[i].spec_hash.size(), 16u);
  }
  EXPECT_EQ(ids.size(), runs.size());
  EXPECT_EQ(hashes.size(), runs.size());
  // The effective inputs carry the seed, the id as name, and the config's overrides.
  EXPECT_NE(runs[2].scenario_yaml.find("seed: 4"), std::string::npos);
  EXPECT_NE(runs[2].scenario_yaml.find("name: l_hallway__paper__s4__k1"), std::string::npos);
  EXPECT_NE(runs[4].vo_yaml.find("ncc_mutual"), std::string::npos);

  // The same text gives the same hashes; another override value gives another hash.
  harness::Suite again, other;
  ASSERT_TRUE(harness::ParseSuite(text, "tiny.yaml", VOBENCH_SOURCE_DIR, &again, &error)) << error;
  std::string changed = text;
  changed.replace(changed.find("pixel_sigma: 3.0"), 16, "pixel_sigma: 3.5");
  ASSERT_TRUE(harness::ParseSuite(changed, "tiny.yaml", VOBENCH_SOURCE_DIR, &other, &error))
      << error;
  const auto runs_again = harness::ExpandSuite(again), runs_other = harness::ExpandSuite(other);
  for (size_t i = 0; i < runs.size(); ++i) {
    EXPECT_EQ(runs_again[i].spec_hash, runs[i].spec_hash);
    EXPECT_EQ(runs_other[i].spec_hash == runs[i].spec_hash, runs[i].scenario != "corridor")
        << runs[i].id;
  }
}

TEST(SuiteFileTest, SeedsDefaultToTheScenariosOwnAndStridesToOne) {
  harness::Suite suite;
  std::string error;
  ASSERT_TRUE(
      harness::ParseSuite("name: s\nscenarios:\n  - scenario: l_hallway\n    set: {seed: 9}\n"
                          "configs:\n  - name: a\n",
                          "s.yaml", VOBENCH_SOURCE_DIR, &suite, &error))
      << error;
  const auto runs = harness::ExpandSuite(suite);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].id, "l_hallway__a__s9__k1");
  EXPECT_EQ(runs[0].max_frames, 0);
}

TEST(SuiteFileTest, ScenarioAndConfigFilesAreRelativeToTheSuite) {
  TempDir dir("suite_rel");
  fs::create_directories(dir / "sub");
  WriteText(dir / "sub/short.yaml", "name: short\nscene: " + std::string(VOBENCH_SOURCE_DIR) +
                                        "/scenes/hallway_l.xml\npath:\n  - [0, 0]\n  - [0.5, 0]\n");
  WriteText(dir / "sub/vo.yaml", "back_end.window_frames: 7\n");
  WriteText(
      dir / "suite.yaml",
      "name: rel\nscenarios:\n  - scenario: sub/short.yaml\nconfigs:\n"
      "  - name: w7\n    config: sub/vo.yaml\n    set: {tracker.matcher.type: lucas_kanade}\n");
  harness::Suite suite;
  std::string error;
  ASSERT_TRUE(harness::LoadSuite(dir / "suite.yaml", &suite, &error)) << error;
  EXPECT_EQ(suite.scenarios[0].name, "short");
  EXPECT_EQ(suite.configs[0].options.back_end.window_frames, 7);
  EXPECT_EQ(suite.configs[0].options.tracker.matcher.type, vo::MatcherType::kLucasKanade);
}

TEST(SuiteFileTest, BadSuiteFilesNameTheFileLineAndKey) {
  struct Case {
    const char* text;
    std::vector<std::string> expected;  // substrings of the message
  };
  const std::vector<Case> cases = {
      {"name: b\nscenarios:\n  - scenario: l_hallway\n    sett: {}\nconfigs:\n  - name: a\n",
       {"bad.yaml:4", "scenarios[0].sett", "unknown key"}},
      {"name: b\nscenario:\n  - scenario: l_hallway\nconfigs:\n  - name: a\n",
       {"bad.yaml:2", "'scenario'", "unknown key"}},
      {"name: b\nscenarios:\n  - scenario: nothere.yaml\nconfigs:\n  - name: a\n",
       {"bad.yaml:3", "scenarios[0].scenario", "nothere.yaml"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\n    set:\n      noise.pixel_sigmaa: "
       "2\nconfigs:\n  - name: a\n",
       {"bad.yaml:5", "noise.pixel_sigmaa", "unknown scenario key"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\n    set: {rate_hz: -1}\nconfigs:\n  - name: "
       "a\n",
       {"bad.yaml:4", "rate_hz"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\n    set:\n      "
       "tracker: {matcher: {typo: 1}}\n",
       {"bad.yaml:7", "configs[0].set.tracker.matcher.typo", "unknown VO option key"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\n    set: "
       "{tracker.matcher.type: magic}\n",
       {"bad.yaml:6", "tracker.matcher.type", "magic"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\n    config: "
       "none.yaml\n",
       {"bad.yaml:6", "configs[0].config", "none.yaml"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\n  - name: a\n",
       {"bad.yaml:6", "used twice"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\nstrides: [1, 0]\n",
       {"bad.yaml:6", "strides[1]"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\nseeds: [-1]\n",
       {"bad.yaml:6", "seeds[0]"}},
      {"name: a__b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\n",
       {"bad.yaml:1", "'name'"}},
      {"name: b\nscenarios: []\nconfigs:\n  - name: a\n", {"bad.yaml:2", "scenarios"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\n", {"bad.yaml", "configs", "required"}},
      {"name: b\nscenarios: [\n", {"bad.yaml", "malformed YAML"}},
      // Issue #11: duplicate keys, and names checked by the one path-name rule.
      {"name: b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\nname: c\n",
       {"bad.yaml:6", "key 'name': duplicate (first at line 1)"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\n    max_frames: 3\n    max_frames: 4\n"
       "configs:\n  - name: a\n",
       {"bad.yaml:5", "key 'scenarios[0].max_frames': duplicate (first at line 4)"}},
      {"name: -b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: a\n",
       {"bad.yaml:1", "suite name '-b': cannot name a folder: starts with '-'"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\n    name: ..\nconfigs:\n  - name: a\n",
       {"bad.yaml:4", "scenario name '..': cannot name a folder"}},
      {"name: b\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: \"a/b\"\n",
       {"bad.yaml:5", "configuration name 'a/b': cannot name a folder: contains a path separator"}},
  };
  for (const auto& c : cases) {
    harness::Suite suite;
    std::string error;
    EXPECT_FALSE(harness::ParseSuite(c.text, "bad.yaml", VOBENCH_SOURCE_DIR, &suite, &error))
        << c.text;
    for (const auto& e : c.expected)
      EXPECT_NE(error.find(e), std::string::npos) << "'" << e << "' not in: " << error;
  }
}

TEST(SuiteFileTest, CommandRefusesABadSuiteWithExitTwoAndWritesNothing) {
  TempDir dir("suite_bad");
  WriteText(dir / "bad.yaml",
            "name: b\nscenarios:\n  - scenario: l_hallway\n    set: {noise.pixel_sigmaa: 2}\n"
            "configs:\n  - name: a\n");
  const auto r = RunVobench("suite " + (dir / "bad.yaml") + " --out " + (dir / "out") + " -q");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.yaml:4"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("noise.pixel_sigmaa"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));

  const auto missing =
      RunVobench("suite " + (dir / "none.yaml") + " --out " + (dir / "out") + " -q");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("none.yaml"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(dir / "out"));

  WriteText(dir / "good.yaml", kTinySuite);
  const auto shard =
      RunVobench("suite " + (dir / "good.yaml") + " --shard 3/2 --out " + (dir / "out") + " -q");
  EXPECT_EQ(shard.exit_code, 2);
  EXPECT_NE(shard.output.find("--shard"), std::string::npos) << shard.output;
  EXPECT_FALSE(fs::exists(dir / "out"));

  // A folder that is not a suite's is not used.
  fs::create_directories(dir / "mine");
  WriteText(dir / "mine/notes.txt", "keep");
  const auto other =
      RunVobench("suite " + (dir / "good.yaml") + " --out " + (dir / "mine") + " -q");
  EXPECT_NE(other.exit_code, 0);
  EXPECT_NE(other.output.find("not a vobench suite folder"), std::string::npos) << other.output;
  EXPECT_EQ(fs::directory_iterator(dir / "mine")->path().filename(), "notes.txt");
}

// Issue #36: external configurations in the suite file.
TEST(SuiteFileTest, ExternalConfigsAreReadAndChecked) {
  TempDir dir("suite_ext_file");
  WriteText(dir / "vo.sh", "#!/bin/sh\n");
  fs::permissions(dir / "vo.sh", fs::perms::owner_all);
  const std::string head = "name: e\nscenarios:\n  - scenario: l_hallway\nconfigs:\n";
  harness::Suite suite;
  std::string error;
  ASSERT_TRUE(harness::ParseSuite(
      head + "  - name: paper\n  - name: mine\n    external: {command: [./vo.sh, \"{dataset}\", "
             "\"--calib={calib}\", \"{out}\"], trajectory: t.txt, format: tum, timeout_s: 5}\n",
      "e.yaml", dir.str(), &suite, &error))
      << error;
  ASSERT_EQ(suite.configs.size(), 2u);
  EXPECT_FALSE(suite.configs[0].external);
  const harness::SuiteConfig& c = suite.configs[1];
  EXPECT_TRUE(c.external);
  EXPECT_EQ(c.estimator.command[0], dir / "vo.sh");  // relative to the suite file
  EXPECT_EQ(c.estimator.command[2], "--calib={calib}");
  EXPECT_EQ(c.estimator.format, harness::TrajectoryFormat::kTum);
  EXPECT_EQ(c.estimator.timeout_s, 5.0);
  const auto runs = harness::ExpandSuite(suite);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_TRUE(runs[1].external);
  EXPECT_EQ(runs[1].id, "l_hallway__mine__s1__k1");
  EXPECT_NE(runs[0].spec_hash, runs[1].spec_hash);
  // The program enters the hash as the suite file names it: the same suite in another folder
  // (another machine's checkout) has the same hashes.
  TempDir other("suite_ext_file_other");
  fs::copy_file(dir / "vo.sh", other / "vo.sh");
  harness::Suite moved;
  ASSERT_TRUE(harness::ParseSuite(
      head + "  - name: paper\n  - name: mine\n    external: {command: [./vo.sh, \"{dataset}\", "
             "\"--calib={calib}\", \"{out}\"], trajectory: t.txt, format: tum, timeout_s: 5}\n",
      "e.yaml", other.str(), &moved, &error))
      << error;
  EXPECT_EQ(moved.configs[1].estimator.command[0], other / "vo.sh");
  EXPECT_EQ(harness::ExpandSuite(moved)[1].spec_hash, runs[1].spec_hash);

  struct Bad {
    std::string config;
    std::vector<std::string> expected;
  };
  const std::vector<Bad> bad = {
      {"  - name: x\n    external: {command: [vo.sh, \"{data}\"], trajectory: t, format: tum}\n",
       {"e.yaml:6", "configs[0].external.command[1]", "unknown placeholder {data}"}},
      {"  - name: x\n    set: {back_end.window_frames: 4}\n    external: {command: [vo.sh], "
       "trajectory: t, format: tum}\n",
       {"e.yaml:6", "configs[0].set", "not with external"}},
      {"  - name: x\n    external: {command: [vo.sh], format: tum}\n",
       {"e.yaml:6", "configs[0].external.trajectory"}},
      {"  - name: x\n    external: {command: [vo.sh], trajectory: t, format: g2o}\n",
       {"e.yaml:6", "configs[0].external.format", "g2o"}},
      {"  - name: x\n    external: {command: [./none.sh], trajectory: t, format: kitti}\n",
       {"e.yaml:6", "configs[0].external.command[0]", "no executable program"}},
      {"  - name: x\n    external: {command: [vo.sh], trajectory: ../t, format: kitti}\n",
       {"e.yaml:6", "configs[0].external.trajectory", "relative to {out}"}},
      {"  - name: x\n    external: {command: [], trajectory: t, format: kitti}\n",
       {"e.yaml:6", "configs[0].external.command", "expected a list"}},
      {"  - name: x\n    external: {command: [vo.sh], trajectory: t, format: kitti, "
       "timeout_s: 0}\n",
       {"e.yaml:6", "configs[0].external.timeout_s"}},
      {"  - name: x\n    external: {command: [vo.sh], trajectory: t, format: kitti, shell: 1}\n",
       {"e.yaml:6", "shell", "unknown key"}},
  };
  for (const Bad& b : bad) {
    EXPECT_FALSE(harness::ParseSuite(head + b.config, "e.yaml", dir.str(), &suite, &error))
        << b.config;
    for (const auto& e : b.expected)
      EXPECT_NE(error.find(e), std::string::npos) << "'" << e << "' not in: " << error;
  }
}

TEST(ShardTest, ParsesAndPartitionsTheRuns) {
  harness::Shard shard;
  std::string error;
  ASSERT_TRUE(harness::ParseShard("2/3", &shard, &error)) << error;
  EXPECT_EQ(shard.index, 2);
  EXPECT_EQ(shard.count, 3);
  for (const char* bad : {"0/3", "4/3", "1/0", "a/3", "2", "2/3/4", "-1/3", ""})
    EXPECT_FALSE(harness::ParseShard(bad, &shard, &error)) << bad;
  // Every run index lands in exactly one shard.
  for (int n = 1; n <= 5; ++n)
    for (int run = 0; run < 17; ++run) {
      int holders = 0;
      for (int i = 1; i <= n; ++i) holders += harness::Shard{i, n}.Contains(run);
      EXPECT_EQ(holders, 1) << run << " in " << n << " shards";
    }
}

TEST(ShardTest, AWorkFolderIsMadeWhileAnotherShardRemovesAnEmptyTmp) {
  // Shards sharing an output folder: one removes tmp/ when it finds it empty (RemoveLeftovers)
  // while another creates tmp/<its tag> in it.
  TempDir dir("suite_workdir");
  const fs::path out = dir.str();
  const fs::path work = harness::suite_internal::WorkDir(out, "shard2of2");
  std::atomic<bool> stop{false};
  std::thread remover([&] {
    while (!stop) harness::suite_internal::RemoveEmptyTmp(out);  // as RemoveLeftovers does
  });
  int failed = 0;
  std::string error;
  for (int i = 0; i < 2000; ++i) {
    if (!harness::suite_internal::MakeWorkDir(work, &error)) ++failed;
    std::error_code ec;
    fs::remove_all(work, ec);
  }
  stop = true;
  remover.join();
  EXPECT_EQ(failed, 0) << error;
}

// --------------------------------------------------------------------------------------------
// Running suites, through the vobench command as users and schedulers run them. Each test makes
// its own unsharded run (ctest runs every test in a process of its own).

// Runs kTinySuite unsharded into dir/full; returns the suite file's path.
std::string RunFullSuite(const TempDir& dir) {
  WriteText(dir / "tiny.yaml", kTinySuite);
  const auto r = RunVobench("suite " + (dir / "tiny.yaml") + " -j 2 --out " + (dir / "full"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return dir / "tiny.yaml";
}

TEST(SuiteRunTest, WritesEveryRunAndResumesOnlyUnfinishedRuns) {
  TempDir dir("suite_resume");
  const std::string suite = RunFullSuite(dir);
  ASSERT_FALSE(::testing::Test::HasFailure());
  const fs::path full = dir / "full";
  for (const char* f : {"suite.json", "suite.yaml", "summary.csv", "summary.md"})
    EXPECT_TRUE(fs::exists(full / f)) << f;
  EXPECT_FALSE(fs::exists(full / "tmp"));
  const std::string csv = ReadAll(full / "summary.csv");
  std::istringstream lines(csv);
  std::string header, line;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("id,scenario,config,seed,stride,max_frames,status,frames,", 0), 0u)
      << header;
  for (const char* col :
       {"end_pose_error_m", "ate_rmse_m", "lost_frames", "drift_pct", "vo_ms_median"})
    EXPECT_NE(header.find(col), std::string::npos) << col;
  int rows = 0;
  while (std::getline(lines, line)) {
    ++rows;
    EXPECT_NE(line.find(",ok,"), std::string::npos) << line;
  }
  EXPECT_EQ(rows, 8);
  // Each run folder: the `vobench run` files, the suite's stamp, the stride and overrides honoured.
  const fs::path k2 = full / "runs" / "l_hallway__paper__s1__k2";
  for (const char* f : {"metrics.json", "suite_run.json", "trajectory_world_tum.txt",
                        "vo_options.yaml", "scenario.yaml"})
    EXPECT_TRUE(fs::exists(k2 / f)) << f;
  const std::string metrics = ReadAll(k2 / "metrics.json");
  EXPECT_NE(metrics.find("\"frames\": 3,"), std::string::npos)
      << metrics;  // 6 source frames, stride 2
  // summary.csv carries every key of metrics.json (a path this short has null percentages and
  // their *_reason keys: columns too).
  std::vector<std::string> columns;
  for (size_t start = 0;;) {
    const size_t comma = header.find(',', start);
    columns.push_back(header.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  EXPECT_EQ(columns, harness::SuiteSummaryColumns());
  const nlohmann::json mj = nlohmann::json::parse(metrics);
  EXPECT_TRUE(mj["end_pose_error_pct"].is_null()) << metrics;
  for (const auto& [k, v] : mj.items()) {
    if (k == "name") continue;  // the id column
    if (v.is_object()) {
      for (const auto& [k2, v2] : v.items())
        EXPECT_NE(std::find(columns.begin(), columns.end(), k + "." + k2), columns.end()) << k2;
    } else {
      EXPECT_NE(std::find(columns.begin(), columns.end(), k), columns.end()) << k;
    }
  }
  EXPECT_NE(metrics.find("\"frame_stride\": 2"), std::string::npos) << metrics;
  EXPECT_NE(ReadAll(full / "runs/corridor__ncc__s1__k1/vo_options.yaml").find("type: ncc_mutual"),
            std::string::npos);
  EXPECT_NE(ReadAll(full / "runs/corridor__ncc__s1__k1/scenario.yaml").find("pixel_sigma: 3"),
            std::string::npos);
  const std::string md = ReadAll(full / "summary.md");
  EXPECT_NE(md.find("## Per configuration"), std::string::npos);
  EXPECT_NE(md.find("| corridor__ncc__s1__k2 | ok |"), std::string::npos) << md;

  // An interrupted suite: one run folder gone, a half-written one left as .partial (with a
  // metrics.json, so only the name says it is unfinished), a leftover in tmp/, and one run
  // whose folder exists but whose stamp records another spec.
  const fs::path out = dir / "resume";
  fs::copy(full, out, fs::copy_options::recursive);
  const std::string gone = "corridor__paper__s1__k1", stale = "l_hallway__ncc__s1__k2";
  fs::remove_all(out / "runs" / gone);
  // vobench's leftover: a work folder of a process that has exited, marked as its work folder.
  const pid_t dead = fork();
  if (dead == 0) _exit(0);
  waitpid(dead, nullptr, 0);
  const std::string partial = gone + ".partial-" + std::to_string(dead) + "-AbC123";
  fs::create_directories(out / "runs" / partial);
  WriteText((out / "runs" / partial / "metrics.json").string(), "{}");
  nlohmann::json work_marker =
      nlohmann::json::parse(ReadAll(out / "runs" / stale / ".vobench.json"));
  work_marker["pid"] = dead;
  work_marker["work_folder_of_pid"] = dead;
  WriteText((out / "runs" / partial / ".vobench.json").string(), work_marker.dump(2));
  // A finished folder copied aside under such a name (a user's backup): kept (issue #31).
  fs::copy(out / "runs" / stale, out / "runs" / (gone + ".partial"), fs::copy_options::recursive);
  fs::create_directories(out / "tmp" / "shard1of1" / "l_hallway__paper__s1__k1.partial");
  std::string stamp = ReadAll(out / "runs" / stale / "suite_run.json");
  stamp.replace(stamp.find("\"spec_hash\": \"") + 14, 16, "0000000000000000");
  WriteText((out / "runs" / stale / "suite_run.json").string(), stamp);
  std::map<std::string, fs::file_time_type> before;
  for (const auto& e : fs::directory_iterator(out / "runs"))
    if (fs::exists(e.path() / "metrics.json"))
      before[e.path().filename().string()] = MTime(e.path() / "metrics.json");

  const auto r = RunVobench("suite " + suite + " -j 2 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("6 finished before (kept), 2 to run"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(2 run now, 6 kept)"), std::string::npos) << r.output;
  // Only those two ran: every other metrics.json is untouched.
  for (const auto& [id, mtime] : before) {
    if (id == stale || id.find(".partial") != std::string::npos) continue;
    EXPECT_EQ(MTime(out / "runs" / id / "metrics.json"), mtime) << id << " was redone";
  }
  EXPECT_NE(MTime(out / "runs" / stale / "metrics.json"), before[stale]);
  EXPECT_TRUE(fs::exists(out / "runs" / gone / "suite_run.json"));
  EXPECT_FALSE(fs::exists(out / "runs" / partial));
  EXPECT_TRUE(fs::exists(out / "runs" / (gone + ".partial") / "metrics.json"));
  fs::remove_all(out / "runs" / (gone + ".partial"));  // not part of the summary below
  EXPECT_FALSE(fs::exists(out / "tmp"));
  EXPECT_EQ(WithoutTimingColumns(ReadAll(out / "summary.csv")), WithoutTimingColumns(csv));
  // The two runs redone are of different sequences: each simulated its own (the cache of the
  // first call went with its work folder).
  for (const std::string& id : {gone, stale})
    EXPECT_NE(ReadAll(out / "logs" / (id + ".log")).find(": simulating"), std::string::npos) << id;

  // Nothing left to do: a third call runs nothing and writes the same summary; --force redoes
  // (here: the one run of shard 1/8).
  const auto again = RunVobench("suite " + suite + " -q --out " + out.string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("(0 run now, 8 kept)"), std::string::npos) << again.output;
  EXPECT_EQ(WithoutTimingColumns(ReadAll(out / "summary.csv")), WithoutTimingColumns(csv));
  const auto first = MTime(out / "runs/l_hallway__paper__s1__k1/metrics.json");
  const auto forced =
      RunVobench("suite " + suite + " -q --force --shard 1/8 --out " + out.string());
  ASSERT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_NE(forced.output.find("(1 run now, 0 kept)"), std::string::npos) << forced.output;
  EXPECT_NE(MTime(out / "runs/l_hallway__paper__s1__k1/metrics.json"), first);
}

// How many of the suite's run logs say the run simulated its sequence, and how many that it read
// the sequence another run simulated (harness/sequence_cache.h).
std::pair<int, int> SimulatedAndReadLogs(const fs::path& out) {
  int simulated = 0, read = 0;
  for (const auto& e : fs::directory_iterator(out / "logs")) {
    const std::string log = ReadAll(e.path().string());
    simulated += log.find(": simulating") != std::string::npos;
    read += log.find("simulated before, reading it") != std::string::npos;
  }
  return {simulated, read};
}

TEST(SuiteRunTest, EachSequenceIsSimulatedOnceAndTheRunsEqualSimulatingRuns) {
  TempDir dir("suite_once");
  RunFullSuite(dir);
  ASSERT_FALSE(::testing::Test::HasFailure());
  const fs::path full = dir / "full";
  // Two sequences (the two scenarios, one seed), each simulated by one of its four runs.
  EXPECT_EQ(SimulatedAndReadLogs(full), std::make_pair(2, 6));
  EXPECT_FALSE(fs::exists(full / "tmp"));  // the cache went with the work folder
  // Each run equals the run of its spec that simulates for itself (as suites did before).
  for (const auto& e : fs::directory_iterator(full / "runs")) {
    const std::string id = e.path().filename().string();
    const nlohmann::json stamp = nlohmann::json::parse(ReadAll(e.path() / "suite_run.json"));
    const std::string plain = dir / ("plain_" + id);
    const auto r =
        RunVobench("run " + (full / "specs" / (id + ".scenario.yaml")).string() + " --config " +
                   (full / "specs" / (id + ".vo.yaml")).string() + " --max-frames 6 --stride " +
                   stamp["stride"].dump() + " --no-plots -q --out " + plain);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* f :
         {"trajectory_world_tum.txt", "groundtruth_world_tum.txt", "trajectory_kitti.txt",
          "estimate_in_gt_world_tum.txt", "vo_options.yaml", "scenario.yaml"})
      EXPECT_EQ(ReadAll(e.path() / f), ReadAll(fs::path(plain) / f)) << id << " " << f;
    auto metrics = [](const fs::path& run) {
      nlohmann::json j = nlohmann::json::parse(ReadAll(run / "metrics.json"));
      for (const char* k : {"vo_ms_median", "vo_ms_p95", "stage_ms_median"}) j.erase(k);
      return j;
    };
    EXPECT_EQ(metrics(e.path()), metrics(plain)) << id;
  }
}

TEST(SuiteRunTest, ShardsMergedEqualTheUnshardedSuite) {
  TempDir dir("suite_shards");
  const std::string suite = RunFullSuite(dir);
  ASSERT_FALSE(::testing::Test::HasFailure());
  std::vector<std::string> shard_dirs;
  for (int i = 1; i <= 2; ++i) {
    shard_dirs.push_back(dir / ("shard" + std::to_string(i)));
    const auto r = RunVobench("suite " + suite + " -q -j 2 --shard " + std::to_string(i) +
                              "/2 --out " + shard_dirs.back());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  // Shard i holds the runs with index % 2 == i - 1.
  std::vector<int> counts;
  for (const auto& d : shard_dirs) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(fs::path(d) / "runs")) n += e.is_directory();
    counts.push_back(n);
  }
  EXPECT_EQ(counts, (std::vector<int>{4, 4}));
  EXPECT_TRUE(fs::exists(fs::path(shard_dirs[0]) / "runs/l_hallway__paper__s1__k1"));  // index 0
  EXPECT_TRUE(fs::exists(fs::path(shard_dirs[1]) / "runs/l_hallway__paper__s1__k2"));  // index 1

  // A merge of one shard reports the other's runs missing (exit 1) ...
  const std::string merged = dir / "merged";
  const auto partial = RunVobench("suite merge --out " + merged + " " + shard_dirs[0]);
  EXPECT_EQ(partial.exit_code, 1) << partial.output;
  EXPECT_NE(partial.output.find("4 missing"), std::string::npos) << partial.output;
  // ... and with both it equals the unsharded summary in every non-timing column.
  const auto r =
      RunVobench("suite merge --out " + merged + " " + shard_dirs[0] + " " + shard_dirs[1]);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(WithoutTimingColumns(ReadAll(fs::path(merged) / "summary.csv")),
            WithoutTimingColumns(ReadAll(dir / "full/summary.csv")));
  EXPECT_TRUE(fs::exists(fs::path(merged) / "runs/corridor__ncc__s1__k2/metrics.json"));
  EXPECT_TRUE(fs::exists(fs::path(merged) / "specs/corridor__ncc__s1__k2.vo.yaml"));
  // The merged folder is a suite folder: running the suite there finds everything finished.
  const auto resume = RunVobench("suite " + suite + " -q --out " + merged);
  ASSERT_EQ(resume.exit_code, 0) << resume.output;
  EXPECT_NE(resume.output.find("(0 run now, 8 kept)"), std::string::npos) << resume.output;

  // Shards of another suite are refused, and nothing is written (the manifest tells).
  const std::string other = dir / "other_shard";
  fs::copy(shard_dirs[1], other, fs::copy_options::recursive);
  std::string manifest = ReadAll(fs::path(other) / "suite.json");
  manifest.replace(manifest.find("\"suite\": \"tiny\""), 15, "\"suite\": \"othr\"");
  WriteText((fs::path(other) / "suite.json").string(), manifest);
  const auto mixed =
      RunVobench("suite merge --out " + (dir / "mixed") + " " + shard_dirs[0] + " " + other);
  EXPECT_EQ(mixed.exit_code, 2) << mixed.output;
  EXPECT_NE(mixed.output.find("holds suite 'othr'"), std::string::npos) << mixed.output;
  EXPECT_FALSE(fs::exists(dir / "mixed"));
}

TEST(SuiteRunTest, ShardsCanShareOneOutputFolder) {
  // As SLURM array tasks on a shared file system might: both shards at once, one --out.
  TempDir dir("suite_shared");
  WriteText(dir / "tiny.yaml", kTinySuite);
  const std::string out = dir / "out";
  std::vector<FILE*> pipes;
  for (int i = 1; i <= 2; ++i)
    pipes.push_back(popen((std::string(VOBENCH_BINARY) + " suite " + (dir / "tiny.yaml") +
                           " -q -j 1 --shard " + std::to_string(i) + "/2 --out " + out + " 2>&1")
                              .c_str(),
                          "r"));
  for (FILE* pipe : pipes) {
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buf[4096];
    while (fgets(buf, sizeof(buf), pipe)) output += buf;
    const int status = pclose(pipe);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
  }
  // Every run finished once; the unsharded suite there has nothing left to do.
  const auto r = RunVobench("suite " + (dir / "tiny.yaml") + " -q --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(0 run now, 8 kept)"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(fs::path(out) / "tmp"));
}

TEST(SuiteFailureTest, AFailedRunIsRecordedAndTheOthersGoOn) {
  TempDir dir("suite_fail");
  // A scene that loads (the scenario reads) but has no robot: the run fails, not the suite.
  WriteText(dir / "broken.xml",
            "<mujoco><worldbody><geom type='plane' size='5 5 0.1'/></worldbody></mujoco>\n");
  WriteText(dir / "broken.yaml",
            "name: broken\nscene: broken.xml\npath:\n  - [0, 0]\n  - [1, 0]\n");
  WriteText(dir / "suite.yaml",
            "name: fail\nmax_frames: 4\nscenarios:\n  - scenario: broken.yaml\n"
            "  - scenario: l_hallway\nconfigs:\n  - name: paper\n");
  const auto r = RunVobench("suite " + (dir / "suite.yaml") + " -q -j 2 --out " + (dir / "out"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("1 failed"), std::string::npos) << r.output;
  const std::string failed = ReadAll(dir / "out/runs/broken__paper__s1__k1.failed.txt");
  EXPECT_NE(failed.find("exit status 1"), std::string::npos) << failed;
  EXPECT_NE(failed.find("robot"), std::string::npos) << failed;  // the child's message
  EXPECT_FALSE(fs::exists(dir / "out/runs/broken__paper__s1__k1"));
  EXPECT_TRUE(fs::exists(dir / "out/runs/l_hallway__paper__s1__k1/metrics.json"));
  const std::string csv = ReadAll(dir / "out/summary.csv");
  EXPECT_NE(csv.find("broken__paper__s1__k1,broken,paper,1,1,4,failed"), std::string::npos) << csv;
  EXPECT_NE(csv.find("l_hallway__paper__s1__k1,l_hallway,paper,1,1,4,ok,4,1,"), std::string::npos)
      << csv;
}

// Issue #36: the built-in VO and external programs side by side. The stand-in estimators write
// the dataset's ground truth as their trajectory (KITTI and TUM): they must score 0; one fails,
// one outlives its timeout. Stride 2 of 4 source frames: the programs see 2 frames.
TEST(SuiteExternalTest, ExternalProgramsRunBesideTheBuiltInVo) {
  TempDir dir("suite_ext");
  const std::vector<std::pair<std::string, std::string>> scripts = {
      {"gt_kitti.sh", "#!/bin/sh\ncp \"$1/poses.txt\" \"$2/traj_kitti.txt\"\n"},
      {"gt_tum.sh",
       "#!/bin/sh\ntest -f \"$3\" && test -d \"$1/mav0/cam0\" && cp \"$1/groundtruth_tum.txt\" "
       "\"$2/traj.txt\"\n"},
      {"fails.sh", "#!/bin/sh\necho 'no features in frame 0'\nexit 3\n"},
      {"slow.sh", "#!/bin/sh\necho 'thinking'\nsleep 60\n"},
  };
  for (const auto& [name, text] : scripts) {
    WriteText(dir / name, text);
    fs::permissions(dir / name, fs::perms::owner_all);
  }
  WriteText(dir / "suite.yaml",
            "name: ext\nmax_frames: 4\nstrides: [2]\nscenarios:\n  - scenario: l_hallway\n"
            "configs:\n  - name: paper\n"
            "  - name: kitti\n    external: {command: [./gt_kitti.sh, \"{dataset}\", \"{out}\"], "
            "trajectory: traj_kitti.txt, format: kitti}\n"
            "  - name: tum\n    external: {command: [./gt_tum.sh, \"{euroc}\", \"{out}\", "
            "\"{calib}\"], trajectory: traj.txt, format: tum}\n"
            "  - name: fails\n    external: {command: [./fails.sh], trajectory: t.txt, "
            "format: kitti}\n"
            "  - name: slow\n    external: {command: [./slow.sh], trajectory: t.txt, "
            "format: kitti, timeout_s: 0.5}\n");
  const std::string out = dir / "out";
  const auto start = std::chrono::steady_clock::now();
  const auto r = RunVobench("suite " + (dir / "suite.yaml") + " -q -j 2 --out " + out);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 50.0);
  EXPECT_EQ(r.exit_code, 1) << r.output;  // two runs failed; the suite itself did not
  EXPECT_NE(r.output.find("3 ok (3 run now, 0 kept), 2 failed"), std::string::npos) << r.output;
  for (const char* config : {"kitti", "tum"}) {
    const std::string run = out + "/runs/l_hallway__" + config + "__s1__k2";
    const nlohmann::json m = nlohmann::json::parse(ReadAll(run + "/metrics.json"));
    EXPECT_EQ(m.at("frames"), 2) << config;
    EXPECT_EQ(m.at("frame_stride"), 2) << config;
    EXPECT_EQ(m.at("ground_truth_frames"), 2) << config;
    EXPECT_GT(m.at("path_length_m").get<double>(), 0.0) << config;
    EXPECT_LT(m.at("end_pose_error_m").get<double>(), 1e-12) << config;
    EXPECT_LT(m.at("ate_rmse_m").get<double>(), 1e-12) << config;
    EXPECT_GT(m.at("command_wall_s").get<double>(), 0.0) << config;
    EXPECT_GT(m.at("command_peak_rss_mb").get<double>(), 0.0) << config;
    EXPECT_TRUE(harness::HasFolderMarker(run, "run")) << config;
    EXPECT_FALSE(fs::exists(run + "/dataset")) << config;  // the images are not kept
  }
  const std::string fails = ReadAll(out + "/runs/l_hallway__fails__s1__k2.failed.txt");
  EXPECT_NE(fails.find("exit status 3"), std::string::npos) << fails;
  EXPECT_NE(fails.find("no features in frame 0"), std::string::npos) << fails;  // its log tail
  const std::string slow = ReadAll(out + "/runs/l_hallway__slow__s1__k2.failed.txt");
  EXPECT_NE(slow.find("timed out after 0.5 s"), std::string::npos) << slow;
  EXPECT_NE(slow.find("thinking"), std::string::npos) << slow;
  EXPECT_FALSE(fs::exists(out + "/tmp"));
  // summary.csv: a row per run, beside each other; an external row has no built-in VO columns.
  const std::string csv = ReadAll(out + "/summary.csv");
  EXPECT_NE(csv.find("l_hallway__paper__s1__k2,l_hallway,paper,1,2,4,ok,2,"), std::string::npos)
      << csv;
  EXPECT_NE(csv.find("l_hallway__kitti__s1__k2,l_hallway,kitti,1,2,4,ok,2,2,"), std::string::npos)
      << csv;
  EXPECT_NE(csv.find("l_hallway__slow__s1__k2,l_hallway,slow,1,2,4,failed"), std::string::npos)
      << csv;
  EXPECT_NE(csv.find(",command_wall_s,command_peak_rss_mb,wall_s\n"), std::string::npos) << csv;

  // Resume: the finished runs are kept, only the failed ones run again.
  const auto again = RunVobench("suite " + (dir / "suite.yaml") + " -q -j 2 --out " + out);
  EXPECT_EQ(again.exit_code, 1) << again.output;
  EXPECT_NE(again.output.find("3 ok (0 run now, 3 kept), 2 failed"), std::string::npos)
      << again.output;
}

// Shards split external runs as any other; the merge holds them, and the unsharded suite on the
// merged folder finds every run finished.
TEST(SuiteExternalTest, ShardsAndMergeHoldExternalRuns) {
  TempDir dir("suite_ext_shards");
  WriteText(dir / "gt.sh", "#!/bin/sh\ncp \"$1/poses.txt\" \"$2/t.txt\"\n");
  fs::permissions(dir / "gt.sh", fs::perms::owner_all);
  WriteText(dir / "suite.yaml",
            "name: exts\nmax_frames: 4\nstrides: [1, 2]\nscenarios:\n  - scenario: l_hallway\n"
            "configs:\n  - name: gt\n    external: {command: [./gt.sh, \"{dataset}\", \"{out}\"], "
            "trajectory: t.txt, format: kitti}\n");
  for (int i = 1; i <= 2; ++i) {
    const auto r = RunVobench("suite " + (dir / "suite.yaml") + " -q --shard " + std::to_string(i) +
                              "/2 --out " + (dir / ("s" + std::to_string(i))));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("1 ok (1 run now"), std::string::npos) << r.output;
  }
  const std::string merged = dir / "merged";
  const auto m =
      RunVobench("suite merge --out " + merged + " " + (dir / "s1") + " " + (dir / "s2"));
  ASSERT_EQ(m.exit_code, 0) << m.output;
  for (const char* id : {"l_hallway__gt__s1__k1", "l_hallway__gt__s1__k2"}) {
    EXPECT_TRUE(fs::exists(merged + "/runs/" + id + "/metrics.json")) << id;
    EXPECT_TRUE(fs::exists(merged + "/specs/" + id + ".external.json")) << id;
  }
  const auto again = RunVobench("suite " + (dir / "suite.yaml") + " -q --out " + merged);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("2 ok (0 run now, 2 kept)"), std::string::npos) << again.output;
}

// The lines of a text file.
std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The IMU samples of a simulated sequence without dropped frames up to its frame `frame`: one
// every 1 / imu.rate_hz from time 0, a frame's up to half a physics step past its time.
size_t ImuSamplesUpToFrame(const sim::Scenario& s, int frame) {
  return static_cast<size_t>(
      std::floor((frame / s.rate_hz + 0.5 * s.physics_dt_s) * s.imu.rate_hz + 1e-9) + 1);
}

// The sequence of `scenario_path` (its first max_frames frames) written at stride 1 into
// dir/full, simulated at `stride` into dir/direct and copied from dir/full at that stride into
// dir/copy: the copy must hold the same files as the simulation, the same bytes (the images,
// depth, stamps, calibration, rig, imu0/data.csv and every sensor.yaml), the ground truth
// (KITTI, TUM and EuRoC's at the IMU rate) to 1e-12. *full_imu, *direct_imu: the lines of
// imu0/data.csv of dir/full and dir/direct.
void ExpectStridedCopyEqualsSimulation(const TempDir& dir, const std::string& scenario_path,
                                       int max_frames, int stride,
                                       std::vector<std::string>* full_imu,
                                       std::vector<std::string>* direct_imu) {
  harness::ExternalRunSpec spec;
  spec.scenario_path = scenario_path;
  spec.max_frames = max_frames;
  spec.stride = 1;
  std::string error;
  ASSERT_TRUE(harness::WriteSequence(spec, dir / "full", &error)) << error;
  spec.stride = stride;
  ASSERT_TRUE(harness::WriteSequence(spec, dir / "direct", &error)) << error;
  ASSERT_TRUE(harness::WriteStridedCopy(spec, dir / "full", dir / "copy", &error)) << error;
  const auto files_of = [](const fs::path& root) {
    std::set<std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(root))
      if (e.is_regular_file() && e.path().filename() != harness::kFolderMarkerFile)
        files.insert(fs::relative(e.path(), root).string());
    return files;
  };
  const std::set<std::string> files = files_of(dir / "direct");
  EXPECT_EQ(files, files_of(dir / "copy"));
  // The IMU as `vobench render --format euroc` writes it.
  for (const char* f : {"mav0/imu0/data.csv", "mav0/imu0/sensor.yaml", "mav0/body.yaml",
                        "mav0/state_groundtruth_estimate0/data.csv",
                        "mav0/state_groundtruth_estimate0/sensor.yaml"})
    EXPECT_EQ(files.count(f), 1u) << f;
  int numbers = 0;
  for (const std::string& rel : files) {
    const std::string a = ReadAll(dir / ("direct/" + rel)), b = ReadAll(dir / ("copy/" + rel));
    if (rel != "poses.txt" && rel != "groundtruth_tum.txt" && rel != "T_world_cam0first.txt" &&
        rel != "mav0/state_groundtruth_estimate0/data.csv") {
      EXPECT_TRUE(a == b) << rel << " differs: " << a.size() << " vs " << b.size() << " bytes";
      continue;
    }
    std::istringstream sa(a), sb(b);
    std::string ta, tb;
    bool same = true;  // up to the first difference beyond 1e-12 (one message per file)
    while (same && sa >> ta) {
      ASSERT_TRUE(static_cast<bool>(sb >> tb)) << rel;
      ++numbers;
      if (ta == tb) continue;
      std::replace(ta.begin(), ta.end(), ',', ' ');
      std::replace(tb.begin(), tb.end(), ',', ' ');
      std::istringstream na(ta), nb(tb);
      std::vector<double> xa, xb;
      for (double x; na >> x;) xa.push_back(x);
      for (double x; nb >> x;) xb.push_back(x);
      same = xa.size() == xb.size();
      for (size_t i = 0; same && i < xa.size(); ++i) same = std::abs(xa[i] - xb[i]) <= 1e-12;
      EXPECT_TRUE(same) << rel << ": '" << ta << "' vs '" << tb << "'";
    }
    EXPECT_FALSE(same && static_cast<bool>(sb >> tb)) << rel;
  }
  const int kept = (max_frames - 1) / stride + 1;
  EXPECT_GE(files.size(), 3u * kept + 6);  // left, right, depth (+ EuRoC images), text files
  EXPECT_GE(numbers, kept * 12);           // poses.txt at least
  *full_imu = Lines(ReadAll(dir / "full/mav0/imu0/data.csv"));
  *direct_imu = Lines(ReadAll(dir / "direct/mav0/imu0/data.csv"));
  // The strided IMU stream is the whole one up to its last frame (no sample lost between
  // frames); one ground-truth line per sample.
  ASSERT_LE(direct_imu->size(), full_imu->size());
  EXPECT_TRUE(std::equal(direct_imu->begin(), direct_imu->end(), full_imu->begin()));
  EXPECT_EQ(Lines(ReadAll(dir / "direct/mav0/state_groundtruth_estimate0/data.csv")).size(),
            direct_imu->size());
}

// The strided sequence an external run sees, written from the whole sequence simulated once,
// equals the one simulated at that stride: the same images, depth, stamps, calibration, rig and
// IMU samples byte for byte, the ground truth to 1e-12. Stride 3 of 5 frames: frames 0 and 3,
// frame 3 with the IMU samples of frames 1 and 2; frame 4's samples are left out.
TEST(SuiteExternalTest, AStridedCopyEqualsTheSequenceSimulatedAtThatStride) {
  TempDir dir("suite_ext_stride");
  const std::string path = sim::BuiltinScenarioPath("l_hallway");
  std::vector<std::string> full, direct;
  ExpectStridedCopyEqualsSimulation(dir, path, 5, 3, &full, &direct);
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(path, &s, &error)) << error;
  EXPECT_EQ(full.size(), 1 + ImuSamplesUpToFrame(s, 4));  // the header line, the samples
  EXPECT_EQ(direct.size(), 1 + ImuSamplesUpToFrame(s, 3));
  EXPECT_LT(direct.size(), full.size());
}

// The same with dropped frames and jittered stamps (frames.*): a frame kept by the simulator
// carries the samples of the frames it dropped, and the copy finds each frame's samples by the
// frame it was captured as.
TEST(SuiteExternalTest, AStridedCopyOfASequenceWithDroppedFramesEqualsItsSimulation) {
  TempDir dir("suite_ext_stride_drops");
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &s, &error)) << error;
  s.frames.drop_rate = 0.3;
  s.frames.time_jitter_s = 0.2 / s.rate_hz;
  WriteText(dir / "drops.yaml", sim::ScenarioToYaml(s));
  std::vector<std::string> full, direct;
  ExpectStridedCopyEqualsSimulation(dir, dir / "drops.yaml", 6, 2, &full, &direct);
  EXPECT_LT(direct.size(), full.size());  // frame 5's samples
}

// Issue #34: a lens goes to {euroc} raw, with its calibration, and to {dataset} rectified by
// that calibration (render's KITTI side); a strided sequence of such a scenario is simulated at
// its stride (the copy would read the rectified side back) and holds the same frames.
TEST(SuiteExternalTest, ALensIsRawInEurocAndRectifiedInTheDataset) {
  TempDir dir("suite_ext_lens");
  WriteText(dir / "lens.sh",
            "#!/bin/sh\ncp \"$1/calib.txt\" \"$3/calib.txt\" && "
            "cp \"$2/mav0/cam0/sensor.yaml\" \"$3/cam0.yaml\" && "
            "cp \"$1/image_0/000001.png\" \"$3/f1.png\" && "
            "{ cp \"$1/image_0/000002.png\" \"$3/f2.png\" || true; } && "
            "test ! -d \"$1/depth\" && cp \"$1/poses.txt\" \"$3/t.txt\"\n");
  fs::permissions(dir / "lens.sh", fs::perms::owner_all);
  const std::string lens = "{model: radtan, coeffs: [-0.28, 0.07, 0.0002, 0.00002]}";
  WriteText(dir / "suite.yaml",
            "name: extlens\nmax_frames: 5\nstrides: [1, 2]\nscenarios:\n  - scenario: l_hallway\n"
            "    set: {camera.distortion: " +
                lens +
                "}\n"
                "configs:\n  - name: lens\n    external: {command: [./lens.sh, \"{dataset}\", "
                "\"{euroc}\", \"{out}\"], trajectory: t.txt, format: kitti}\n");
  const std::string out = dir / "out";
  const auto r = RunVobench("suite " + (dir / "suite.yaml") + " -q -j 1 --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2 ok (2 run now"), std::string::npos) << r.output;
  const std::string k1 = out + "/runs/l_hallway__lens__s1__k1/estimate/";
  const std::string k2 = out + "/runs/l_hallway__lens__s1__k2/estimate/";
  EXPECT_NE(ReadAll(k1 + "cam0.yaml").find("distortion_coefficients: [-0.28, 0.07"),
            std::string::npos);
  // calib.txt: the rectified camera of the exported calibration.
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &s, &error)) << error;
  s.camera.distortion = {sim::kRadTan, {-0.28, 0.07, 0.0002, 0.00002}};
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  harness::StereoRectification rectification;
  ASSERT_TRUE(harness::ExportedRectification(s, simulator->calibration(), &rectification, &error))
      << error;
  ASSERT_FALSE(rectification.IsIdentity());
  const std::string calib = ReadAll(k1 + "calib.txt");
  EXPECT_EQ(calib.rfind("P0: " + harness::FormatDouble(rectification.camera.fx_px) + " ", 0), 0u)
      << calib;
  EXPECT_EQ(ReadAll(k2 + "calib.txt"), calib);
  EXPECT_EQ(ReadAll(k2 + "f1.png"), ReadAll(k1 + "f2.png"));  // source frame 2 in both
}

// Issues #33/#36: an external command finds the IMU in {euroc} as `render --format euroc` writes
// it, every sample up to the sequence's last frame at every stride. 4 source frames: stride 1
// sees frames 0-3, stride 2 frames 0 and 2 (frame 2 with frame 1's samples). The stand-in
// estimator keeps imu0/data.csv in its {out} (the run's estimate/).
TEST(SuiteExternalTest, AnExternalCommandSeesTheImu) {
  TempDir dir("suite_ext_imu");
  WriteText(dir / "imu.sh",
            "#!/bin/sh\ntest -f \"$1/mav0/imu0/sensor.yaml\" && test -f \"$1/mav0/body.yaml\" && "
            "test -f \"$1/mav0/state_groundtruth_estimate0/data.csv\" && "
            "cp \"$1/mav0/imu0/data.csv\" \"$2/imu.csv\" && cp \"$1/poses.txt\" \"$2/t.txt\"\n");
  fs::permissions(dir / "imu.sh", fs::perms::owner_all);
  WriteText(dir / "suite.yaml",
            "name: extimu\nmax_frames: 4\nstrides: [1, 2]\nscenarios:\n  - scenario: l_hallway\n"
            "configs:\n  - name: imu\n    external: {command: [./imu.sh, \"{euroc}\", \"{out}\"], "
            "trajectory: t.txt, format: kitti}\n");
  const std::string out = dir / "out";
  const auto r = RunVobench("suite " + (dir / "suite.yaml") + " -q -j 1 --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2 ok (2 run now"), std::string::npos) << r.output;
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &s, &error)) << error;
  const std::vector<std::string> k1 =
      Lines(ReadAll(out + "/runs/l_hallway__imu__s1__k1/estimate/imu.csv"));
  const std::vector<std::string> k2 =
      Lines(ReadAll(out + "/runs/l_hallway__imu__s1__k2/estimate/imu.csv"));
  ASSERT_EQ(k1.size(), 1 + ImuSamplesUpToFrame(s, 3));  // the header line, the samples
  ASSERT_EQ(k2.size(), 1 + ImuSamplesUpToFrame(s, 2));
  EXPECT_EQ(k1[0].rfind("#timestamp [ns],w_RS_S_x [rad s^-1]", 0), 0u) << k1[0];
  EXPECT_EQ(k1[1].rfind(std::to_string(harness::kSimulationEpochNs) + ",", 0), 0u) << k1[1];
  EXPECT_TRUE(std::equal(k2.begin(), k2.end(), k1.begin()));  // stride 2: no sample lost
}

}  // namespace
