// RunOptions::frame_stride (`vobench run --stride`): the VO sees every k-th source frame and the
// metrics are on those frames; --max-frames counts source frames.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "harness/render.h"
#include "harness/run.h"
#include "harness/trajectory_io.h"
#include "tests/sim/sim_test_util.h"

namespace {

using vobench_test::TempDir;

std::vector<harness::StampedPose> RunAndReadGroundTruth(const sim::Scenario& scenario,
                                                        int max_frames, int stride,
                                                        const std::string& out,
                                                        harness::RunSummary* summary) {
  harness::RunOptions options;
  options.out_dir = out;
  options.progress = false;
  options.plots = false;
  options.max_frames = max_frames;
  options.frame_stride = stride;
  std::string error;
  EXPECT_TRUE(harness::RunScenario(scenario, vo::OdometryOptions(), options, summary, &error))
      << error;
  std::vector<harness::StampedPose> gt;
  EXPECT_TRUE(harness::ReadTum(out + "/groundtruth_tum.txt", &gt, &error)) << error;
  return gt;
}

TEST(RunStrideTest, TheVoSeesEveryKthFrame) {
  TempDir dir("run_stride");
  sim::Scenario scenario;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  scenario.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(1.0, 0)};
  harness::RunSummary all, strided;
  const auto gt_all = RunAndReadGroundTruth(scenario, 8, 1, dir / "k1", &all);
  const auto gt_k3 = RunAndReadGroundTruth(scenario, 8, 3, dir / "k3", &strided);
  // 8 source frames, stride 3: frames 0, 3, 6.
  ASSERT_EQ(gt_all.size(), 8u);
  ASSERT_EQ(gt_k3.size(), 3u);
  EXPECT_EQ(all.metrics.frames, 8);
  EXPECT_EQ(strided.metrics.frames, 3);
  EXPECT_EQ(strided.frame_stride, 3);
  for (size_t i = 0; i < gt_k3.size(); ++i) {
    EXPECT_EQ(gt_k3[i].time_s, gt_all[3 * i].time_s) << i;
    EXPECT_TRUE(gt_k3[i].T_world_cam.isApprox(gt_all[3 * i].T_world_cam, 1e-12)) << i;
  }
  // The strided path runs through frames 0, 3, 6.
  const auto t = [&](int i) { return gt_all[i].T_world_cam.translation(); };
  EXPECT_NEAR(strided.metrics.path_length_m, (t(3) - t(0)).norm() + (t(6) - t(3)).norm(), 1e-9);

  harness::RunOptions bad;
  bad.out_dir = dir / "k0";
  bad.progress = false;
  bad.frame_stride = 0;
  harness::RunSummary s;
  EXPECT_FALSE(harness::RunScenario(scenario, vo::OdometryOptions(), bad, &s, &error));
  EXPECT_NE(error.find("stride"), std::string::npos) << error;
  EXPECT_FALSE(std::filesystem::exists(dir / "k0"));
}

}  // namespace
