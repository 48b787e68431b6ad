// Simulator: the reported calibration and ground truth are the ones it renders with; the
// robot drives the paper's L through the physics; renders are deterministic.
#include "sim/simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "sim_test_util.h"
#include "tests/test_util.h"

namespace {

using vobench_test::MakeScenario;
using vobench_test::TempDir;
using vobench_test::WriteScene;

constexpr double kProjectionTolPx = 0.3;   // the bound for marker reprojection
constexpr double kMarkerDepthTolM = 0.01;  // depth of the marker's front surface vs GT
constexpr double kMarkerRadiusM = 0.03;

// Small self-lit white spheres at known world points in an otherwise black, empty scene.
const std::vector<Eigen::Vector3d> kMarkers = {{2.0, 0.0, 1.0},  {2.5, 0.6, 1.3},  {1.6, -0.5, 0.7},
                                               {3.0, -0.9, 1.5}, {2.2, 0.45, 0.6}, {1.8, 0.3, 1.25},
                                               {2.8, 0.0, 0.45}, {2.4, -0.7, 1.1}};

std::string MarkerXml() {
  std::string xml;
  for (const auto& p : kMarkers) {
    char buf[256];
    std::snprintf(buf, sizeof(buf),
                  "    <geom type='sphere' size='%g' pos='%g %g %g' material='marker' contype='0' "
                  "conaffinity='0'/>\n",
                  kMarkerRadiusM, p.x(), p.y(), p.z());
    xml += buf;
  }
  return xml;
}

// Intensity-weighted centroids of the bright blobs in `image`.
std::vector<Eigen::Vector2d> BlobCentroids(const cv::Mat& image) {
  cv::Mat mask, labels, stats, centroids;
  cv::threshold(image, mask, 5, 255, cv::THRESH_BINARY);
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
  std::vector<Eigen::Vector2d> out;
  for (int i = 1; i < n; ++i) {
    double sw = 0, su = 0, sv = 0;
    for (int r = 0; r < image.rows; ++r)
      for (int c = 0; c < image.cols; ++c)
        if (labels.at<int>(r, c) == i) {
          const double w = image.at<unsigned char>(r, c);
          sw += w;
          su += w * c;
          sv += w * r;
        }
    out.emplace_back(su / sw, sv / sw);
  }
  return out;
}

struct ProjectionCase {
  int width, height;
  double fovy_deg, pitch_deg, baseline_m;
};

void PrintTo(const ProjectionCase& c, std::ostream* os) {
  *os << c.width << "x" << c.height << " fovy " << c.fovy_deg << " pitch " << c.pitch_deg
      << " baseline " << c.baseline_m;
}

class ProjectionTest : public ::testing::TestWithParam<ProjectionCase> {};

TEST_P(ProjectionTest, MarkersLandWhereCalibrationAndPoseProjectThem) {
  const ProjectionCase pc = GetParam();
  TempDir dir("proj");
  const std::string scene =
      WriteScene(dir, MarkerXml(), "<material name='marker' rgba='1 1 1 1' emission='1'/>");
  sim::Scenario s = MakeScenario(scene);
  s.camera.width = pc.width;
  s.camera.height = pc.height;
  s.camera.fovy_deg = pc.fovy_deg;
  s.camera.pitch_deg = pc.pitch_deg;
  s.camera.baseline_m = pc.baseline_m;
  std::string error;
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  sim::StereoFrame frame;
  ASSERT_TRUE(simulator->Next(&frame, &error)) << error;
  ASSERT_EQ(frame.left.cols, pc.width);
  ASSERT_EQ(frame.left.rows, pc.height);
  const sim::StereoCalibration& cal = simulator->calibration();

  Eigen::Isometry3d T_cam0_cam1 = Eigen::Isometry3d::Identity();
  T_cam0_cam1.translation() = Eigen::Vector3d(cal.baseline_m, 0, 0);
  const Eigen::Isometry3d T_world_cam1 = frame.T_world_cam0 * T_cam0_cam1;
  int checked = 0;
  for (int cam = 0; cam < 2; ++cam) {
    const cv::Mat& image = cam == 0 ? frame.left : frame.right;
    const Eigen::Isometry3d T_cam_world = (cam == 0 ? frame.T_world_cam0 : T_world_cam1).inverse();
    const std::vector<Eigen::Vector2d> blobs = BlobCentroids(image);
    for (const auto& p_world : kMarkers) {
      const Eigen::Vector3d p = T_cam_world * p_world;
      ASSERT_GT(p.z(), 0.5);
      const Eigen::Vector2d uv(cal.fx_px * p.x() / p.z() + cal.cx_px,
                               cal.fy_px * p.y() / p.z() + cal.cy_px);
      if (uv.x() < 8 || uv.y() < 8 || uv.x() > pc.width - 9 || uv.y() > pc.height - 9) continue;
      double best = 1e9;
      for (const auto& b : blobs) best = std::min(best, (b - uv).norm());
      EXPECT_LT(best, kProjectionTolPx) << "camera " << cam << " marker " << p_world.transpose()
                                        << " projected at " << uv.transpose();
      if (cam == 0) {
        // Ground-truth depth at the marker's centre pixel: its front surface.
        const double z = frame.depth_m.at<float>(static_cast<int>(std::lround(uv.y())),
                                                 static_cast<int>(std::lround(uv.x())));
        EXPECT_NEAR(z, p.z() - kMarkerRadiusM * p.z() / p.norm(), kMarkerDepthTolM);
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 10);
}

INSTANTIATE_TEST_SUITE_P(Rigs, ProjectionTest,
                         ::testing::Values(ProjectionCase{320, 240, 55.0, 0.0, 0.09},
                                           ProjectionCase{400, 300, 60.0, 8.0, 0.12},
                                           ProjectionCase{321, 199, 45.0, -5.0, 0.3}));

TEST(SimulatorTest, RobotDrivesThePapersLPath) {
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &s, &error)) << error;
  auto simulator = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(simulator) << error;
  sim::StereoFrame frame;
  int frames = 0;
  std::vector<sim::ImuSample> imu;
  while (simulator->Next(&frame, &error)) {
    ++frames;
    imu.insert(imu.end(), frame.imu.begin(), frame.imu.end());
  }
  ASSERT_TRUE(error.empty()) << error;
  // The default IMU (ICM-20602 noise, sim/imu.h) integrated over the L: within 2 deg of the
  // ground truth's rotation (the turn is 90 deg).
  ASSERT_GT(imu.size(), 1000u);
  Eigen::Matrix3d R = imu.front().T_world_imu.linear();
  for (size_t k = 1; k < imu.size(); ++k) {
    const Eigen::Vector3d w =
        0.5 * (imu[k - 1].gyro_radps + imu[k].gyro_radps) * (imu[k].time_s - imu[k - 1].time_s);
    if (w.norm() > 0) R = R * Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  }
  const double gyro_error_deg =
      Eigen::AngleAxisd(R.transpose() * imu.back().T_world_imu.linear()).angle() * 180.0 / M_PI;
  RecordProperty("default_imu_gyro_error_deg", std::to_string(gyro_error_deg));
  EXPECT_LT(gyro_error_deg, 2.0);
  const auto& track = simulator->body_track();
  ASSERT_GT(track.size(), 100u);
  double length = 0.0;
  double corner_dist = 1e9;
  const Eigen::Vector2d corner = s.path[1];
  for (size_t i = 0; i < track.size(); ++i) {
    if (i > 0) length += (track[i] - track[i - 1]).head<2>().norm();
    corner_dist = std::min(corner_dist, (track[i].head<2>() - corner).norm());
  }
  EXPECT_NEAR(length, 16.0, 0.3);
  EXPECT_LT(corner_dist, 0.1);
  EXPECT_LT((track.back().head<2>() - s.path.back()).norm(), 0.1);
  // It really drove: the body stayed on the floor and upright, frames came at the rate.
  for (const auto& p : track) ASSERT_NEAR(p.z(), s.robot.wheel_radius_m, 0.01);
  EXPECT_NEAR(frame.time_s, (frames - 1) / s.rate_hz, 1e-9);
  EXPECT_GT(frames, 300);
}

TEST(SimulatorTest, SameScenarioAndSeedGiveIdenticalFrames) {
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &s, &error)) << error;
  s.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.6, 0)};
  s.noise.motion_blur_exposure_s = 0.03;  // every noise model on
  std::vector<sim::StereoFrame> runs[2];
  for (auto& run : runs) {
    auto simulator = sim::Simulator::Create(s, &error);
    ASSERT_TRUE(simulator) << error;
    sim::StereoFrame f;
    while (simulator->Next(&f, &error)) run.push_back(f);
    ASSERT_TRUE(error.empty()) << error;
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  ASSERT_GT(runs[0].size(), 5u);
  for (size_t i = 0; i < runs[0].size(); ++i) {
    EXPECT_EQ(cv::norm(runs[0][i].left, runs[1][i].left, cv::NORM_INF), 0) << i;
    EXPECT_EQ(cv::norm(runs[0][i].right, runs[1][i].right, cv::NORM_INF), 0) << i;
    EXPECT_EQ(cv::norm(runs[0][i].depth_m, runs[1][i].depth_m, cv::NORM_INF), 0) << i;
    EXPECT_TRUE(runs[0][i].T_world_cam0.matrix() == runs[1][i].T_world_cam0.matrix()) << i;
  }
  // Another noise seed changes the images, not the ground truth.
  s.seed = 2;
  auto simulator = sim::Simulator::Create(s, &error);
  sim::StereoFrame f;
  ASSERT_TRUE(simulator->Next(&f, &error));
  EXPECT_GT(cv::norm(f.left, runs[0][0].left, cv::NORM_L1), 0);
  EXPECT_TRUE(f.T_world_cam0.matrix() == runs[0][0].T_world_cam0.matrix());
}

