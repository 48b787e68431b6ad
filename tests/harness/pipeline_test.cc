// The run pipeline's steps on their own: RunFrames (frame stride, max frames, records),
// Summarize on crafted records with exact answers (counts, medians, metrics, the bad start)
// and the per-frame log of the run folder.
#include "harness/pipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "harness/run_folder.h"
#include "tests/sim/sim_test_util.h"
#include "tests/vo/vo_test_util.h"

namespace {

using harness::FrameRecord;
using harness::RunRecords;
using harness::RunSummary;

// `n` black frames of the test camera 0.1 s apart, ground truth moving 0.1 m along z per frame.
harness::FrameSource BlackFrames(int n, int* given) {
  const vo::StereoCamera cam = vo::test::TestCamera();
  return [n, given, cam](harness::DatasetFrame* f, std::string*) {
    if (*given >= n) return false;
    f->time_s = 0.1 * *given;
    f->left = cv::Mat::zeros(cam.height, cam.width, CV_8UC1);
    f->right = cv::Mat::zeros(cam.height, cam.width, CV_8UC1);
    f->has_gt = true;
    f->T_world_cam0 = Eigen::Isometry3d::Identity();
    f->T_world_cam0.translation() = Eigen::Vector3d(0, 0, 0.1 * *given);
    ++*given;
    return true;
  };
}

TEST(PipelineTest, RunFramesTakesEveryKthFrameUpToMaxFrames) {
  vo::StereoOdometry odometry(vo::test::TestCamera(), vo::OdometryOptions());
  int given = 0;
  harness::RunFramesOptions options;
  options.progress = false;
  options.frame_stride = 3;
  options.max_frames = 8;  // source frames 0..7: the VO sees 0, 3, 6
  RunRecords records;
  std::string error;
  ASSERT_TRUE(
      harness::RunFrames("black", BlackFrames(20, &given), odometry, options, &records, &error))
      << error;
  ASSERT_EQ(records.frames.size(), 3u);
  EXPECT_EQ(given, 8);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(records.frames[i].source_index, static_cast<int64_t>(3 * i));
    EXPECT_DOUBLE_EQ(records.frames[i].time_s, 0.3 * i);
    EXPECT_TRUE(records.frames[i].has_gt);
    EXPECT_DOUBLE_EQ(records.frames[i].T_world_cam0_gt.translation().z(), 0.3 * i);
    EXPECT_EQ(records.frames[i].result.status, vo::TrackingStatus::kLost);  // black: no features
  }
  EXPECT_EQ(records.frame_stride, 3);
  // A VO that never initialised has no summary, and the message says so.
  RunSummary summary;
  EXPECT_FALSE(harness::Summarize(records, &summary, &error));
  EXPECT_NE(error.find("black: the VO never initialised on any of the 3 frames"), std::string::npos)
      << error;
}

TEST(PipelineTest, RunFramesRefusesAStrideBelowOne) {
  vo::StereoOdometry odometry(vo::test::TestCamera(), vo::OdometryOptions());
  int given = 0;
  harness::RunFramesOptions options;
  options.frame_stride = 0;
  RunRecords records;
  std::string error;
  EXPECT_FALSE(
      harness::RunFrames("x", BlackFrames(3, &given), odometry, options, &records, &error));
  EXPECT_EQ(error, "frame stride must be >= 1, got 0");
}

