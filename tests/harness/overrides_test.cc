// Scenario and VO option overrides (suites, tuning): dotted keys, deep merge, strict checking.
#include "harness/overrides.h"

#include <gtest/gtest.h>

#include "harness/render.h"

namespace {

TEST(OverridesTest, DottedKeysBecomeNestedMaps) {
  YAML::Node nested;
  std::string error;
  ASSERT_TRUE(
      harness::NestDottedKeys(YAML::Load("{a.b.c: 1, a.d: 2, e: {f.g: 3}}"), "t", &nested, &error))
      << error;
  EXPECT_EQ(nested["a"]["b"]["c"].as<int>(), 1);
  EXPECT_EQ(nested["a"]["d"].as<int>(), 2);
  EXPECT_EQ(nested["e"]["f"]["g"].as<int>(), 3);
}

TEST(OverridesTest, RefusesEmptyComponentsAndKeysGivenTwice) {
  YAML::Node nested;
  std::string error;
  EXPECT_FALSE(harness::NestDottedKeys(YAML::Load("{a..b: 1}"), "suite.yaml", &nested, &error));
  EXPECT_NE(error.find("suite.yaml"), std::string::npos) << error;
  EXPECT_NE(error.find("a..b"), std::string::npos) << error;
  EXPECT_FALSE(harness::NestDottedKeys(YAML::Load("{a.b: 1, a: {b: 2}}"), "t", &nested, &error));
  EXPECT_NE(error.find("twice"), std::string::npos) << error;
  EXPECT_FALSE(harness::NestDottedKeys(YAML::Load("[1, 2]"), "t", &nested, &error));
}

TEST(OverridesTest, ScenarioOverridesChangeOnlyTheNamedKeys) {
  sim::Scenario base;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &base, &error)) << error;
  sim::Scenario s;
  ASSERT_TRUE(harness::ApplyScenarioOverrides(
      base, YAML::Load("{noise.pixel_sigma: 4.5, textures: {seed: 11}, name: other}"), "t", &s,
      &error))
      << error;
  EXPECT_EQ(s.noise.pixel_sigma, 4.5);
  EXPECT_EQ(s.textures.seed, 11u);
  EXPECT_EQ(s.name, "other");
  EXPECT_EQ(s.noise.gain_sigma, base.noise.gain_sigma);
  EXPECT_EQ(s.scene_path, base.scene_path);
  EXPECT_EQ(s.path.size(), base.path.size());
  EXPECT_EQ(sim::ScenarioToYaml(s).size() > 0, true);
  // No overrides: the same scenario.
  ASSERT_TRUE(harness::ApplyScenarioOverrides(base, YAML::Node(), "t", &s, &error)) << error;
  EXPECT_EQ(sim::ScenarioToYaml(s), sim::ScenarioToYaml(base));
}

TEST(OverridesTest, ScenarioOverridesAreCheckedStrictly) {
  sim::Scenario base;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &base, &error)) << error;
  sim::Scenario s;
  EXPECT_FALSE(harness::ApplyScenarioOverrides(base, YAML::Load("{noise.pixel_sigmaa: 1}"),
                                               "suite.yaml", &s, &error));
  EXPECT_NE(error.find("pixel_sigmaa"), std::string::npos) << error;
  EXPECT_FALSE(
      harness::ApplyScenarioOverrides(base, YAML::Load("{rate_hz: -1}"), "suite.yaml", &s, &error));
  EXPECT_NE(error.find("rate_hz"), std::string::npos) << error;
}

TEST(OverridesTest, VoOverridesApplyOnTopOfTheGivenOptions) {
  vo::OdometryOptions options;
  options.back_end.window_frames = 7;
  std::string error;
  ASSERT_TRUE(harness::ApplyVoOverrides(YAML::Load("{tracker.matcher.type: ncc_mutual}"), "t",
                                        &options, &error))
      << error;
  EXPECT_EQ(options.back_end.window_frames, 7);
  EXPECT_EQ(options.tracker.matcher.type, vo::MatcherType::kNccMutual);
  vo::OdometryOptions bad = options;
  EXPECT_FALSE(harness::ApplyVoOverrides(YAML::Load("{tracker.matcher.type: nonsense}"),
                                         "tune.yaml", &bad, &error));
  EXPECT_NE(error.find("tune.yaml"), std::string::npos) << error;
}

// Overrides from a file are told in the readers' one format, at the override map's line.
TEST(OverridesTest, ErrorsOfFileOverridesNameTheFileLineAndFullKey) {
  vo::OdometryOptions options;
  std::string error;
  EXPECT_FALSE(harness::ApplyVoOverrides(YAML::Load("{tracker.matcher.type: nonsense}"),
                                         harness::kOverridesSource, &options, &error));
  EXPECT_EQ(harness::OverrideErrorAt("s.yaml:6", "configs[0].set", error)
                .rfind("s.yaml:6: key 'configs[0].set.tracker.matcher.type': expected one of ", 0),
            0u)
      << error;
  sim::Scenario base, s;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &base, &error)) << error;
  EXPECT_FALSE(harness::ApplyScenarioOverrides(base, YAML::Load("{camera: {width: 8}}"),
                                               harness::kOverridesSource, &s, &error));
  EXPECT_EQ(harness::OverrideErrorAt("s.yaml:4", "scenarios[0].set", error),
            "s.yaml:4: key 'scenarios[0].set.camera.width': expected 16..4096 pixels, got 8");
  EXPECT_FALSE(harness::ApplyScenarioOverrides(base, YAML::Load("{a..b: 1}"),
                                               harness::kOverridesSource, &s, &error));
  EXPECT_EQ(harness::OverrideErrorAt("s.yaml:4", "scenarios[0].set", error),
            "s.yaml:4: key 'scenarios[0].set': override key 'a..b' has an empty path component");
  EXPECT_EQ(harness::OverrideErrorAt("s.yaml:4", "x", "other.yaml:2: boom"), "other.yaml:2: boom");
}

}  // namespace
