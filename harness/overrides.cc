#include "harness/overrides.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>

#include "harness/vo_config.h"

namespace harness {

namespace {

// Splits "a.b.c" at dots; false on an empty component.
bool SplitPath(const std::string& key, std::vector<std::string>* parts) {
  parts->clear();
  std::string part;
  std::istringstream in(key);
  while (std::getline(in, part, '.')) {
    if (part.empty()) return false;
    parts->push_back(part);
  }
  return !parts->empty() && key.back() != '.';
}

bool NestInto(const YAML::Node& overrides, const std::string& prefix,
              const std::string& source_name, YAML::Node out, std::string* error) {
  for (const auto& kv : overrides) {
    const std::string key = kv.first.as<std::string>();
    std::vector<std::string> parts;
    if (!SplitPath(key, &parts)) {
      *error = source_name + ": override key '" + prefix + key + "' has an empty path component";
      return false;
    }
    YAML::Node node = out;
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
      YAML::Node child = node[parts[i]];
      if (child.IsDefined() && !child.IsMap()) {
        *error = source_name + ": override key '" + prefix + key + "' conflicts with '" + parts[i] +
                 "' given as a value";
        return false;
      }
      if (!child.IsDefined()) node[parts[i]] = YAML::Node(YAML::NodeType::Map);
      node.reset(node[parts[i]]);
    }
    const std::string& leaf = parts.back();
    const std::string full = prefix + key;
    if (kv.second.IsMap()) {
      YAML::Node child = node[leaf];
      if (child.IsDefined() && !child.IsMap()) {
        *error = source_name + ": override key '" + full + "' is given twice";
        return false;
      }
      if (!child.IsDefined()) node[leaf] = YAML::Node(YAML::NodeType::Map);
      if (!NestInto(kv.second, full + ".", source_name, node[leaf], error)) return false;
    } else {
      if (node[leaf].IsDefined()) {
        *error = source_name + ": override key '" + full + "' is given twice";
        return false;
      }
      node[leaf] = YAML::Clone(kv.second);
    }
  }
  return true;
}

}  // namespace

bool NestDottedKeys(const YAML::Node& overrides, const std::string& source_name, YAML::Node* nested,
                    std::string* error) {
  *nested = YAML::Node(YAML::NodeType::Map);
  if (!overrides.IsDefined() || overrides.IsNull()) return true;
  if (!overrides.IsMap()) {
    *error = source_name + ": overrides must be a mapping of keys to values";
    return false;
  }
  return NestInto(overrides, "", source_name, *nested, error);
}

void DeepMerge(const YAML::Node& overrides, YAML::Node base) {
  for (const auto& kv : overrides) {
    const std::string key = kv.first.as<std::string>();
    YAML::Node target = base[key];
    if (kv.second.IsMap() && target.IsDefined() && target.IsMap()) {
      DeepMerge(kv.second, target);
    } else {
      base[key] = YAML::Clone(kv.second);
    }
  }
}

bool ApplyScenarioOverrides(const sim::Scenario& base, const YAML::Node& overrides,
                            const std::string& source_name, sim::Scenario* scenario,
                            std::string* error) {
  YAML::Node nested;
  if (!NestDottedKeys(overrides, source_name, &nested, error)) return false;
  YAML::Node doc = YAML::Load(sim::ScenarioToYaml(base));
  DeepMerge(nested, doc);
  YAML::Emitter out;
  out << doc;
  // ScenarioToYaml writes the scene as an absolute path, so no base folder is needed.
  const std::string base_dir = base.source_path.empty()
                                   ? std::string(".")
                                   : std::filesystem::path(base.source_path).parent_path().string();
  sim::Scenario result;
  if (!sim::ParseScenario(out.c_str(), source_name + " (overrides of " + base.name + ")", base_dir,
                          &result, error)) {
    return false;
  }
  result.source_path = base.source_path;
  *scenario = result;
  return true;
}

bool ApplyVoOverrides(const YAML::Node& overrides, const std::string& source_name,
                      vo::OdometryOptions* options, std::string* error) {
  YAML::Node nested;
  if (!NestDottedKeys(overrides, source_name, &nested, error)) return false;
  YAML::Emitter out;
  out << nested;
  vo::OdometryOptions result = *options;
  if (!ParseVoConfig(out.c_str(), source_name + " (VO overrides)", &result, error)) return false;
  *options = result;
  return true;
}

std::string OverrideErrorAt(const std::string& where, const std::string& key_prefix,
                            const std::string& message) {
  const std::string source = kOverridesSource;
  if (message.rfind(source, 0) != 0) return message;
  size_t at = source.size();
  // The strict reader's own source name: " (VO overrides)" or " (overrides of NAME)".
  for (const std::string inner : {" (VO overrides)", " (overrides of "}) {
    if (message.compare(at, inner.size(), inner) != 0) continue;
    at += inner.size();
    if (inner.back() == ' ') {
      while (at < message.size() && !(message[at] == ')' && message.compare(at + 1, 1, ":") == 0))
        ++at;
      ++at;
    }
    break;
  }
  // The line in the generated text means nothing to the user.
  if (at < message.size() && message[at] == ':') {
    size_t digits = at + 1;
    while (digits < message.size() && std::isdigit(static_cast<unsigned char>(message[digits])))
      ++digits;
    if (digits > at + 1) at = digits;
  }
  if (message.compare(at, 2, ": ") == 0) at += 2;
  std::string rest = message.substr(std::min(at, message.size()));
  std::string key = key_prefix;
  if (rest.rfind("key '", 0) == 0) {
    const size_t end = rest.find("': ", 5);
    if (end != std::string::npos) {
      key += "." + rest.substr(5, end - 5);
      rest = rest.substr(end + 3);
    }
  }
  return where + ": key '" + key + "': " + rest;
}

std::string FlowYaml(const YAML::Node& node) {
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

}  // namespace harness
