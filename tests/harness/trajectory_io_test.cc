#include "harness/trajectory_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "tests/test_util.h"

namespace harness {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using vobench_test::IsNearPose;

constexpr double kRoundTripTolerance = 1e-9;  // per matrix entry: text round trip of a pose

// Entry-wise comparison of two transforms. (IsNearPose measures the angle through acos, which
// cannot resolve rotations below ~2e-8 rad; a text round trip is far more exact.)
MATCHER_P2(IsNearTransform, expected, tol,
           "has every matrix entry within " + ::testing::PrintToString(tol) + " of the expected") {
  const double d = (expected.matrix() - arg.matrix()).cwiseAbs().maxCoeff();
  *result_listener << "largest entry difference " << d;
  return d <= tol;
}

// A unique temporary folder, removed with everything in it at the end of the test.
class TrajectoryIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) /
           ("vobench_trajectory_io_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  std::string WriteFile(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name), std::ios::binary) << text;
    return Path(name);
  }

  fs::path dir_;
};

Eigen::Isometry3d RandomPose(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Quaterniond q(u(*rng), u(*rng), u(*rng), u(*rng));
  q.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = Eigen::Vector3d(u(*rng), u(*rng), u(*rng)) * 50.0;
  return T;
}

std::vector<StampedPose> RandomTrajectory(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<StampedPose> poses;
  for (int i = 0; i < n; ++i) poses.push_back({1305031102.175304 + 0.0333 * i, RandomPose(&rng)});
  return poses;
}

TEST(FormatDoubleTest, ShortestTextReadsBackExactly) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1e6, 1e6);
  std::vector<double> values = {
      0.0, 1.0, -1.0, 0.1, 1e-300, 5e-324, 1.7976931348623157e308, 1305031102.175304, -2.5e-5};
  for (int i = 0; i < 1000; ++i) values.push_back(u(rng) * std::pow(10.0, i % 20 - 10));
  for (double v : values) {
    double back = 0.0;
    ASSERT_TRUE(ParseDouble(FormatDouble(v), &back)) << FormatDouble(v);
    EXPECT_EQ(back, v) << FormatDouble(v);
  }
  EXPECT_EQ(FormatDouble(0.1), "0.1");
  EXPECT_EQ(FormatDouble(-0.0), "0");
  EXPECT_EQ(FormatDouble(20.0), "20");
  double v = 0.0;
  EXPECT_TRUE(ParseDouble("+1.5", &v));
  EXPECT_EQ(v, 1.5);
  EXPECT_FALSE(ParseDouble("1.5x", &v));
  EXPECT_FALSE(ParseDouble("", &v));
  EXPECT_FALSE(ParseDouble(" 1", &v));
}

TEST_F(TrajectoryIoTest, TumRoundTrip) {
  const std::vector<StampedPose> poses = RandomTrajectory(200, 1);
  std::string error;
  ASSERT_TRUE(WriteTum(Path("traj.txt"), poses, &error)) << error;
  std::vector<StampedPose> back;
  ASSERT_TRUE(ReadTum(Path("traj.txt"), &back, &error)) << error;
  ASSERT_EQ(back.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(back[i].time_s, poses[i].time_s);
    EXPECT_THAT(back[i].T_world_cam, IsNearTransform(poses[i].T_world_cam, kRoundTripTolerance));
  }
}

TEST_F(TrajectoryIoTest, TumLineFormat) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(1.0, -2.5, 0.125);
  // -q of a rotation is the same rotation: written with qw >= 0.
  T.linear() = Eigen::Quaterniond(-0.5, 0.5, -0.5, 0.5).toRotationMatrix();
  std::string error;
  ASSERT_TRUE(WriteTum(Path("one.txt"), {{0.5, T}}, &error)) << error;
  std::ifstream in(Path("one.txt"));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "0.5 1 -2.5 0.125 -0.5 0.5 -0.5 0.5");
}

