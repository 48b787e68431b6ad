// `vobench eval` (harness/eval.h) on the simulator's exports: in each layout (kitti, euroc, tum)
// the same frames give the same trajectory and metrics as `vobench run` on the scenario; ground
// truth at another rate covering part of the frames; no ground truth. And on small synthetic
// datasets, bad input ends with a message naming the file, a non-zero exit and no run folder.
#include "harness/eval.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "harness/dataset/rig.h"
#include "harness/metrics.h"
#include "harness/render.h"
#include "harness/trajectory_io.h"
#include "sim/simulator.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace harness {
namespace {

using vobench_test::CommandResult;
using vobench_test::ExpectTrajectoriesNear;
using vobench_test::ReadAll;
using vobench_test::RunVobench;

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using vobench_test::WriteText;

// Ground truth read back from text (17 digits) and recomposed (EuRoC: body * T_BS) differs from
// the simulator's in the last bits; metrics follow within this.
constexpr double kMetricTolerance = 1e-9;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

RunOptions QuietRun(const std::string& out_dir) {
  RunOptions o;
  o.out_dir = out_dir;
  o.progress = false;
  o.plots = false;
  return o;
}

// One short noisy scenario in the real hallway (0.5 m), simulated once per test process: its
// frames written in the euroc and tum layouts (both also hold the kitti layout) with the writer
// options of `vobench render`, and the VO run on the frames as `vobench run` runs it.
class EvalTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ =
        new fs::path(fs::temp_directory_path() / ("vobench_eval_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    const std::string scenario_path = (*root_ / "short.yaml").string();
    WriteText(scenario_path, "name: short\nscene: " + std::string(VOBENCH_SOURCE_DIR) +
                                 "/scenes/hallway_l.xml\npath:\n  - [0, 0]\n  - [0.5, 0]\n"
                                 "noise:\n  pixel_sigma: 1.5\n  gain_sigma: 0.02\n");
    std::string error;
    scenario_ = new sim::Scenario;
    ASSERT_TRUE(ResolveScenario(scenario_path, scenario_, &error)) << error;
    auto simulator = sim::Simulator::Create(*scenario_, &error);
    ASSERT_TRUE(simulator) << error;
    std::vector<DatasetFrame> frames;
    sim::StereoFrame f;
    while (simulator->Next(&f, &error)) frames.push_back(ToDatasetFrame(f));
    ASSERT_EQ(error, "");
    const vo::StereoCamera camera = ToStereoCamera(simulator->calibration());
    for (DatasetFormat format : {DatasetFormat::kEuroc, DatasetFormat::kTum}) {
      DatasetWriter::Options options;  // as RenderScenario sets them
      options.format = format;
      options.T_body_cam0 = simulator->calibration().T_body_cam0;
      options.T_body_imu = simulator->calibration().T_body_imu;  // the frames carry the IMU
      options.imu = scenario_->imu;
      options.rate_hz = scenario_->rate_hz;
      options.stamp_offset_ns = kSimulationEpochNs;
      options.write_rig = true;  // the mounting, so a run on the export knows the ground vehicle
      options.rig.forward_m = scenario_->camera.forward_m;
      options.rig.height_m = scenario_->camera.height_m;
      options.rig.pitch_deg = scenario_->camera.pitch_deg;
      DatasetWriter writer(options);
      ASSERT_TRUE(writer.Open(Export(format), camera, &error)) << error;
      for (const DatasetFrame& frame : frames) ASSERT_TRUE(writer.Add(frame, &error)) << error;
      ASSERT_TRUE(writer.Finish(&error)) << error;
    }
    run_ = new RunSummary;
    size_t next = 0;
    FrameSource source = [&](DatasetFrame* frame, std::string*) {
      if (next >= frames.size()) return false;
      *frame = frames[next++];
      return true;
    };
    // As `vobench run` resolves the platform on the simulated rig (a ground vehicle).
    ASSERT_TRUE(RunOdometry(scenario_->name, camera, source, static_cast<int>(frames.size()),
                            vo::ResolvePlatform(vo::OdometryOptions(), scenario_->camera.forward_m),
                            QuietRun(RunDir()), "", run_, &error))
        << error;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
    delete scenario_;
    delete run_;
  }
  void SetUp() override {
    ASSERT_TRUE(fs::exists(RunDir() + "/metrics.json")) << "suite set-up failed";
    dir_ = *root_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string Export(DatasetFormat format) {
    return (*root_ / (std::string("export_") + DatasetFormatName(format))).string();
  }
  static std::string RunDir() { return (*root_ / "run").string(); }
  // A private copy of an export, to change.
  std::string Copy(DatasetFormat format) const {
    const std::string copy = (dir_ / "data").string();
    fs::copy(Export(format), copy, fs::copy_options::recursive);
    return copy;
  }
  std::string Out() const { return (dir_ / "out").string(); }

  static fs::path* root_;
  static sim::Scenario* scenario_;
  static RunSummary* run_;
  fs::path dir_;
};

fs::path* EvalTest::root_ = nullptr;
sim::Scenario* EvalTest::scenario_ = nullptr;
RunSummary* EvalTest::run_ = nullptr;

void ExpectSameAccuracy(const nlohmann::json& a, const nlohmann::json& b, const std::string& what,
                        double tolerance = kMetricTolerance) {
  for (const char* k :
       {"path_length_m", "end_pose_error_m", "end_rotation_error_deg", "ate_rmse_m",
        "ate_rmse_unaligned_m", "rpe_trans_rmse_m", "rpe_rot_rmse_deg", "drift_pct"}) {
    ASSERT_TRUE(a.contains(k) && b.contains(k)) << what << ": " << k;
    ASSERT_EQ(a[k].is_null(), b[k].is_null()) << what << ": " << k;  // not applicable in both
    if (!a[k].is_null()) {
      EXPECT_NEAR(a[k].get<double>(), b[k].get<double>(), tolerance) << what << ": " << k;
    }
  }
  for (const char* k : {"frames", "lost_frames", "ground_truth_frames", "has_ground_truth"})
    EXPECT_EQ(a[k], b[k]) << what << ": " << k;
}

TEST_F(EvalTest, SimulatorExportsInEachFormatGiveTheRunsTrajectoryAndMetrics) {
  // `vobench run` on the scenario itself (simulating again) is the reference: without the gyro
  // for the layouts that carry no IMU (kitti, tum), with it (the default, imu.gyro_prior) for
  // euroc, whose imu0 holds the simulated IMU and its mounting.
  struct Reference {
    std::string trajectory;
    nlohmann::json metrics;
  };
  auto reference = [&](bool gyro, Reference* r) {
    const std::string dir = (dir_ / (gyro ? "scenario_run_gyro" : "scenario_run")).string();
    vo::OdometryOptions vo_options;
    vo_options.imu.gyro_prior = gyro;
    RunSummary s0;
    std::string error0;
    ASSERT_TRUE(RunScenario(*scenario_, vo_options, QuietRun(dir), &s0, &error0)) << error0;
    r->metrics = ReadJson(dir + "/metrics.json");
    ASSERT_TRUE(s0.has_ground_truth);
    EXPECT_GT(s0.metrics.frames, 12);
    EXPECT_EQ(r->metrics["ground_truth_frames"], s0.metrics.frames);
    r->trajectory = ReadAll(dir + "/trajectory_kitti.txt");
  };
  Reference without_gyro, with_gyro;
  ASSERT_NO_FATAL_FAILURE(reference(false, &without_gyro));
  ASSERT_NO_FATAL_FAILURE(reference(true, &with_gyro));
  EXPECT_NE(with_gyro.trajectory, without_gyro.trajectory);  // the gyro is used
  // The fixture's run (the frames without their gyro) is the run without the gyro.
  EXPECT_EQ(ReadAll(RunDir() + "/trajectory_kitti.txt"), without_gyro.trajectory);
  const struct {
    DatasetFormat format;
    std::string dir;
    const Reference& reference;
    double tolerance;  // 0: bit for bit
  } cases[] = {{DatasetFormat::kKitti, Export(DatasetFormat::kEuroc), without_gyro, 0.0},
               // The gyro's samples are stamped in nanoseconds since the simulation's epoch
               // (1.77e9 s): read back as seconds, their differences carry ~1e-7 s of rounding,
               // so the gyro's rotations, and the trajectory, agree to ~1e-6 only.
               {DatasetFormat::kEuroc, Export(DatasetFormat::kEuroc), with_gyro, 1e-5},
               {DatasetFormat::kTum, Export(DatasetFormat::kTum), without_gyro, 0.0}};
  for (const auto& c : cases) {
    const std::string name = DatasetFormatName(c.format);
    EvalOptions options;
    options.format = c.format;
    RunSummary s;
    EvalInfo info;
    std::string error;
    const std::string out = (dir_ / name).string();
    ASSERT_TRUE(
        EvalDataset(c.dir, options, vo::OdometryOptions(), QuietRun(out), &s, &info, &error))
        << name << ": " << error;
    EXPECT_FALSE(info.rectified) << name;  // the simulator's pair is ideal: images untouched
    EXPECT_EQ(info.ground_truth_frames, c.reference.metrics["ground_truth_frames"]) << name;
    // Same frames (and gyro) -> the same trajectory, bit for bit, and the same metrics; the
    // default VO options on every layout (the gyro is used where the layout has one).
    const std::string trajectory = ReadAll(out + "/trajectory_kitti.txt");
    if (c.tolerance == 0.0) {
      EXPECT_EQ(trajectory, c.reference.trajectory) << name;
      ExpectSameAccuracy(ReadJson(out + "/metrics.json"), c.reference.metrics, name);
    } else {
      ExpectTrajectoriesNear(trajectory, c.reference.trajectory,
                             c.reference.metrics["frames"].get<int>(), c.tolerance, name);
      ExpectSameAccuracy(ReadJson(out + "/metrics.json"), c.reference.metrics, name, c.tolerance);
    }
    for (const char* f : {"trajectory_world_tum.txt", "groundtruth_world_tum.txt", "per_frame.csv",
                          "vo_options.yaml", "report.md", "estimate_in_gt_world_tum.txt"})
      EXPECT_TRUE(fs::exists(out + "/" + f)) << name << ": " << f;
  }
  // The euroc export's ground truth came from its own data.csv, not the KITTI-side files.
  EurocReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(Export(DatasetFormat::kEuroc), &error)) << error;
  EXPECT_THAT(reader.ground_truth_path(), HasSubstr("mav0/state_groundtruth_estimate0/data.csv"));
}

TEST_F(EvalTest, CommandPrintsTheRunTableAndWritesTheDefaultFolder) {
  const std::string data = Copy(DatasetFormat::kTum);
  const std::string cwd = fs::current_path().string();
  fs::current_path(dir_);
  const CommandResult r = RunVobench("eval --dataset " + data + " --format tum -q --no-plots");
  fs::current_path(cwd);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("(tum layout)"));
  EXPECT_THAT(r.output, HasSubstr("ground truth    " + data + "/groundtruth.txt: " +
                                  std::to_string(run_->metrics.frames) + " of " +
                                  std::to_string(run_->metrics.frames) + " frames associated"));
  EXPECT_THAT(r.output, HasSubstr("end-pose error"));
  EXPECT_THAT(r.output, HasSubstr("ATE RMSE"));
  EXPECT_TRUE(fs::exists(dir_ / "out/eval/data/metrics.json"));
  ExpectSameAccuracy(ReadJson((dir_ / "out/eval/data/metrics.json").string()),
                     ReadJson(RunDir() + "/metrics.json"), "cli");
  // `vobench run --dataset` keeps reading the KITTI layout.
  const std::string kitti_run = (dir_ / "kitti_run").string();
  const CommandResult k =
      RunVobench("run --dataset " + data + " --out " + kitti_run + " -q --no-plots --max-frames 4");
  ASSERT_EQ(k.exit_code, 0) << k.output;
  EXPECT_EQ(ReadJson(kitti_run + "/metrics.json")["frames"], 4);
}

