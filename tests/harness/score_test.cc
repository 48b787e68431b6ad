// `vobench score`: the accuracy metrics of a trajectory file against a ground truth. Known
// answers on synthetic trajectories, the identity with a run's own figures (a run folder's files
// scored give its metrics.json), and bad input (exit 2 naming the file and line, nothing
// written).
#include "harness/score.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/metric_registry.h"
#include "harness/output_folder.h"
#include "harness/trajectory_io.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using vobench_test::ReadAll;
using vobench_test::RunVobench;
using vobench_test::TempDir;
using vobench_test::WriteText;

// A straight 2 m path along z (the camera's forward), one pose every 0.1 s, 21 poses.
std::vector<harness::StampedPose> StraightPath() {
  std::vector<harness::StampedPose> poses;
  for (int i = 0; i <= 20; ++i) {
    harness::StampedPose p;
    p.time_s = 0.1 * i;
    p.T_world_cam.translation() = Eigen::Vector3d(0, 0, 0.1 * i);
    poses.push_back(p);
  }
  return poses;
}

std::vector<Eigen::Isometry3d> Poses(const std::vector<harness::StampedPose>& stamped) {
  std::vector<Eigen::Isometry3d> poses;
  for (const auto& p : stamped) poses.push_back(p.T_world_cam);
  return poses;
}

TEST(ScoreTest, AKnownEndErrorIsMeasuredInBothFormats) {
  TempDir dir("score_known");
  const auto gt = StraightPath();
  auto est = gt;
  est.back().T_world_cam.translation().x() += 0.1;  // the last pose 10 cm to the side
  std::string error;
  ASSERT_TRUE(harness::WriteTum(dir / "gt.txt", gt, &error)) << error;
  ASSERT_TRUE(harness::WriteTum(dir / "est.txt", est, &error)) << error;
  ASSERT_TRUE(harness::WriteKittiPoses(dir / "gt_kitti.txt", Poses(gt), &error)) << error;
  ASSERT_TRUE(harness::WriteKittiPoses(dir / "est_kitti.txt", Poses(est), &error)) << error;
  for (const auto format : {harness::TrajectoryFormat::kTum, harness::TrajectoryFormat::kKitti}) {
    const bool tum = format == harness::TrajectoryFormat::kTum;
    harness::ScoreOptions options;
    options.format = format;
    harness::ScoreResult r;
    ASSERT_TRUE(harness::ScoreTrajectory("est", dir / (tum ? "gt.txt" : "gt_kitti.txt"),
                                         dir / (tum ? "est.txt" : "est_kitti.txt"), options, &r,
                                         &error))
        << error;
    EXPECT_EQ(r.summary.ground_truth_frames, 21);
    EXPECT_NEAR(r.summary.metrics.path_length_m, 2.0, 1e-12);
    EXPECT_NEAR(r.summary.metrics.end_pose_error_m, 0.1, 1e-12);
    EXPECT_NEAR(r.summary.metrics.end_pose_error_pct, 5.0, 1e-10);
    EXPECT_NEAR(r.summary.metrics.ate_rmse_unaligned_m, std::sqrt(0.01 / 21), 1e-12);
    EXPECT_NEAR(r.summary.metrics.end_rotation_error_deg, 0.0, 1e-12);
  }
}

TEST(ScoreTest, TumPosesAreAssociatedByTimeWithinTheMaxDifference) {
  TempDir dir("score_assoc");
  const auto gt = StraightPath();
  // The estimate at half the rate and stamped 5 ms late: 11 poses pair with the ground truth.
  std::vector<harness::StampedPose> est;
  for (size_t i = 0; i < gt.size(); i += 2) {
    est.push_back(gt[i]);
    est.back().time_s += 0.005;
  }
  std::string error;
  ASSERT_TRUE(harness::WriteTum(dir / "gt.txt", gt, &error)) << error;
  ASSERT_TRUE(harness::WriteTum(dir / "est.txt", est, &error)) << error;
  harness::ScoreOptions options;
  harness::ScoreResult r;
  ASSERT_TRUE(harness::ScoreTrajectory("est", dir / "gt.txt", dir / "est.txt", options, &r, &error))
      << error;
  EXPECT_EQ(r.estimate_poses, 11u);
  EXPECT_EQ(r.ground_truth_poses, 21u);
  EXPECT_EQ(r.summary.ground_truth_frames, 11);
  EXPECT_NEAR(r.summary.metrics.ate_rmse_m, 0.0, 1e-12);
  EXPECT_NEAR(r.summary.metrics.path_length_m, 2.0, 1e-12);
  // With a max difference below the 5 ms, nothing pairs: no time overlap.
  options.max_difference_s = 0.004;
  EXPECT_FALSE(
      harness::ScoreTrajectory("est", dir / "gt.txt", dir / "est.txt", options, &r, &error));
  EXPECT_NE(error.find("no time overlap"), std::string::npos) << error;
}