TEST_F(TrajectoryIoTest, TumReadSkipsCommentsBlankLinesAndAcceptsSeparators) {
  const std::string path = WriteFile("tum.txt",
                                     "# ground truth trajectory\n"
                                     "# timestamp tx ty tz qx qy qz qw\n"
                                     "\n"
                                     "1.0 1 2 3 0 0 0 1\r\n"
                                     "  \t\n"
                                     "2.0,4,5,6,0,0,0.70710678,0.70710678\n"
                                     "3.0\t7\t8\t9\t0\t0\t0\t1\n");
  std::vector<StampedPose> poses;
  std::string error;
  ASSERT_TRUE(ReadTum(path, &poses, &error)) << error;
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_EQ(poses[1].time_s, 2.0);
  EXPECT_TRUE(poses[1].T_world_cam.translation().isApprox(Eigen::Vector3d(4, 5, 6)));
  Eigen::Isometry3d expected = Eigen::Isometry3d::Identity();
  expected.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  expected.translation() = Eigen::Vector3d(4, 5, 6);
  EXPECT_THAT(poses[1].T_world_cam, IsNearPose(expected, 1e-7, 1e-12));
}

TEST_F(TrajectoryIoTest, TumMalformedRowsNameFileAndLine) {
  struct Case {
    std::string text;
    std::string expected;  // substring of the error
  };
  const std::vector<Case> cases = {
      {"# c\n1 2 3 4 0 0 0 1\n1 2 3 0 0 0 1\n", ":3: expected 8 numbers, got 7"},
      {"1 2 3 4 0 0 0 1 9\n", ":1: expected 8 numbers, got 9"},
      {"1 2 x 4 0 0 0 1\n", ":1: field 3 ('x') is not a number"},
      {"1 2 3 nan 0 0 0 1\n", ":1: field 4 ('nan') is not finite"},
      {"\n\n1 2 3 4 0 0 0 2\n", ":3: expected a unit quaternion"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string path = WriteFile("bad" + std::to_string(i) + ".txt", cases[i].text);
    std::vector<StampedPose> poses;
    std::string error;
    EXPECT_FALSE(ReadTum(path, &poses, &error)) << cases[i].text;
    EXPECT_THAT(error, HasSubstr(path + cases[i].expected));
  }
  std::vector<StampedPose> poses;
  std::string error;
  EXPECT_FALSE(ReadTum(Path("missing.txt"), &poses, &error));
  EXPECT_THAT(error, HasSubstr(Path("missing.txt")));
  EXPECT_THAT(error, HasSubstr("not found"));
}

TEST_F(TrajectoryIoTest, KittiPosesRoundTrip) {
  std::vector<Eigen::Isometry3d> poses;
  for (const StampedPose& p : RandomTrajectory(100, 2)) poses.push_back(p.T_world_cam);
  std::string error;
  ASSERT_TRUE(WriteKittiPoses(Path("poses.txt"), poses, &error)) << error;
  std::vector<Eigen::Isometry3d> back;
  ASSERT_TRUE(ReadKittiPoses(Path("poses.txt"), &back, &error)) << error;
  ASSERT_EQ(back.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i)
    EXPECT_EQ(back[i].matrix(), poses[i].matrix());  // the 12 numbers are exact
}

TEST_F(TrajectoryIoTest, KittiPosesReadsKittiGroundTruthStyle) {
  const std::string path = WriteFile(
      "00.txt",
      "1.000000e+00 9.043680e-12 2.326809e-11 5.551115e-17 9.043683e-12 1.000000e+00 "
      "2.392370e-10 3.330669e-16 2.326810e-11 2.392370e-10 9.999999e-01 -4.440892e-16\n"
      "9.999978e-01 5.272628e-04 -2.066935e-03 -4.690294e-02 -5.296506e-04 9.999992e-01 "
      "-1.154865e-03 -2.839928e-02 2.066324e-03 1.155958e-03 9.999971e-01 8.586941e-01\n");
  std::vector<Eigen::Isometry3d> poses;
  std::string error;
  ASSERT_TRUE(ReadKittiPoses(path, &poses, &error)) << error;
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_DOUBLE_EQ(poses[1].translation().z(), 8.586941e-01);
}

TEST_F(TrajectoryIoTest, KittiPosesMalformedRowsNameFileAndLine) {
  const std::string short_row =
      WriteFile("short.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  const std::string not_rotation = WriteFile("scaled.txt", "2 0 0 0 0 1 0 0 0 0 1 0\n");
  const std::string reflection = WriteFile("mirror.txt", "-1 0 0 0 0 1 0 0 0 0 1 0\n");
  std::vector<Eigen::Isometry3d> poses;
  std::string error;
  EXPECT_FALSE(ReadKittiPoses(short_row, &poses, &error));
  EXPECT_THAT(error, HasSubstr(short_row + ":2: expected 12 numbers, got 11"));
  EXPECT_FALSE(ReadKittiPoses(not_rotation, &poses, &error));
  EXPECT_THAT(error, HasSubstr(not_rotation + ":1: expected a rotation"));
  EXPECT_FALSE(ReadKittiPoses(reflection, &poses, &error));
  EXPECT_THAT(error, HasSubstr(reflection + ":1: expected a rotation"));
}

TEST_F(TrajectoryIoTest, KittiTimesRoundTripAndErrors) {
  const std::vector<double> times = {0.0, 1e-5, 0.1, 0.2, 123456.789};
  std::string error;
  ASSERT_TRUE(WriteKittiTimes(Path("times.txt"), times, &error)) << error;
  std::vector<double> back;
  ASSERT_TRUE(ReadKittiTimes(Path("times.txt"), &back, &error)) << error;
  EXPECT_EQ(back, times);
  const std::string kitti_style = WriteFile("kitti_times.txt", "0.000000e+00\n1.036231e-01\n");
  ASSERT_TRUE(ReadKittiTimes(kitti_style, &back, &error)) << error;
  EXPECT_EQ(back, (std::vector<double>{0.0, 1.036231e-01}));
  const std::string bad = WriteFile("bad_times.txt", "0.0\n0.1 0.2\n");
  EXPECT_FALSE(ReadKittiTimes(bad, &back, &error));
  EXPECT_THAT(error, HasSubstr(bad + ":2: expected 1 numbers, got 2"));
}

// Issue #11: stamps that go backwards or repeat were accepted (the trajectory then got a
// repeated stamp); every reader refuses them with the file and line of the offending stamp.
TEST_F(TrajectoryIoTest, TimeStampsThatGoBackwardsOrRepeatAreRefusedWithFileAndLine) {
  std::vector<double> times;
  std::string error;
  const std::string backwards = WriteFile("back_times.txt", "0.0\n0.1\n# note\n0.05\n0.3\n");
  EXPECT_FALSE(ReadKittiTimes(backwards, &times, &error));
  EXPECT_THAT(error, HasSubstr(backwards + ":4: time stamp 0.05 is before the previous one, 0.1 "
                                           "(line 2); expected strictly increasing time stamps"));
  const std::string repeated = WriteFile("repeat_times.txt", "0.0\n0.1\n0.1\n");
  EXPECT_FALSE(ReadKittiTimes(repeated, &times, &error));
  EXPECT_THAT(error, HasSubstr(repeated + ":3: time stamp 0.1 repeats the previous one, 0.1"));

  std::vector<StampedPose> poses;
  const std::string tum = WriteFile("back_tum.txt",
                                    "# t tx ty tz qx qy qz qw\n"
                                    "2.0 0 0 0 0 0 0 1\n"
                                    "1.5 0 0 0 0 0 0 1\n");
  EXPECT_FALSE(ReadTum(tum, &poses, &error));
  EXPECT_THAT(error,
              HasSubstr(tum + ":3: time stamp 1.5 is before the previous one, 2.0 (line 2)"));
}

TEST_F(TrajectoryIoTest, WriteRejectsNonFiniteAndUnwritablePaths) {
  std::vector<StampedPose> poses = RandomTrajectory(3, 3);
  poses[1].time_s = std::numeric_limits<double>::quiet_NaN();
  std::string error;
  EXPECT_FALSE(WriteTum(Path("nan.txt"), poses, &error));
  EXPECT_THAT(error, HasSubstr("pose 1"));
  EXPECT_FALSE(WriteTum(Path("no/such/folder/t.txt"), RandomTrajectory(1, 4), &error));
  EXPECT_THAT(error, HasSubstr(Path("no/such/folder/t.txt")));
}

// associate.py, by hand: greedy by smallest |difference|, each stamp once, sorted by first.
TEST(AssociateTest, GreedyKnownAnswer) {
  // 1.00 and 1.01 both want 1.008; 1.01 is closer (0.002 < 0.008) and wins; 1.00 then takes
  // 0.985 (0.015 < 0.02). 2.0 has nothing within 0.02. 3.0 ties exactly between 3 -+ 2^-7:
  // the smaller second stamp wins (tuple order of associate.py).
  const std::vector<double> first = {1.00, 1.01, 2.0, 3.0};
  const std::vector<double> second = {0.985, 1.008, 2.03, 3.0 - 0.0078125, 3.0 + 0.0078125};
  const std::vector<AssociatedPair> pairs = AssociateStamps(first, second);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].first, 0u);
  EXPECT_EQ(pairs[0].second, 0u);
  EXPECT_EQ(pairs[1].first, 1u);
  EXPECT_EQ(pairs[1].second, 1u);
  EXPECT_EQ(pairs[2].first, 3u);
  EXPECT_EQ(pairs[2].second, 3u);
}