TEST_F(EvalTest, GroundTruthAtAnotherRateCoveringPartOfTheFrames) {
  // A TUM ground truth at 3x the frame rate: the true pose 4 ms after each of the first 60 % of
  // the frames, poses far off in between (33 ms from every frame, so never associated), nothing
  // after. Metrics must be those of the associated frames only.
  const std::string data = Copy(DatasetFormat::kTum);
  std::vector<StampedPose> gt, est;
  std::string error;
  ASSERT_TRUE(ReadTum(RunDir() + "/groundtruth_world_tum.txt", &gt, &error)) << error;
  ASSERT_TRUE(ReadTum(RunDir() + "/trajectory_world_tum.txt", &est, &error)) << error;
  const size_t n = gt.size(), covered = n * 6 / 10;
  const double period_s = gt[1].time_s - gt[0].time_s;
  std::vector<StampedPose> fast;
  for (size_t i = 0; i < covered; ++i) {
    for (int k = 0; k < 3; ++k) {
      StampedPose p = gt[i];
      // On the export's clock: the simulator's time on the render's epoch (writer.h).
      p.time_s = kSimulationEpochNs * 1e-9 + gt[i].time_s + 0.004 + k * period_s / 3.0;
      if (k > 0) p.T_world_cam.translation() += Eigen::Vector3d(100.0, 0, 0);  // never used
      fast.push_back(p);
    }
  }
  ASSERT_TRUE(WriteTum(data + "/gt_fast.txt", fast, &error)) << error;
  EvalOptions options;
  options.format = DatasetFormat::kTum;
  options.gt_path = data + "/gt_fast.txt";
  RunSummary s;
  EvalInfo info;
  ASSERT_TRUE(EvalDataset(data, options, vo::OdometryOptions(), QuietRun(Out()), &s, &info, &error))
      << error;
  EXPECT_EQ(info.ground_truth_frames, covered);
  EXPECT_EQ(s.ground_truth_frames, static_cast<int>(covered));
  EXPECT_EQ(s.metrics.frames, static_cast<int>(n));  // every frame ran
  // The known answer: the metrics of the first `covered` frames of the full run.
  std::vector<Eigen::Isometry3d> e, g;
  for (size_t i = 0; i < covered; ++i) {
    e.push_back(est[i].T_world_cam);
    g.push_back(gt[i].T_world_cam);
  }
  const TrajectoryMetrics expected = ComputeTrajectoryMetrics(e, g);
  const nlohmann::json j = ReadJson(Out() + "/metrics.json");
  EXPECT_EQ(j["ground_truth_frames"], covered);
  EXPECT_NEAR(j["ate_rmse_m"].get<double>(), expected.ate_rmse_m, kMetricTolerance);
  EXPECT_NEAR(j["end_pose_error_m"].get<double>(), expected.end_pose_error_m, kMetricTolerance);
  EXPECT_NEAR(j["path_length_m"].get<double>(), expected.path_length_m, kMetricTolerance);
  // The run folder's ground truth holds the associated frames only; the per-frame log all.
  std::vector<StampedPose> written;
  ASSERT_TRUE(ReadTum(Out() + "/groundtruth_world_tum.txt", &written, &error)) << error;
  EXPECT_EQ(written.size(), covered);
  EXPECT_FALSE(fs::exists(Out() + "/groundtruth_kitti.txt"));  // would not line up
  const std::string csv = ReadAll(Out() + "/per_frame.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), static_cast<long>(n) + 1);
  EXPECT_THAT(csv, HasSubstr(",nan,nan,nan,"));  // frames without ground truth
}

TEST_F(EvalTest, KittiWithAGroundTruthFileInTumOrKittiFormat) {
  const std::string data = Copy(DatasetFormat::kTum);
  EvalOptions options;
  options.format = DatasetFormat::kKitti;
  // The left camera in the world, TUM format, on times.txt's clock (the TUM layout's
  // groundtruth.txt less the render's epoch).
  std::vector<StampedPose> gt;
  std::string error;
  ASSERT_TRUE(ReadTum(data + "/groundtruth.txt", &gt, &error)) << error;
  for (StampedPose& p : gt) p.time_s -= kSimulationEpochNs * 1e-9;
  options.gt_path = data + "/groundtruth_from_0.txt";
  ASSERT_TRUE(WriteTum(options.gt_path, gt, &error)) << error;
  RunSummary s;
  EvalInfo info;
  ASSERT_TRUE(EvalDataset(data, options, vo::OdometryOptions(), QuietRun(Out()), &s, &info, &error))
      << error;
  EXPECT_EQ(info.ground_truth_path, data + "/groundtruth_from_0.txt");
  ExpectSameAccuracy(ReadJson(Out() + "/metrics.json"), ReadJson(RunDir() + "/metrics.json"), "gt");
  // The KITTI benchmark's way: poses in a file of their own (poses/NN.txt), told by 12 fields.
  fs::create_directories(data + "/poses");
  fs::rename(data + "/poses.txt", data + "/poses/00.txt");
  options.gt_path = data + "/poses/00.txt";
  ASSERT_TRUE(EvalDataset(data, options, vo::OdometryOptions(), QuietRun(Out()), &s, &info, &error))
      << error;
  EXPECT_EQ(info.ground_truth_path, data + "/poses/00.txt");
  ExpectSameAccuracy(ReadJson(Out() + "/metrics.json"), ReadJson(RunDir() + "/metrics.json"),
                     "kitti poses");
}

TEST_F(EvalTest, WithoutGroundTruthTheRunHasNoAccuracyMetrics) {
  const std::string data = Copy(DatasetFormat::kTum);
  fs::remove(data + "/groundtruth.txt");
  const CommandResult r =
      RunVobench("eval --dataset " + data + " --format tum --out " + Out() + " -q --no-plots");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("ground truth    none: trajectory and per-frame log only"));
  EXPECT_THAT(r.output, Not(HasSubstr("ATE RMSE")));
  const nlohmann::json j = ReadJson(Out() + "/metrics.json");
  EXPECT_EQ(j["has_ground_truth"], false);
  EXPECT_EQ(j["ground_truth_frames"], 0);
  EXPECT_EQ(j["frames"], run_->metrics.frames);
  for (const char* k : {"ate_rmse_m", "end_pose_error_m", "path_length_m", "drift_pct"})
    EXPECT_FALSE(j.contains(k)) << k;
  EXPECT_EQ(ReadAll(Out() + "/trajectory_kitti.txt"), ReadAll(RunDir() + "/trajectory_kitti.txt"));
  EXPECT_TRUE(fs::exists(Out() + "/per_frame.csv"));
  EXPECT_FALSE(fs::exists(Out() + "/groundtruth_world_tum.txt"));
}

