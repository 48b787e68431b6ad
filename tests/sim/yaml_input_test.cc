// The strict input helpers every YAML reader uses (issue #11): duplicate keys at any depth are
// refused with both lines, and a folder or missing path is an error that names it.
#include "sim/yaml_input.h"

#include <gtest/gtest.h>

#include "sim_test_util.h"

namespace {

using vobench_test::TempDir;
using vobench_test::WriteText;

std::string LoadError(const std::string& text) {
  YAML::Node root;
  std::string error;
  if (sim::LoadYamlDocument(text, "f.yaml", &root, &error)) return "";
  return error.empty() ? "(empty message)" : error;
}

TEST(YamlInputTest, DuplicateKeysAtAnyDepthNameBothLines) {
  EXPECT_EQ(LoadError("rate_hz: 10\nrate_hz: 20\n"),
            "f.yaml:2: key 'rate_hz': duplicate (first at line 1)");
  EXPECT_EQ(LoadError("camera:\n  width: 320\n  height: 240\n  width: 640\n"),
            "f.yaml:4: key 'camera.width': duplicate (first at line 2)");
  EXPECT_EQ(LoadError("scenarios:\n  - name: a\n  - name: b\n    set: {seed: 1, seed: 2}\n"),
            "f.yaml:4: key 'scenarios[1].set.seed': duplicate (first at line 4)");
  // Quoting does not make another key.
  EXPECT_EQ(LoadError("a: 1\n\"a\": 2\n"), "f.yaml:2: key 'a': duplicate (first at line 1)");
}

TEST(YamlInputTest, TheSameKeyInDifferentMapsIsFine) {
  EXPECT_EQ(LoadError("scenarios:\n  - name: a\n  - name: b\nconfigs:\n  - name: a\n"), "");
  EXPECT_EQ(LoadError("a: {x: 1}\nb: {x: 1}\nc: &anchor {x: 1}\nd: *anchor\n"), "");
  EXPECT_EQ(LoadError(""), "");
  EXPECT_NE(LoadError("a: [1\n").find("f.yaml:2: malformed YAML"), std::string::npos);
}

TEST(YamlInputTest, AliasBombIsRefusedNotWalked) {
  std::string text = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 9; ++i) {
    const std::string prev = "*a" + std::to_string(i - 1);
    text += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [" + prev;
    for (int k = 1; k < 10; ++k) text += ", " + prev;
    text += "]\n";
  }
  EXPECT_NE(LoadError(text).find("more than 1000000 YAML nodes"), std::string::npos);
}

TEST(YamlInputTest, ReadInputFileNamesFoldersAndMissingPaths) {
  TempDir dir("yaml_input");
  std::string text, error;
  EXPECT_FALSE(sim::ReadInputFile(dir.str(), "YAML VO config file", &text, &error));
  EXPECT_EQ(error, dir.str() + ": is a folder, expected a YAML VO config file");
  EXPECT_FALSE(sim::ReadInputFile(dir / "none.yaml", "YAML VO config file", &text, &error));
  EXPECT_EQ(error, dir / "none.yaml" + ": no such file (expected a YAML VO config file)");
  WriteText(dir / "ok.yaml", "a: 1\n");
  ASSERT_TRUE(sim::ReadInputFile(dir / "ok.yaml", "YAML file", &text, &error)) << error;
  EXPECT_EQ(text, "a: 1\n");
}

}  // namespace
