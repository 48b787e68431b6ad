// The one check for names that become folder names (issue #11).
#include "harness/path_names.h"

#include <gtest/gtest.h>

#include <string>

namespace {

std::string Problem(const std::string& name) {
  std::string error;
  if (harness::CheckPathName(name, "scenario name", &error)) return "";
  return error.empty() ? "(empty message)" : error;
}

TEST(PathNameTest, OrdinaryNamesPass) {
  for (const char* ok : {"l_hallway", "plain_corridor", "a.b", "run-2", "Hallway 2 (wide)", "x",
                         "l_hallway__paper__s1__k1", "shard1of4", "ü"})
    EXPECT_EQ(Problem(ok), "") << ok;
  EXPECT_EQ(Problem(std::string(harness::kMaxPathNameBytes, 'a')), "");
}

TEST(PathNameTest, NamesThatWouldLeaveOrConfuseTheFolderAreRefused) {
  EXPECT_EQ(Problem("../../../escaped_run"),
            "scenario name '../../../escaped_run': cannot name a folder: contains '..'");
  EXPECT_EQ(Problem(".."), "scenario name '..': cannot name a folder: contains '..'");
  EXPECT_EQ(Problem("."), "scenario name '.': cannot name a folder: '.' is the folder itself");
  EXPECT_EQ(Problem(""), "scenario name '': cannot name a folder: empty");
  EXPECT_EQ(Problem("a/b"),
            "scenario name 'a/b': cannot name a folder: contains a path separator ('/' or '\\')");
  EXPECT_NE(Problem("a\\b").find("path separator"), std::string::npos);
  EXPECT_NE(Problem("/abs").find("path separator"), std::string::npos);
  EXPECT_EQ(Problem("-rf"), "scenario name '-rf': cannot name a folder: starts with '-'");
  EXPECT_EQ(Problem("a\nb"),
            "scenario name 'a\\x0ab': cannot name a folder: contains a control character");
  EXPECT_NE(Problem(std::string("a\x7f", 2)).find("control character"), std::string::npos);
  EXPECT_NE(Problem(std::string(harness::kMaxPathNameBytes + 1, 'a')).find("longer than 255"),
            std::string::npos);
}

}  // namespace
