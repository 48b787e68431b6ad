// `vobench run` on the simulator: the paper's configuration against ground truth on the
// L-hallway, run-folder contents, determinism, VO config files.
#include "harness/run.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "harness/render.h"
#include "harness/vo_config.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using vobench_test::TempDir;
using vobench_test::WriteText;

// The paper reports 0.29 m end-pose deviation over its L path; the issue asks for at most that.
constexpr double kPaperEndPoseErrorM = 0.29;
constexpr double kMaxAteM = 0.10;
constexpr int kMaxLostFrames = 10;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(RunTest, PapersConfigurationOnTheLHallwayMeetsThePapersFigure) {
  TempDir dir("run_l");
  sim::Scenario scenario;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  harness::RunOptions options;
  options.out_dir = dir / "run";
  options.progress = false;
  options.plots = false;
  harness::RunSummary s;
  ASSERT_TRUE(harness::RunScenario(scenario, vo::OdometryOptions(), options, &s, &error)) << error;
  std::printf("l_hallway: end-pose error %.4f m, ATE %.4f m, lost %d, median %.2f ms\n",
              s.metrics.end_pose_error_m, s.metrics.ate_rmse_m, s.lost_frames, s.vo_ms_median);
  EXPECT_LE(s.metrics.end_pose_error_m, kPaperEndPoseErrorM);
  EXPECT_LE(s.metrics.ate_rmse_m, kMaxAteM);
  EXPECT_LE(s.lost_frames, kMaxLostFrames);
  EXPECT_NEAR(s.metrics.path_length_m, 16.0, 0.5);
  // Matcher statistics from the simulator's depth: the matcher's own precision (match-eval:
  // 0.986 at stride 1) and that of the RANSAC inliers, which must be nearly all correct.
  std::printf("VO matches: %ld evaluated, precision %.4f, inliers %.4f\n", s.match_stats.matches,
              s.match_stats.precision(), s.match_stats.inlier_precision());
  EXPECT_GT(s.match_stats.matches, 10000);
  EXPECT_GT(s.match_stats.precision(), 0.95);
  EXPECT_GT(s.match_stats.inlier_precision(), 0.99);
  // The run folder has what the issue names.
  for (const char* f :
       {"trajectory_world_tum.txt", "trajectory_kitti.txt", "groundtruth_world_tum.txt",
        "per_frame.csv", "vo_options.yaml", "scenario.yaml", "metrics.json", "report.md"})
    EXPECT_TRUE(fs::exists(fs::path(options.out_dir) / f)) << f;
  const nlohmann::json j = ReadJson(options.out_dir + "/metrics.json");
  for (const char* k : {"frames", "path_length_m", "end_pose_error_m", "end_pose_error_pct",
                        "ate_rmse_m", "lost_frames", "vo_ms_median", "vo_ms_p95", "match_precision",
                        "inlier_match_precision", "rpe_distance_trans_rmse_m"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["frames"].get<int>(), s.metrics.frames);
  EXPECT_FALSE(fs::exists(options.out_dir + ".partial"));
}

TEST(RunTest, SameScenarioGivesIdenticalAccuracyMetricsAndTrajectory) {
  TempDir dir("run_det");
  sim::Scenario scenario;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  scenario.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(2.0, 0)};
  std::string traj[2];
  nlohmann::json metrics[2];
  for (int k = 0; k < 2; ++k) {
    harness::RunOptions options;
    options.out_dir = dir / ("run" + std::to_string(k));
    options.progress = false;
    options.plots = false;
    harness::RunSummary s;
    ASSERT_TRUE(harness::RunScenario(scenario, vo::OdometryOptions(), options, &s, &error))
        << error;
    std::ifstream in(options.out_dir + "/trajectory_world_tum.txt");
    traj[k].assign(std::istreambuf_iterator<char>(in), {});
    metrics[k] = ReadJson(options.out_dir + "/metrics.json");
  }
  EXPECT_EQ(traj[0], traj[1]);
  for (const char* key : {"frames", "end_pose_error_m", "ate_rmse_m", "drift_pct", "lost_frames"})
    EXPECT_EQ(metrics[0][key], metrics[1][key]) << key;
}