// Records of a crafted run: 2 frames before the VO initialised, then 6 frames whose estimate
// equals the ground truth (1 m steps along x, 1 s apart), one of them lost and re-initialised.
RunRecords CraftedRecords() {
  RunRecords r;
  r.name = "crafted";
  for (int i = 0; i < 8; ++i) {
    FrameRecord f;
    f.source_index = i;
    f.time_s = i;
    f.has_gt = true;
    f.T_world_cam0_gt.translation() = Eigen::Vector3d(i, 0, 0);
    vo::OdometryResult& res = f.result;
    res.time_s = i;
    res.T_world_cam0 = f.T_world_cam0_gt;
    res.times.total_ms = 10.0 * i;  // medians over frames 3..7 (the first initialised excluded)
    res.times.detect_ms = i;
    res.num_features_with_depth = 100 + i;
    res.num_inliers = 50 + i;
    if (i < 2) {
      res.status = vo::TrackingStatus::kLost;
      res.bridge_aligned = true;  // not counted: before the first initialised frame
    } else if (i == 2) {
      res.status = vo::TrackingStatus::kInitializing;
    } else if (i == 5) {
      res.status = vo::TrackingStatus::kRecovered;
      res.reinitialised = true;
      res.bridge_aligned = true;  // counted: a lost frame whose bridge was measured
    } else {
      res.status = vo::TrackingStatus::kTracking;
      res.motion_measured = true;
    }
    r.frames.push_back(f);
  }
  return r;
}

TEST(PipelineTest, SummarizeCountsAndMediansOfACraftedRunAreExact) {
  const RunRecords records = CraftedRecords();
  EXPECT_EQ(harness::FirstInitialisedFrame(records), 2u);
  RunSummary s;
  std::string error;
  ASSERT_TRUE(harness::Summarize(records, &s, &error)) << error;
  EXPECT_EQ(s.name, "crafted");
  EXPECT_EQ(s.frames_not_initialised, 2);
  EXPECT_EQ(s.metrics.frames, 6);
  EXPECT_EQ(s.lost_frames, 1);  // frame 5: no measured motion
  EXPECT_EQ(s.reinitialisations, 1);
  EXPECT_EQ(s.bridge_aligned_frames, 1);
  EXPECT_TRUE(s.has_ground_truth);
  EXPECT_EQ(s.ground_truth_frames, 6);
  EXPECT_DOUBLE_EQ(s.metrics.path_length_m, 5.0);
  EXPECT_NEAR(s.metrics.end_pose_error_m, 0.0, 1e-12);
  EXPECT_NEAR(s.metrics.ate_rmse_m, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.vo_ms_median, 50.0);  // 30, 40, 50, 60, 70
  EXPECT_DOUBLE_EQ(s.stage_ms_median.at("detect"), 5.0);
  EXPECT_DOUBLE_EQ(s.features_median, 104.0);  // 102..107, first included; nearest rank
  EXPECT_DOUBLE_EQ(s.inliers_median, 55.0);    // 53..57
}

TEST(PipelineTest, SummarizeUsesOnlyTheFramesWithGroundTruth) {
  RunRecords records = CraftedRecords();
  records.frames[7].has_gt = false;
  records.frames[7].result.T_world_cam0.translation().x() += 3.0;  // not compared
  RunSummary s;
  std::string error;
  ASSERT_TRUE(harness::Summarize(records, &s, &error)) << error;
  EXPECT_EQ(s.ground_truth_frames, 5);
  EXPECT_DOUBLE_EQ(s.metrics.path_length_m, 4.0);
  EXPECT_NEAR(s.metrics.end_pose_error_m, 0.0, 1e-12);
  records.frames.resize(4);  // 2 not initialised + 2
  for (auto& f : records.frames) f.has_gt = false;
  ASSERT_TRUE(harness::Summarize(records, &s, &error)) << error;
  EXPECT_FALSE(s.has_ground_truth);
  records.frames.resize(3);  // 1 frame after the bad start
  EXPECT_FALSE(harness::Summarize(records, &s, &error));
  EXPECT_EQ(error, "crafted: fewer than 2 frames after the first 2 (not initialised)");
}