// --- Bad input: a message naming the file, a non-zero exit, no run folder ----------------------

// Small synthetic datasets (random images, a moving ground truth): no simulator needed.
class EvalBadInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("vobench_eval_bad_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    vo::StereoCamera camera;
    camera.width = 160;
    camera.height = 120;
    camera.fx_px = camera.fy_px = 120.0;
    camera.cx_px = 79.5;
    camera.cy_px = 59.5;
    camera.baseline_m = 0.1;
    cv::RNG rng(3);
    for (DatasetFormat format : {DatasetFormat::kEuroc, DatasetFormat::kTum}) {
      DatasetWriter::Options options;
      options.format = format;
      options.stamp_offset_ns = kSimulationEpochNs;  // as render: stamps of one width
      DatasetWriter writer(options);
      std::string error;
      ASSERT_TRUE(writer.Open(Data(format), camera, &error)) << error;
      for (int i = 0; i < 8; ++i) {
        DatasetFrame f;
        f.time_s = 0.1 * i;
        // A random texture seen 6 px apart (disparity 6), so the VO initialises on it.
        cv::Mat wide(120, 166, CV_8UC1);
        rng.fill(wide, cv::RNG::UNIFORM, 0, 256);
        cv::GaussianBlur(wide, wide, cv::Size(3, 3), 0.8);
        f.left = wide(cv::Rect(0, 0, 160, 120)).clone();
        f.right = wide(cv::Rect(6, 0, 160, 120)).clone();
        f.has_gt = true;
        f.T_world_cam0.translation() = Eigen::Vector3d(0.0, 0.0, 0.05 * i);
        ASSERT_TRUE(writer.Add(f, &error)) << error;
      }
      ASSERT_TRUE(writer.Finish(&error)) << error;
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Data(DatasetFormat format) const {
    return (dir_ / (std::string("data_") + DatasetFormatName(format))).string();
  }
  std::string Out() const { return (dir_ / "out").string(); }

  // Runs `vobench eval ARGS --out Out() -q --no-plots`; expects failure with a message holding
  // `message` and no run folder (nor a partial one) left behind. A dataset its reader refuses
  // is bad input: exit 2 (issue #31); a frame that fails during the run: 1.
  void ExpectCliFailure(const std::string& args, const std::string& message, int exit_code = 2) {
    const CommandResult r = RunVobench("eval " + args + " --out " + Out() + " -q --no-plots");
    EXPECT_EQ(r.exit_code, exit_code) << r.output;
    EXPECT_THAT(r.output, HasSubstr(message));
    EXPECT_FALSE(fs::exists(Out())) << args;
    EXPECT_FALSE(fs::exists(Out() + ".partial")) << args;
  }

  fs::path dir_;
};

TEST_F(EvalBadInputTest, WellFormedDatasetsRun) {
  for (const char* format : {"kitti", "euroc", "tum"}) {
    const std::string data =
        Data(std::string(format) == "tum" ? DatasetFormat::kTum : DatasetFormat::kEuroc);
    const CommandResult r = RunVobench("eval --dataset " + data + " --format " + format +
                                       " --out " + Out() + " -q --no-plots");
    EXPECT_EQ(r.exit_code, 0) << format << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr("8 of 8 frames associated")) << format;
  }
}

