// Tests of vo/features.h: Harris corners at known positions, non-maximum suppression, count
// limit, bucketing, border margin, SIFT repeatability, invalid inputs.
#include "vo/features.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "tests/test_util.h"

namespace vo {
namespace {

// Harris maxima of an ideal corner lie on one of the pixels next to the geometric corner,
// which sits on a pixel boundary (x.5): within 1 px.
constexpr double kCornerTolPx = 1.0;
// cornerSubPix on an ideal, noise-free checkerboard junction.
constexpr double kSubpixelTolPx = 0.1;
// SIFT: a feature counts as repeated when the shifted image has one within this distance.
constexpr double kRepeatTolPx = 1.0;
constexpr double kMinRepeatability = 0.8;

std::unique_ptr<FeatureDetector> MakeDetector(const DetectorOptions& options) {
  std::string error;
  std::unique_ptr<FeatureDetector> detector = CreateFeatureDetector(options, &error);
  EXPECT_NE(detector, nullptr) << error;
  return detector;
}

// Textured image: blurred uniform noise at two scales, full 8-bit range; seeded.
cv::Mat Texture(int width, int height, uint64_t seed, double blur_px = 1.5) {
  cv::Mat noise(height, width, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::Mat fine, coarse;
  cv::GaussianBlur(noise, fine, cv::Size(0, 0), blur_px);
  cv::GaussianBlur(noise, coarse, cv::Size(0, 0), 4.0 * blur_px);
  cv::Mat sum = fine + 4.0 * coarse;
  cv::normalize(sum, sum, 0.0, 255.0, cv::NORM_MINMAX);
  cv::Mat grey;
  sum.convertTo(grey, CV_8U);
  return grey;
}

// Distance from p to the nearest of `points`.
double NearestDistance(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& points) {
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& q : points) best = std::min(best, (p - q).norm());
  return best;
}

std::vector<Eigen::Vector2d> Positions(const std::vector<Feature>& features) {
  std::vector<Eigen::Vector2d> out;
  for (const Feature& f : features) out.push_back(f.uv_px);
  return out;
}

void ExpectHouseOrder(const std::vector<Feature>& features) {
  for (size_t i = 1; i < features.size(); ++i) {
    const Feature& a = features[i - 1];
    const Feature& b = features[i];
    const bool ordered =
        a.response > b.response ||
        (a.response == b.response &&
         (a.uv_px.y() < b.uv_px.y() || (a.uv_px.y() == b.uv_px.y() && a.uv_px.x() < b.uv_px.x())));
    EXPECT_TRUE(ordered) << "features " << i - 1 << " and " << i << " out of order";
  }
}

void ExpectInsideMargin(const std::vector<Feature>& features, const cv::Size& size, int margin) {
  for (const Feature& f : features) {
    EXPECT_GE(f.uv_px.x(), margin);
    EXPECT_GE(f.uv_px.y(), margin);
    EXPECT_LE(f.uv_px.x(), size.width - 1 - margin);
    EXPECT_LE(f.uv_px.y(), size.height - 1 - margin);
  }
}

TEST(DetectorOptionsTest, DefaultsAndFactory) {
  std::string error;
  DetectorOptions options;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  EXPECT_EQ(options.type, DetectorType::kHarris);
  std::unique_ptr<FeatureDetector> harris = MakeDetector(options);
  ASSERT_NE(harris, nullptr);
  EXPECT_EQ(harris->type(), DetectorType::kHarris);
  options.type = DetectorType::kSift;
  std::unique_ptr<FeatureDetector> sift = MakeDetector(options);
  ASSERT_NE(sift, nullptr);
  EXPECT_EQ(sift->type(), DetectorType::kSift);
}

TEST(DetectorOptionsTest, InvalidOptionsGiveNoDetector) {
  struct Case {
    const char* expected;  // part of the message
    DetectorOptions options;
  };
  std::vector<Case> cases(7);
  cases[0] = {"max_features", {}};
  cases[0].options.max_features = -1;
  cases[1] = {"bucket", {}};
  cases[1].options.bucket_cols = 4;  // rows left at 0
  cases[2] = {"harris.k", {}};
  cases[2].options.harris.k = 0.0;
  cases[3] = {"harris.aperture_size", {}};
  cases[3].options.harris.aperture_size = 4;
  cases[4] = {"harris.nms_radius_px", {}};
  cases[4].options.harris.nms_radius_px = 0.5;
  cases[5] = {"sift.contrast_threshold", {}};
  cases[5].options.type = DetectorType::kSift;
  cases[5].options.sift.contrast_threshold = 0.0;
  cases[6] = {"border_margin_px", {}};
  cases[6].options.border_margin_px = -2;
  for (const Case& c : cases) {
    std::string error;
    EXPECT_EQ(CreateFeatureDetector(c.options, &error), nullptr) << c.expected;
    EXPECT_NE(error.find(c.expected), std::string::npos) << error;
  }
  // Sub-options of the detector not selected are not checked.
  DetectorOptions harris;
  harris.sift.sigma = -1.0;
  EXPECT_TRUE(harris.IsValid(nullptr));
}

TEST(HarrisTest, ResponseMatchesOpenCv) {
  // Relative to the largest response: float rounding of sums of ~1e6 integer terms.
  constexpr double kRelativeTol = 1e-5;
  cv::Mat image = Texture(160, 120, 3);
  cv::rectangle(image, cv::Rect(40, 30, 50, 40), cv::Scalar(255), cv::FILLED);
  for (int aperture : {3, 5}) {
    for (int block : {2, 3, 4, 5, 7}) {
      HarrisOptions options;
      options.aperture_size = aperture;
      options.block_size = block;
      cv::Mat ours, reference;
      ASSERT_TRUE(HarrisResponse(image, options, &ours));
      cv::cornerHarris(image, reference, block, aperture, options.k, cv::BORDER_REFLECT_101);
      ASSERT_EQ(ours.type(), CV_32FC1);
      ASSERT_EQ(ours.size(), image.size());
      const cv::Rect inside(block, block, image.cols - 2 * block, image.rows - 2 * block);
      double max_ref = 0.0;
      cv::minMaxLoc(cv::abs(reference(inside)), nullptr, &max_ref);
      EXPECT_LE(cv::norm(ours(inside), reference(inside), cv::NORM_INF), kRelativeTol * max_ref)
          << "aperture " << aperture << " block " << block;
    }
  }
  cv::Mat response;
  EXPECT_FALSE(HarrisResponse(cv::Mat(), HarrisOptions(), &response));
  EXPECT_FALSE(HarrisResponse(cv::Mat(10, 10, CV_32F), HarrisOptions(), &response));
  EXPECT_FALSE(HarrisResponse(image, HarrisOptions(), nullptr));
}

TEST(HarrisTest, TheResponseIsTheSameWithAndWithoutAvx2) {
  // Odd widths leave a remainder after every vector width; a saturated rectangle gives the
  // largest products. Bit for bit: integer sums and element-wise float arithmetic.
  for (const cv::Size size : {cv::Size(320, 240), cv::Size(37, 29), cv::Size(1241, 376)}) {
    cv::Mat image = Texture(size.width, size.height, 5);
    cv::rectangle(image, cv::Rect(size.width / 4, size.height / 4, size.width / 3, size.height / 3),
                  cv::Scalar(255), cv::FILLED);
    for (int block : {2, 3, 5, 31}) {
      HarrisOptions options;
      options.block_size = block;
      cv::Mat with, without;
      ASSERT_TRUE(HarrisResponse(image, options, &with, true));
      ASSERT_TRUE(HarrisResponse(image, options, &without, false));
      ASSERT_EQ(with.size(), without.size());
      EXPECT_EQ(std::memcmp(with.data, without.data, with.total() * with.elemSize()), 0)
          << size << " block " << block;
    }
  }
}

TEST(HarrisTest, FindsRectangleCorners) {
  cv::Mat image(240, 320, CV_8UC1, cv::Scalar(30));
  // Filled rectangles (pixels x0..x1, y0..y1 inclusive); corners on the pixel boundaries.
  const std::vector<cv::Rect> rects = {cv::Rect(40, 30, 60, 50), cv::Rect(150, 60, 80, 40),
                                       cv::Rect(60, 140, 40, 60), cv::Rect(200, 150, 70, 50)};
  std::vector<Eigen::Vector2d> corners;
  for (const cv::Rect& r : rects) {
    cv::rectangle(image, r, cv::Scalar(220), cv::FILLED);
    const double x0 = r.x - 0.5, y0 = r.y - 0.5;
    const double x1 = r.x + r.width - 0.5, y1 = r.y + r.height - 0.5;
    corners.insert(corners.end(), {{x0, y0}, {x1, y0}, {x0, y1}, {x1, y1}});
  }
  const std::vector<Feature> features = MakeDetector(DetectorOptions())->Detect(image);
  ASSERT_EQ(features.size(), corners.size());
  for (const Eigen::Vector2d& c : corners) {
    EXPECT_LE(NearestDistance(c, Positions(features)), kCornerTolPx) << c.transpose();
  }
  for (const Feature& f : features) {
    EXPECT_LE(NearestDistance(f.uv_px, corners), kCornerTolPx) << f.uv_px.transpose();
    EXPECT_GT(f.response, 0.0);
    EXPECT_FALSE(f.has_depth());
    EXPECT_EQ(f.track_id, -1);
  }
  ExpectHouseOrder(features);
}

// Checkerboard of `cell` px squares filling the image; X-junctions at (k cell - 0.5).
cv::Mat Checkerboard(int width, int height, int cell) {
  cv::Mat image(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.at<uint8_t>(y, x) = ((x / cell + y / cell) % 2) ? 200 : 50;
    }
  }
  return image;
}

TEST(HarrisTest, FindsCheckerboardJunctionsAndRefinesThem) {
  constexpr int kCell = 20;
  const cv::Mat image = Checkerboard(240, 180, kCell);
  DetectorOptions options;
  std::vector<Eigen::Vector2d> junctions;
  for (int y = kCell; y < image.rows; y += kCell) {
    for (int x = kCell; x < image.cols; x += kCell) {
      const double u = x - 0.5, v = y - 0.5;
      if (u >= options.border_margin_px && v >= options.border_margin_px &&
          u <= image.cols - 1 - options.border_margin_px &&
          v <= image.rows - 1 - options.border_margin_px) {
        junctions.emplace_back(u, v);
      }
    }
  }
  for (bool subpixel : {false, true}) {
    options.harris.subpixel = subpixel;
    const double tol = subpixel ? kSubpixelTolPx : kCornerTolPx;
    const std::vector<Feature> features = MakeDetector(options)->Detect(image);
    EXPECT_EQ(features.size(), junctions.size()) << "subpixel " << subpixel;
    for (const Eigen::Vector2d& j : junctions) {
      EXPECT_LE(NearestDistance(j, Positions(features)), tol)
          << j.transpose() << " subpixel " << subpixel;
    }
    ExpectInsideMargin(features, image.size(), options.border_margin_px);
  }
}

TEST(HarrisTest, QualityLevelIsRelativeToTheStrongestCorner) {
  cv::Mat image(160, 200, CV_8UC1, cv::Scalar(100));
  cv::rectangle(image, cv::Rect(30, 30, 50, 50), cv::Scalar(250), cv::FILLED);   // strong
  cv::rectangle(image, cv::Rect(120, 60, 50, 50), cv::Scalar(140), cv::FILLED);  // weak
  DetectorOptions options;
  options.harris.quality_level = 0.001;
  EXPECT_EQ(MakeDetector(options)->Detect(image).size(), 8u);
  options.harris.quality_level = 0.5;
  const std::vector<Feature> strong = MakeDetector(options)->Detect(image);
  ASSERT_EQ(strong.size(), 4u);
  for (const Feature& f : strong) EXPECT_LT(f.uv_px.x(), 100.0);
}

TEST(HarrisTest, NonMaximumSuppressionKeepsFeaturesApart) {
  const cv::Mat image = Texture(320, 240, 11);
  for (double radius : {3.0, 7.5, 12.0}) {
    DetectorOptions options;
    options.max_features = 0;  // no limit
    options.harris.nms_radius_px = radius;
    const std::vector<Feature> features = MakeDetector(options)->Detect(image);
    ASSERT_GT(features.size(), 20u) << radius;
    double closest = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < features.size(); ++i) {
      for (size_t j = i + 1; j < features.size(); ++j) {
        closest = std::min(closest, (features[i].uv_px - features[j].uv_px).norm());
      }
    }
    EXPECT_GE(closest, radius) << features.size() << " features";
    ExpectHouseOrder(features);
  }
}