TEST(SimulatorTest, FrameDropsAndStampJitterFollowTheSeed) {
  // The fate of each frame: a pinned pattern for seed 1 (a change to the stream shows here), and
  // the statistics over many frames: drops binomial(n, rate) within 5 sigma, jitter uniform on
  // [-j, j] (mean 0, variance j^2 / 3, bounded), frame 0 never jittered.
  sim::FrameOptions options;
  options.drop_rate = 0.3;
  options.time_jitter_s = 0.01;
  std::string pattern;
  for (int k = 0; k < 20; ++k) pattern += sim::FrameFateOf(options, 1, k).dropped ? 'x' : '.';
  EXPECT_EQ(pattern, ".x...x.x.x.xx..x..xx");  // 8 of 20 at 0.3
  EXPECT_EQ(sim::FrameFateOf(options, 7, 0).jitter_s, 0.0);
  constexpr int kN = 100000;
  int dropped = 0;
  double sum = 0.0, sum2 = 0.0, largest = 0.0;
  for (int k = 1; k <= kN; ++k) {
    const sim::FrameFate fate = sim::FrameFateOf(options, 7, k);
    dropped += fate.dropped;
    sum += fate.jitter_s;
    sum2 += fate.jitter_s * fate.jitter_s;
    largest = std::max(largest, std::abs(fate.jitter_s));
  }
  EXPECT_NEAR(dropped, 0.3 * kN, 5.0 * std::sqrt(kN * 0.3 * 0.7));
  const double j = options.time_jitter_s;
  EXPECT_NEAR(sum / kN, 0.0, 5.0 * j / std::sqrt(3.0 * kN));
  EXPECT_NEAR(sum2 / kN, j * j / 3.0, 5.0 * j * j * std::sqrt(4.0 / 45.0 / kN));
  EXPECT_LE(largest, j);
  EXPECT_GT(largest, 0.999 * j);
  options = sim::FrameOptions();  // off: nothing dropped, no jitter
  EXPECT_FALSE(sim::FrameFateOf(options, 7, 3).dropped);
  EXPECT_EQ(sim::FrameFateOf(options, 7, 3).jitter_s, 0.0);

  // In the simulator: the kept frames are the undropped sequence's frames at their index, their
  // stamps the capture time plus the frame's jitter, and no IMU sample is lost with a drop.
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &s, &error)) << error;
  s.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.6, 0)};
  std::vector<sim::StereoFrame> all, kept;
  size_t all_imu = 0, kept_imu = 0;
  for (auto* run : {&all, &kept}) {
    if (run == &kept) s.frames = {0.3, 0.02};
    auto simulator = sim::Simulator::Create(s, &error);
    ASSERT_TRUE(simulator) << error;
    sim::StereoFrame f;
    while (simulator->Next(&f, &error)) {
      (run == &all ? all_imu : kept_imu) += f.imu.size();
      run->push_back(f);
    }
    ASSERT_TRUE(error.empty()) << error;
  }
  ASSERT_GT(all.size(), 10u);
  size_t expected_kept = 0, drops_before_last = 0;
  for (size_t k = 0; k < all.size(); ++k)
    if (!sim::FrameFateOf(s.frames, s.seed, static_cast<int>(k)).dropped) ++expected_kept;
  EXPECT_EQ(kept.size(), expected_kept);
  EXPECT_LT(kept.size(), all.size());
  for (const sim::StereoFrame& f : kept) {
    ASSERT_LT(static_cast<size_t>(f.index), all.size());
    const sim::StereoFrame& same = all[f.index];
    EXPECT_EQ(cv::norm(f.left, same.left, cv::NORM_INF), 0) << f.index;
    EXPECT_EQ(cv::norm(f.right, same.right, cv::NORM_INF), 0) << f.index;
    EXPECT_TRUE(f.T_world_cam0.matrix() == same.T_world_cam0.matrix()) << f.index;
    EXPECT_EQ(f.time_s, same.time_s + sim::FrameFateOf(s.frames, s.seed, f.index).jitter_s);
  }
  for (size_t k = static_cast<size_t>(kept.back().index) + 1; k < all.size(); ++k)
    drops_before_last += all[k].imu.size();  // dropped after the last frame kept: not carried
  EXPECT_EQ(kept_imu + drops_before_last, all_imu);
}

