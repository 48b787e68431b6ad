// The vobench command line (issue #11): argument errors exit with 2 and one readable line,
// --config must name a readable file, names that become folders pass one check, and
// implausible calibrations are refused before anything is written.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using vobench_test::CommandResult;
using vobench_test::RunVobench;
using vobench_test::TempDir;
using vobench_test::WriteText;

// Runs `vobench ARGS` with `dir` as the working folder.
CommandResult RunVobenchIn(const std::string& dir, const std::string& args) {
  return vobench_test::RunVobench(args, dir);
}

int Lines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

TEST(CliTest, ArgumentErrorsExitTwoWithOneReadableLine) {
  struct Case {
    std::string args, expected;
  };
  const std::vector<Case> cases = {
      {"run --stride 0", "vobench run: --stride: must be >= 1, got 0 (see vobench run --help)"},
      {"run --stride x", "vobench run: --stride: expected an integer >= 1, got 'x'"},
      {"run --max-frames -1", "vobench run: --max-frames: must be >= 0, got -1"},
      {"eval --dataset d --format kitti --max-frames -1",
       "vobench eval: --max-frames: must be >= 0, got -1"},
      {"match-eval --max-frames -2", "vobench match-eval: --max-frames: must be >= 0, got -2"},
      {"suite s.yaml -j 0", "vobench suite: --jobs: must be >= 1, got 0"},
      {"check -j 0", "vobench check: --jobs: must be >= 1, got 0"},
      {"tune t.yaml --max-evals 0", "vobench tune: --max-evals: must be >= 1, got 0"},
      {"run --bogus", "vobench run: The following argument was not expected: --bogus"},
      {"render", "vobench render: --out is required"},
      {"suite merge d1", "vobench suite merge: --out is required"},
      {"", "vobench: A subcommand is required (see vobench --help)"},
      {"fly", "vobench: A subcommand is required"},
  };
  for (const Case& c : cases) {
    const CommandResult r = RunVobench(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << ": " << r.output;
    EXPECT_EQ(Lines(r.output), 1) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.args << ": " << r.output;
    EXPECT_EQ(r.output.find("1797693"), std::string::npos) << c.args << ": " << r.output;
  }
  EXPECT_EQ(RunVobench("--help").exit_code, 0);
  EXPECT_EQ(RunVobench("run --help").exit_code, 0);
  EXPECT_EQ(RunVobench("suite merge --help").exit_code, 0);
}

TEST(CliTest, ConfigThatIsAFolderOrMissingIsAnErrorNamingIt) {
  TempDir dir("cli_config");
  fs::create_directories(dir / "conf.d");
  for (const std::string& command : std::vector<std::string>{
           "run", "eval --dataset " + dir.str() + " --format kitti", "match-eval"}) {
    const CommandResult folder =
        RunVobench(command + " --config " + (dir / "conf.d") + " -q --out " + (dir / "out"));
    EXPECT_EQ(folder.exit_code, 2) << folder.output;
    EXPECT_NE(folder.output.find(dir / "conf.d" + ": is a folder, expected a YAML VO config file"),
              std::string::npos)
        << folder.output;
    const CommandResult missing =
        RunVobench(command + " --config " + (dir / "none.yaml") + " -q --out " + (dir / "out"));
    EXPECT_EQ(missing.exit_code, 2) << missing.output;
    EXPECT_NE(missing.output.find(dir / "none.yaml" + ": no such file"), std::string::npos)
        << missing.output;
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
}

// match-eval --config evaluates the config's matcher options: gabor_min_ncc 0.99 (only near-perfect
// patches pair) leaves fewer matches than the default 0.6 on the same frames; keys outside the
// matcher do not matter there, and a bad key is refused naming the file.
TEST(CliTest, MatchEvalTakesTheMatcherOptionsOfAVoConfig) {
  TempDir dir("cli_match_eval_config");
  WriteText(dir / "strict.yaml",
            "platform: free\ntracker.matcher:\n  svd:\n    gabor_min_ncc: 0.99\n");
  WriteText(dir / "bad.yaml", "tracker.matcher:\n  svd:\n    min_ncc: 2\n");
  const std::string common =
      " --strides 1 --matchers svd_ncc_gabor --max-frames 4 -q --out " + (dir / "out");
  auto matches = [&](const std::string& config) {
    const CommandResult r = RunVobench("match-eval" + common + config);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const std::string csv = vobench_test::ReadAll(dir / "out/match_eval.csv");
    const size_t row = csv.find("\nsvd_ncc_gabor,1,");
    EXPECT_NE(row, std::string::npos) << csv;
    std::stringstream fields(csv.substr(row + 1));
    std::string field;
    for (int i = 0; i < 4; ++i)
      std::getline(fields, field, ',');  // matcher, stride, pairs, matches
    return std::stol(field);
  };
  const long plain = matches("");
  const long strict = matches(" --config " + (dir / "strict.yaml"));
  EXPECT_GT(plain, 0);
  EXPECT_LT(strict, plain);
  const CommandResult bad = RunVobench("match-eval" + common + " --config " + (dir / "bad.yaml"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find(dir / "bad.yaml" + ":3: key 'tracker.matcher.svd.min_ncc'"),
            std::string::npos)
      << bad.output;
}

// --correct-px sets how close to the ground truth a match must land to count: a tighter
// distance counts fewer matches correct (and fewer possible), the same matches are made; a
// distance that is not a finite number > 0 is refused before anything is simulated or written.
TEST(CliTest, MatchEvalCorrectDistanceIsAnOption) {
  TempDir dir("cli_match_eval_correct_px");
  const std::string common = " --strides 1 --matchers svd_ncc_gabor --max-frames 4 -q --out ";
  auto row = [&](const std::string& out, const std::string& extra) {
    const CommandResult r = RunVobench("match-eval" + common + (dir / out) + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const std::string csv = vobench_test::ReadAll(dir / (out + "/match_eval.csv"));
    const size_t at = csv.find("\nsvd_ncc_gabor,1,");
    EXPECT_NE(at, std::string::npos) << csv;
    std::stringstream fields(csv.substr(at + 1));
    std::vector<long> v;  // pairs, matches, correct, possible
    std::string field;
    for (int i = 0; i < 6; ++i) {
      std::getline(fields, field, ',');
      if (i >= 2) v.push_back(std::stol(field));
    }
    return v;
  };
  const std::vector<long> loose = row("loose", "");
  const std::vector<long> tight = row("tight", " --correct-px 0.5");
  ASSERT_EQ(loose.size(), 4u);
  ASSERT_EQ(tight.size(), 4u);
  EXPECT_EQ(tight[1], loose[1]);  // the same matches
  EXPECT_GT(loose[2], 0);
  EXPECT_LT(tight[2], loose[2]);
  EXPECT_LE(tight[3], loose[3]);
  for (const char* bad : {"0", "-1", "nan", "inf"}) {
    const CommandResult r =
        RunVobench("match-eval" + common + (dir / "bad") + " --correct-px " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    EXPECT_NE(r.output.find("--correct-px: expected a finite distance > 0"), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "bad")) << bad;
  }
}

// Without --out, `run` wrote to out/run/<name>: a scenario named ../../../escaped_run wrote
// beside the working folder.
TEST(CliTest, ScenarioNamesThatCannotNameAFolderAreRefusedWithoutOut) {
  TempDir dir("cli_names");
  const std::string work = dir / "work";
  fs::create_directories(work);
  WriteText(dir / "escape.yaml",
            "name: ../../../escaped_run\nscene: " + std::string(VOBENCH_SOURCE_DIR) +
                "/scenes/hallway_l.xml\npath: [[0, 0], [0.5, 0]]\n");
  for (const char* command : {"run", "match-eval"}) {
    const CommandResult r = RunVobenchIn(
        work, std::string(command) + " " + (dir / "escape.yaml") + " -q --max-frames 2");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("scenario name '../../../escaped_run': cannot name a folder: "
                            "contains '..' (give --out)"),
              std::string::npos)
        << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "escaped_run"));
  EXPECT_FALSE(fs::exists(dir / "escaped_run.partial"));
  EXPECT_FALSE(fs::exists(fs::path(work) / "out"));
}

// `baseline_m: 1e300` in calib.txt exited 0 with inf/NaN in the metrics.
TEST(CliTest, ImplausibleCalibrationIsRefusedAndNothingIsWritten) {
  TempDir dir("cli_calib");
  const std::string seq = dir / "seq";
  fs::create_directories(seq);
  WriteText(seq + "/calib.txt",
            "P0: 500 0 320 0 0 500 240 0 0 0 1 0\nP1: 500 0 320 -5e302 0 500 240 0 0 0 1 0\n");
  WriteText(seq + "/times.txt", "0\n0.1\n");
  const CommandResult run = RunVobench("run --dataset " + seq + " -q --out " + (dir / "out"));
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find(seq + "/calib.txt: baseline 1e+300 m is outside the plausible range "
                                  "0.001 .. 5 m"),
            std::string::npos)
      << run.output;
  const CommandResult eval =
      RunVobench("eval --dataset " + seq + " --format kitti -q --out " + (dir / "out"));
  EXPECT_NE(eval.exit_code, 0) << eval.output;
  EXPECT_NE(eval.output.find("calib.txt: baseline 1e+300 m"), std::string::npos) << eval.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
  EXPECT_FALSE(fs::exists(dir / "out.partial"));
}

}  // namespace
