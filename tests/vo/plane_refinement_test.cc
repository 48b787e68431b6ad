// Photometric plane refinement against exact ground truth: a stereo pair rendered from textured
// planes (the floor 1 m below a level camera, as on the simulated robot, and a side wall), every
// pixel sampled from the same planar texture in both views, so the true plane is known exactly.
#include "vo/plane_refinement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "tests/synthetic_images.h"
#include "tests/vo/vo_test_util.h"

namespace vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

StereoCamera Camera() { return test::TestCamera(); }  // 320×240, f 300 px, baseline 0.12 m

// A textured plane n·p + o = 0 (cam0); the texture lies on the plane at 5 mm a texel.
struct TexturedPlane {
  Plane plane;
  cv::Mat texture;  // CV_32F
};

// Renders the view of a camera at cam0 + (x_offset, 0, 0) (0: left, baseline: right): each pixel
// shows the nearest plane its ray meets (grey 0 where none within 20 m).
cv::Mat Render(const StereoCamera& cam, const std::vector<TexturedPlane>& planes, double x_offset) {
  cv::Mat image(cam.height, cam.width, CV_8UC1, cv::Scalar(0));
  const Eigen::Vector3d centre(x_offset, 0.0, 0.0);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d ray((u - cam.cx_px) / cam.fx_px, (v - cam.cy_px) / cam.fy_px, 1.0);
      double best = 20.0;
      const TexturedPlane* hit = nullptr;
      for (const TexturedPlane& tp : planes) {
        const double denom = tp.plane.normal_cam0.dot(ray);
        if (std::abs(denom) < 1e-9) continue;
        const double z = -(tp.plane.offset_m + tp.plane.normal_cam0.dot(centre)) / denom;
        if (z > 0.05 && z < best) {
          best = z;
          hit = &tp;
        }
      }
      if (hit == nullptr) continue;
      const Eigen::Vector3d p = centre + best * ray;
      // Texture coordinates: two axes across the plane's normal, through the foot point.
      const Eigen::Vector3d n = hit->plane.normal_cam0;
      const Eigen::Vector3d e1 = n.unitOrthogonal();
      const Eigen::Vector3d e2 = n.cross(e1);
      const Eigen::Vector3d q = p + hit->plane.offset_m * n;  // on the plane, relative to foot
      const float s = static_cast<float>(e1.dot(q) / 0.005 + hit->texture.cols / 2.0);
      const float t = static_cast<float>(e2.dot(q) / 0.005 + hit->texture.rows / 2.0);
      cv::Mat px;
      cv::getRectSubPix(hit->texture, cv::Size(1, 1), cv::Point2f(s, t), px, CV_32F);
      image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(px.at<float>(0, 0));
    }
  }
  return image;
}

TexturedPlane MakePlane(const Eigen::Vector3d& normal, double offset, uint64_t seed) {
  TexturedPlane tp;
  tp.plane.normal_cam0 = normal.normalized();
  tp.plane.offset_m = offset;
  tp.plane.kind = Plane::Kind::kFloor;
  vobench_test::RandomTexture(2048, 2048, seed).convertTo(tp.texture, CV_32F);
  return tp;
}

// The floor 1.0 m below a camera pitched down by 2° (its normal in cam0 points up, to −y).
Plane TrueFloor() {
  Plane p;
  p.normal_cam0 = Eigen::Vector3d(0.0, -std::cos(2.0 * kDeg), -std::sin(2.0 * kDeg));
  p.offset_m = 1.0;
  p.kind = Plane::Kind::kFloor;
  return p;
}

// The plane tilted by `deg` about the camera's x axis (pitch) and moved `dh` metres.
Plane Perturbed(const Plane& p, double deg, double dh) {
  Plane q = p;
  q.normal_cam0 = Eigen::AngleAxisd(deg * kDeg, Eigen::Vector3d::UnitX()) * p.normal_cam0;
  q.offset_m += dh;
  return q;
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) / kDeg;
}

// The lower half of the image below the horizon (where a level camera sees the floor).
std::vector<cv::Point> LowerRows(const StereoCamera& cam, int from_row) {
  std::vector<cv::Point> pixels;
  for (int v = from_row; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) pixels.emplace_back(u, v);
  }
  return pixels;
}

TEST(PlaneRefinementTest, DisparityCoefficientsAreThePlanesDisparity) {
  const StereoCamera cam = Camera();
  const Plane floor = TrueFloor();
  const Eigen::Vector3d abc = PlaneDisparityCoefficients(cam, floor);
  for (const auto& [u, v] : std::vector<std::pair<double, double>>{{10, 200}, {300, 150}}) {
    // The point on the plane seen at (u, v), projected into both views.
    const Eigen::Vector3d ray((u - cam.cx_px) / cam.fx_px, (v - cam.cy_px) / cam.fy_px, 1.0);
    const Eigen::Vector3d p = -floor.offset_m / floor.normal_cam0.dot(ray) * ray;
    Eigen::Vector2d l, r;
    ASSERT_TRUE(cam.ProjectLeft(p, &l));
    ASSERT_TRUE(cam.ProjectRight(p, &r));
    const double d = abc.x() * (u - cam.cx_px) + abc.y() * (v - cam.cy_px) + abc.z();
    EXPECT_NEAR(d, l.x() - r.x(), 1e-9);
  }
  Plane back;
  ASSERT_TRUE(PlaneFromDisparityCoefficients(cam, abc, &back));
  EXPECT_LT((back.normal_cam0 - floor.normal_cam0).norm(), 1e-12);
  EXPECT_NEAR(back.offset_m, floor.offset_m, 1e-12);
  EXPECT_FALSE(PlaneFromDisparityCoefficients(cam, Eigen::Vector3d::Zero(), &back));
}

