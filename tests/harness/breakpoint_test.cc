// `vobench breakpoint`: the scan and bisection on crafted functions of the key (a step at a
// known value: the exact bracket and number of evaluations; integer keys; a metric that is not
// monotone; no crossing; the evaluation budget), the --until and --range parsers, the key
// checks, the command's bad input (message, exit 2, nothing written), and tiny real breaking
// points with the built-in VO and an external estimator (the stride at which a run sees fewer
// than 4 frames: a known answer), deterministic.
#include "harness/breakpoint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "harness/sim_adapter.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using harness::FindBreakpoint;
using harness::PointOutcome;
using harness::SearchOptions;
using harness::SearchResult;
using vobench_test::ReadAll;
using vobench_test::RunVobench;
using vobench_test::TempDir;
using vobench_test::WriteText;

// An evaluation that is crossed where `crossed(x)` says, recording the values asked for.
harness::EvaluatePoint Crafted(std::function<bool(double)> crossed, std::vector<double>* asked) {
  return [crossed, asked](double x, const std::string&, PointOutcome* o, std::string*) {
    asked->push_back(x);
    o->value = x;
    o->crossed = crossed(x);
    return true;
  };
}

// Search options over [lo, hi] with `scan` scan points and the tolerance.
SearchOptions Options(double lo, double hi, int scan, double tolerance, bool integer = false) {
  SearchOptions o;
  o.lo = lo;
  o.hi = hi;
  o.scan_points = scan;
  o.tolerance = tolerance;
  o.integer = integer;
  return o;
}

// A step at 7.3 over [0, 20]: the scan 0, 5, 10, 15, 20 brackets (5, 10]; bisection 7.5 (crossed),
// 6.25, 6.875, 7.1875 (not) ends at (7.1875, 7.5], 0.3125 <= 0.5 wide: 5 + 4 evaluations.
TEST(BreakpointSearchTest, AStepIsBracketedExactlyInAKnownNumberOfEvaluations) {
  SearchOptions o = Options(0, 20, 5, 0.5);
  std::vector<double> asked;
  SearchResult r;
  std::string error;
  ASSERT_TRUE(FindBreakpoint(o, Crafted([](double x) { return x >= 7.3; }, &asked), &r, &error))
      << error;
  EXPECT_EQ(asked, (std::vector<double>{0, 5, 10, 15, 20, 7.5, 6.25, 6.875, 7.1875}));
  ASSERT_EQ(r.points.size(), 9u);
  EXPECT_EQ(r.points[4].phase, "scan");
  EXPECT_EQ(r.points[5].phase, "bisect");
  EXPECT_EQ(r.status, "bracketed");
  EXPECT_EQ(r.bracket_lo, 7.1875);
  EXPECT_EQ(r.bracket_hi, 7.5);
  EXPECT_EQ(r.threshold, 7.34375);
  EXPECT_TRUE(r.tolerance_reached);
  EXPECT_TRUE(r.monotone);
  EXPECT_TRUE(r.uncrossed_after_crossing.empty());
}