TEST(SimulatorTest, DistortedRenderRectifiesBackToThePinholeRender) {
  // The round trip: render through a radtan lens, rectify with the calibration's lens
  // (OpenCV's initUndistortRectifyMap onto the same K), compare with the pinhole render of the
  // same frame: closer than the pinhole render is to itself shifted by half a pixel.
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &s, &error)) << error;
  s.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.6, 0)};
  s.noise = sim::NoiseOptions();
  sim::StereoFrame pinhole, raw;
  for (auto* f : {&pinhole, &raw}) {
    if (f == &raw) s.camera.distortion = {sim::kRadTan, {-0.28, 0.07, 0.0002, 0.00002}};
    auto simulator = sim::Simulator::Create(s, &error);
    ASSERT_TRUE(simulator) << error;
    ASSERT_TRUE(simulator->Next(f, &error)) << error;
    EXPECT_EQ(simulator->calibration().lens.model, s.camera.distortion.model);
  }
  ASSERT_EQ(raw.left.size(), pinhole.left.size());
  const double f = 0.5 * s.camera.height / std::tan(0.5 * s.camera.fovy_deg * M_PI / 180.0);
  const cv::Matx33d K(f, 0, 0.5 * (s.camera.width - 1), 0, f, 0.5 * (s.camera.height - 1), 0, 0, 1);
  cv::Mat map_x, map_y, rectified, shifted;
  cv::initUndistortRectifyMap(K, cv::Mat(s.camera.distortion.coeffs, true), cv::Matx33d::eye(), K,
                              raw.left.size(), CV_32FC1, map_x, map_y);
  cv::remap(raw.left, rectified, map_x, map_y, cv::INTER_LINEAR);
  const cv::Matx23d half_px(1, 0, 0.5, 0, 1, 0);
  cv::warpAffine(pinhole.left, shifted, half_px, pinhole.left.size());
  const cv::Rect inner(20, 20, s.camera.width - 40, s.camera.height - 40);
  cv::Mat a, b;
  cv::absdiff(rectified(inner), pinhole.left(inner), a);
  cv::absdiff(shifted(inner), pinhole.left(inner), b);
  const double round_trip = cv::mean(a)[0], half_pixel = cv::mean(b)[0];
  EXPECT_LT(round_trip, half_pixel) << "grey levels";
  EXPECT_GT(cv::norm(raw.left, pinhole.left, cv::NORM_L1), 0);  // the lens did change the image
}