// rig.yaml beside a dataset (vobench render writes it): its forward distance becomes the
// sequence's axle (a ground-vehicle run takes it, vo::ResolvePlatform); without it the rig is
// unknown. RigYaml's text reads back exactly.
TEST_F(EvalBadInputTest, RigFileGivesTheAxleAndThePitch) {
  EvalOptions options;
  options.format = DatasetFormat::kKitti;
  const std::string data = Data(DatasetFormat::kTum);
  StereoSequence sequence;
  EvalInfo info;
  std::string error;
  ASSERT_TRUE(OpenDataset(data, options, &sequence, &info, &error)) << error;
  EXPECT_EQ(sequence.axle_behind_camera_m, -1.0);
  EXPECT_TRUE(std::isnan(sequence.camera_pitch_deg));
  RigMounting rig;
  rig.forward_m = 0.1234567890123;
  rig.height_m = 0.4;
  rig.pitch_deg = -7.5;
  WriteText(data + "/rig.yaml", RigYaml(rig));
  ASSERT_TRUE(OpenDataset(data, options, &sequence, &info, &error)) << error;
  EXPECT_EQ(sequence.axle_behind_camera_m, rig.forward_m);
  EXPECT_EQ(sequence.camera_pitch_deg, rig.pitch_deg);
  RigMounting back;
  ASSERT_TRUE(ReadRigYaml(data + "/rig.yaml", &back, &error)) << error;
  EXPECT_EQ(back.forward_m, rig.forward_m);
  EXPECT_EQ(back.height_m, rig.height_m);
  EXPECT_EQ(back.pitch_deg, rig.pitch_deg);
}

