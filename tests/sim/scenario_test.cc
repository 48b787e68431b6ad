// Scenario files: the shipped ones load; every malformed input is refused with a message that
// names the file, the key (and line) and what was expected.
#include "sim/scenario.h"

#include <cmath>

#include <gtest/gtest.h>

#include "sim_test_util.h"

namespace {

using vobench_test::TempDir;
using vobench_test::WriteText;

const char* kGood = R"(name: t
scene: scene.xml
seed: 3
rate_hz: 10
path:
  - [0, 0]
  - [2, 0]
camera:
  baseline_m: 0.12
noise:
  pixel_sigma: 1.0
)";

class ScenarioFileTest : public ::testing::Test {
 protected:
  ScenarioFileTest() : dir_("scenario") { WriteText(dir_ / "scene.xml", "<mujoco/>"); }
  // Loads `yaml` from a file; returns the error ("" on success).
  std::string Load(const std::string& yaml, sim::Scenario* s = nullptr) {
    const std::string path = dir_ / "s.yaml";
    WriteText(path, yaml);
    sim::Scenario local;
    std::string error;
    if (sim::LoadScenario(path, s ? s : &local, &error)) return "";
    EXPECT_NE(error.find(path), std::string::npos) << "message must name the file: " << error;
    return error.empty() ? "(empty message)" : error;
  }
  std::string Replace(const std::string& from, const std::string& to) {
    std::string y = kGood;
    const size_t at = y.find(from);
    EXPECT_NE(at, std::string::npos);
    return y.replace(at, from.size(), to);
  }
  TempDir dir_;
};

TEST_F(ScenarioFileTest, GoodFileLoadsWithDefaults) {
  sim::Scenario s;
  ASSERT_EQ(Load(kGood, &s), "");
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.seed, 3u);
  EXPECT_DOUBLE_EQ(s.camera.baseline_m, 0.12);
  EXPECT_EQ(s.camera.width, 320);  // default
  ASSERT_EQ(s.path.size(), 2u);
  EXPECT_EQ(s.path[1], Eigen::Vector2d(2, 0));
  EXPECT_EQ(s.scene_path, dir_ / "scene.xml");
}

TEST_F(ScenarioFileTest, ShippedScenariosLoad) {
  for (const char* name : {"l_hallway", "plain_corridor"}) {
    sim::Scenario s;
    std::string error;
    EXPECT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath(name), &s, &error)) << error;
    EXPECT_EQ(s.name, name);
  }
}

TEST_F(ScenarioFileTest, EffectiveScenarioRoundTrips) {
  sim::Scenario s, again;
  ASSERT_EQ(Load(kGood, &s), "");
  const std::string path = dir_ / "effective.yaml";
  WriteText(path, sim::ScenarioToYaml(s));
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(path, &again, &error)) << error;
  EXPECT_EQ(sim::ScenarioToYaml(again), sim::ScenarioToYaml(s));
}

TEST_F(ScenarioFileTest, MissingFile) {
  sim::Scenario s;
  std::string error;
  EXPECT_FALSE(sim::LoadScenario(dir_ / "nope.yaml", &s, &error));
  EXPECT_NE(error.find("nope.yaml"), std::string::npos);
  EXPECT_NE(error.find("no such file"), std::string::npos) << error;
}

TEST_F(ScenarioFileTest, MalformedYamlGivesLine) {
  const std::string e = Load("name: t\npath: [[0, 0], [1, 0]\nscene: scene.xml\n");
  EXPECT_NE(e.find("malformed YAML"), std::string::npos) << e;
}

TEST_F(ScenarioFileTest, UnknownKeyNamedWithLine) {
  const std::string e = Load(Replace("  baseline_m: 0.12", "  baseline_m: 0.12\n  focal: 3"));
  EXPECT_NE(e.find("'camera.focal'"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("s.yaml:10"), std::string::npos) << e;  // the line of the key
}

TEST_F(ScenarioFileTest, WrongType) {
  const std::string e = Load(Replace("rate_hz: 10", "rate_hz: fast"));
  EXPECT_NE(e.find("'rate_hz'"), std::string::npos) << e;
  EXPECT_NE(e.find("expected a number"), std::string::npos) << e;
  const std::string e2 = Load(Replace("seed: 3", "seed: [1, 2]"));
  EXPECT_NE(e2.find("'seed'"), std::string::npos) << e2;
}

TEST_F(ScenarioFileTest, NegativeBaseline) {
  const std::string e = Load(Replace("baseline_m: 0.12", "baseline_m: -0.09"));
  EXPECT_NE(e.find("'camera.baseline_m'"), std::string::npos) << e;
  EXPECT_NE(e.find("positive"), std::string::npos) << e;
}

TEST_F(ScenarioFileTest, NaNRefused) {
  const std::string e = Load(Replace("pixel_sigma: 1.0", "pixel_sigma: .nan"));
  EXPECT_NE(e.find("'noise.pixel_sigma'"), std::string::npos) << e;
  EXPECT_NE(e.find("finite"), std::string::npos) << e;
  const std::string e2 = Load(Replace("[2, 0]", "[.nan, 0]"));
  EXPECT_NE(e2.find("path[1]"), std::string::npos) << e2;
}

TEST_F(ScenarioFileTest, PathNeedsTwoWaypoints) {
  const std::string e = Load(Replace("  - [0, 0]\n  - [2, 0]\n", "  - [0, 0]\n"));
  EXPECT_NE(e.find("'path'"), std::string::npos) << e;
  EXPECT_NE(e.find("at least 2 waypoints"), std::string::npos) << e;
  const std::string e2 = Load(Replace("  - [2, 0]\n", "  - [2, 0, 1]\n"));
  EXPECT_NE(e2.find("path[1]"), std::string::npos) << e2;
}

TEST_F(ScenarioFileTest, MissingSceneFile) {
  const std::string e = Load(Replace("scene: scene.xml", "scene: nowhere.xml"));
  EXPECT_NE(e.find("nowhere.xml"), std::string::npos) << e;
  EXPECT_NE(e.find("not found"), std::string::npos) << e;
  const std::string e2 = Load(Replace("scene: scene.xml\n", ""));
  EXPECT_NE(e2.find("'scene'"), std::string::npos) << e2;
}

TEST_F(ScenarioFileTest, OutOfRangeValues) {
  EXPECT_NE(Load(Replace("rate_hz: 10", "rate_hz: 0")), "");
  EXPECT_NE(Load(Replace("  baseline_m: 0.12", "  width: 8")).find("'camera.width'"), std::string::npos);
  EXPECT_NE(Load(Replace("name: t", "name: t\nrobot:\n  corner_mode: drift")).find("corner_mode"), std::string::npos);
}

}  // namespace
