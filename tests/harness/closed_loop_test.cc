// The closed loop through the run pipeline (navigation: vo, sim/navigation.h): the robot steers
// on the VO frame by frame; the run reports what it physically did; reruns are bit-identical;
// commands that simulate without a VO refuse such a scenario.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "harness/metric_registry.h"
#include "harness/render.h"
#include "harness/run.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using vobench_test::TempDir;

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The L-hallway's first 3 m, the robot steering on the VO.
sim::Scenario ShortClosedLoop() {
  sim::Scenario scenario;
  std::string error;
  EXPECT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  scenario.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(3.0, 0)};
  scenario.navigation = "vo";
  return scenario;
}

TEST(ClosedLoopTest, TheRobotSteersOnTheVoAndRerunsAreBitIdentical) {
  TempDir dir("closed_loop");
  const sim::Scenario scenario = ShortClosedLoop();
  std::string files[2][3];
  nlohmann::json metrics[2];
  harness::RunSummary summary;
  for (int k = 0; k < 2; ++k) {
    harness::RunOptions options;
    options.out_dir = dir / ("run" + std::to_string(k));
    options.progress = false;
    options.plots = false;
    std::string error;
    ASSERT_TRUE(harness::RunScenario(scenario, vo::OdometryOptions(), options, &summary, &error))
        << error;
    int i = 0;
    for (const char* f :
         {"trajectory_world_tum.txt", "groundtruth_world_tum.txt", "navigation.csv"})
      files[k][i++] = ReadText(options.out_dir + "/" + f);
    metrics[k] = nlohmann::json::parse(ReadText(options.out_dir + "/metrics.json"));
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_FALSE(files[0][i].empty()) << i;
    EXPECT_EQ(files[0][i], files[1][i]) << i;
  }
  for (const harness::MetricInfo& m : harness::RunMetrics()) {
    if (m.group == harness::MetricGroup::kTiming) continue;
    const nlohmann::json* a = harness::FindMetricValue(metrics[0], m.key);
    const nlohmann::json* b = harness::FindMetricValue(metrics[1], m.key);
    ASSERT_EQ(a == nullptr, b == nullptr) << m.key;
    if (a) {
      EXPECT_EQ(*a, *b) << m.key;
    }
  }
  // What the robot did, in metrics.json's navigation group.
  const nlohmann::json& n = metrics[0]["navigation"];
  EXPECT_EQ(n["mode"], "vo");
  EXPECT_EQ(n["reached_goal"], true);
  EXPECT_EQ(n["wall_contacts"], 0);  // l_hallway's walls are solid (hallway_l.xml)
  EXPECT_LT(n["end_error_m"].get<double>(), 0.10);
  EXPECT_LT(n["max_waypoint_error_m"].get<double>(), 0.10);  // when it believed it was there
  // The VO steered: every frame it measured fixed the belief, which is not the truth.
  const sim::NavigationReport& nav = summary.navigation;
  ASSERT_EQ(static_cast<int>(nav.frames.size()), summary.metrics.frames);
  int fixed = 0;
  double belief_off_m = 0.0;
  for (const sim::NavigationFrame& f : nav.frames) {
    fixed += f.fixed ? 1 : 0;
    belief_off_m = std::max(belief_off_m, (f.believed.position - f.truth.position).norm());
  }
  EXPECT_EQ(fixed, summary.metrics.frames - summary.lost_frames);
  EXPECT_GT(belief_off_m, 0.0);
  EXPECT_LT(belief_off_m, 0.10);
}

// An open-loop run reports the same group: the follower's own precision on the true pose; no
// navigation.csv (the believed path is the true one).
TEST(ClosedLoopTest, AnOpenLoopRunReportsTheFollowersOwnEndError) {
  TempDir dir("closed_loop");
  sim::Scenario scenario = ShortClosedLoop();
  scenario.navigation = "ground_truth";
  harness::RunOptions options;
  options.out_dir = dir / "run";
  options.progress = false;
  options.plots = false;
  harness::RunSummary s;
  std::string error;
  ASSERT_TRUE(harness::RunScenario(scenario, vo::OdometryOptions(), options, &s, &error)) << error;
  const nlohmann::json m = nlohmann::json::parse(ReadText(options.out_dir + "/metrics.json"));
  EXPECT_EQ(m["navigation"]["mode"], "ground_truth");
  EXPECT_EQ(m["navigation"]["reached_goal"], true);
  EXPECT_LT(m["navigation"]["end_error_m"].get<double>(), 0.03);  // goal_tolerance_m 0.02
  EXPECT_FALSE(fs::exists(options.out_dir + "/navigation.csv"));
}

// A run cut short (--max-frames) ends before the robot does: no end error, with the reason.
TEST(ClosedLoopTest, ARunCutShortHasNoEndErrorAndSaysWhy) {
  TempDir dir("closed_loop");
  harness::RunOptions options;
  options.out_dir = dir / "run";
  options.progress = false;
  options.plots = false;
  options.max_frames = 10;
  harness::RunSummary s;
  std::string error;
  ASSERT_TRUE(harness::RunScenario(ShortClosedLoop(), vo::OdometryOptions(), options, &s, &error))
      << error;
  const nlohmann::json m = nlohmann::json::parse(ReadText(options.out_dir + "/metrics.json"));
  const nlohmann::json& n = m["navigation"];
  EXPECT_EQ(n["reached_goal"], false);
  EXPECT_TRUE(n["end_error_m"].is_null());
  EXPECT_TRUE(n["max_waypoint_error_m"].is_null());
  EXPECT_EQ(n["error_reason"], "the run ended before the robot did (--max-frames)");
}

// render, match-eval and tune simulate without a VO in the loop: a closed-loop scenario is
// refused, naming the file and the key, before anything is written.
TEST(ClosedLoopTest, CommandsThatSimulateWithoutAVoRefuseIt) {
  TempDir dir("closed_loop");
  const std::string yaml = dir / "cl.yaml";
  vobench_test::WriteText(yaml, "scene: " + std::string(VOBENCH_SOURCE_DIR) +
                                    "/scenes/hallway_l.xml\npath: [[0, 0], [2, 0]]\n"
                                    "navigation: vo\n");
  for (const std::string command : {"render", "match-eval"}) {
    const vobench_test::CommandResult r =
        vobench_test::RunVobench(command + " " + yaml + " -o " + (dir / command));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(yaml + ": navigation: vo steers the robot on the VO"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / command)) << command;
  }
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(yaml, &s, &error)) << error;
  EXPECT_NE(harness::ClosedLoopProblem(s, "tune").find("`tune` simulates without a VO"),
            std::string::npos);
  s.navigation = "ground_truth";
  EXPECT_EQ(harness::ClosedLoopProblem(s, "tune"), "");
}

}  // namespace