TEST(AssociateTest, TwoRatesPairEachEstimateWithNearestGroundTruth) {
  // Ground truth at 100 Hz, estimates at 30 Hz shifted by 1 ms: the nearest 100 Hz sample of
  // estimate j is round(100 * (j / 30 + 0.001)), never a tie (fractions 0.1, 0.43, 0.77).
  std::vector<double> gt, est;
  for (int k = 0; k <= 300; ++k) gt.push_back(k * 0.01);
  for (int j = 0; j < 90; ++j) est.push_back(j / 30.0 + 0.001);
  AssociateOptions options;
  options.max_difference_s = 0.01;
  const std::vector<AssociatedPair> pairs = AssociateStamps(est, gt, options);
  ASSERT_EQ(pairs.size(), est.size());
  for (size_t j = 0; j < pairs.size(); ++j) {
    EXPECT_EQ(pairs[j].first, j);
    EXPECT_EQ(pairs[j].second, static_cast<size_t>(std::lround(100.0 * (j / 30.0 + 0.001))));
  }
  // With an offset the same pairs come from a shifted stream.
  std::vector<double> gt_shifted;
  for (double t : gt) gt_shifted.push_back(t - 5.0);
  options.offset_s = 5.0;
  const std::vector<AssociatedPair> shifted = AssociateStamps(est, gt_shifted, options);
  ASSERT_EQ(shifted.size(), pairs.size());
  for (size_t j = 0; j < pairs.size(); ++j) EXPECT_EQ(shifted[j].second, pairs[j].second);
}

