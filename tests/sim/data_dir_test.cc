// sim::DataDir: an installed vobench finds its data under <prefix>/share/vobench, a build-tree
// executable falls back to the source tree.
#include "sim/data_dir.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using vobench_test::TempDir;

TEST(DataDirTest, InstalledExecutableFindsShareVobenchBesideItsBin) {
  TempDir prefix("prefix");
  fs::create_directories(prefix / "bin");
  fs::create_directories(prefix / "share/vobench/scenes");
  EXPECT_EQ(sim::DataDirFor(prefix / "bin/vobench", "/fallback"), prefix / "share/vobench");
}

TEST(DataDirTest, WithoutScenesUnderThePrefixFallsBack) {
  TempDir prefix("prefix");
  fs::create_directories(prefix / "bin");
  fs::create_directories(prefix / "share/vobench");  // no scenes/: not a vobench install
  EXPECT_EQ(sim::DataDirFor(prefix / "bin/vobench", "/fallback"), "/fallback");
  EXPECT_EQ(sim::DataDirFor("", "/fallback"), "/fallback");
}

TEST(DataDirTest, BuildTreeExecutableUsesTheSourceTree) {
  EXPECT_EQ(sim::DataDir(), VOBENCH_SOURCE_DIR);
  EXPECT_TRUE(fs::is_regular_file(sim::DataDir() + "/scenes/l_hallway.yaml"));
}

}  // namespace
