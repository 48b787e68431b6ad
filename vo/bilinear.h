// Bilinear sampling of a float image between pixel centres, the one interpolation that the
// direct stages (direct_alignment's photometric residuals, plane_refinement's intensity and
// gradient samples) read their images with. (x, y) in pixels, pixel centres at integers; the
// caller keeps the point inside [0, cols − 1) × [0, rows − 1), so that the 2 × 2 neighbours
// exist (direct_alignment checks it, plane_refinement's windows stay inside by construction).
#pragma once

#include <opencv2/core.hpp>

namespace vo {

// The CV_32F image `img` at (x, y), weights (1 − fx, fx) × (1 − fy, fy) of the four neighbours.
inline double Bilinear(const cv::Mat& img, double x, double y) {
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const double fx = x - x0;
  const double fy = y - y0;
  const float* r0 = img.ptr<float>(y0);
  const float* r1 = img.ptr<float>(y0 + 1);
  return (1.0 - fy) * ((1.0 - fx) * r0[x0] + fx * r0[x0 + 1]) +
         fy * ((1.0 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

}  // namespace vo
