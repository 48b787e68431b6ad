#include "vo/camera.h"

#include <cmath>
#include <sstream>

namespace vo {

bool StereoCamera::IsValid(std::string* error) const {
  std::ostringstream msg;
  if (width <= 0 || height <= 0)
    msg << "image size must be positive, got " << width << "x" << height;
  else if (!std::isfinite(fx_px) || fx_px <= 0)
    msg << "fx_px must be finite and > 0, got " << fx_px;
  else if (!std::isfinite(fy_px) || fy_px <= 0)
    msg << "fy_px must be finite and > 0, got " << fy_px;
  else if (!std::isfinite(cx_px))
    msg << "cx_px must be finite, got " << cx_px;
  else if (!std::isfinite(cy_px))
    msg << "cy_px must be finite, got " << cy_px;
  else if (!std::isfinite(baseline_m) || baseline_m <= 0)
    msg << "baseline_m must be finite and > 0, got " << baseline_m;
  if (msg.tellp() == 0) return true;
  if (error) *error = msg.str();
  return false;
}

Eigen::Vector3d StereoCamera::Backproject(double u_px, double v_px, double disparity_px) const {
  return BackprojectDepth(u_px, v_px, DepthFromDisparity(disparity_px));
}

Eigen::Vector3d StereoCamera::BackprojectDepth(double u_px, double v_px, double depth_m) const {
  return Eigen::Vector3d((u_px - cx_px) / fx_px * depth_m, (v_px - cy_px) / fy_px * depth_m,
                         depth_m);
}

}  // namespace vo
