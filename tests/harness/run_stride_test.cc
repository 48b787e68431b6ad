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
  EXPECT_TRUE(harness::ReadTum(out + "/groundtruth_world_tum.txt", &gt, &error)) << error;
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

namespace {

// A sequence that starts with unusable frames: they have no pose, and the world and the ground
// truth are anchored at the first frame the VO initialised on, so the metrics are those of the
// same sequence without them (issue #11: three black frames at the start once gave 140 % error).
TEST(RunBadStartTest, BlackFirstFramesAreNotInitialisedAndCostNothing) {
  TempDir dir("run_bad_start");
  sim::Scenario scenario;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  scenario.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(1.2, 0)};
  auto simulator = sim::Simulator::Create(scenario, &error);
  ASSERT_TRUE(simulator) << error;
  const vo::StereoCamera camera = harness::ToStereoCamera(simulator->calibration());
  std::vector<harness::DatasetFrame> frames;
  sim::StereoFrame f;
  while (frames.size() < 25 && simulator->Next(&f, &error)) {
    harness::DatasetFrame d;
    d.left = f.left.clone();
    d.right = f.right.clone();
    d.time_s = f.time_s;
    d.has_gt = true;
    d.T_world_cam0 = f.T_world_cam0;
    frames.push_back(d);
  }
  ASSERT_EQ(frames.size(), 25u) << error;
  // The same frames behind three black ones (the robot at rest, then the clean sequence).
  std::vector<harness::DatasetFrame> dark;
  for (int i = 0; i < 3; ++i) {
    harness::DatasetFrame d = frames.front();
    d.left = cv::Mat(d.left.size(), CV_8UC1, cv::Scalar(0));    // new buffers (assigning
    d.right = cv::Mat(d.right.size(), CV_8UC1, cv::Scalar(0));  // Mat::zeros would write into
                                                                // the shared clean frame)
    d.time_s = frames.front().time_s - 0.1 * (3 - i);
    dark.push_back(d);
  }
  dark.insert(dark.end(), frames.begin(), frames.end());
  auto run = [&](const std::vector<harness::DatasetFrame>& seq, const std::string& out,
                 harness::RunSummary* s) {
    size_t next = 0;
    harness::FrameSource source = [&](harness::DatasetFrame* frame, std::string*) {
      if (next >= seq.size()) return false;
      *frame = seq[next++];
      return true;
    };
    harness::RunOptions options;
    options.out_dir = out;
    options.progress = false;
    options.plots = false;
    std::string e;
    EXPECT_TRUE(harness::RunOdometry("bad_start", camera, source, static_cast<int>(seq.size()),
                                     vo::OdometryOptions(), options, "", s, &e))
        << e;
  };
  harness::RunSummary clean, bad;
  run(frames, dir / "clean", &clean);
  run(dark, dir / "dark", &bad);
  EXPECT_EQ(clean.frames_not_initialised, 0);
  EXPECT_EQ(bad.frames_not_initialised, 3);
  EXPECT_EQ(bad.metrics.frames, clean.metrics.frames);
  EXPECT_EQ(bad.lost_frames, clean.lost_frames);
  // Within the clean run's own error (and far from the 1.9 m / 120° of the wrong world).
  const double tol_m = std::max(0.01, clean.metrics.end_pose_error_m);
  EXPECT_NEAR(bad.metrics.end_pose_error_m, clean.metrics.end_pose_error_m, tol_m);
  EXPECT_NEAR(bad.metrics.ate_rmse_m, clean.metrics.ate_rmse_m,
              std::max(0.01, clean.metrics.ate_rmse_m));
  EXPECT_LT(bad.metrics.end_rotation_error_deg, clean.metrics.end_rotation_error_deg + 0.5);
  // No pose for the black frames: the trajectories start at the first initialised frame.
  std::vector<harness::StampedPose> traj;
  ASSERT_TRUE(harness::ReadTum(dir / "dark/trajectory_world_tum.txt", &traj, &error)) << error;
  ASSERT_EQ(traj.size(), frames.size());
  EXPECT_EQ(traj.front().time_s, frames.front().time_s);
  std::ifstream csv(dir / "dark/per_frame.csv");
  std::string header, row0, row3;
  std::getline(csv, header);
  std::getline(csv, row0);
  for (int i = 0; i < 3; ++i) std::getline(csv, row3);
  EXPECT_NE(row0.find(",not_initialised,"), std::string::npos) << row0;
  EXPECT_EQ(row3.rfind("3,", 0), 0u) << row3;
  EXPECT_EQ(row3.find("not_initialised"), std::string::npos) << row3;

  // A sequence the VO never initialises on is an error that says so, and writes nothing.
  std::vector<harness::DatasetFrame> black(dark.begin(), dark.begin() + 3);
  size_t next = 0;
  harness::FrameSource source = [&](harness::DatasetFrame* frame, std::string*) {
    if (next >= black.size()) return false;
    *frame = black[next++];
    return true;
  };
  harness::RunOptions options;
  options.out_dir = dir / "black";
  options.progress = false;
  options.plots = false;
  harness::RunSummary s;
  EXPECT_FALSE(harness::RunOdometry("black", camera, source, 3, vo::OdometryOptions(), options, "",
                                    &s, &error));
  EXPECT_NE(error.find("never initialised"), std::string::npos) << error;
  EXPECT_FALSE(std::filesystem::exists(dir / "black"));
}

}  // namespace