TEST(AssociateTest, StrictWindowUnsortedInputAndEachStampOnce) {
  AssociateOptions options;
  options.max_difference_s = 0.5;
  // |1 - 1.5| == 0.5 is not < 0.5: no pair. Unsorted input still gives sorted output.
  EXPECT_TRUE(AssociateStamps({1.0}, {1.5}, options).empty());
  const std::vector<AssociatedPair> pairs = AssociateStamps({3.0, 1.0, 2.0}, {2.1}, options);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].first, 2u);
  const std::vector<AssociatedPair> sorted =
      AssociateStamps({3.0, 1.0, 2.0}, {1.1, 3.2, 2.05}, options);
  ASSERT_EQ(sorted.size(), 3u);
  EXPECT_EQ(sorted[0].first, 1u);  // 1.0
  EXPECT_EQ(sorted[1].first, 2u);  // 2.0
  EXPECT_EQ(sorted[2].first, 0u);  // 3.0
  EXPECT_EQ(sorted[2].second, 1u);
  std::string error;
  options.max_difference_s = 0.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("max_difference_s"));
}

TEST(AssociateTest, AssociatePosesReturnsMatchedSubsequences) {
  const std::vector<StampedPose> est = RandomTrajectory(5, 5);
  std::vector<StampedPose> gt = RandomTrajectory(10, 6);
  for (size_t i = 0; i < gt.size(); ++i) gt[i].time_s = est[0].time_s + 0.0333 * 0.5 * i + 0.001;
  std::vector<StampedPose> a, b;
  const std::vector<AssociatedPair> pairs = AssociatePoses(est, gt, AssociateOptions(), &a, &b);
  ASSERT_EQ(a.size(), pairs.size());
  ASSERT_EQ(b.size(), pairs.size());
  ASSERT_FALSE(pairs.empty());
  for (size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_EQ(a[k].time_s, est[pairs[k].first].time_s);
    EXPECT_EQ(b[k].time_s, gt[pairs[k].second].time_s);
    EXPECT_LT(std::abs(a[k].time_s - b[k].time_s), 0.02);
  }
}

}  // namespace
}  // namespace harness
