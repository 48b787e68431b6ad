// Plain data types that cross VO stage boundaries.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

namespace vo {

// A feature detected in the left (cam0) image, with optional 3D from the disparity map.
struct Feature {
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();  // position in the left image (pixels)
  double response = 0.0;  // detector score (Harris response or SIFT contrast); larger = stronger
  double disparity_px = -1.0;  // x_left - x_right (pixels); < 0 when no valid disparity
  Eigen::Vector3d p_cam0 = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // 3D point in the cam0 frame (metres); valid iff has_depth()
  int64_t track_id = -1;  // id of the multi-frame track this feature belongs to; -1 = none
  int track_age = 0;      // number of earlier frames this track was seen in

  bool has_depth() const { return disparity_px > 0.0; }
};

// A one-to-one correspondence between feature `prev` of the previous frame and feature `curr`
// of the current frame (indices into the frames' feature vectors).
struct Match {
  int prev = -1;
  int curr = -1;
  double score = 0.0;  // matcher-specific confidence; larger = better
};

}  // namespace vo