// End to end: a ground-vehicle run on a dataset with rig.yaml records the rig's axle in its
// vo_options.yaml; an axle the configuration gives is kept.
TEST_F(EvalBadInputTest, GroundVehicleRunTakesTheRigFilesAxle) {
  const std::string data = Data(DatasetFormat::kTum);
  WriteText(data + "/rig.yaml",
            "camera_forward_m: 0.2\ncamera_height_m: 0.4\ncamera_pitch_deg: 0\n");
  const std::string config = (dir_ / "gv.yaml").string();
  for (const char* axle : {"", "  axle_behind_camera_m: 0.05\n"}) {
    WriteText(config, std::string("vehicle:\n  enabled: true\n") + axle);
    const CommandResult r = RunVobench("eval --dataset " + data + " --format kitti --config " +
                                       config + " --out " + Out() + " -q --no-plots");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(ReadAll(Out() + "/vo_options.yaml"),
                HasSubstr(std::string("axle_behind_camera_m: ") + (*axle ? "0.05" : "0.2")));
  }
}

// End to end: platform auto (no configuration) runs a dataset with rig.yaml as a ground vehicle
// with the rig's axle, one without it free; `platform: free` keeps the 6-DoF VO on a rig.
// metrics.json, vo_options.yaml and the printed table say which.
TEST_F(EvalBadInputTest, PlatformAutoFollowsTheRigFile) {
  const std::string data = Data(DatasetFormat::kTum);
  const std::string free_config = (dir_ / "free.yaml").string();
  WriteText(free_config, "platform: free\n");
  const struct {
    bool rig;
    std::string config;
    std::string platform;
  } cases[] = {{false, "", "free"}, {true, "", "ground_vehicle"}, {true, free_config, "free"}};
  for (const auto& c : cases) {
    if (c.rig)
      WriteText(data + "/rig.yaml",
                "camera_forward_m: 0.2\ncamera_height_m: 0.4\ncamera_pitch_deg: 0\n");
    const CommandResult r = RunVobench("eval --dataset " + data + " --format kitti" +
                                       (c.config.empty() ? "" : " --config " + c.config) +
                                       " --out " + Out() + " -q --no-plots");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("platform        " + c.platform)) << c.platform;
    EXPECT_EQ(ReadJson(Out() + "/metrics.json")["platform"], c.platform);
    const std::string options = ReadAll(Out() + "/vo_options.yaml");
    EXPECT_THAT(options, HasSubstr("platform: " + c.platform));
    const bool vehicle = c.platform == "ground_vehicle";
    EXPECT_THAT(options, HasSubstr(std::string("flat_floor:\n    enabled: ") +
                                   (vehicle ? "true" : "false")));
    EXPECT_THAT(options,
                HasSubstr(std::string("axle_behind_camera_m: ") + (vehicle ? "0.2" : "0")));
  }
}

