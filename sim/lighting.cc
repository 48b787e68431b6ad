#include "sim/lighting.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace sim {

double GlobalBrightness(const LightsOptions& o, double t_s) {
  const double drift = std::max(0.0, 1.0 + o.brightness_drift * t_s / 60.0);
  double flicker = 1.0;
  if (o.flicker_hz > 0.0 && o.flicker_depth > 0.0)
    flicker = 1.0 - o.flicker_depth * 0.5 * (1.0 - std::cos(2.0 * M_PI * o.flicker_hz * t_s));
  return drift * flicker;
}

bool LightOnAt(const LightsOptions& o, int light, double t_s) {
  bool on = true;
  for (const LightSwitch& s : o.switches)  // in time order: the last one at or before t wins
    if (s.light == light && s.at_s <= t_s) on = s.on;
  return on;
}

SceneLighting::SceneLighting(const mjModel* m, const LightsOptions& options) : options_(options) {
  active_.assign(m->light_active, m->light_active + m->nlight);
  diffuse_.assign(m->light_diffuse, m->light_diffuse + 3 * m->nlight);
  ambient_.assign(m->light_ambient, m->light_ambient + 3 * m->nlight);
  specular_.assign(m->light_specular, m->light_specular + 3 * m->nlight);
  emission_.assign(m->mat_emission, m->mat_emission + m->nmat);
}

void SceneLighting::Apply(mjModel* m, double t_s) const {
  if (!options_.any()) return;
  const float b = static_cast<float>(GlobalBrightness(options_, t_s));
  for (int i = 0; i < m->nlight; ++i) {
    // A lamp switched off gives no light. It stays active with a black colour: MuJoCo's renderer
    // draws a scene without any active light unlit (full brightness), not dark.
    const float on = LightOnAt(options_, i, t_s) ? b : 0.0f;
    m->light_active[i] = active_[i];
    for (int c = 0; c < 3; ++c) {
      m->light_diffuse[3 * i + c] = on * diffuse_[3 * i + c];
      m->light_ambient[3 * i + c] = on * ambient_[3 * i + c];
      m->light_specular[3 * i + c] = on * specular_[3 * i + c];
    }
  }
  for (int i = 0; i < m->nmat; ++i) m->mat_emission[i] = b * emission_[i];
}

int FindLight(const mjModel* m, const std::string& name, std::string* known) {
  int found = -1;
  known->clear();
  for (int i = 0; i < m->nlight; ++i) {
    const char* n = mj_id2name(m, mjOBJ_LIGHT, i);
    *known += (known->empty() ? "" : ", ") + std::to_string(i);
    if (n && *n) *known += std::string(" (") + n + ")";
    if (n && name == n) found = i;
  }
  if (found < 0 && !name.empty() && name.find_first_not_of("0123456789") == std::string::npos &&
      name.size() < 6) {
    const int i = std::atoi(name.c_str());
    if (i < m->nlight) found = i;
  }
  return found;
}

AutoExposure::AutoExposure(const AutoExposureOptions& options, double frame_period_s)
    : options_(options), alpha_(1.0 - std::exp(-frame_period_s / options.time_constant_s)) {}

double AutoExposure::Update(const cv::Mat& grey) { return UpdateOnMean(cv::mean(grey)[0]); }

double AutoExposure::UpdateOnMean(double mean) {
  const double wanted =
      std::clamp(options_.target_mean / std::max(mean, 1e-6), kMinExposureGain, kMaxExposureGain);
  gain_ = started_ ? gain_ + alpha_ * (wanted - gain_) : wanted;
  started_ = true;
  return gain_;
}

}  // namespace sim