TEST(SimulatorTest, NoiseModelsChangeTheImageAsConfigured) {
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(sim::BuiltinScenarioPath("l_hallway"), &s, &error)) << error;
  s.path = {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.3, 0)};
  s.noise = sim::NoiseOptions();  // all off
  auto clean_sim = sim::Simulator::Create(s, &error);
  ASSERT_TRUE(clean_sim) << error;
  sim::StereoFrame clean;
  ASSERT_TRUE(clean_sim->Next(&clean, &error));
  s.noise.pixel_sigma = 4.0;
  auto noisy_sim = sim::Simulator::Create(s, &error);
  sim::StereoFrame noisy;
  ASSERT_TRUE(noisy_sim->Next(&noisy, &error));
  cv::Mat diff;
  cv::subtract(noisy.left, clean.left, diff, cv::noArray(), CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(diff, mean, stddev);
  EXPECT_NEAR(stddev[0], 4.0, 0.6);  // clipping at 0/255 shrinks it a little
  EXPECT_NEAR(mean[0], 0.0, 0.5);
}

TEST(SimulatorTest, SceneErrorsNameTheFile) {
  TempDir dir("bad");
  std::string error;
  // Malformed MJCF.
  const std::string broken = dir / "broken.xml";
  vobench_test::WriteText(broken, "<mujoco><worldbody><geom type='sphere'</worldbody>");
  sim::Scenario s = MakeScenario(broken);
  EXPECT_EQ(sim::Simulator::Create(s, &error), nullptr);
  EXPECT_NE(error.find(broken), std::string::npos) << error;
  // Valid MJCF without the robot.
  const std::string empty = dir / "empty.xml";
  vobench_test::WriteText(
      empty, "<mujoco><worldbody><geom type='plane' size='1 1 1'/></worldbody></mujoco>");
  s = MakeScenario(empty);
  EXPECT_EQ(sim::Simulator::Create(s, &error), nullptr);
  EXPECT_NE(error.find(empty), std::string::npos) << error;
  EXPECT_NE(error.find("robot"), std::string::npos) << error;
}