TEST(PipelineTest, PerFrameCsvMarksTheFramesBeforeTheFirstInitialisedOne) {
  const RunRecords records = CraftedRecords();
  RunSummary s;
  std::string error;
  ASSERT_TRUE(harness::Summarize(records, &s, &error)) << error;
  std::istringstream csv(harness::PerFrameCsv(records, s));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("frame,time_s,status,", 0), 0u);
  std::vector<std::string> statuses;
  while (std::getline(csv, line)) {
    std::stringstream fields(line);
    std::string frame, time, status;
    std::getline(fields, frame, ',');
    std::getline(fields, time, ',');
    std::getline(fields, status, ',');
    EXPECT_EQ(frame, std::to_string(statuses.size()));
    statuses.push_back(status);
  }
  ASSERT_EQ(statuses.size(), 8u);
  EXPECT_EQ(statuses[0], "not_initialised");
  EXPECT_EQ(statuses[1], "not_initialised");
  EXPECT_EQ(statuses[2], vo::ToString(vo::TrackingStatus::kInitializing));
  EXPECT_EQ(statuses[5], vo::ToString(vo::TrackingStatus::kRecovered));
}

// platform auto: a sequence that knows its rig's axle (a simulated robot, a dataset with
// rig.yaml) runs as a ground vehicle with that axle; an unknown rig runs free with the options
// as given. free keeps the options (a ground vehicle set by hand still takes the rig's axle when
// its own is left at 0); ground_vehicle switches the vehicle options on without a rig too.
TEST(PipelineTest, PlatformAutoIsAGroundVehicleOnAKnownRig) {
  vo::OdometryOptions o;
  ASSERT_EQ(o.platform, vo::Platform::kAuto);
  const vo::OdometryOptions known = vo::ResolvePlatform(o, 0.15);
  EXPECT_EQ(known.platform, vo::Platform::kGroundVehicle);
  EXPECT_TRUE(known.motion.few_point_motion && known.motion.ground_vehicle &&
              known.back_end.vehicle_planar.enabled && known.back_end.flat_floor.enabled);
  EXPECT_EQ(known.motion.few_point.axle_behind_camera_m, 0.15);
  const vo::OdometryOptions unknown = vo::ResolvePlatform(o, -1.0);
  EXPECT_EQ(unknown.platform, vo::Platform::kFree);
  EXPECT_FALSE(unknown.motion.few_point_motion || unknown.motion.ground_vehicle ||
               unknown.back_end.vehicle_planar.enabled || unknown.back_end.flat_floor.enabled);
  EXPECT_EQ(unknown.motion.few_point.axle_behind_camera_m, 0.0);

  o.platform = vo::Platform::kFree;
  const vo::OdometryOptions free_on_rig = vo::ResolvePlatform(o, 0.15);
  EXPECT_EQ(free_on_rig.platform, vo::Platform::kFree);
  EXPECT_FALSE(free_on_rig.motion.ground_vehicle || free_on_rig.motion.few_point_motion);
  EXPECT_EQ(free_on_rig.motion.few_point.axle_behind_camera_m, 0.0);
  o.motion.ground_vehicle = true;  // by hand, on the free platform
  EXPECT_EQ(vo::ResolvePlatform(o, 0.15).motion.few_point.axle_behind_camera_m, 0.15);
  EXPECT_FALSE(vo::ResolvePlatform(o, 0.15).back_end.flat_floor.enabled);
  EXPECT_EQ(vo::ResolvePlatform(o, -1.0).motion.few_point.axle_behind_camera_m, 0.0);
  o.motion.few_point.axle_behind_camera_m = 0.05;  // given: kept
  EXPECT_EQ(vo::ResolvePlatform(o, 0.15).motion.few_point.axle_behind_camera_m, 0.05);

  vo::OdometryOptions g;
  g.platform = vo::Platform::kGroundVehicle;  // without a rig: the options on, the axle as given
  const vo::OdometryOptions forced = vo::ResolvePlatform(g, -1.0);
  EXPECT_TRUE(forced.back_end.flat_floor.enabled && forced.motion.few_point_motion);
  EXPECT_EQ(forced.motion.few_point.axle_behind_camera_m, 0.0);
}

