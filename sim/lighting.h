// Light that changes (issue #34): lamps switched on and off at set times, a slow global brightness
// drift, a flicker (scenario keys lights.*, sim/scenario.h LightsOptions), applied to MuJoCo's
// light and material properties before each render; and the camera's auto-exposure
// (camera.auto_exposure, AutoExposureOptions), a first-order loop on the rendered grey levels.
// Everything is a function of the render's time: deterministic, no random draws.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sim/scenario.h"

struct mjModel_;
typedef struct mjModel_ mjModel;

namespace sim {

// The global brightness factor at time t (s from frame 0), LightsOptions' formula: the drift
// times the flicker, >= 0; 1 without either.
double GlobalBrightness(const LightsOptions& options, double t_s);

// Whether light `light` is on at time t: its last switch at or before t, else on (every lamp of
// a scene starts on).
bool LightOnAt(const LightsOptions& options, int light, double t_s);

// The scene's lights and materials as loaded, and their state at a time. Apply() writes
// light_diffuse, light_ambient, light_specular (times the brightness; 0 for a lamp switched off)
// and mat_emission (times the brightness) of `m` from the values captured by the constructor; a
// lamp switched off stays active with a black colour (MuJoCo draws a scene without any active
// light unlit, at full brightness). Without any lights.* option it writes nothing (renders stay
// byte-identical).
class SceneLighting {
 public:
  SceneLighting(const mjModel* m, const LightsOptions& options);
  void Apply(mjModel* m, double t_s) const;

 private:
  LightsOptions options_;
  std::vector<unsigned char> active_;
  std::vector<float> diffuse_, ambient_, specular_, emission_;
};

// The index of the scene's light named `name`, or given as a whole number ("0", "1", ...) within
// [0, nlight): -1 when there is none; *known lists the lights (for messages).
int FindLight(const mjModel* m, const std::string& name, std::string* known);

// Gains the auto-exposure keeps to (a camera's range of exposure times and analogue gains).
constexpr double kMinExposureGain = 1.0 / 16.0;
constexpr double kMaxExposureGain = 16.0;

// The auto-exposure loop of AutoExposureOptions: Update() with each frame's render (grey, CV_32F,
// at gain 1) gives that frame's gain; the caller multiplies both cameras' renders by it.
class AutoExposure {
 public:
  AutoExposure(const AutoExposureOptions& options, double frame_period_s);
  // The mean of `grey` (CV_32FC1) steers the gain; the first call starts converged.
  double Update(const cv::Mat& grey);
  // The same on a measured mean (grey levels at gain 1).
  double UpdateOnMean(double mean);
  double gain() const { return gain_; }
  double alpha() const { return alpha_; }  // 1 - exp(-T / time_constant_s)

 private:
  AutoExposureOptions options_;
  double alpha_ = 1.0;
  double gain_ = 1.0;
  bool started_ = false;
};

}  // namespace sim