TEST(HarrisTest, MaxCountKeepsTheStrongest) {
  const cv::Mat image = Texture(320, 240, 12);
  DetectorOptions options;
  options.max_features = 0;
  const std::vector<Feature> all = MakeDetector(options)->Detect(image);
  options.max_features = 50;
  const std::vector<Feature> top = MakeDetector(options)->Detect(image);
  ASSERT_GT(all.size(), 50u);
  ASSERT_EQ(top.size(), 50u);
  for (size_t i = 0; i < top.size(); ++i) {
    EXPECT_EQ(top[i].uv_px, all[i].uv_px) << i;
    EXPECT_EQ(top[i].response, all[i].response) << i;
  }
}

TEST(HarrisTest, BucketingSpreadsFeatures) {
  // Strong texture on the left half, faint (30 % contrast) on the right: without bucketing
  // the strongest features all come from the left.
  cv::Mat image = Texture(320, 240, 13);
  cv::Mat right = image(cv::Rect(160, 0, 160, 240));
  right.convertTo(right, CV_8U, 0.3, 90.0);
  DetectorOptions options;
  options.harris.quality_level = 0.001;  // faint corners are ~1 % of the strongest response
  options.max_features = 80;
  const std::vector<Feature> plain = MakeDetector(options)->Detect(image);
  int plain_right = 0;
  for (const Feature& f : plain) plain_right += f.uv_px.x() >= 160.0;
  EXPECT_EQ(plain_right, 0);

  options.bucket_cols = 4;
  options.bucket_rows = 3;
  options.max_per_bucket = 6;
  const std::vector<Feature> bucketed = MakeDetector(options)->Detect(image);
  const double cell_w = (image.cols - 2.0 * options.border_margin_px) / options.bucket_cols;
  const double cell_h = (image.rows - 2.0 * options.border_margin_px) / options.bucket_rows;
  std::vector<int> count(options.bucket_cols * options.bucket_rows, 0);
  for (const Feature& f : bucketed) {
    const int cx = std::min(options.bucket_cols - 1,
                            static_cast<int>((f.uv_px.x() - options.border_margin_px) / cell_w));
    const int cy = std::min(options.bucket_rows - 1,
                            static_cast<int>((f.uv_px.y() - options.border_margin_px) / cell_h));
    ++count[cy * options.bucket_cols + cx];
  }
  for (int n : count) {
    EXPECT_LE(n, options.max_per_bucket);
    EXPECT_GT(n, 0);  // every cell has texture, faint or not
  }
  EXPECT_EQ(static_cast<int>(bucketed.size()),
            std::min(options.max_features, options.max_per_bucket * 12));
  ExpectHouseOrder(bucketed);
}