TEST(PlaneRefinementTest, RecoversTheFloorFromAStartOneDegreeAndThreeCentimetresOff) {
  const StereoCamera cam = Camera();
  const std::vector<TexturedPlane> scene = {MakePlane(TrueFloor().normal_cam0, 1.0, 3)};
  const cv::Mat left = Render(cam, scene, 0.0);
  const cv::Mat right = Render(cam, scene, cam.baseline_m);
  const std::vector<cv::Point> pixels = LowerRows(cam, 140);
  for (double deg : {1.0, -1.0}) {
    const Plane start = Perturbed(TrueFloor(), deg, deg * 0.03);
    const PlaneRefinementResult r = RefinePlanePhotometric(left, right, cam, start, pixels);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_LT(AngleDeg(r.plane.normal_cam0, TrueFloor().normal_cam0), 0.02) << deg;
    EXPECT_NEAR(r.plane.offset_m, 1.0, 0.002) << deg;
    EXPECT_EQ(r.plane.kind, Plane::Kind::kFloor);
    EXPECT_LT(r.iterations, 30);
  }
}

// A brighter right camera with sensor noise, and a side wall that covers part of the pixels
// given (they are all the lower rows: the caller's region is only roughly the floor).
TEST(PlaneRefinementTest, ToleratesGainNoiseAndAWallInTheRegion) {
  const StereoCamera cam = Camera();
  const std::vector<TexturedPlane> scene = {MakePlane(TrueFloor().normal_cam0, 1.0, 3),
                                            MakePlane(Eigen::Vector3d(-1.0, 0.0, 0.0), 0.8, 4)};
  cv::Mat left = Render(cam, scene, 0.0);
  cv::Mat right = Render(cam, scene, cam.baseline_m);
  right.convertTo(right, CV_8U, 1.08, 4.0);
  cv::RNG rng(5);
  for (cv::Mat* img : {&left, &right}) {
    cv::Mat noise(img->size(), CV_16S);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
    cv::Mat sum;
    cv::add(*img, noise, sum, cv::noArray(), CV_16S);
    sum.convertTo(*img, CV_8U);
  }
  const std::vector<cv::Point> pixels = LowerRows(cam, 140);
  int wall = 0;  // pixels of the region that see the wall (the wall is at x = 0.8 m)
  for (const cv::Point& p : pixels) {
    const Eigen::Vector3d ray((p.x - cam.cx_px) / cam.fx_px, (p.y - cam.cy_px) / cam.fy_px, 1.0);
    const double z_floor = -1.0 / TrueFloor().normal_cam0.dot(ray);
    if (0.8 / ray.x() > 0.0 && 0.8 / ray.x() < z_floor) ++wall;
  }
  ASSERT_GT(wall, static_cast<int>(pixels.size()) / 5);  // a fifth of the region or more
  const PlaneRefinementResult r =
      RefinePlanePhotometric(left, right, cam, Perturbed(TrueFloor(), 0.8, 0.02), pixels);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT(AngleDeg(r.plane.normal_cam0, TrueFloor().normal_cam0), 0.05);
  EXPECT_NEAR(r.plane.offset_m, 1.0, 0.004);
  // The model maps the right view onto the left: mid-grey 128 is 1.08·128 + 4 on the right.
  EXPECT_NEAR((1.0 + r.gain) * (1.08 * 128.0 + 4.0) + r.bias, 128.0, 1.0);
  EXPECT_GT(r.residual_sigma, 1.5);  // the noise, σ √2 · 2 grey levels
  EXPECT_LT(r.residual_sigma, 4.0);
}

TEST(PlaneRefinementTest, RejectsBadInputWithAMessage) {
  const StereoCamera cam = Camera();
  const cv::Mat grey(cam.height, cam.width, CV_8UC1, cv::Scalar(100));
  const std::vector<cv::Point> pixels = LowerRows(cam, 140);
  auto fails = [&](const cv::Mat& l, const cv::Mat& r, const Plane& p,
                   const std::vector<cv::Point>& px, const PlaneRefinementOptions& o,
                   const std::string& what) {
    const PlaneRefinementResult res = RefinePlanePhotometric(l, r, cam, p, px, o);
    EXPECT_FALSE(res.ok) << what;
    EXPECT_NE(res.message.find(what), std::string::npos) << res.message;
  };
  fails(cv::Mat(cam.height, cam.width, CV_32F), grey, TrueFloor(), pixels, {}, "CV_8UC1");
  fails(grey, grey(cv::Rect(0, 0, 100, 100)).clone(), TrueFloor(), pixels, {}, "CV_8UC1");
  Plane behind = TrueFloor();
  behind.offset_m = 0.0;
  fails(grey, grey, behind, pixels, {}, "distance > 0");
  fails(grey, grey, TrueFloor(), {}, {}, "too few pixels");
  PlaneRefinementOptions bad;
  bad.max_iterations = 0;
  fails(grey, grey, TrueFloor(), pixels, bad, "max_iterations");
  fails(grey, grey, TrueFloor(), pixels, {}, "no texture");  // a flat grey pair
}

}  // namespace
}  // namespace vo
