// The TUM-style stereo layout (dataset.h): DatasetWriter with kTum and TumReader. Round trip,
// association of left/right and of a ground truth at another rate (associate.py rules), and
// malformed input: false and a message that names the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "harness/dataset.h"
#include "harness/trajectory_io.h"
#include "tests/harness/cli_test_util.h"

namespace harness {

namespace {

using vobench_test::ReadAll;

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr double kPoseTolerance = 1e-12;  // TUM text round trip: 17 digits, quaternion
constexpr int kNumFrames = 6;

vo::StereoCamera TestCamera() {
  vo::StereoCamera camera;
  camera.width = 40;
  camera.height = 30;
  camera.fx_px = 35.5;
  camera.fy_px = 35.5;
  camera.cx_px = 19.5;
  camera.cy_px = 14.5;
  camera.baseline_m = 0.1;
  return camera;
}

Eigen::Isometry3d PoseAt(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(2.0 + t, -1.0 + 0.5 * t * t, 0.3);
  return T;
}

// Frames at 8 Hz from t = 1305031102 s (TUM-like absolute stamps, exact in binary), random
// images.
std::vector<DatasetFrame> MakeFrames(int n, bool with_gt) {
  cv::RNG rng(7);
  std::vector<DatasetFrame> frames;
  for (int i = 0; i < n; ++i) {
    DatasetFrame f;
    f.time_s = 1305031102.0 + 0.125 * i;
    f.left.create(30, 40, CV_8UC1);
    f.right.create(30, 40, CV_8UC1);
    rng.fill(f.left, cv::RNG::UNIFORM, 0, 256);
    rng.fill(f.right, cv::RNG::UNIFORM, 0, 256);
    f.has_gt = with_gt;
    if (with_gt) f.T_world_cam0 = PoseAt(0.125 * i);
    frames.push_back(f);
  }
  return frames;
}

void WriteAll(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

class TumDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::path(::testing::TempDir()) /
            ("vobench_tum_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    frames_ = MakeFrames(kNumFrames, true);
    DatasetWriter::Options options;
    options.format = DatasetFormat::kTum;
    DatasetWriter writer(options);
    std::string error;
    dir_ = (root_ / "seq").string();
    EXPECT_TRUE(writer.Open(dir_, TestCamera(), &error)) << error;
    for (const DatasetFrame& f : frames_) EXPECT_TRUE(writer.Add(f, &error)) << error;
    EXPECT_TRUE(writer.Finish(&error)) << error;
  }
  void TearDown() override { fs::remove_all(root_); }

  // Opens the dataset and reads every frame; returns the first error (empty when all is well).
  std::string OpenAndReadAll(const TumReader::Options& options = {}) const {
    TumReader reader;
    std::string error;
    if (!reader.Open(dir_, options, &error)) return error.empty() ? "<empty error>" : error;
    for (size_t i = 0; i < reader.size(); ++i) {
      DatasetFrame f;
      if (!reader.ReadFrame(i, &f, &error)) return error.empty() ? "<empty error>" : error;
    }
    return "";
  }

  fs::path root_;
  std::string dir_;
  std::vector<DatasetFrame> frames_;
};

TEST_F(TumDatasetTest, WriterLayoutAndRoundTrip) {
  // The layout: TUM lists, images named by stamp, the KITTI calibration, the left camera's
  // ground truth at the frame stamps; the KITTI layout as well.
  const std::string left_list = ReadAll(dir_ + "/left.txt");
  EXPECT_THAT(left_list, ::testing::StartsWith("# left images"));
  EXPECT_THAT(left_list, HasSubstr("\n1305031102.125000000 left/1305031102.125000000.png\n"));
  EXPECT_THAT(ReadAll(dir_ + "/right.txt"),
              HasSubstr("\n1305031102.250000000 right/1305031102.250000000.png\n"));
  for (const char* f : {"left/1305031102.625000000.png", "right/1305031102.000000000.png",
                        "calib.txt", "groundtruth.txt", "image_0/000005.png", "times.txt"})
    EXPECT_TRUE(fs::is_regular_file(dir_ + "/" + f)) << f;

  TumReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  ASSERT_EQ(reader.size(), frames_.size());
  EXPECT_EQ(reader.unpaired_frames(), 0u);
  EXPECT_EQ(reader.ground_truth_path(), dir_ + "/groundtruth.txt");
  EXPECT_EQ(reader.ground_truth_frames(), frames_.size());
  const vo::StereoCamera& c = reader.camera();
  EXPECT_EQ(c.width, 40);
  EXPECT_EQ(c.height, 30);
  EXPECT_EQ(c.fx_px, 35.5);
  EXPECT_NEAR(c.baseline_m, 0.1, 1e-12);
  for (size_t i = 0; i < frames_.size(); ++i) {
    DatasetFrame f;
    ASSERT_TRUE(reader.ReadFrame(i, &f, &error)) << error;
    EXPECT_EQ(f.time_s, frames_[i].time_s);  // exact: 9 decimals are finer than a double here
    EXPECT_EQ(cv::norm(f.left, frames_[i].left, cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(cv::norm(f.right, frames_[i].right, cv::NORM_INF), 0.0) << i;
    ASSERT_TRUE(f.has_gt);
    EXPECT_LT((f.T_world_cam0.matrix() - frames_[i].T_world_cam0.matrix()).cwiseAbs().maxCoeff(),
              kPoseTolerance);
  }
}

TEST_F(TumDatasetTest, WithoutGroundTruth) {
  fs::remove(dir_ + "/groundtruth.txt");
  TumReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  EXPECT_EQ(reader.ground_truth_path(), "");
  EXPECT_EQ(reader.ground_truth_frames(), 0u);
  DatasetFrame f;
  ASSERT_TRUE(reader.ReadFrame(0, &f, &error)) << error;
  EXPECT_FALSE(f.has_gt);
}

TEST_F(TumDatasetTest, GroundTruthAtThreeTimesTheRateWithOffsetStamps) {
  // Hand-written ground truth at 24 Hz (images at 8 Hz), its stamps 4 ms after a grid that
  // starts 0.25 s before the first image and ends at the 4th: frame k (t_k = t0 + 0.125 k)
  // pairs with the pose at t_k + 0.004 (difference 4 ms; the neighbours are 38 and 46 ms away);
  // frames 4 and 5 are more than 0.02 s from every pose and are left out.
  const double t0 = frames_[0].time_s;
  std::string gt = "# ground truth at 24 Hz\n# timestamp tx ty tz qx qy qz qw\n";
  std::vector<double> stamps;
  for (int r = -6; r <= 9; ++r) {
    const double t = t0 + r / 24.0 + 0.004;
    stamps.push_back(t);
    gt += FormatDouble(t) + " " + std::to_string(r) + " 0 0 0 0 0 1\n";
  }
  WriteAll(dir_ + "/gt30.txt", gt);
  TumReader::Options options;
  options.gt_path = dir_ + "/gt30.txt";
  TumReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir_, options, &error)) << error;
  EXPECT_EQ(reader.ground_truth().size(), 16u);
  EXPECT_EQ(reader.ground_truth_frames(), 4u);
  for (size_t k = 0; k < frames_.size(); ++k) {
    DatasetFrame f;
    ASSERT_TRUE(reader.ReadFrame(k, &f, &error)) << error;
    if (k < 4) {
      ASSERT_TRUE(f.has_gt) << k;
      EXPECT_EQ(f.T_world_cam0.translation().x(), 3.0 * k) << k;  // row r = 3k
    } else {
      EXPECT_FALSE(f.has_gt) << k;
    }
  }
  // A tighter tolerance than the 4 ms offset: no pose associates, which is an error.
  options.gt_max_difference_s = 0.003;
  EXPECT_FALSE(reader.Open(dir_, options, &error));
  EXPECT_THAT(error, HasSubstr(dir_ + "/gt30.txt: no ground-truth pose within 0.003 s of any of "
                                      "the 6 frames"));
}

TEST_F(TumDatasetTest, LeftAndRightArePairedByStamp) {
  // The right camera's stamps lag by 5 ms and one right image is missing from the list; an extra
  // right image far from every left stamp is left unpaired.
  std::string right = "# right\n";
  for (size_t i = 0; i < frames_.size(); ++i) {
    if (i == 2) continue;
    right += FormatDouble(frames_[i].time_s + 0.005) + " right/" + std::to_string(i) + ".png\n";
    cv::imwrite(dir_ + "/right/" + std::to_string(i) + ".png", frames_[i].right);
  }
  right += FormatDouble(frames_.back().time_s + 0.05) + " right/5.png\n";
  WriteAll(dir_ + "/right.txt", right);
  TumReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  ASSERT_EQ(reader.size(), frames_.size() - 1);
  EXPECT_EQ(reader.unpaired_frames(), 2u);  // left 2 and the extra right image
  DatasetFrame f;
  ASSERT_TRUE(reader.ReadFrame(2, &f, &error)) << error;  // the 3rd pair is frame 3
  EXPECT_EQ(f.time_s, frames_[3].time_s);
  EXPECT_EQ(cv::norm(f.right, frames_[3].right, cv::NORM_INF), 0.0);
  // A tolerance below the lag pairs nothing.
  TumReader::Options options;
  options.stereo_max_difference_s = 0.001;
  EXPECT_FALSE(reader.Open(dir_, options, &error));
  EXPECT_THAT(error, HasSubstr(dir_ + "/left.txt: no left stamp within 0.001 s of a stamp in " +
                               dir_ + "/right.txt"));
}

// --- Malformed input ------------------------------------------------------------------------

TEST_F(TumDatasetTest, WellFormedReadsCleanly) { EXPECT_EQ(OpenAndReadAll(), ""); }

TEST_F(TumDatasetTest, MissingCalibration) {
  fs::remove(dir_ + "/calib.txt");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/calib.txt: file not found"));
}

TEST_F(TumDatasetTest, NanInCalibration) {
  WriteAll(dir_ + "/calib.txt",
           "P0: 35.5 0 19.5 0 0 35.5 nan 0 0 0 1 0\nP1: 35.5 0 19.5 -3.55 0 "
           "35.5 14.5 0 0 0 1 0\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/calib.txt:1: P0: field 7 ('nan') is not finite"));
}

TEST_F(TumDatasetTest, MissingListFile) {
  fs::remove(dir_ + "/right.txt");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/right.txt: file not found"));
}

TEST_F(TumDatasetTest, MalformedListLines) {
  WriteAll(dir_ + "/left.txt", "# left\n1305031102.125\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/left.txt:2: expected 'timestamp filename'"));
  WriteAll(dir_ + "/left.txt", "1305031102.125 left/a.png extra\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/left.txt:1: expected 'timestamp filename'"));
  WriteAll(dir_ + "/left.txt", "nan left/a.png\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/left.txt:1: expected 'timestamp filename'"));
  WriteAll(dir_ + "/left.txt", "1 left/a.png\n1 left/b.png\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/left.txt:2: time stamp 1 repeats the previous one, 1 (line 1)"));
  // Issue #11: stamps that go backwards are refused too (they were accepted).
  WriteAll(dir_ + "/left.txt", "2 left/a.png\n1 left/b.png\n");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/left.txt:2: time stamp 1 is before the previous one, 2 (line 1)"));
  WriteAll(dir_ + "/left.txt", "# nothing\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/left.txt: no images listed"));
}

