// Offscreen rendering of MuJoCo cameras through OSMesa (no display, no X server).
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace sim {

class OffscreenRenderer {
 public:
  // Makes an OSMesa context current on this thread and a MuJoCo render context for `model`.
  // The model's vis.global.offwidth/offheight must be >= width/height. Returns nullptr and
  // fills *error when no OSMesa context can be made. Logs the GL renderer string once.
  static std::unique_ptr<OffscreenRenderer> Create(const mjModel* model, int width, int height,
                                                   std::string* error);
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  // Renders fixed camera `cam_id` at the state in `data` (after mj_forward / mj_step).
  // rgb: CV_8UC3 (RGB order), row 0 = image top; may be null.
  // depth_m: CV_32FC1 z-depth along the optical axis (m), 0 where nothing was hit; may be null.
  void Render(const mjModel* model, mjData* data, int cam_id, cv::Mat* rgb, cv::Mat* depth_m);

  // "renderer | version" of the current GL context.
  const std::string& gl_renderer() const { return gl_renderer_; }

 private:
  OffscreenRenderer() = default;

  int width_ = 0;
  int height_ = 0;
  std::string gl_renderer_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sim