// A malformed rig.yaml stops the run with a message naming it and the problem.
TEST_F(EvalBadInputTest, MalformedRigFile) {
  const std::string data = Data(DatasetFormat::kTum);
  const std::string rig = data + "/rig.yaml";
  const std::string ok_rest = "camera_height_m: 0.4\ncamera_pitch_deg: 0\n";
  const std::pair<std::string, std::string> cases[] = {
      {"[1, 2]\n", "1: expected a mapping"},
      {"camera_forward_m: [\n", "2: malformed YAML"},
      {"camera_height_m: 0.4\ncamera_pitch_deg: 0\n",
       "1: key 'camera_forward_m': required: a number"},
      {"camera_forward_m: ahead\n" + ok_rest,
       "1: key 'camera_forward_m': expected a number, got 'ahead'"},
      {"camera_forward_m: 0.15\naxle_m: 0.1\n" + ok_rest, "2: key 'axle_m': unknown key"},
      {"camera_forward_m: .nan\n" + ok_rest, "1: key 'camera_forward_m': expected a finite number"},
      {"camera_forward_m: 0.15\ncamera_height_m: -0.4\ncamera_pitch_deg: 0\n",
       "2: key 'camera_height_m': must be > 0"},
      {"camera_forward_m: 0.15\ncamera_height_m: 0.4\ncamera_pitch_deg: 95\n",
       "3: key 'camera_pitch_deg': must be in (-90, 90)"}};
  for (const auto& [text, why] : cases) {
    WriteText(rig, text);
    ExpectCliFailure("--dataset " + data + " --format kitti", rig + ":" + why);
  }
}

