// Overrides of scenario and VO option keys, as suites and tuning use them: a YAML mapping whose
// keys are dotted paths ("noise.pixel_sigma: 3", "tracker.matcher.svd.sigma_px: 12") or nested maps
// ("noise: {pixel_sigma: 3}"), deep-merged onto the effective YAML of the base and parsed again
// by the strict readers, so an unknown key or a bad value is refused with its name.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "sim/scenario.h"
#include "vo/odometry.h"

namespace harness {

// Turns dotted keys into nested maps ("a.b: 1" -> {a: {b: 1}}), recursively; nested maps and
// dotted keys may be mixed. Fails (with `source_name` in the message) on a non-map input, an
// empty path component, or a key given twice.
bool NestDottedKeys(const YAML::Node& overrides, const std::string& source_name, YAML::Node* nested,
                    std::string* error);

// Deep-merges `overrides` (nested maps) onto `base`: maps merge key by key, anything else
// replaces the base's value.
void DeepMerge(const YAML::Node& overrides, YAML::Node base);

// base + overrides -> *scenario (validated). `source_name` names where the overrides come from.
bool ApplyScenarioOverrides(const sim::Scenario& base, const YAML::Node& overrides,
                            const std::string& source_name, sim::Scenario* scenario,
                            std::string* error);

// *options + overrides -> *options (validated by the VO config reader).
bool ApplyVoOverrides(const YAML::Node& overrides, const std::string& source_name,
                      vo::OdometryOptions* options, std::string* error);

// The source name to give ApplyScenarioOverrides / ApplyVoOverrides for overrides read from a
// file (a suite's or tune file's `set:`); OverrideErrorAt then tells their message in the one
// format of the readers, at the place of the overrides in that file:
//   "(overrides) (VO overrides):1: key 'matcher.type': expected ..."
//   -> "WHERE: key 'KEY_PREFIX.matcher.type': expected ..."
// (WHERE = "FILE:LINE" of the override map, KEY_PREFIX its key, e.g. "configs[0].set"). A
// message without a key ("invalid VO options: ...") is told under KEY_PREFIX itself; a message
// from another source is returned as it is.
inline constexpr char kOverridesSource[] = "(overrides)";
std::string OverrideErrorAt(const std::string& where, const std::string& key_prefix,
                            const std::string& message);

// A YAML node as one line of flow-style text (for names, logs and messages).
std::string FlowYaml(const YAML::Node& node);

}  // namespace harness