// Integer keys (the stride): scan 1, 4, 7, 10, then 2 and 3 to the neighbours (3, 4].
TEST(BreakpointSearchTest, AnIntegerKeyEndsAtNeighbours) {
  SearchOptions o = Options(1, 10, 4, 1, true);
  std::vector<double> asked;
  SearchResult r;
  std::string error;
  ASSERT_TRUE(FindBreakpoint(o, Crafted([](double x) { return x >= 4; }, &asked), &r, &error));
  EXPECT_EQ(asked, (std::vector<double>{1, 4, 7, 10, 2, 3}));
  EXPECT_EQ(r.bracket_lo, 3);
  EXPECT_EQ(r.bracket_hi, 4);
  // A range shorter than the scan: each whole number once.
  o.hi = 3;
  o.scan_points = 9;
  asked.clear();
  ASSERT_TRUE(FindBreakpoint(o, Crafted([](double x) { return x >= 3; }, &asked), &r, &error));
  EXPECT_EQ(asked, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(r.bracket_lo, 2);
  EXPECT_EQ(r.bracket_hi, 3);
  // Whole-number ranges only.
  o.lo = 1.5;
  EXPECT_FALSE(FindBreakpoint(o, Crafted([](double) { return false; }, &asked), &r, &error));
  EXPECT_NE(error.find("whole numbers"), std::string::npos) << error;
}

// Crossed on [4, 12] only: the scan sees 15 and 20 below the condition again; reported, and the
// bisection works on the first crossing (0, 5].
TEST(BreakpointSearchTest, ANonMonotoneMetricIsReported) {
  SearchOptions o = Options(0, 20, 5, 1);
  std::vector<double> asked;
  SearchResult r;
  std::string error;
  ASSERT_TRUE(
      FindBreakpoint(o, Crafted([](double x) { return x >= 4 && x <= 12; }, &asked), &r, &error));
  EXPECT_FALSE(r.monotone);
  EXPECT_EQ(r.uncrossed_after_crossing, (std::vector<double>{15, 20}));
  EXPECT_EQ(r.status, "bracketed");
  EXPECT_EQ(r.bracket_lo, 3.75);  // 2.5 (not), 3.75 (not), 4.375 (crossed): 0.625 wide
  EXPECT_EQ(r.bracket_hi, 4.375);
  EXPECT_EQ(asked.size(), 8u);
}

TEST(BreakpointSearchTest, NoCrossingInTheRangeIsSaidAndTheBudgetEndsTheBisection) {
  SearchOptions o = Options(0, 1, 3, 1e-9);
  std::vector<double> asked;
  SearchResult r;
  std::string error;
  ASSERT_TRUE(FindBreakpoint(o, Crafted([](double) { return true; }, &asked), &r, &error));
  EXPECT_EQ(r.status, "crossed_at_low");
  EXPECT_EQ(asked.size(), 3u);
  EXPECT_FALSE(std::isfinite(r.bracket_lo));
  ASSERT_TRUE(FindBreakpoint(o, Crafted([](double) { return false; }, &asked), &r, &error));
  EXPECT_EQ(r.status, "not_crossed");
  o.max_evals = 6;  // 3 scan points and 3 bisections, far from 1e-9
  asked.clear();
  ASSERT_TRUE(FindBreakpoint(o, Crafted([](double x) { return x > 0.3; }, &asked), &r, &error));
  EXPECT_EQ(asked.size(), 6u);
  EXPECT_EQ(r.status, "bracketed");
  EXPECT_FALSE(r.tolerance_reached);
  EXPECT_EQ(r.bracket_lo, 0.25);
  EXPECT_EQ(r.bracket_hi, 0.3125);
  // An evaluation that fails ends the search with its error.
  const harness::EvaluatePoint broken = [](double, const std::string&, PointOutcome*,
                                           std::string* why) {
    *why = "the disk is full";
    return false;
  };
  EXPECT_FALSE(FindBreakpoint(o, broken, &r, &error));
  EXPECT_EQ(error, "the disk is full");
  o.max_evals = 2;
  EXPECT_FALSE(FindBreakpoint(o, broken, &r, &error));
  EXPECT_NE(error.find("the scan alone takes 3"), std::string::npos) << error;
}

TEST(BreakpointInputTest, UntilAndRangeAreParsedOrRefusedWithTheExpectedForm) {
  harness::UntilCondition u;
  std::string error;
  ASSERT_TRUE(harness::ParseUntil(" end_pose_error_pct >= 2.5 ", &u, &error)) << error;
  EXPECT_EQ(u.metric, "end_pose_error_pct");
  EXPECT_EQ(u.op, ">=");
  EXPECT_EQ(u.value, 2.5);
  EXPECT_TRUE(u.Met(2.5));
  EXPECT_FALSE(u.Met(std::nan("")));
  ASSERT_TRUE(harness::ParseUntil("frames<4", &u, &error)) << error;
  EXPECT_TRUE(u.Met(3));
  EXPECT_FALSE(u.Met(4));
  EXPECT_FALSE(u.HigherIsWorse());
  EXPECT_EQ(u.Text(), "frames<4");
  EXPECT_FALSE(harness::ParseUntil("end_pose_error_pct=2", &u, &error));
  EXPECT_NE(error.find("expected METRIC>VALUE"), std::string::npos) << error;
  EXPECT_FALSE(harness::ParseUntil("end_pose_error_pct>two", &u, &error));
  EXPECT_NE(error.find("'two' is not a finite number"), std::string::npos) << error;
  EXPECT_FALSE(harness::ParseUntil("end_error>2", &u, &error));
  EXPECT_NE(error.find("unknown metric 'end_error' (expected frames, "), std::string::npos)
      << error;
  EXPECT_NE(error.find("ate_rmse_m"), std::string::npos) << error;
  // Names, flags and reasons are no metrics to cross; timings are not deterministic.
  for (const char* no : {"platform", "has_ground_truth", "drift_reason", "vo_ms_median"})
    EXPECT_FALSE(harness::ParseUntil(std::string(no) + ">1", &u, &error)) << no;

  double lo = 0, hi = 0;
  ASSERT_TRUE(harness::ParseRange("0, 20", &lo, &hi, &error)) << error;
  EXPECT_EQ(lo, 0);
  EXPECT_EQ(hi, 20);
  for (const char* bad : {"20,0", "3,3", "0", "0,1,2", "a,1", "0,inf", ""})
    EXPECT_FALSE(harness::ParseRange(bad, &lo, &hi, &error)) << bad;
}

harness::BreakpointSpec L(const std::string& key, double lo, double hi) {
  harness::BreakpointSpec s;
  std::string error;
  EXPECT_TRUE(harness::ResolveScenario("l_hallway", &s.scenario, &error)) << error;
  s.scenario_arg = "l_hallway";
  s.key = key;
  s.lo = lo;
  s.hi = hi;
  s.range_text = harness::FormatDouble(lo) + "," + harness::FormatDouble(hi);
  return s;
}

TEST(BreakpointInputTest, TheKeyIsAScenarioKeyWhoseParserTakesTheRange) {
  std::string error;
  harness::BreakpointSpec s = L("noise.pixel_sigma", 0, 20);
  ASSERT_TRUE(harness::PrepareBreakpoint(&s, &error)) << error;
  EXPECT_FALSE(s.integer);
  EXPECT_EQ(s.search.tolerance, 20.0 / 32);
  s = L("noise.motion_blur_samples", 2, 40);  // a whole number of renders
  ASSERT_TRUE(harness::PrepareBreakpoint(&s, &error)) << error;
  EXPECT_TRUE(s.integer);
  EXPECT_EQ(s.search.tolerance, 1);
  s = L("stride", 1, 8);
  ASSERT_TRUE(harness::PrepareBreakpoint(&s, &error)) << error;
  EXPECT_TRUE(s.integer);
  s = L("noise.sigma", 0, 20);
  EXPECT_FALSE(harness::PrepareBreakpoint(&s, &error));
  EXPECT_NE(error.find("--vary: 'noise.sigma' is not a numeric key of scenario l_hallway "
                       "(expected stride or one of "),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("robot.turn_rate_dps"), std::string::npos) << error;
  s = L("noise.pixel_sigma", -5, 20);
  EXPECT_FALSE(harness::PrepareBreakpoint(&s, &error));
  EXPECT_NE(error.find("--range: noise.pixel_sigma=-5 is refused: key 'noise.pixel_sigma': "),
            std::string::npos)
      << error;
  s = L("noise.motion_blur_samples", 2, 40.5);
  EXPECT_FALSE(harness::PrepareBreakpoint(&s, &error));
  s = L("stride", 0, 8);
  EXPECT_FALSE(harness::PrepareBreakpoint(&s, &error));
  EXPECT_NE(error.find("stride takes whole numbers >= 1"), std::string::npos) << error;
}

// Bad input: a clear message naming the option, exit 2, no output folder (nor out/).
TEST(BreakpointCommandTest, BadInputIsRefusedAndNothingIsWritten) {
  TempDir dir("bp_bad");
  const std::string base = "breakpoint l_hallway --out o --max-frames 6 ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--vary noise.pixel_sigma --range 20,0 --until 'end_pose_error_m>1'",
       "--range '20,0': LO must be below HI"},
      {"--vary noise.pixel_sigma --range 0 --until 'end_pose_error_m>1'",
       "--range '0': expected LO,HI"},
      {"--vary noise.sigma --range 0,20 --until 'end_pose_error_m>1'",
       "--vary: 'noise.sigma' is not a numeric key of scenario l_hallway"},
      {"--vary noise.pixel_sigma --range 0,20 --until 'end_error_m>1'",
       "--until: unknown metric 'end_error_m' (expected frames, "},
      {"--vary noise.pixel_sigma --range 0,20 --until 'end_pose_error_m=1'",
       "expected METRIC>VALUE, METRIC<VALUE, METRIC>=VALUE or METRIC<=VALUE"},
      {"--vary noise.pixel_sigma --range 0,20 --until 'end_pose_error_m>1' --aggregate max",
       "--aggregate"},
      {"--vary noise.pixel_sigma --range 0,20 --until 'end_pose_error_m>1' --external x.yaml",
       "--external 'x.yaml': expected SUITE.yaml:CONFIG"},
      {"--vary noise.pixel_sigma --range 0,20 --until 'frames<2' --scan 9 --max-evals 4",
       "--max-evals 4: the scan alone takes 9 evaluations"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = RunVobench(base + args, dir.str());
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << args << "\n" << r.output;
    EXPECT_NE(r.output.find("vobench breakpoint"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "o")) << args;
    EXPECT_FALSE(fs::exists(dir / "out")) << args;
  }
}

