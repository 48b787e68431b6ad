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

// The one strict reader (issue #12 item 3): one message format "SOURCE:LINE: key 'a.b': WHAT".
sim::YamlReader Reader(const std::string& text) {
  sim::YamlReader r("f.yaml");
  EXPECT_TRUE(r.Parse(text)) << r.error();
  return r;
}

TEST(YamlReaderTest, UnknownKeysListTheAllowedOnesAtTheirLine) {
  sim::YamlReader r = Reader("a: 1\nsub:\n  x: 2\n  y: 3\n");
  EXPECT_TRUE(r.CheckKeys(r.root(), "", {"a", "sub"}));
  EXPECT_FALSE(r.CheckKeys(r.root()["sub"], "sub", {"x", "z"}));
  EXPECT_EQ(r.error(), "f.yaml:4: key 'sub.y': unknown key (expected one of: x, z)");
  // The first error is kept; later calls do nothing.
  EXPECT_FALSE(r.CheckKeys(r.root(), "", {"b"}));
  EXPECT_EQ(r.error(), "f.yaml:4: key 'sub.y': unknown key (expected one of: x, z)");
  sim::YamlReader s = Reader("[1, 2]\n");
  EXPECT_FALSE(s.CheckKeys(s.root(), "", {"a"}));
  EXPECT_EQ(s.error(), "f.yaml:1: expected a mapping");
}

TEST(YamlReaderTest, AbsentKeysKeepDefaultsAndRequiredOnesAreNamed) {
  sim::YamlReader r = Reader("n: 3\n");
  double d = 7.5;
  std::string text = "kept";
  EXPECT_TRUE(r.Double(r.root(), "", "x", &d));
  EXPECT_TRUE(r.String(r.root(), "", "s", &text));
  EXPECT_EQ(d, 7.5);
  EXPECT_EQ(text, "kept");
  EXPECT_TRUE(r.Require(r.root(), "", "n", "a count"));
  EXPECT_FALSE(r.Require(r.root(), "top", "m", "the m"));
  EXPECT_EQ(r.error(), "f.yaml:1: key 'top.m': required: the m");
}

TEST(YamlReaderTest, TypedGettersSayWhatWasExpected) {
  const auto error = [](const std::string& text, auto read) {
    sim::YamlReader r = Reader(text);
    EXPECT_FALSE(read(r, r.root())) << text;
    return r.error();
  };
  EXPECT_EQ(error("a:\n  v: x\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    double v = 0;
                    return r.Double(n["a"], "a", "v", &v);
                  }),
            "f.yaml:2: key 'a.v': expected a number, got 'x'");
  EXPECT_EQ(error("v: .inf\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    double v = 0;
                    return r.ReadDoubleIn(n["v"], "v", 0, 1, &v);
                  }),
            "f.yaml:1: key 'v': expected a finite number, got .inf");
  EXPECT_EQ(error("v: 2.5\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    double v = 0;
                    return r.ReadDoubleIn(n["v"], "v", 0, 1, &v);
                  }),
            "f.yaml:1: key 'v': expected a finite value in [0, 1], got 2.5");
  EXPECT_EQ(error("v: 3.0\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    int v = 0;
                    return r.Int(n, "", "v", 0, 10, &v);
                  }),
            "f.yaml:1: key 'v': expected an integer, got '3.0'");
  EXPECT_EQ(error("v: 11\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    int v = 0;
                    return r.Int(n, "", "v", 0, 10, &v);
                  }),
            "f.yaml:1: key 'v': expected an integer in [0, 10], got 11");
  EXPECT_EQ(error("v: -1\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    uint64_t v = 0;
                    return r.Uint64(n, "", "v", &v);
                  }),
            "f.yaml:1: key 'v': expected a non-negative integer, got '-1'");
  EXPECT_EQ(error("v: maybe\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    bool v = false;
                    return r.Bool(n, "", "v", &v);
                  }),
            "f.yaml:1: key 'v': expected true or false, got 'maybe'");
  EXPECT_EQ(error("v: c\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    int v = 0;
                    return r.Enum<int>(n, "", "v", {{"a", 1}, {"b", 2}}, &v);
                  }),
            "f.yaml:1: key 'v': expected one of a, b; got 'c'");
  EXPECT_EQ(error("l:\n  - [1, 2]\n  - [3, x]\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    std::vector<std::pair<double, double>> v;
                    return r.ReadPairs(n["l"], "l", &v);
                  }),
            "f.yaml:3: key 'l[1]': expected numbers, got 'x'");
  EXPECT_EQ(error("l: [1, .nan, 3]\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    std::vector<double> v;
                    return r.ReadNumbers(n["l"], "l", 3, &v);
                  }),
            "f.yaml:1: key 'l[1]': expected a finite number, got .nan");
  EXPECT_EQ(error("l: [1, 2]\n",
                  [](sim::YamlReader& r, const YAML::Node& n) {
                    std::vector<double> v;
                    return r.ReadNumbers(n["l"], "l", 3, &v);
                  }),
            "f.yaml:1: key 'l': expected a list of 3 numbers");
}

TEST(YamlReaderTest, GoodValuesAreRead) {
  sim::YamlReader r = Reader(
      "d: 1.5\ni: 7\nu: 18446744073709551615\nb: yes\ne: b\n"
      "w: 3.0\nl: [1, 2]\np: [[1, 2], [3, 4]]\ns: hi\n");
  double d = 0;
  int i = 0, e = 0;
  uint64_t u = 0;
  bool b = false;
  long long w = 0;
  std::string s;
  std::vector<double> l;
  std::vector<std::pair<double, double>> p;
  EXPECT_TRUE(r.Double(r.root(), "", "d", &d) && r.Int(r.root(), "", "i", 0, 10, &i) &&
              r.Uint64(r.root(), "", "u", &u) && r.Bool(r.root(), "", "b", &b) &&
              r.Enum<int>(r.root(), "", "e", {{"a", 1}, {"b", 2}}, &e) &&
              r.ReadWholeNumber(r.root()["w"], "w", 0, 5, &w) &&
              r.ReadNumbers(r.root()["l"], "l", 0, &l) && r.ReadPairs(r.root()["p"], "p", &p) &&
              r.String(r.root(), "", "s", &s, false))
      << r.error();
  EXPECT_EQ(d, 1.5);
  EXPECT_EQ(i, 7);
  EXPECT_EQ(u, UINT64_MAX);
  EXPECT_TRUE(b);
  EXPECT_EQ(e, 2);
  EXPECT_EQ(w, 3);
  EXPECT_EQ(l, (std::vector<double>{1, 2}));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1].second, 4.0);
  EXPECT_EQ(s, "hi");
}

}  // namespace