TEST(HarrisTest, RespectsTheBorderMargin) {
  const cv::Mat image = Texture(200, 150, 14);
  for (int margin : {0, 5, 12, 30}) {
    DetectorOptions options;
    options.border_margin_px = margin;
    options.max_features = 0;
    const std::vector<Feature> features = MakeDetector(options)->Detect(image);
    EXPECT_FALSE(features.empty()) << margin;
    ExpectInsideMargin(features, image.size(), margin);
  }
}

TEST(HarrisTest, IsDeterministic) {
  const cv::Mat image = Texture(320, 240, 15);
  std::unique_ptr<FeatureDetector> detector = MakeDetector(DetectorOptions());
  const std::vector<Feature> a = detector->Detect(image);
  const std::vector<Feature> b = detector->Detect(image);
  const std::vector<Feature> c = MakeDetector(DetectorOptions())->Detect(image);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].uv_px, b[i].uv_px);
    EXPECT_EQ(a[i].uv_px, c[i].uv_px);
  }
  // Harris has no descriptors; the default DetectWithDescriptors wraps Detect.
  const FeatureSet set = detector->DetectWithDescriptors(image);
  EXPECT_EQ(set.features.size(), a.size());
  EXPECT_EQ(set.keypoints.size(), a.size());
  EXPECT_TRUE(set.descriptors.empty());
}

