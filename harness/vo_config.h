// VO configuration files (`vobench run --config VO.yaml`): a YAML mapping whose keys mirror
// vo::OdometryOptions (nested: `matcher: {type: svd_ncc_gabor, svd: {sigma_px: 10}}`). Keys
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

}  // namespace harness
