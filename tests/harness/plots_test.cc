// The plot scripts (harness/plots/*.py) run on the committed results/ fixtures, through the same
// runner the commands use (RunPlot / RunPythonScript: Debian's /usr/bin/python3), and the
// trajectory plot's outline comes from the scene's walls. Skipped without python3-matplotlib.
#include "harness/plots/plots.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "sim/data_dir.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using vobench_test::TempDir;

const std::string kSource = VOBENCH_SOURCE_DIR;

bool HaveMatplotlib() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") == 0;
}

// A PNG file of some size: the signature and more than a header.
void ExpectPng(const std::string& path) {
  ASSERT_TRUE(fs::is_regular_file(path)) << path << " not written";
  EXPECT_GT(fs::file_size(path), 1000u) << path;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  ASSERT_NE(f, nullptr) << path;
  unsigned char sig[8] = {};
  EXPECT_EQ(std::fread(sig, 1, 8, f), 8u);
  std::fclose(f);
  const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  EXPECT_TRUE(std::equal(sig, sig + 8, kPng)) << path << " is not a PNG";
}

TEST(SceneOutlineTest, HallwayOutlineComesFromTheScenesWalls) {
  std::vector<sim::SceneWall> walls;
  std::string error;
  ASSERT_TRUE(sim::WallsOfScene(kSource + "/scenes/hallway_l.xml", &walls, &error)) << error;
  // The polygon plot.py used to copy by hand: (-1.5,-1) (9,-1) (9,12) (7,12) (7,1) (-1.5,1),
  // as the six walls' ends.
  EXPECT_EQ(harness::SceneOutlineCsv(walls),
            "wall,x0_m,y0_m,x1_m,y1_m\n"
            "wall_south,9,-1,-1.5,-1\n"
            "wall_north,-1.5,1,7,1\n"
            "wall_back,-1.5,-1,-1.5,1\n"
            "wall_east,9,12,9,-1\n"
            "wall_west,7,1,7,12\n"
            "wall_end,7,12,9,12\n");
}

TEST(SceneOutlineTest, InfiniteWallsAreLeftOut) {
  sim::SceneWall w;
  w.name = "endless";
  w.centre_xy = Eigen::Vector2d(0, 1);
  w.along_xy = Eigen::Vector2d(1, 0);
  w.half_length_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(harness::SceneOutlineCsv({w}), "wall,x0_m,y0_m,x1_m,y1_m\n");
}

TEST(SceneOutlineTest, UnloadableSceneNamesTheFile) {
  std::vector<sim::SceneWall> walls;
  std::string error;
  EXPECT_FALSE(sim::WallsOfScene("/no/such/scene.xml", &walls, &error));
  EXPECT_NE(error.find("/no/such/scene.xml"), std::string::npos) << error;
}

// Every plot script with every subcommand, on the committed fixtures.
TEST(PlotScriptsTest, EveryScriptWritesAPngFromTheCommittedResults) {
  if (!HaveMatplotlib()) GTEST_SKIP() << "python3-matplotlib is not installed (/usr/bin/python3)";
  ASSERT_EQ(sim::DataDir(), kSource)
      << "the test binary should find the scripts in the source tree";
  TempDir dir("plots");
  const std::string l_run = kSource + "/results/l_hallway";
  std::string error;
  std::set<std::string> ran;

  EXPECT_TRUE(harness::RunTrajectoryPlot(
      l_run + "/groundtruth_world_tum.txt", l_run + "/estimate_in_gt_world_tum.txt",
      dir / "trajectory.png", kSource + "/scenes/hallway_l.xml", &error))
      << error;
  ExpectPng(dir / "trajectory.png");
  EXPECT_FALSE(fs::exists(dir / "trajectory.png.outline.csv")) << "the outline file is left behind";
  EXPECT_TRUE(harness::RunTrajectoryPlot(l_run + "/groundtruth_world_tum.txt",
                                         l_run + "/estimate_in_gt_world_tum.txt",
                                         dir / "trajectory_no_outline.png", "", &error))
      << error;
  ExpectPng(dir / "trajectory_no_outline.png");
  EXPECT_TRUE(harness::RunPlot({"errors", l_run, dir / "errors.png"}, &error)) << error;
  ExpectPng(dir / "errors.png");
  EXPECT_TRUE(harness::RunPlot({"timing", l_run, dir / "timing.png"}, &error)) << error;
  ExpectPng(dir / "timing.png");
  EXPECT_TRUE(harness::RunPlot(
      {"match-eval", kSource + "/results/matching/match_eval.csv", dir / "match_eval.png"}, &error))
      << error;
  ExpectPng(dir / "match_eval.png");
  ran.insert("plot.py");

  EXPECT_TRUE(harness::RunPythonScript(
      "suite_plot.py", {kSource + "/results/suites/hallway/summary.csv", dir / "summary.png"},
      &error))
      << error;
  ExpectPng(dir / "summary.png");
  ran.insert("suite_plot.py");

  EXPECT_TRUE(harness::RunPythonScript("tune_plot.py",
                                       {kSource + "/results/tune", dir / "objective.png"}, &error))
      << error;
  ExpectPng(dir / "objective.png");
  ran.insert("tune_plot.py");

  // A breaking point with a bracket, and one without (not crossed in the range).
  for (const char* result : {"l_hallway_pixel_sigma", "l_hallway_turn_rate"}) {
    const std::string png = dir / (std::string(result) + ".png");
    EXPECT_TRUE(harness::RunPythonScript("breakpoint_plot.py",
                                         {kSource + "/results/breakpoint/" + result, png}, &error))
        << error;
    ExpectPng(png);
  }
  ran.insert("breakpoint_plot.py");

  // A new script in harness/plots/ needs a case here.
  for (const auto& e : fs::directory_iterator(kSource + "/harness/plots")) {
    if (e.path().extension() == ".py") {
      EXPECT_TRUE(ran.count(e.path().filename().string()))
          << e.path() << " is not run by this smoke test: add it";
    }
  }
}

TEST(PlotScriptsTest, AFailingScriptReportsItsOutput) {
  if (!HaveMatplotlib()) GTEST_SKIP() << "python3-matplotlib is not installed (/usr/bin/python3)";
  TempDir dir("plots_bad");
  std::string error;
  EXPECT_FALSE(harness::RunPlot({"errors", dir / "no_run_here", dir / "errors.png"}, &error));
  EXPECT_NE(error.find("plot.py errors failed"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir / "errors.png"));
}

}  // namespace
