// Real lenses for the simulated rig (issue #34): the maps that turn a pinhole render into the
// image of a distorted lens, in OpenCV's two distortion models, the ones EuRoC's sensor.yaml
// names and `vobench eval --format euroc` rectifies (harness/dataset/rectification.h):
//   "radial-tangential"  k1 k2 p1 p2 (cv::projectPoints with distCoeffs (k1, k2, p1, p2))
//   "equidistant"        k1 k2 k3 k4 (Kannala-Brandt, cv::fisheye::projectPoints)
// How: every pixel (u, v) of the distorted image of intrinsics K is undistorted to its ray
// (x, y, 1) (cv::undistortPoints / cv::fisheye::undistortPoints, iterative), and the distorted
// image samples a WIDER pinhole render at K_wide (x, y, 1): same focal lengths as K (the same
// pixel density at the centre), an image just large enough to hold every ray plus a margin for
// interpolation, principal point at its centre. MakeDistortedView gives K_wide, its size and
// the two maps for cv::remap; the simulator renders at K_wide and remaps (bilinear). Accuracy:
// the maps agree with OpenCV's forward model (projectPoints) to about 1e-3 px (lens_test.cc);
// bilinear resampling blurs the image by less than a pixel.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sim {

// EuRoC's names; coeffs as listed in sensor.yaml (4 numbers for both models).
inline constexpr const char* kRadTan = "radial-tangential";
inline constexpr const char* kEquidistant = "equidistant";

struct LensDistortion {
  std::string model;           // kRadTan or kEquidistant; empty = none (an ideal pinhole)
  std::vector<double> coeffs;  // k1 k2 p1 p2 (radtan) or k1 k2 k3 k4 (equidistant)
  bool any() const { return !model.empty(); }
};

// The pinhole render a distorted image is made from, and the maps that make it.
struct DistortedView {
  int wide_width = 0, wide_height = 0;  // size of the pinhole render (pixels)
  double wide_fx_px = 0.0, wide_fy_px = 0.0, wide_cx_px = 0.0, wide_cy_px = 0.0;
  double wide_fovy_deg = 0.0;  // its vertical field of view (degrees), for MuJoCo's camera
  cv::Mat map_x, map_y;        // CV_32FC1, width x height of the distorted image: the position
                               // of each distorted pixel in the wide render (cv::remap)
};

// Maps for a distorted camera of intrinsics (fx, fy, cx, cy) and size width x height. False,
// with *error saying why, for an unknown model, a coefficient count other than 4, non-finite
// coefficients, or a lens whose field of view a pinhole render cannot hold (>= 170 degrees
// across, or a pixel whose ray does not undistort).
bool MakeDistortedView(const LensDistortion& lens, double fx_px, double fy_px, double cx_px,
                       double cy_px, int width, int height, DistortedView* view,
                       std::string* error);

}  // namespace sim