// A clip shorter than 1 m, rendered and run from its KITTI-layout folder without plots:
// `render` and `run` report the same camera path length; the figures relative to the path are
// null with their reason; report.md links no plot (none was made); without
// T_world_cam0first.txt the ground truth's world is the first camera (not gravity-aligned):
// no initial-orientation error, null with the reason.
TEST(RunTest, ShortClipHasNullFiguresWithReasonsAndNoDanglingLinks) {
  TempDir dir("run_short");
  sim::Scenario scenario;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  scenario.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.4, 0)};
  harness::RenderOptions render_options;
  render_options.progress = false;
  harness::RenderSummary rendered;
  ASSERT_TRUE(harness::RenderScenario(scenario, dir / "data", render_options, &rendered, &error))
      << error;
  EXPECT_GT(rendered.path_length_m, 0.2);
  EXPECT_LT(rendered.path_length_m, 1.0);
  EXPECT_GT(rendered.base_path_length_m, 0.2);
  harness::RunOptions options;
  options.progress = false;
  options.plots = false;
  for (const bool world_file : {true, false}) {
    if (!world_file) fs::remove(dir / "data/T_world_cam0first.txt");
    options.out_dir = dir / (world_file ? "run_world" : "run_first_camera");
    harness::RunSummary s;
    ASSERT_TRUE(harness::RunKittiDataset(dir / "data", vo::OdometryOptions(), options, &s, &error))
        << error;
    ASSERT_EQ(s.frames_not_initialised, 0);
    EXPECT_NEAR(s.metrics.path_length_m, rendered.path_length_m, 1e-6);
    const nlohmann::json j = ReadJson(options.out_dir + "/metrics.json");
    for (const char* k : {"end_pose_error_pct", "drift_pct", "drift_deg_per_m", "kitti_drift_pct",
                          "kitti_drift_deg_per_m"})
      EXPECT_TRUE(j[k].is_null()) << k;
    const std::string too_short = j["end_pose_error_pct_reason"].get<std::string>();
    EXPECT_NE(too_short.find("shorter than 1.000 m"), std::string::npos) << too_short;
    EXPECT_EQ(j["drift_reason"], too_short);
    EXPECT_EQ(j["kitti_drift_reason"], too_short);
    EXPECT_TRUE(j["end_pose_error_m"].is_number());
    if (world_file && s.initial_orientation_ok) {
      EXPECT_TRUE(j["initial_orientation_error_deg"].is_number());
      EXPECT_FALSE(j.contains("initial_orientation_error_reason"));
    } else if (!world_file) {
      EXPECT_TRUE(j["initial_orientation_error_deg"].is_null());
      EXPECT_EQ(j["initial_orientation_error_reason"],
                "ground truth not gravity-aligned (KITTI layout without T_world_cam0first.txt: "
                "world = first camera)");
    }
    std::ifstream in(options.out_dir + "/report.md");
    const std::string report(std::istreambuf_iterator<char>(in), {});
    EXPECT_EQ(report.find("!["), std::string::npos) << report;
    EXPECT_EQ(report.find(".png"), std::string::npos) << report;
    EXPECT_NE(report.find("n/a (ground-truth path"), std::string::npos) << report;
  }
}

TEST(RunTest, RefusesToReplaceAFolderThatIsNotARun) {
  TempDir dir("run_refuse");
  fs::create_directories(dir / "mine");
  WriteText(dir / "mine/notes.txt", "keep");
  sim::Scenario scenario;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  scenario.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.3, 0)};
  harness::RunOptions options;
  options.out_dir = dir / "mine";
  options.progress = false;
  options.plots = false;
  harness::RunSummary s;
  EXPECT_FALSE(harness::RunScenario(scenario, vo::OdometryOptions(), options, &s, &error));
  EXPECT_NE(error.find("not a vobench run folder"), std::string::npos) << error;
  EXPECT_TRUE(fs::exists(dir / "mine/notes.txt"));
}