nlohmann::json WithoutTiming(nlohmann::json j) {
  j.erase("timing");
  return j;
}

// The stride at which a run of 8 source frames sees fewer than 3 frames: frames = ceil(8 / k) is
// 3 at k = 3 and 2 at k = 4, so the bracket is (3, 4]; scan 1, 4 (3.5 rounded), 6, then 2 and 3.
constexpr char kStrideArgs[] =
    "breakpoint l_hallway --vary stride --range 1,6 --until 'frames<3' --max-frames 8 --scan 3 "
    "--max-lost-frames -1 -q --out ";
const std::vector<double> kStrideXs = {1, 4, 6, 2, 3};
const std::vector<double> kStrideFrames = {8, 2, 2, 4, 3};

std::vector<double> Column(const nlohmann::json& j, const char* field) {
  std::vector<double> v;
  for (const auto& p : j["points"]) v.push_back(p[field]);
  return v;
}

// Real runs of the built-in VO on a known answer; the same call gives the same file.
TEST(BreakpointCommandTest, ATinyRealBreakingPointIsFoundAndDeterministic) {
  TempDir dir("bp_real");
  const auto r = RunVobench(kStrideArgs + (dir / "a"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frames<3 from stride in (3, 4]"), std::string::npos) << r.output;
  for (const char* f : {"breakpoint.json", "points.csv", "breakpoint.png", "report.md",
                        "points/p00_s1/metrics.json", ".vobench.json"})
    EXPECT_TRUE(fs::exists(dir / "a/" + f)) << f;
  const nlohmann::json j = nlohmann::json::parse(ReadAll(dir / "a/breakpoint.json"));
  EXPECT_EQ(j["result"]["status"], "bracketed");
  EXPECT_EQ(j["result"]["bracket"], nlohmann::json::parse("[3, 4]"));
  EXPECT_EQ(j["result"]["evaluations"], 5);
  EXPECT_EQ(Column(j, "x"), kStrideXs);
  EXPECT_EQ(Column(j, "value"), kStrideFrames);
  EXPECT_EQ(ReadAll(dir / "a/points.csv")
                .rfind("index,phase,stride,frames,crossed,failed_runs,"
                       "max_lost_frames,s1:frames\n0,scan,1,8,0,0,",
                       0),
            0u)
      << ReadAll(dir / "a/points.csv");
  EXPECT_NE(j["command"].get<std::string>().find("vobench breakpoint l_hallway --vary stride"),
            std::string::npos);
  EXPECT_NE(ReadAll(dir / "a/report.md").find("| 4 | bisect | 3 | 3 | no |"), std::string::npos)
      << ReadAll(dir / "a/report.md");

  // Deterministic: the same call gives the same file, timing aside; an earlier result replaced.
  const auto again = RunVobench(kStrideArgs + (dir / "b"));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  nlohmann::json b = nlohmann::json::parse(ReadAll(dir / "b/breakpoint.json"));
  b["command"] = j["command"];  // the --out differs
  EXPECT_EQ(WithoutTiming(b), WithoutTiming(j));
  // A folder vobench did not write is not replaced.
  fs::create_directories(dir / "mine");
  WriteText(dir / "mine/notes.txt", "mine");
  const auto mine = RunVobench(kStrideArgs + (dir / "mine"));
  EXPECT_EQ(mine.exit_code, 1) << mine.output;
  EXPECT_NE(mine.output.find("was not written by vobench"), std::string::npos) << mine.output;
  EXPECT_EQ(ReadAll(dir / "mine/notes.txt"), "mine");
}

// An external configuration of a suite file (a script that writes the ground truth) on the same
// known answer.
TEST(BreakpointCommandTest, AnExternalEstimatorOfASuiteFile) {
  TempDir dir("bp_ext");
  WriteText(dir / "gt.sh", "#!/bin/sh\ncp \"$1/poses.txt\" \"$2/t.txt\"\n");
  fs::permissions(dir / "gt.sh", fs::perms::owner_all);
  WriteText(dir / "suite.yaml",
            "name: ext\nscenarios:\n  - scenario: l_hallway\nconfigs:\n  - name: paper\n"
            "  - name: gt\n    external: {command: [./gt.sh, \"{dataset}\", \"{out}\"], "
            "trajectory: t.txt, format: kitti}\n");
  const auto ext = RunVobench(kStrideArgs + (dir / "e") + " --external " + (dir / "suite.yaml:gt"));
  ASSERT_EQ(ext.exit_code, 0) << ext.output;
  EXPECT_NE(ext.output.find("frames<3 from stride in (3, 4]"), std::string::npos) << ext.output;
  const nlohmann::json e = nlohmann::json::parse(ReadAll(dir / "e/breakpoint.json"));
  EXPECT_EQ(e["estimator"]["kind"], "external");
  EXPECT_EQ(Column(e, "x"), kStrideXs);
  EXPECT_EQ(Column(e, "value"), kStrideFrames);
  EXPECT_TRUE(e["points"][0]["runs"][0]["lost_frames"].is_null());  // counted by the built-in VO
  // The ground truth as the trajectory: an accuracy metric of 0 never crosses.
  const auto zero = RunVobench(
      "breakpoint l_hallway --vary noise.pixel_sigma --range 0,20 --until 'ate_rmse_m>1e-9' "
      "--max-frames 4 --scan 2 -q --out " +
      (dir / "z") + " --external " + (dir / "suite.yaml:gt"));
  ASSERT_EQ(zero.exit_code, 0) << zero.output;
  EXPECT_NE(zero.output.find("nowhere in noise.pixel_sigma in [0, 20]"), std::string::npos)
      << zero.output;
  // The built-in configuration of the suite is refused for --external.
  const auto paper =
      RunVobench(kStrideArgs + (dir / "p") + " --external " + (dir / "suite.yaml:paper"));
  EXPECT_EQ(paper.exit_code, 2) << paper.output;
  EXPECT_NE(paper.output.find("is the built-in VO; give its options with --config"),
            std::string::npos)
      << paper.output;
  EXPECT_FALSE(fs::exists(dir / "p"));
}

}  // namespace