// Issue #11: walls are visual only, so a path through one was simulated with the camera
// outside the scene. Scenarios built in code are checked by Create (files when read).
TEST(SimulatorTest, PathThroughAWallIsRefusedBeforeSimulating) {
  TempDir dir("wall");
  // A 2 m wide, 2.5 m high wall across the x axis at x = 0.5 (normal along -x).
  const std::string scene =
      WriteScene(dir,
                 "    <geom name='blocker' type='plane' size='1 1.25 0.1' pos='0.5 0 1.25' "
                 "xyaxes='0 1 0 0 0 1' contype='0' conaffinity='0'/>\n");
  std::string error;
  EXPECT_EQ(sim::Simulator::Create(MakeScenario(scene, 1.0), &error), nullptr);
  EXPECT_NE(error.find("key 'path[1]'"), std::string::npos) << error;
  EXPECT_NE(error.find("crosses wall 'blocker'"), std::string::npos) << error;
  EXPECT_NE(error.find("at (0.5, 0)"), std::string::npos) << error;
  // Stopping short of it, the robot (0.33 m about its axle) clear of it, is fine; 0.4 m (the
  // camera 0.1 m short of the wall) is not (issue #31).
  error.clear();
  EXPECT_NE(sim::Simulator::Create(MakeScenario(scene, 0.15), &error), nullptr) << error;
  EXPECT_EQ(sim::Simulator::Create(MakeScenario(scene, 0.4), &error), nullptr);
  EXPECT_NE(error.find("comes within 0.1 m of wall 'blocker'"), std::string::npos) << error;
}

TEST(SimulatorTest, IntrinsicsFromFovy) {
  double fx, fy, cx, cy;
  sim::IntrinsicsFromFovy(90.0, 640, 480, &fx, &fy, &cx, &cy);
  EXPECT_NEAR(fy, 240.0, 1e-9);
  EXPECT_NEAR(fx, 240.0, 1e-9);
  EXPECT_DOUBLE_EQ(cx, 319.5);
  EXPECT_DOUBLE_EQ(cy, 239.5);
}

}  // namespace