TEST(SiftTest, FindsFeaturesWithDescriptors) {
  const cv::Mat image = Texture(320, 240, 21);
  DetectorOptions options;
  options.type = DetectorType::kSift;
  options.max_features = 200;
  std::unique_ptr<FeatureDetector> detector = MakeDetector(options);
  const FeatureSet set = detector->DetectWithDescriptors(image);
  std::printf("[ sift ] %zu features on a 320x240 texture\n", set.features.size());
  ASSERT_GE(set.features.size(), 50u);
  EXPECT_LE(set.features.size(), 200u);
  ASSERT_EQ(set.keypoints.size(), set.features.size());
  ASSERT_EQ(set.descriptors.rows, static_cast<int>(set.features.size()));
  EXPECT_EQ(set.descriptors.cols, 128);
  EXPECT_EQ(set.descriptors.type(), CV_32F);
  ExpectHouseOrder(set.features);
  ExpectInsideMargin(set.features, image.size(), options.border_margin_px);
  for (size_t i = 0; i < set.features.size(); ++i) {
    EXPECT_FLOAT_EQ(static_cast<float>(set.features[i].uv_px.x()), set.keypoints[i].pt.x);
    EXPECT_FLOAT_EQ(static_cast<float>(set.features[i].uv_px.y()), set.keypoints[i].pt.y);
  }
  // One feature per position.
  for (size_t i = 0; i < set.features.size(); ++i) {
    for (size_t j = i + 1; j < set.features.size(); ++j) {
      EXPECT_NE(set.features[i].uv_px, set.features[j].uv_px);
    }
  }
  // Detect() gives the same features.
  const std::vector<Feature> plain = detector->Detect(image);
  ASSERT_EQ(plain.size(), set.features.size());
  for (size_t i = 0; i < plain.size(); ++i) EXPECT_EQ(plain[i].uv_px, set.features[i].uv_px);
}