TEST_F(TumDatasetTest, LeftAndRightImagesOfDifferentSizes) {
  cv::imwrite(dir_ + "/right/1305031102.000000000.png", cv::Mat::zeros(30, 38, CV_8UC1));
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/right/1305031102.000000000.png: size 38x30 "
                                                 "differs from the left image's 40x30"));
}

TEST_F(TumDatasetTest, ImageSizeChangesAcrossFrames) {
  cv::imwrite(dir_ + "/left/1305031102.500000000.png", cv::Mat::zeros(32, 40, CV_8UC1));
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/left/1305031102.500000000.png: image size "
                                                 "40x32 differs from 40x30"));
}

TEST_F(TumDatasetTest, MissingOrUnreadableImage) {
  WriteAll(dir_ + "/left/1305031102.375000000.png", "not a png");
  EXPECT_THAT(OpenAndReadAll(),
              HasSubstr(dir_ + "/left/1305031102.375000000.png: cannot decode the image"));
  fs::remove(dir_ + "/right/1305031102.625000000.png");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ +
                                          "/right/1305031102.625000000.png: missing image "
                                          "file (listed in " +
                                          dir_ + "/right.txt)"));
}

TEST_F(TumDatasetTest, GroundTruthWithFewerPosesCoversTheFirstFrames) {
  std::vector<StampedPose> gt;
  std::string error;
  ASSERT_TRUE(ReadTum(dir_ + "/groundtruth.txt", &gt, &error)) << error;
  gt.resize(2);
  ASSERT_TRUE(WriteTum(dir_ + "/groundtruth.txt", gt, &error)) << error;
  TumReader reader;
  ASSERT_TRUE(reader.Open(dir_, &error)) << error;
  EXPECT_EQ(reader.ground_truth_frames(), 2u);
  DatasetFrame f;
  ASSERT_TRUE(reader.ReadFrame(1, &f, &error)) << error;
  EXPECT_TRUE(f.has_gt);
  ASSERT_TRUE(reader.ReadFrame(2, &f, &error)) << error;
  EXPECT_FALSE(f.has_gt);
}

TEST_F(TumDatasetTest, MalformedGroundTruth) {
  WriteAll(dir_ + "/groundtruth.txt", "1305031102 1 2 3 0 0 0\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/groundtruth.txt:1:"));
  WriteAll(dir_ + "/groundtruth.txt", "# nothing\n");
  EXPECT_THAT(OpenAndReadAll(), HasSubstr(dir_ + "/groundtruth.txt: no ground-truth pose"));
}

TEST_F(TumDatasetTest, MissingFolder) {
  TumReader reader;
  std::string error;
  EXPECT_FALSE(reader.Open(dir_ + "_nope", &error));
  EXPECT_THAT(error, HasSubstr(dir_ + "_nope: dataset folder not found"));
}

}  // namespace
}  // namespace harness