// A ground vehicle whose rig's camera pitch is known takes its up from the mounting when the
// first frame shows no floor: initial_orientation.up_from_mounting on, expected_up_cam0 the up of
// that pitch (cv axes: y down; a camera tilted down by p sees the up as (0, −cos p, −sin p)). An
// unknown pitch, the free platform or an up given in the options change nothing of it.
TEST(PipelineTest, AGroundVehicleTakesItsUpFromTheRigsPitch) {
  vo::OdometryOptions o;
  const Eigen::Vector3d level(0.0, -1.0, 0.0);
  ASSERT_FALSE(o.initial_orientation.up_from_mounting);
  ASSERT_EQ(o.initial_orientation.planes.expected_up_cam0, level);
  const vo::OdometryOptions no_pitch = vo::ResolvePlatform(o, 0.15);
  EXPECT_FALSE(no_pitch.initial_orientation.up_from_mounting);
  EXPECT_EQ(no_pitch.initial_orientation.planes.expected_up_cam0, level);
  const vo::OdometryOptions flat = vo::ResolvePlatform(o, 0.15, 0.0);
  EXPECT_TRUE(flat.initial_orientation.up_from_mounting);
  EXPECT_EQ(flat.initial_orientation.planes.expected_up_cam0, level);
  const vo::OdometryOptions pitched = vo::ResolvePlatform(o, 0.15, 30.0);
  EXPECT_TRUE(pitched.initial_orientation.up_from_mounting);
  EXPECT_NEAR((pitched.initial_orientation.planes.expected_up_cam0 -
               Eigen::Vector3d(0.0, -std::sqrt(3.0) / 2, -0.5))
                  .norm(),
              0.0, 1e-12);
  EXPECT_FALSE(vo::ResolvePlatform(o, -1.0, 30.0).initial_orientation.up_from_mounting);  // free
  vo::OdometryOptions given = o;
  given.initial_orientation.planes.expected_up_cam0 = Eigen::Vector3d(0.0, -1.0, -0.1);
  EXPECT_EQ(vo::ResolvePlatform(given, 0.15, 30.0).initial_orientation.planes.expected_up_cam0,
            given.initial_orientation.planes.expected_up_cam0);
}

}  // namespace

namespace {

// A simulated sequence carries the IMU: each frame the samples since the previous one (250 Hz
// at 10 Hz frames: 25, the first frame the sample at time 0) with their ground truth, and the
// sequence the IMU's rate, noise numbers and cam0 in the IMU frame.
TEST(PipelineTest, ASimulatedSequenceCarriesTheImuSamplesBetweenFrames) {
  vobench_test::TempDir dir("pipeline_imu");
  sim::Scenario s = vobench_test::MakeScenario(vobench_test::WriteScene(dir, ""));
  s.camera.width = 16;
  s.camera.height = 16;
  s.imu.gyro_noise_density = 1e-3;
  harness::StereoSequence sequence;
  std::string error;
  ASSERT_TRUE(harness::OpenScenarioSequence(s, &sequence, &error)) << error;
  EXPECT_TRUE(sequence.has_imu);
  EXPECT_EQ(sequence.imu.rate_hz, 250.0);
  EXPECT_EQ(sequence.imu.gyro_noise_density, 1e-3);
  // cam0: 0.15 m ahead of the axle, 0.045 m left, 1.0 - 0.095 m above it; the IMU 0.19 m above.
  EXPECT_LT((sequence.T_imu_cam0.translation() - Eigen::Vector3d(0.15, 0.045, 0.715)).norm(),
            1e-12);
  harness::DatasetFrame f;
  double last = -1.0;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(sequence.next(&f, &error)) << error;
    ASSERT_EQ(f.imu.size(), k == 0 ? 1u : 25u) << k;
    EXPECT_GT(f.imu.front().time_s, last);
    EXPECT_NEAR(f.imu.back().time_s, f.time_s, 1e-12);
    EXPECT_TRUE(f.imu.back().has_gt);
    // The IMU's ground-truth pose and cam0's agree through T_imu_cam0.
    EXPECT_TRUE((f.imu.back().T_world_imu * sequence.T_imu_cam0).isApprox(f.T_world_cam0, 1e-9));
    last = f.imu.back().time_s;
  }
}

}  // namespace
