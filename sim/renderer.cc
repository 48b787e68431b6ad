#include "sim/renderer.h"

#include <GL/osmesa.h>
#include <spdlog/spdlog.h>

#include <cstring>
#include <vector>

namespace sim {

struct OffscreenRenderer::Impl {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> window_buffer;  // OSMesa's default framebuffer (unused for drawing)
  mjvScene scene;
  mjvCamera camera;
  mjvOption option;
  mjrContext render_context;
  std::vector<unsigned char> rgb_flipped;
  std::vector<float> depth_flipped;
  bool scene_made = false;
  bool context_made = false;
};

std::unique_ptr<OffscreenRenderer> OffscreenRenderer::Create(const mjModel* model, int width,
                                                             int height, std::string* error) {
  if (model->vis.global.offwidth < width || model->vis.global.offheight < height) {
    if (error)
      *error = "offscreen buffer of the model (" + std::to_string(model->vis.global.offwidth) +
               "x" + std::to_string(model->vis.global.offheight) +
               ") is smaller than the requested " + std::to_string(width) + "x" +
               std::to_string(height);
    return nullptr;
  }
  std::unique_ptr<OffscreenRenderer> r(new OffscreenRenderer());
  r->width_ = width;
  r->height_ = height;
  r->impl_ = std::make_unique<Impl>();
  Impl& im = *r->impl_;
  im.context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (!im.context) {
    if (error)
      *error = "could not create an OSMesa context (is libOSMesa from libosmesa6 installed?)";
    return nullptr;
  }
  im.window_buffer.assign(static_cast<size_t>(width) * height * 4, 0);
  if (!OSMesaMakeCurrent(im.context, im.window_buffer.data(), GL_UNSIGNED_BYTE, width, height)) {
    if (error) *error = "could not make the OSMesa context current";
    return nullptr;
  }
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  r->gl_renderer_ = std::string(renderer ? renderer : "?") + " | " + (version ? version : "?");
  static bool logged = false;
  if (!logged) {
    spdlog::info("OpenGL renderer: {}", r->gl_renderer_);
    logged = true;
  }

  mjv_defaultScene(&im.scene);
  mjv_defaultCamera(&im.camera);
  mjv_defaultOption(&im.option);
  mjr_defaultContext(&im.render_context);
  mjv_makeScene(model, &im.scene, 2000);
  im.scene_made = true;
  mjr_makeContext(model, &im.render_context, mjFONTSCALE_100);
  im.context_made = true;
  mjr_setBuffer(mjFB_OFFSCREEN, &im.render_context);
  if (im.render_context.currentBuffer != mjFB_OFFSCREEN) {
    if (error) *error = "MuJoCo could not select its offscreen framebuffer in the OSMesa context";
    return nullptr;
  }
  // Plain, view-independent rendering: no shadows, reflections, skybox or fog.
  im.scene.flags[mjRND_SHADOW] = 0;
  im.scene.flags[mjRND_REFLECTION] = 0;
  im.scene.flags[mjRND_SKYBOX] = 0;
  im.scene.flags[mjRND_FOG] = 0;
  // Geom group 3 holds collision-only geoms (the physics floor): never drawn.
  im.option.geomgroup[3] = 0;
  im.camera.type = mjCAMERA_FIXED;
  im.rgb_flipped.resize(static_cast<size_t>(width) * height * 3);
  im.depth_flipped.resize(static_cast<size_t>(width) * height);
  return r;
}

OffscreenRenderer::~OffscreenRenderer() {
  if (!impl_) return;
  if (impl_->context_made) mjr_freeContext(&impl_->render_context);
  if (impl_->scene_made) mjv_freeScene(&impl_->scene);
  if (impl_->context) OSMesaDestroyContext(impl_->context);
}

void OffscreenRenderer::Render(const mjModel* model, mjData* data, int cam_id, cv::Mat* rgb,
                               cv::Mat* depth_m) {
  Impl& im = *impl_;
  im.camera.fixedcamid = cam_id;
  mjv_updateScene(model, data, &im.option, nullptr, &im.camera, mjCAT_ALL, &im.scene);
  const mjrRect viewport = {0, 0, width_, height_};
  mjr_render(viewport, &im.scene, &im.render_context);
  mjr_readPixels(rgb ? im.rgb_flipped.data() : nullptr, depth_m ? im.depth_flipped.data() : nullptr,
                 viewport, &im.render_context);
  // mjr_readPixels returns rows bottom-up (OpenGL); images here are top-down.
  if (rgb) {
    rgb->create(height_, width_, CV_8UC3);
    for (int r = 0; r < height_; ++r) {
      std::memcpy(rgb->ptr<unsigned char>(r),
                  &im.rgb_flipped[static_cast<size_t>(height_ - 1 - r) * width_ * 3],
                  static_cast<size_t>(width_) * 3);
    }
  }
  if (depth_m) {
    // Linearise the depth buffer of a glFrustum projection: z = n f / (f - d (f - n)).
    const double extent = model->stat.extent;
    const double n = model->vis.map.znear * extent;
    const double f = model->vis.map.zfar * extent;
    depth_m->create(height_, width_, CV_32FC1);
    for (int r = 0; r < height_; ++r) {
      const float* src = &im.depth_flipped[static_cast<size_t>(height_ - 1 - r) * width_];
      float* dst = depth_m->ptr<float>(r);
      for (int c = 0; c < width_; ++c) {
        const double d = src[c];
        dst[c] = d >= 1.0 ? 0.0f : static_cast<float>(n * f / (f - d * (f - n)));
      }
    }
  }
}

}  // namespace sim