TEST(VoConfigTest, RoundTripAndErrors) {
  vo::OdometryOptions o;
  std::string error;
  ASSERT_TRUE(harness::ParseVoConfig(
      "tracker:\n  matcher:\n    type: ncc_mutual\n    svd:\n      sigma_px: 14\n"
      "back_end.bundle_adjustment: false\nback_end.window_frames: 7\n",
      "cfg.yaml", &o, &error))
      << error;
  EXPECT_EQ(o.tracker.matcher.type, vo::MatcherType::kNccMutual);
  EXPECT_DOUBLE_EQ(o.tracker.matcher.svd.sigma_px, 14);
  EXPECT_FALSE(o.back_end.bundle_adjustment);
  EXPECT_EQ(o.back_end.window_frames, 7);
  // The effective file reads back to the same options, every key away from its default (a key
  // written twice, e.g. a nested map split in two, would lose one of them).
  o.back_end.ba.max_num_iterations = 7;
  o.back_end.ba.loss_scale_px = 2.5;
  o.back_end.max_points = 55;
  o.front_end.disparity.algorithm = vo::DisparityAlgorithm::kSemiGlobal;
  o.front_end.disparity_mode =
      vo::DisparityMode::kDense;  // at_features needs the one-volume matcher
  o.front_end.disparity_range_margin_px = 4.0;
  o.front_end.disparity.block_size = 7;
  o.front_end.disparity_min_depth_m = 0.6;
  const std::string effective = harness::VoConfigToYaml(o);
  for (const char* top :
       {"\n  ba:", "\n  disparity:", "\n  matcher:", "\n  detector:", "\n  ransac:", "\nfront_end:",
        "\ntracker:", "\nmotion:", "\nrecovery:", "\nback_end:"}) {
    const size_t first = effective.find(top);
    EXPECT_EQ(effective.find(top, first + 1), std::string::npos) << top << " twice in\n"
                                                                 << effective;
  }
  vo::OdometryOptions again;
  ASSERT_TRUE(harness::ParseVoConfig(harness::VoConfigToYaml(o), "effective.yaml", &again, &error))
      << error;
  EXPECT_EQ(harness::VoConfigToYaml(again), harness::VoConfigToYaml(o));
  EXPECT_EQ(again.back_end.ba.max_num_iterations, 7);
  EXPECT_EQ(again.back_end.ba.loss_scale_px, 2.5);
  EXPECT_EQ(again.back_end.max_points, 55);
  EXPECT_EQ(again.front_end.disparity.algorithm, vo::DisparityAlgorithm::kSemiGlobal);
  EXPECT_EQ(again.front_end.disparity_min_depth_m, 0.6);

  vo::OdometryOptions bad;
  EXPECT_FALSE(
      harness::ParseVoConfig("tracker:\n  matcher:\n    typo: 1\n", "cfg.yaml", &bad, &error));
  EXPECT_NE(error.find("cfg.yaml:3"), std::string::npos) << error;
  EXPECT_NE(error.find("tracker.matcher.typo"), std::string::npos) << error;
  EXPECT_FALSE(harness::ParseVoConfig("back_end.window_frames: 11\n", "cfg.yaml", &bad, &error));
  EXPECT_NE(error.find("back_end.window_frames"), std::string::npos) << error;
  EXPECT_FALSE(harness::ParseVoConfig("motion:\n  ransac:\n    inlier_threshold_px: .nan\n",
                                      "cfg.yaml", &bad, &error));
  EXPECT_FALSE(
      harness::ParseVoConfig("tracker.matcher:\n  type: magic\n", "cfg.yaml", &bad, &error));
  EXPECT_FALSE(
      harness::ParseVoConfig("back_end.bundle_adjustment: maybe\n", "cfg.yaml", &bad, &error));
  EXPECT_FALSE(harness::ParseVoConfig("a: [1\n", "cfg.yaml", &bad, &error));
  EXPECT_NE(error.find("malformed"), std::string::npos);
}

// Issue #11: a key given twice was read from its first occurrence, silently; a folder given as
// --config ran the defaults.
TEST(VoConfigTest, DuplicateKeysAndFoldersAreRefused) {
  vo::OdometryOptions o;
  std::string error;
  EXPECT_FALSE(harness::ParseVoConfig(
      "tracker:\n  matcher: {type: ncc_mutual}\ntracker:\n  matcher: {type: kalman}\n", "cfg.yaml",
      &o, &error));
  EXPECT_EQ(error, "cfg.yaml:3: key 'tracker': duplicate (first at line 1)");
  // The same option dotted and nested.
  EXPECT_FALSE(harness::ParseVoConfig(
      "tracker.matcher.type: kalman\ntracker:\n  matcher:\n    type: ncc_mutual\n", "cfg.yaml", &o,
      &error));
  EXPECT_EQ(error, "cfg.yaml:4: key 'tracker.matcher.type': duplicate (first at line 1)");
  const std::string folder = ::testing::TempDir();
  EXPECT_FALSE(harness::LoadVoConfig(folder, &o, &error));
  EXPECT_EQ(error, folder + ": is a folder, expected a YAML VO config file");
}

// A simulated run with the ground-vehicle model and no axle uses the rig's camera.forward_m,
// and its run folder records it.
TEST(RunTest, GroundVehicleRunTakesTheSimulatedRigsAxle) {
  TempDir dir("run_axle");
  sim::Scenario scenario;
  std::string error;
  ASSERT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  scenario.camera.forward_m = 0.2;
  harness::RunOptions options;
  options.out_dir = dir / "run";
  options.progress = false;
  options.plots = false;
  options.max_frames = 3;
  vo::OdometryOptions vo_options;
  vo_options.motion.ground_vehicle = true;
  harness::RunSummary s;
  ASSERT_TRUE(harness::RunScenario(scenario, vo_options, options, &s, &error)) << error;
  vo::OdometryOptions written;
  ASSERT_TRUE(harness::LoadVoConfig(options.out_dir + "/vo_options.yaml", &written, &error))
      << error;
  EXPECT_EQ(written.motion.few_point.axle_behind_camera_m, 0.2);
}

}  // namespace
