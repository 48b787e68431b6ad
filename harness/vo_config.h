// VO configuration files (`vobench run --config VO.yaml`): a YAML mapping grouped by the
// pipeline's stages, in the order a frame meets them: platform and vehicle (the one place that
// configures the stages for a ground vehicle), front_end, initial_orientation, tracker, motion,
// recovery, back_end (nested: `tracker: {matcher: {type: svd_ncc_gabor, svd: {sigma_px: 10}}}`;
// docs/DESIGN.md, "VO options by stage"). The keys of the earlier flat layout are refused with
// the new key's name (RenamedVoKey). Keys
// not given keep the library defaults; unknown keys, wrong types and invalid values are
// refused with the file, line and key. The effective options are written back in the same
// form (every supported key), so a result can be reproduced with --config.
#pragma once

#include <string>

#include "vo/odometry.h"

namespace harness {

// Applies the YAML text to *options (starting from its current values).
bool ParseVoConfig(const std::string& yaml_text, const std::string& source_name,
                   vo::OdometryOptions* options, std::string* error);
bool LoadVoConfig(const std::string& path, vo::OdometryOptions* options, std::string* error);

// Every supported key with its effective value, as YAML that ParseVoConfig accepts.
std::string VoConfigToYaml(const vo::OdometryOptions& options);

// The new key of a key that vo_options.yaml had before its options were grouped by the
// pipeline's stages (issue #32: "tracking.few_point_motion" -> "motion.few_point.enabled",
// "matcher.type" -> "tracker.matcher.type"); "" when `old_key` is no old key, or when the option
// became a constant (then *constant, when given, names it). ParseVoConfig refuses old keys with
// this name in its message.
std::string RenamedVoKey(const std::string& old_key, std::string* constant = nullptr);

}  // namespace harness