TEST_F(EvalBadInputTest, KittiMissingCalibrationOrFewerPoses) {
  const std::string data = Data(DatasetFormat::kTum);
  std::vector<Eigen::Isometry3d> poses;
  std::string error;
  ASSERT_TRUE(ReadKittiPoses(data + "/poses.txt", &poses, &error)) << error;
  poses.pop_back();
  ASSERT_TRUE(WriteKittiPoses(data + "/poses.txt", poses, &error)) << error;
  ExpectCliFailure("--dataset " + data + " --format kitti",
                   data + "/poses.txt: has 7 poses but " + data + "/times.txt lists 8 frames");
  fs::remove(data + "/calib.txt");
  ExpectCliFailure("--dataset " + data + " --format kitti", data + "/calib.txt: file not found");
}

TEST_F(EvalBadInputTest, UnreadableImageInTheMiddleLeavesNoRunFolder) {
  // Open() checks only that the files exist: the broken frame is met during the run.
  const std::string data = Data(DatasetFormat::kTum);
  WriteText(data + "/image_1/000005.png", "not a png");
  ExpectCliFailure("--dataset " + data + " --format kitti",
                   data + "/image_1/000005.png: cannot decode the image", 1);
}

TEST_F(EvalBadInputTest, EurocMissingOrBadCalibration) {
  const std::string data = Data(DatasetFormat::kEuroc);
  std::string yaml = ReadAll(data + "/mav0/cam1/sensor.yaml");
  const size_t at = yaml.find("intrinsics: [");
  ASSERT_NE(at, std::string::npos);
  const size_t start = at + std::string("intrinsics: [").size();
  yaml.replace(start, yaml.find(',', start) - start, ".nan");  // fu = NaN
  WriteText(data + "/mav0/cam1/sensor.yaml", yaml);
  ExpectCliFailure("--dataset " + data + " --format euroc", data + "/mav0/cam1/sensor.yaml:");
  ExpectCliFailure("--dataset " + data + " --format euroc",
                   "key 'intrinsics[0]': expected a finite number, got .nan");
  fs::remove(data + "/mav0/cam0/sensor.yaml");
  ExpectCliFailure("--dataset " + data + " --format euroc",
                   data + "/mav0/cam0/sensor.yaml: file not found");
}

