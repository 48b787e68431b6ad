// Lens distortion maps (sim/lens.h) against OpenCV's own models: a ray projected by
// cv::projectPoints / cv::fisheye::projectPoints lands, through the map, where the wide pinhole
// render sees it; and the round trip — distort with the maps, rectify with OpenCV's
// initUndistortRectifyMap of the same calibration — returns the pinhole image, sub-pixel.
#include "sim/lens.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace {

constexpr int kW = 320, kH = 240;
constexpr double kF = 230.0, kCx = 159.5, kCy = 119.5;

// Bilinear sample of a CV_32FC1 map at (x, y).
double Sample(const cv::Mat& map, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double ax = x - x0, ay = y - y0;
  auto at = [&](int r, int c) { return static_cast<double>(map.at<float>(r, c)); };
  return (1 - ay) * ((1 - ax) * at(y0, x0) + ax * at(y0, x0 + 1)) +
         ay * ((1 - ax) * at(y0 + 1, x0) + ax * at(y0 + 1, x0 + 1));
}

// A smooth pattern of the ray (x, y): what any pinhole camera sees of one scene.
float Scene(double x, double y) {
  return static_cast<float>(128.0 + 60.0 * std::sin(9.0 * x) * std::cos(7.0 * y) + 40.0 * x * y);
}

struct LensCase {
  const char* model;
  std::vector<double> coeffs;
};

class LensTest : public ::testing::TestWithParam<LensCase> {};

TEST_P(LensTest, MapsAgreeWithOpenCvsModelAndRectifyBackSubPixel) {
  const LensCase& c = GetParam();
  const sim::LensDistortion lens{c.model, c.coeffs};
  sim::DistortedView view;
  std::string error;
  ASSERT_TRUE(sim::MakeDistortedView(lens, kF, kF, kCx, kCy, kW, kH, &view, &error)) << error;
  EXPECT_GT(view.wide_width, kW);  // barrel lenses see more than the pinhole of the same focal
  EXPECT_GT(view.wide_height, kH);
  EXPECT_NEAR(view.wide_fy_px,
              0.5 * view.wide_height / std::tan(0.5 * view.wide_fovy_deg * M_PI / 180.0), 1e-9);
  const bool radtan = lens.model == sim::kRadTan;
  const cv::Matx33d K(kF, 0, kCx, 0, kF, kCy, 0, 0, 1);
  const cv::Mat D(lens.coeffs, true);

  // 1. Rays projected by OpenCV's forward model land where the wide render sees them.
  std::vector<cv::Point3d> rays;
  for (double y = -0.45; y <= 0.45; y += 0.05)
    for (double x = -0.6; x <= 0.6; x += 0.05) rays.emplace_back(x, y, 1.0);
  std::vector<cv::Point2d> distorted;
  const cv::Vec3d no_turn(0, 0, 0), no_shift(0, 0, 0);
  if (radtan)
    cv::projectPoints(rays, no_turn, no_shift, K, D, distorted);
  else
    cv::fisheye::projectPoints(rays, distorted, no_turn, no_shift, K, D);
  double worst = 0.0;
  int inside = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const cv::Point2d& d = distorted[i];
    if (!(d.x >= 0 && d.y >= 0 && d.x < kW - 1 && d.y < kH - 1)) continue;
    ++inside;
    worst = std::max(
        worst,
        std::hypot(Sample(view.map_x, d.x, d.y) - (view.wide_fx_px * rays[i].x + view.wide_cx_px),
                   Sample(view.map_y, d.x, d.y) - (view.wide_fy_px * rays[i].y + view.wide_cy_px)));
  }
  EXPECT_GT(inside, 300);
  EXPECT_LT(worst, 0.01) << "px";

  // 2. Round trip: a wide pinhole image of the scene, distorted by the maps, rectified with
  // OpenCV's maps of the same calibration onto the pinhole K, equals the pinhole image of K.
  cv::Mat wide(view.wide_height, view.wide_width, CV_32FC1);
  for (int v = 0; v < wide.rows; ++v)
    for (int u = 0; u < wide.cols; ++u)
      wide.at<float>(v, u) =
          Scene((u - view.wide_cx_px) / view.wide_fx_px, (v - view.wide_cy_px) / view.wide_fy_px);
  cv::Mat raw, rect_x, rect_y, rectified;
  cv::remap(wide, raw, view.map_x, view.map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  if (radtan)
    cv::initUndistortRectifyMap(K, D, cv::Matx33d::eye(), K, cv::Size(kW, kH), CV_32FC1, rect_x,
                                rect_y);
  else
    cv::fisheye::initUndistortRectifyMap(K, D, cv::Matx33d::eye(), K, cv::Size(kW, kH), CV_32FC1,
                                         rect_x, rect_y);
  cv::remap(raw, rectified, rect_x, rect_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(-1));
  double worst_px = 0.0, sum_grey = 0.0;
  int n = 0;
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u) {
      const float rx = rect_x.at<float>(v, u), ry = rect_y.at<float>(v, u);
      if (!(rx >= 1 && ry >= 1 && rx < kW - 2 && ry < kH - 2)) continue;  // seen by the lens
      // Geometry: the pinhole pixel, through OpenCV's rectification and our map, lands on its
      // own ray in the wide render.
      worst_px =
          std::max(worst_px, std::hypot(Sample(view.map_x, rx, ry) - (u - kCx + view.wide_cx_px),
                                        Sample(view.map_y, rx, ry) - (v - kCy + view.wide_cy_px)));
      sum_grey += std::abs(rectified.at<float>(v, u) - Scene((u - kCx) / kF, (v - kCy) / kF));
      ++n;
    }
  EXPECT_GT(n, kW * kH / 2);
  EXPECT_LT(worst_px, 0.01) << "px";
  EXPECT_LT(sum_grey / n, 0.5) << "grey levels, mean (two bilinear resamplings)";
}

INSTANTIATE_TEST_SUITE_P(
    Models, LensTest,
    ::testing::Values(LensCase{sim::kRadTan, {-0.28, 0.07, 0.0002, 0.00002}},  // EuRoC cam0
                      LensCase{sim::kEquidistant, {0.05, -0.01, 0.002, -0.0005}}));

TEST(LensTest, BadLensesAreRefused) {
  sim::DistortedView view;
  std::string error;
  EXPECT_FALSE(
      sim::MakeDistortedView({"fisheye", {0, 0, 0, 0}}, kF, kF, kCx, kCy, kW, kH, &view, &error));
  EXPECT_NE(error.find("expected 'radial-tangential' or 'equidistant'"), std::string::npos)
      << error;
  EXPECT_FALSE(sim::MakeDistortedView({sim::kRadTan, {0.1, 0.0, 0.0}}, kF, kF, kCx, kCy, kW, kH,
                                      &view, &error));
  EXPECT_NE(error.find("expected 4 finite numbers (k1 k2 p1 p2), got 3"), std::string::npos)
      << error;
  EXPECT_FALSE(sim::MakeDistortedView({sim::kEquidistant, {NAN, 0, 0, 0}}, kF, kF, kCx, kCy, kW, kH,
                                      &view, &error));
  EXPECT_NE(error.find("4 finite numbers"), std::string::npos) << error;
  // A fisheye of 90 px focal over 320 px sees more than 170 degrees across.
  EXPECT_FALSE(sim::MakeDistortedView({sim::kEquidistant, {0, 0, 0, 0}}, 60, 60, kCx, kCy, kW, kH,
                                      &view, &error));
  EXPECT_NE(error.find("more than a pinhole render holds"), std::string::npos) << error;
}

}  // namespace