// A 40-frame run scored on its own files gives the run's accuracy figures: to 1e-12 from the
// KITTI pair (written relative to the first pose, so rounded once more), to 1e-9 from the TUM
// pair (the rotation is written as a quaternion).
TEST(ScoreTest, ARunFoldersFilesGiveTheRunsAccuracyFigures) {
  TempDir dir("score_run");
  const std::string run = dir / "run";
  const auto r = RunVobench("run l_hallway --max-frames 40 --no-plots -q --out " + run);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json run_metrics = json::parse(ReadAll(run + "/metrics.json"));
  ASSERT_TRUE(run_metrics.at("has_ground_truth").get<bool>());
  for (const std::string format : {"kitti", "tum"}) {
    const std::string out = dir / ("score_" + format);
    const std::string suffix = format == "tum" ? "_world_tum.txt" : "_kitti.txt";
    const auto s = RunVobench("score --format " + format + " --gt " + run + "/groundtruth" +
                              suffix + " --est " + run + "/trajectory" + suffix + " --out " + out);
    ASSERT_EQ(s.exit_code, 0) << s.output;
    EXPECT_NE(s.output.find("ATE RMSE"), std::string::npos) << s.output;
    EXPECT_TRUE(harness::HasFolderMarker(out, "score"));
    const json scored = json::parse(ReadAll(out + "/metrics.json"));
    EXPECT_EQ(scored.at("ground_truth_frames"), run_metrics.at("ground_truth_frames"));
    int keys = 0;
    for (const harness::MetricInfo& m : harness::RunMetrics()) {
      if (m.group != harness::MetricGroup::kAccuracy) continue;
      ++keys;
      const json* a = harness::FindMetricValue(run_metrics, m.key);
      const json* b = harness::FindMetricValue(scored, m.key);
      if (m.reason) {  // written only beside its null figure: in both or in neither
        EXPECT_EQ(a == nullptr, b == nullptr) << m.key;
        if (a != nullptr && b != nullptr) {
          EXPECT_EQ(*a, *b) << m.key;
        }
        continue;
      }
      ASSERT_TRUE(a != nullptr && b != nullptr) << m.key;
      if (a->is_null() || b->is_null()) {  // not applicable: in both
        EXPECT_TRUE(a->is_null() && b->is_null()) << m.key;
      } else {
        // The run computes on its world-frame poses; the KITTI files start at the identity
        // (issue #33) and the TUM ones write the rotation as a quaternion: equal to rounding.
        const double x = a->get<double>(), y = b->get<double>();
        EXPECT_NEAR(x, y, (format == "kitti" ? 1e-12 : 1e-9) * std::max(1.0, std::abs(x))) << m.key;
      }
    }
    EXPECT_GE(keys, 10);
  }
}

TEST(ScoreTest, BadInputExitsWith2NamingTheFileAndWritesNothing) {
  TempDir dir("score_bad");
  const auto gt = StraightPath();
  std::string error;
  ASSERT_TRUE(harness::WriteTum(dir / "gt.txt", gt, &error)) << error;
  ASSERT_TRUE(harness::WriteKittiPoses(dir / "gt_kitti.txt", Poses(gt), &error)) << error;
  WriteText(dir / "malformed.txt", "0 0 0 0 0 0 0 1\n0.1 0 0 0.1 0 0 1\n");  // line 2: 7 numbers
  WriteText(dir / "one.txt", "0 0 0 0 0 0 0 1\n");
  WriteText(dir / "late.txt", "100 0 0 0 0 0 0 1\n100.1 0 0 0.1 0 0 0 1\n");
  std::vector<harness::StampedPose> shorter(gt.begin(), gt.begin() + 5);
  ASSERT_TRUE(harness::WriteKittiPoses(dir / "short_kitti.txt", Poses(shorter), &error)) << error;
  const std::string out = dir / "out";
  struct Case {
    std::string args, expected;
  };
  const std::vector<Case> cases = {
      {"--format tum --est " + (dir / "missing.txt"), dir / "missing.txt"},
      {"--format tum --est " + (dir / "malformed.txt"), dir / "malformed.txt:2"},
      {"--format tum --est " + (dir / "one.txt"), "at least 2"},
      {"--format tum --est " + (dir / "late.txt"), "no time overlap"},
      {"--format kitti --gt " + (dir / "gt_kitti.txt") + " --est " + (dir / "short_kitti.txt"),
       "line by line"},
      {"--format g2o --est " + (dir / "gt.txt"), "expected tum or kitti"},
      {"--format tum --max-difference 0 --est " + (dir / "gt.txt"), "--max-difference"},
      {"--format kitti --max-difference 0.1 --gt " + (dir / "gt_kitti.txt") + " --est " +
           (dir / "gt_kitti.txt"),
       "only for --format tum"},
  };
  for (const Case& c : cases) {
    const std::string gt_arg =
        c.args.find("--gt") == std::string::npos ? " --gt " + (dir / "gt.txt") : "";
    const auto r = RunVobench("score " + c.args + gt_arg + " --out " + out);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find("vobench score: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.expected << "\n" << r.output;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
}

}  // namespace