TEST_F(EvalBadInputTest, TumImagesOfDifferentSizesOrMissingList) {
  const std::string data = Data(DatasetFormat::kTum);
  const std::string right0 = data + "/right/1767225600.000000000.png";
  ASSERT_TRUE(fs::exists(right0));
  cv::imwrite(right0, cv::Mat::zeros(100, 160, CV_8UC1));
  ExpectCliFailure("--dataset " + data + " --format tum",
                   right0 + ": size 160x100 differs from the left image's 160x120");
  fs::remove(data + "/left.txt");
  ExpectCliFailure("--dataset " + data + " --format tum", data + "/left.txt: file not found");
}

TEST_F(EvalBadInputTest, BadArguments) {
  const std::string data = Data(DatasetFormat::kTum);
  ExpectCliFailure("--dataset " + data + " --format asl",
                   "--format: expected kitti, euroc, tum or rosbag", 2);
  ExpectCliFailure("--dataset " + data + " --format tum --max-difference -1",
                   "--max-difference: expected seconds > 0", 2);
  ExpectCliFailure("--dataset " + data + " --format tum --gt " + (dir_ / "none.txt").string(),
                   (dir_ / "none.txt").string() + ": file not found");
  ExpectCliFailure("--dataset " + (dir_ / "nowhere").string() + " --format euroc",
                   (dir_ / "nowhere").string() + ": dataset folder not found");
  WriteText((dir_ / "vo.yaml").string(), "tracker.matcher:\n  typo: 1\n");
  ExpectCliFailure("--dataset " + data + " --format tum --config " + (dir_ / "vo.yaml").string(),
                   (dir_ / "vo.yaml").string() + ":2", 2);
  // A ground truth on another clock: nothing associates.
  std::vector<StampedPose> gt(2);
  gt[1].time_s = 1.0;
  for (StampedPose& p : gt) p.time_s += 1000.0;
  std::string error;
  ASSERT_TRUE(WriteTum((dir_ / "late.txt").string(), gt, &error)) << error;
  ExpectCliFailure("--dataset " + data + " --format tum --gt " + (dir_ / "late.txt").string(),
                   (dir_ / "late.txt").string() + ": no ground-truth pose within 0.02 s");
}

}  // namespace
}  // namespace harness
