// Real EuRoC data (../shared/data/euroc_v101_clip, skipped when absent): rectification from the
// sensor.yaml calibration, a standing-still run through `eval`, and one real odometry step on
// the moving pairs against the Vicon ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "harness/dataset.h"
#include "harness/eval.h"
#include "harness/metrics.h"
#include "tests/sim/sim_test_util.h"
#include "tests/test_util.h"
#include "vo/odometry.h"

namespace harness {
namespace {

namespace fs = std::filesystem;
using vobench_test::TempDir;

const std::string kClip = std::string(VOBENCH_SHARED_DATA_DIR) + "/euroc_v101_clip";

// Measured on the clip: median |dy| 0.12-0.13 px after rectification, 12.9 px before; 0.5 px is
// what the issue asks for.
constexpr double kMaxMedianRectifiedDyPx = 0.5;
constexpr double kMinMedianRawDyPx = 1.0;  // the raw pair is visibly off: the test can tell
// Standing still (the ground truth moves ~6 mm in 1 s, mostly Vicon noise): the estimate must
// stay this close to its start. Measured: 3.5 mm at most, ATE 1.1 mm, no frame lost.
constexpr double kMaxStandStillDisplacementM = 0.03;
constexpr double kMaxStandStillAteM = 0.01;
constexpr int kMaxStandStillLostFrames = 1;

#define SKIP_WITHOUT_CLIP() \
  if (!fs::is_directory(kClip)) GTEST_SKIP() << kClip << " not found: skipped"

// Median |dy| of SIFT matches (ratio test + mutual) between a left and a right image, over
// matches with a plausible disparity (0..120 px, x_left >= x_right).
double MedianMatchDy(const cv::Mat& left, const cv::Mat& right, int* num_matches) {
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(1000);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  sift->detectAndCompute(left, cv::noArray(), kl, dl);
  sift->detectAndCompute(right, cv::noArray(), kr, dr);
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> lr, rl;
  matcher.knnMatch(dl, dr, lr, 2);
  matcher.knnMatch(dr, dl, rl, 1);
  std::vector<double> dy;
  for (const auto& m : lr) {
    if (m.size() < 2 || m[0].distance > 0.7f * m[1].distance) continue;
    if (rl[m[0].trainIdx].empty() || rl[m[0].trainIdx][0].trainIdx != m[0].queryIdx) continue;
    const cv::Point2f a = kl[m[0].queryIdx].pt, b = kr[m[0].trainIdx].pt;
    const double disparity = a.x - b.x;
    if (disparity < 0.0 || disparity > 120.0) continue;
    dy.push_back(std::abs(a.y - b.y));
  }
  *num_matches = static_cast<int>(dy.size());
  return Median(dy);
}

TEST(EurocClipTest, RectificationAlignsRowsOfTheRealPair) {
  SKIP_WITHOUT_CLIP();
  EurocReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(kClip, &error)) << error;
  ASSERT_EQ(reader.size(), 20u);
  StereoRectification r;
  ASSERT_TRUE(reader.Rectification(&r, &error)) << error;
  ASSERT_FALSE(r.IsIdentity());
  // Baseline ~11 cm; the rectified focal length a little below the raw 457 px (alpha 0 zooms in).
  EXPECT_NEAR(r.camera.baseline_m, 0.110, 0.002);
  EXPECT_GT(r.camera.fx_px, 400.0);
  EXPECT_LT(r.camera.fx_px, 458.0);
  // alpha 0: every rectified pixel samples inside the raw images (no black border).
  for (const cv::Mat* map : {&r.map0_x, &r.map1_x, &r.map0_y, &r.map1_y}) {
    double lo, hi;
    cv::minMaxLoc(*map, &lo, &hi);
    EXPECT_GE(lo, 0.0);
    EXPECT_LE(hi, (map == &r.map0_x || map == &r.map1_x) ? 751.0 : 479.0);
  }
  for (size_t i : {size_t{0}, size_t{10}, size_t{19}}) {
    DatasetFrame frame;
    ASSERT_TRUE(reader.ReadFrame(i, &frame, &error)) << error;
    int raw_n = 0, rect_n = 0;
    const double raw_dy = MedianMatchDy(frame.left, frame.right, &raw_n);
    RectifyFrame(r, &frame);
    const double rect_dy = MedianMatchDy(frame.left, frame.right, &rect_n);
    std::printf("frame %zu: median |dy| %.3f px over %d matches rectified (raw: %.3f px, %d)\n", i,
                rect_dy, rect_n, raw_dy, raw_n);
    EXPECT_GE(rect_n, 100);
    EXPECT_LT(rect_dy, kMaxMedianRectifiedDyPx);
    EXPECT_GT(raw_dy, kMinMedianRawDyPx);
  }
}

TEST(EurocClipTest, StandingStillRunStaysAtItsStart) {
  SKIP_WITHOUT_CLIP();
  TempDir dir("euroc_clip");
  EvalOptions options;
  options.format = DatasetFormat::kEuroc;
  RunOptions run;
  run.out_dir = dir / "run";
  run.progress = false;
  run.plots = false;
  RunSummary s;
  EvalInfo info;
  std::string error;
  ASSERT_TRUE(EvalDataset(kClip, options, vo::OdometryOptions(), run, &s, &info, &error)) << error;
  EXPECT_TRUE(info.rectified);
  EXPECT_EQ(fs::path(info.ground_truth_path).filename(), "groundtruth_tum.txt");
  EXPECT_EQ(info.ground_truth_frames, 20u);
  EXPECT_EQ(s.metrics.frames, 20);
  EXPECT_EQ(s.ground_truth_frames, 20);
  ASSERT_TRUE(s.has_ground_truth);
  EXPECT_LE(s.lost_frames, kMaxStandStillLostFrames);
  // The estimate, from the run folder: finite and near the first pose all along.
  std::vector<StampedPose> est;
  ASSERT_TRUE(ReadTum(run.out_dir + "/trajectory_world_tum.txt", &est, &error)) << error;
  ASSERT_EQ(est.size(), 20u);
  double max_displacement_m = 0.0;
  for (const StampedPose& p : est) {
    ASSERT_TRUE(p.T_world_cam.matrix().allFinite());
    max_displacement_m =
        std::max(max_displacement_m,
                 (p.T_world_cam.translation() - est[0].T_world_cam.translation()).norm());
  }
  std::printf(
      "standing still: max displacement %.4f m, end-pose error %.4f m, ATE %.4f m, "
      "ground-truth path %.4f m, lost %d\n",
      max_displacement_m, s.metrics.end_pose_error_m, s.metrics.ate_rmse_m, s.metrics.path_length_m,
      s.lost_frames);
  EXPECT_LE(max_displacement_m, kMaxStandStillDisplacementM);
  EXPECT_LE(s.metrics.ate_rmse_m, kMaxStandStillAteM);
  EXPECT_LE(s.metrics.end_pose_error_m, kMaxStandStillDisplacementM);
}

// The real gyro (imu0: ADIS16448, 200 Hz) with the gyro prior on (issue #35). The reader gives the
// VO the rectified left camera's mounting on the IMU (cam0's T_BS turned by the rectification),
// and standing still the estimate turns as the ground truth does: at every frame the rotation
// since the first frame is within kMaxGyroStandStillRotationDeg of the ground truth's.
constexpr double kMaxGyroStandStillRotationDeg = 0.2;

double RotationSinceFirstErrorDeg(const std::vector<StampedPose>& est,
                                  const std::vector<StampedPose>& gt, size_t k) {
  const Eigen::Matrix3d e = est[0].T_world_cam.linear().transpose() * est[k].T_world_cam.linear();
  const Eigen::Matrix3d g = gt[0].T_world_cam.linear().transpose() * gt[k].T_world_cam.linear();
  return Eigen::AngleAxisd(e.transpose() * g).angle() * 180.0 / M_PI;
}

TEST(EurocClipTest, StandingStillWithTheRealGyroTurnsAsTheGroundTruth) {
  SKIP_WITHOUT_CLIP();
  TempDir dir("euroc_clip_gyro");
  EvalOptions options;
  options.format = DatasetFormat::kEuroc;
  StereoSequence sequence;
  EvalInfo info;
  std::string error;
  ASSERT_TRUE(OpenDataset(kClip, options, &sequence, &info, &error)) << error;
  ASSERT_TRUE(sequence.has_imu);
  ASSERT_TRUE(sequence.imu_extrinsics_known);
  EurocReader reader;
  ASSERT_TRUE(reader.Open(kClip, &error)) << error;
  StereoRectification rectification;
  ASSERT_TRUE(reader.Rectification(RectificationOptions(), &rectification, &error)) << error;
  EXPECT_LT((sequence.T_imu_cam0.linear() -
             reader.cam0().T_body_cam.linear() * rectification.R_cam0_rect0)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_EQ(sequence.T_imu_cam0.translation(), reader.cam0().T_body_cam.translation());

  // The gyro prior alone; with the window BA's rotation prior too (its default); and that
  // without the standing start: the ADIS16448's turn-on bias (0.078 rad/s about z) is then not
  // known in the clip's 0.95 s and the BA's prior turns the estimate with it (1.1°).
  struct Case {
    const char* name;
    bool ba_rotation_prior;
    double standing_start_s;
    bool within;
  };
  for (const Case& c : {Case{"gyro prior", false, 1.0, true}, Case{"and BA prior", true, 1.0, true},
                        Case{"no standing start", true, 0.0, false}}) {
    vo::OdometryOptions vo_options;
    vo_options.imu.gyro_prior = true;
    vo_options.imu.ba_rotation_prior = c.ba_rotation_prior;
    vo_options.imu.standing_start_s = c.standing_start_s;
    RunOptions run;
    run.out_dir = dir / c.name;
    run.progress = false;
    run.plots = false;
    RunSummary s;
    ASSERT_TRUE(EvalDataset(kClip, options, vo_options, run, &s, &info, &error)) << error;
    EXPECT_EQ(s.metrics.frames, 20);
    EXPECT_LE(s.lost_frames, kMaxStandStillLostFrames);
    std::ifstream options_yaml(run.out_dir + "/vo_options.yaml");
    std::stringstream recorded;
    recorded << options_yaml.rdbuf();
    EXPECT_NE(recorded.str().find("gyro_prior: true"), std::string::npos) << recorded.str();
    std::vector<StampedPose> est, gt;
    ASSERT_TRUE(ReadTum(run.out_dir + "/trajectory_world_tum.txt", &est, &error)) << error;
    ASSERT_TRUE(ReadTum(run.out_dir + "/groundtruth_world_tum.txt", &gt, &error)) << error;
    ASSERT_EQ(est.size(), 20u);
    ASSERT_EQ(gt.size(), 20u);
    double worst_deg = 0.0;
    for (size_t k = 0; k < est.size(); ++k)
      worst_deg = std::max(worst_deg, RotationSinceFirstErrorDeg(est, gt, k));
    std::printf("standing still with the gyro (%s): worst rotation error %.4f deg, ATE %.4f m\n",
                c.name, worst_deg, s.metrics.ate_rmse_m);
    if (c.within) {
      EXPECT_LE(worst_deg, kMaxGyroStandStillRotationDeg) << c.name;
      EXPECT_LE(s.metrics.ate_rmse_m, kMaxStandStillAteM) << c.name;
    } else {
      EXPECT_GT(worst_deg, 0.5) << c.name;
    }
  }
}

// --- The moving pairs: img_3 -> img_2, 0.5 s apart (img_3 is the earlier one).
//
// timestamps_and_gt.txt gives two ground truths per pair: the original EuRoC one (the clip's
// groundtruth_tum.txt comes from the same file) and OpenVINS' recomputation (vicon2gt). At all
// four pairs, spread over the sequence, they differ by the same body-frame transform: 5.6 deg
// and 4 cm (the original's Vicon-to-IMU extrinsic is known to be off in V1/V2). Rotating by
// 15.6 deg about a lever arm that is 4 cm off moves the camera ~1 cm, and the 5.6 deg tilts the
// motion's direction: against the original the VO's step is 3.9 cm / 0.32 deg off, against the
// recomputed ground truth 0.9 cm / 0.26 deg. Both are checked: the original with the issue's
// bounds, the recomputed one tighter.
constexpr double kMaxStepErrorOriginalM = 0.05;
constexpr double kMaxStepErrorOriginalDeg = 2.0;
constexpr double kMaxStepErrorRecomputedM = 0.025;
constexpr double kMaxStepErrorRecomputedDeg = 1.0;

struct MovingPair {
  cv::Mat left, right;
  double time_s = 0.0;
  Eigen::Isometry3d T_world_body_original = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_world_body_recomputed = Eigen::Isometry3d::Identity();
};

// timestamps_and_gt.txt: "left_img_N/right_img_N <t_ns>", then
// "  original: t tx ty tz qx qy qz qw" and "  openvins: t_ns,px,py,pz,qw,qx,qy,qz,...".
bool ReadMovingPair(int n, MovingPair* pair, std::string* error) {
  const std::string dir = kClip + "/moving_pairs/";
  std::ifstream in(dir + "timestamps_and_gt.txt");
  const std::string key = "left_img_" + std::to_string(n) + "/";
  std::string line;
  bool found = false;
  int rows = 0;
  while (std::getline(in, line) && rows < 2) {
    if (line.rfind("left_img_", 0) == 0) found = line.rfind(key, 0) == 0;
    const bool original = line.find("original:") != std::string::npos;
    const bool recomputed = line.find("openvins:") != std::string::npos;
    if (!found || (!original && !recomputed)) continue;
    std::string rest = line.substr(line.find(':') + 1);
    std::replace(rest.begin(), rest.end(), ',', ' ');
    std::istringstream s(rest);
    double t, x, y, z, qw, qx, qy, qz;
    if (original && !(s >> t >> x >> y >> z >> qx >> qy >> qz >> qw)) break;
    if (recomputed && !(s >> t >> x >> y >> z >> qw >> qx >> qy >> qz)) break;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, y, z);
    if (original) {
      pair->time_s = t;
      pair->T_world_body_original = T;
    } else {
      pair->T_world_body_recomputed = T;
    }
    ++rows;
  }
  pair->left = cv::imread(dir + "left_img_" + std::to_string(n) + ".png", cv::IMREAD_GRAYSCALE);
  pair->right = cv::imread(dir + "right_img_" + std::to_string(n) + ".png", cv::IMREAD_GRAYSCALE);
  if (rows == 2 && !pair->left.empty() && !pair->right.empty()) return true;
  *error = dir + ": cannot read pair " + std::to_string(n);
  return false;
}

double AngleDeg(const Eigen::Matrix3d& R) {
  return RotationAngle(Eigen::Matrix3d::Identity(), R) * 180.0 / M_PI;
}

TEST(EurocClipTest, OneRealOdometryStepMatchesTheGroundTruth) {
  SKIP_WITHOUT_CLIP();
  // The moving pairs' calibration files: the same camera, slightly different keys.
  EurocCameraCalibration cam[2];
  std::string error;
  ASSERT_TRUE(ReadEurocSensorYaml(kClip + "/moving_pairs/sensorLeft.yaml", &cam[0], &error))
      << error;
  ASSERT_TRUE(ReadEurocSensorYaml(kClip + "/moving_pairs/sensorRight.yaml", &cam[1], &error))
      << error;
  StereoRectification r;
  ASSERT_TRUE(ComputeStereoRectification(cam[0], cam[1], RectificationOptions(), &r, &error))
      << error;

  MovingPair a, b;  // img_3 (earlier), img_2 (0.5 s later)
  ASSERT_TRUE(ReadMovingPair(3, &a, &error)) << error;
  ASSERT_TRUE(ReadMovingPair(2, &b, &error)) << error;
  ASSERT_NEAR(b.time_s - a.time_s, 0.5, 1e-3);
  // Ground-truth step of the rectified left camera, T_rect0(a)_rect0(b), from either body pose.
  auto gt_step = [&](const Eigen::Isometry3d& T_world_body_a,
                     const Eigen::Isometry3d& T_world_body_b) {
    DatasetFrame fa, fb;
    fa.has_gt = fb.has_gt = true;
    fa.T_world_cam0 = T_world_body_a * cam[0].T_body_cam;
    fb.T_world_cam0 = T_world_body_b * cam[0].T_body_cam;
    fa.left = fa.right = fb.left = fb.right = a.left;  // images do not matter here
    RectifyFrame(r, &fa);
    RectifyFrame(r, &fb);
    return Eigen::Isometry3d(fa.T_world_cam0.inverse() * fb.T_world_cam0);
  };
  const Eigen::Isometry3d T_a_b_original =
      gt_step(a.T_world_body_original, b.T_world_body_original);
  const Eigen::Isometry3d T_a_b_recomputed =
      gt_step(a.T_world_body_recomputed, b.T_world_body_recomputed);
  EXPECT_NEAR(T_a_b_original.translation().norm(), 0.32, 0.01);
  EXPECT_NEAR(AngleDeg(T_a_b_original.linear()), 15.6, 0.3);

  DatasetFrame fa, fb;
  for (auto [pair, frame] : {std::pair{&a, &fa}, std::pair{&b, &fb}}) {
    frame->time_s = pair->time_s;
    frame->left = pair->left;
    frame->right = pair->right;
    RectifyFrame(r, frame);
  }
  vo::StereoOdometry odometry(r.camera, vo::OdometryOptions());
  odometry.Process(fa.left, fa.right, fa.time_s);
  const vo::OdometryResult result = odometry.Process(fb.left, fb.right, fb.time_s);
  EXPECT_EQ(result.status, vo::TrackingStatus::kTracking) << result.message;
  const Eigen::Isometry3d& T_a_b = result.T_prev_curr;
  std::printf("moving pair img_3 -> img_2: %d matches, %d inliers; estimate %.4f m %.3f deg\n",
              result.num_matches, result.num_inliers, T_a_b.translation().norm(),
              AngleDeg(T_a_b.linear()));
  for (auto [name, gt, max_m, max_deg] :
       {std::tuple{"original", &T_a_b_original, kMaxStepErrorOriginalM, kMaxStepErrorOriginalDeg},
        std::tuple{"recomputed", &T_a_b_recomputed, kMaxStepErrorRecomputedM,
                   kMaxStepErrorRecomputedDeg}}) {
    const double dt_m = (T_a_b.translation() - gt->translation()).norm();
    const double dr_deg = RotationAngle(T_a_b.linear(), gt->linear()) * 180.0 / M_PI;
    std::printf("  vs %s ground truth (%.4f m, %.3f deg): error %.4f m, %.3f deg\n", name,
                gt->translation().norm(), AngleDeg(gt->linear()), dt_m, dr_deg);
    EXPECT_LE(dt_m, max_m) << name;
    EXPECT_LE(dr_deg, max_deg) << name;
  }
}

}  // namespace
}  // namespace harness