TEST(SiftTest, IsRepeatableUnderTranslation) {
  // Two crops of one texture, shifted by (dx, dy): a feature at p in the first should appear
  // at p - (dx, dy) in the second, with a similar descriptor.
  constexpr int kDx = 7, kDy = 4;
  constexpr double kMaxDescriptorDistance = 0.25;  // relative to the descriptor norm
  const cv::Mat big = Texture(360, 280, 22);
  const cv::Mat a = big(cv::Rect(20, 20, 320, 240)).clone();
  const cv::Mat b = big(cv::Rect(20 + kDx, 20 + kDy, 320, 240)).clone();
  DetectorOptions options;
  options.type = DetectorType::kSift;
  options.max_features = 0;
  std::unique_ptr<FeatureDetector> detector = MakeDetector(options);
  const FeatureSet fa = detector->DetectWithDescriptors(a);
  const FeatureSet fb = detector->DetectWithDescriptors(b);
  int considered = 0, repeated = 0, similar = 0;
  const int guard = options.border_margin_px + 8;  // away from where either crop ends
  for (size_t i = 0; i < fa.features.size(); ++i) {
    const Eigen::Vector2d expected = fa.features[i].uv_px - Eigen::Vector2d(kDx, kDy);
    if (expected.x() < guard || expected.y() < guard || expected.x() > a.cols - 1 - guard ||
        expected.y() > a.rows - 1 - guard) {
      continue;
    }
    ++considered;
    int best = -1;
    double best_dist = kRepeatTolPx;
    for (size_t j = 0; j < fb.features.size(); ++j) {
      const double d = (fb.features[j].uv_px - expected).norm();
      if (d <= best_dist) {
        best_dist = d;
        best = static_cast<int>(j);
      }
    }
    if (best < 0) continue;
    ++repeated;
    const cv::Mat da = fa.descriptors.row(static_cast<int>(i));
    const cv::Mat db = fb.descriptors.row(best);
    if (cv::norm(da, db) <= kMaxDescriptorDistance * cv::norm(da)) ++similar;
  }
  const double repeatability = considered ? static_cast<double>(repeated) / considered : 0.0;
  std::printf("[ sift ] repeatability %.3f (%d of %d), similar descriptors %d\n", repeatability,
              repeated, considered, similar);
  ASSERT_GT(considered, 30);
  EXPECT_GE(repeatability, kMinRepeatability);
  EXPECT_GE(similar, kMinRepeatability * repeated);
}

TEST(FeatureDetectorTest, InvalidOrFeaturelessImagesGiveNoFeatures) {
  const cv::Mat texture = Texture(64, 48, 31);
  cv::Mat colour, as_float;
  cv::cvtColor(texture, colour, cv::COLOR_GRAY2BGR);
  texture.convertTo(as_float, CV_32F);
  const std::vector<cv::Mat> images = {
      cv::Mat(),                                   // empty
      colour,                                      // CV_8UC3
      as_float,                                    // CV_32F
      texture(cv::Rect(0, 0, 20, 20)).clone(),     // no room inside a 12-px margin
      cv::Mat(240, 320, CV_8UC1, cv::Scalar(77)),  // uniform
  };
  for (DetectorType type : {DetectorType::kHarris, DetectorType::kSift}) {
    DetectorOptions options;
    options.type = type;
    std::unique_ptr<FeatureDetector> detector = MakeDetector(options);
    for (size_t i = 0; i < images.size(); ++i) {
      EXPECT_TRUE(detector->Detect(images[i]).empty()) << ToString(type) << " image " << i;
      const FeatureSet set = detector->DetectWithDescriptors(images[i]);
      EXPECT_TRUE(set.features.empty()) << ToString(type) << " image " << i;
      EXPECT_TRUE(set.descriptors.empty()) << ToString(type) << " image " << i;
    }
  }
}

TEST(SelectFeaturesTest, LimitsAndBuckets) {
  std::vector<Feature> features;
  for (int i = 0; i < 10; ++i) {
    Feature f;
    f.uv_px = Eigen::Vector2d(5.0 + i, 5.0);  // all in the top-left cell
    f.response = 10.0 - i;
    features.push_back(f);
  }
  DetectorOptions options;
  options.border_margin_px = 0;
  options.max_features = 4;
  EXPECT_EQ(SelectFeatures(features, cv::Size(100, 100), options), (std::vector<int>{0, 1, 2, 3}));
  options.max_features = 0;
  options.bucket_cols = options.bucket_rows = 2;
  options.max_per_bucket = 3;
  EXPECT_EQ(SelectFeatures(features, cv::Size(100, 100), options), (std::vector<int>{0, 1, 2}));
}

}  // namespace
}  // namespace vo
