#include "harness/suite/spec.h"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "harness/overrides.h"
#include "harness/path_names.h"
#include "harness/run.h"
#include "harness/suite/folder.h"
#include "harness/vo_config.h"
#include "sim/yaml_input.h"

namespace harness {

namespace {

namespace fs = std::filesystem;
using sim::YamlReader;
using suite_internal::ReadWholeFile;

constexpr int kIntMax = std::numeric_limits<int>::max();

// Checks every (dotted or nested) key of an override map against `reference` (an effective
// document that has every supported key), so a typo is reported at its line in the suite file.
void CheckOverrideKeys(const YAML::Node& set, const YAML::Node& reference,
                       const std::string& key_prefix, const std::string& what, YamlReader* r) {
  for (const auto& kv : set) {
    if (!r->ok()) return;
    const std::string key = kv.first.Scalar();
    YAML::Node node = reference;
    std::stringstream parts(key);
    std::string part;
    bool found = true;
    while (std::getline(parts, part, '.')) {
      if (!node.IsMap() || !node[part].IsDefined()) {
        found = false;
        break;
      }
      node.reset(node[part]);
    }
    const std::string full = YamlReader::Join(key_prefix, key);
    if (!found || key.empty() || key.back() == '.') {
      r->Fail(kv.first, full, "unknown " + what + " key");
      return;
    }
    if (kv.second.IsMap()) {
      if (!node.IsMap()) {
        r->Fail(kv.first, full, "expected a single value, got a mapping");
        return;
      }
      CheckOverrideKeys(kv.second, node, full, what, r);
    }
  }
}

// The scenario of a suite entry: a file relative to the suite, or a built-in name.
bool ResolveSuiteScenario(const std::string& value, const fs::path& base_dir,
                          const YAML::Node& node, const std::string& key, sim::Scenario* scenario,
                          YamlReader* r) {
  fs::path path = value;
  if (path.is_relative()) path = base_dir / path;
  const std::string builtin = sim::BuiltinScenarioPath(value);
  if (!fs::is_regular_file(path)) {
    if (value.find('/') == std::string::npos && fs::is_regular_file(builtin)) {
      path = builtin;
    } else {
      r->Fail(node, key,
              "no scenario file '" + path.lexically_normal().string() +
                  "' and no built-in scenario '" + value + "' in " +
                  fs::path(builtin).parent_path().string());
      return false;
    }
  }
  std::string error;
  if (!sim::LoadScenario(path.string(), scenario, &error)) {
    r->Fail(node, key, error);
    return false;
  }
  return true;
}

// A configuration's `external:` mapping (suite/external.h).
void ParseExternal(const YAML::Node& node, const std::string& key, const std::string& base_dir,
                   ExternalEstimator* e, YamlReader* r) {
  if (!r->ExpectMap(node, key, "a mapping with command, trajectory, format (and timeout_s)"))
    return;
  r->CheckKeys(node, key, {"command", "trajectory", "format", "timeout_s"});
  if (!r->Require(node, key, "command", "the program and its arguments, a list") ||
      !r->Require(node, key, "trajectory", "the trajectory file the command writes in {out}") ||
      !r->Require(node, key, "format", "the trajectory's format, kitti or tum"))
    return;
  const YAML::Node command = node["command"];
  if (!command.IsSequence() || command.size() == 0) {
    r->Fail(command, key + ".command", "expected a list: the program, then its arguments");
    return;
  }
  e->command.clear();
  for (size_t i = 0; r->ok() && i < command.size(); ++i) {
    std::string a;
    if (r->ReadString(command[i], YamlReader::Item(key + ".command", i), &a, i > 0))
      e->command.push_back(a);
  }
  r->String(node, key, "trajectory", &e->trajectory, false);
  r->Enum(node, key, "format",
          std::vector<std::pair<std::string, TrajectoryFormat>>{{"kitti", TrajectoryFormat::kKitti},
                                                                {"tum", TrajectoryFormat::kTum}},
          &e->format);
  if (r->ok() && YamlReader::Has(node, "timeout_s"))
    r->ReadDoubleIn(node["timeout_s"], key + ".timeout_s", 1e-3, 1e7, &e->timeout_s);
  if (!r->ok()) return;
  std::string why;
  if (!CheckExternalEstimator(*e, &why)) {
    // why is "command[1]: ...", "trajectory: ...": the key below `external` and the problem.
    const size_t colon = why.find(": ");
    const std::string part = why.substr(0, why.find_first_of("[:"));
    r->Fail(node[part].IsDefined() ? node[part] : node, key + "." + why.substr(0, colon),
            why.substr(colon + 2));
    return;
  }
  // A program given as a path: relative to the suite file, and it must be there.
  std::string& program = e->command[0];
  e->program_given = program;
  if (program.find('/') != std::string::npos) {
    fs::path path = program;
    if (path.is_relative()) path = fs::path(base_dir) / path;
    program = path.lexically_normal().string();
    if (!fs::is_regular_file(path) || access(program.c_str(), X_OK) != 0)
      r->Fail(command[0], key + ".command[0]",
              "no executable program '" + program + "' (a path is relative to the suite file)");
  }
}

}  // namespace

bool CheckRunIdPart(const std::string& name, const std::string& what, std::string* why) {
  if (!CheckPathName(name, what, why)) return false;
  static const std::regex kName("[A-Za-z0-9_.-]+");
  if (std::regex_match(name, kName) && name.find("__") == std::string::npos) return true;
  *why = what + " '" + name + "': expected letters, digits, '_', '.', '-' (no '__')";
  return false;
}

namespace {

// What vobench appends to a run id in a file name: "<id>.partial-<pid>-XXXXXX" (the run's work
// folder), "<id>.failed.txt.tmp<pid>"; a pid has at most 7 digits (pid_max 4194304).
constexpr size_t kLongestIdSuffix = std::char_traits<char>::length(".failed.txt.tmp") + 7 + 2;

// Before the first run starts: every run id fits in a file name with the longest suffix, and
// each scenario's frame limit and the strides leave the VO 2 frames (a suite of runs that
// would all fail is refused at the line to change).
void CheckRunsCanRun(const Suite& s, const YAML::Node& root, YamlReader* r) {
  const std::vector<uint64_t> no_seeds;
  for (size_t i = 0; i < s.scenarios.size() && r->ok(); ++i) {
    const SuiteScenario& sc = s.scenarios[i];
    const YAML::Node entry = root["scenarios"][i];
    const std::string key = "scenarios[" + std::to_string(i) + "]";
    const std::vector<uint64_t> seeds =
        s.seeds.empty() ? std::vector<uint64_t>{sc.scenario.seed} : s.seeds;
    for (const SuiteConfig& c : s.configs)
      for (uint64_t seed : seeds)
        for (int stride : s.strides) {
          const std::string id = sc.name + "__" + c.name + "__s" + std::to_string(seed) + "__k" +
                                 std::to_string(stride);
          if (id.size() + kLongestIdSuffix > kMaxPathNameBytes && r->ok())
            r->Fail(entry["name"].IsDefined() ? entry["name"] : entry, key + ".name",
                    "run id '" + id.substr(0, 40) + "...' (" + std::to_string(id.size()) +
                        " bytes: scenario, configuration, seed and stride) leaves no room for "
                        "the file names made from it (" +
                        std::to_string(kLongestIdSuffix) + " more bytes, at most " +
                        std::to_string(kMaxPathNameBytes) +
                        "): shorten the scenario or configuration name");
        }
    for (int stride : s.strides) {
      const std::string problem =
          FrameBudgetProblem(sim::EstimatedFrames(sc.scenario), true, sc.max_frames, stride);
      if (problem.empty() || !r->ok()) continue;
      const YAML::Node at = entry["max_frames"].IsDefined() ? entry["max_frames"]
                            : root["max_frames"].IsDefined() && sc.max_frames > 0
                                ? root["max_frames"]
                            : root["strides"].IsDefined() ? root["strides"]
                                                          : entry;
      // The option names of `vobench run` read as the suite's keys here.
      std::string what = std::regex_replace(problem, std::regex("--max-frames"), "max_frames");
      what = std::regex_replace(what, std::regex("--stride"), "stride");
      r->Fail(at, key, what);
    }
  }
}

}  // namespace

bool ParseSuite(const std::string& yaml_text, const std::string& source_name,
                const std::string& base_dir, Suite* suite, std::string* error) {
  YamlReader r(source_name);
  if (!r.Parse(yaml_text)) return r.Report(error);
  YAML::Node root = r.root();  // not const: a missing key reads as undefined, not invalid
  if (!root.IsMap()) {
    *error =
        source_name + ": expected a YAML mapping at the top level (name, scenarios, configs, ...)";
    return false;
  }
  Suite s;
  s.source_text = yaml_text;
  r.CheckKeys(root, "", {"name", "max_frames", "scenarios", "configs", "seeds", "strides"});
  if (r.Require(root, "", "name", "the suite's name")) r.String(root, "", "name", &s.name, false);
  std::string name_error;
  if (r.ok() && !CheckRunIdPart(s.name, "suite name", &name_error))
    r.Fail(root["name"], "name", name_error);
  int default_max_frames = 0;
  r.Int(root, "", "max_frames", 0, kIntMax, &default_max_frames);

  // scenarios
  const YAML::Node scenarios = root["scenarios"];
  if (r.ok() && (!scenarios.IsSequence() || scenarios.size() == 0))
    r.Fail(scenarios.IsDefined() ? scenarios : root, "scenarios",
           "required: a list of at least one scenario");
  std::set<std::string> names;
  for (size_t i = 0; r.ok() && i < scenarios.size(); ++i) {
    const YAML::Node e = scenarios[i];
    const std::string key = "scenarios[" + std::to_string(i) + "]";
    r.CheckKeys(e, key, {"name", "scenario", "set", "max_frames"});
    SuiteScenario sc;
    std::string value;
    if (!r.Require(e, key, "scenario",
                   "a built-in scenario name or a scenario file relative to the suite") ||
        !r.String(e, key, "scenario", &value, false))
      break;
    sim::Scenario base;
    if (!ResolveSuiteScenario(value, base_dir, e["scenario"], key + ".scenario", &base, &r)) break;
    sc.name = base.name;
    r.String(e, key, "name", &sc.name, false);
    if (r.ok() && !CheckRunIdPart(sc.name, "scenario name", &name_error))
      r.Fail(e["name"].IsDefined() ? e["name"] : e["scenario"], key + ".name", name_error);
    if (r.ok() && !names.insert(sc.name).second)
      r.Fail(e, key + ".name", "scenario name '" + sc.name + "' is used twice");
    sc.max_frames = default_max_frames;
    r.Int(e, key, "max_frames", 0, kIntMax, &sc.max_frames);
    sc.scenario = base;
    if (const YAML::Node set = e["set"]; set.IsDefined() && r.ok()) {
      if (!set.IsMap()) {
        r.Fail(set, key + ".set", "expected a mapping of scenario keys to values");
        break;
      }
      // Every key, the optional sections too (written only where set).
      CheckOverrideKeys(set, YAML::Load(sim::ScenarioKeysYaml(base)), key + ".set", "scenario", &r);
      std::string why;
      if (r.ok() && !ApplyScenarioOverrides(base, set, kOverridesSource, &sc.scenario, &why))
        r.SetError(OverrideErrorAt(r.Where(set), key + ".set", why));
    }
    s.scenarios.push_back(sc);
  }

  // configs
  const YAML::Node configs = root["configs"];
  if (r.ok() && (!configs.IsSequence() || configs.size() == 0))
    r.Fail(configs.IsDefined() ? configs : root, "configs",
           "required: a list of at least one VO configuration");
  names.clear();
  const YAML::Node vo_reference = YAML::Load(VoConfigToYaml(vo::OdometryOptions()));
  for (size_t i = 0; r.ok() && i < configs.size(); ++i) {
    const YAML::Node e = configs[i];
    const std::string key = "configs[" + std::to_string(i) + "]";
    r.CheckKeys(e, key, {"name", "config", "set", "external"});
    SuiteConfig c;
    if (!r.Require(e, key, "name", "the configuration's name") ||
        !r.String(e, key, "name", &c.name, false))
      break;
    if (!CheckRunIdPart(c.name, "configuration name", &name_error))
      r.Fail(e["name"], key + ".name", name_error);
    if (r.ok() && !names.insert(c.name).second)
      r.Fail(e["name"], key + ".name", "configuration name '" + c.name + "' is used twice");
    if (r.ok() && YamlReader::Has(e, "external")) {
      for (const char* k : {"config", "set"})
        if (YamlReader::Has(e, k))
          r.Fail(e[k], key + "." + k,
                 "not with external (an external program has no VO options; give its "
                 "settings in its command)");
      c.external = true;
      if (r.ok()) ParseExternal(e["external"], key + ".external", base_dir, &c.estimator, &r);
      s.configs.push_back(c);
      continue;
    }
    std::string file;
    if (YamlReader::Has(e, "config") && r.String(e, key, "config", &file, false)) {
      fs::path path = file;
      if (path.is_relative()) path = fs::path(base_dir) / path;
      std::string why;
      if (!fs::is_regular_file(path))
        r.Fail(e["config"], key + ".config",
               "no VO config file '" + path.lexically_normal().string() + "'");
      else if (!LoadVoConfig(path.string(), &c.options, &why))
        r.Fail(e["config"], key + ".config", why);
    }
    if (const YAML::Node set = e["set"]; set.IsDefined() && r.ok()) {
      if (!set.IsMap()) {
        r.Fail(set, key + ".set", "expected a mapping of VO option keys to values");
        break;
      }
      CheckOverrideKeys(set, vo_reference, key + ".set", "VO option", &r);
      std::string why;
      if (r.ok() && !ApplyVoOverrides(set, kOverridesSource, &c.options, &why))
        r.SetError(OverrideErrorAt(r.Where(set), key + ".set", why));
    }
    s.configs.push_back(c);
  }

  // seeds, strides
  if (const YAML::Node seeds = root["seeds"]; seeds.IsDefined() && r.ok()) {
    if (!seeds.IsSequence() || seeds.size() == 0)
      r.Fail(seeds, "seeds", "expected a list of noise seeds (integers >= 0)");
    std::set<uint64_t> seen;
    for (size_t i = 0; r.ok() && i < seeds.size(); ++i) {
      uint64_t v = 0;
      if (r.ReadUint64(seeds[i], YamlReader::Item("seeds", i), &v) && !seen.insert(v).second)
        r.Fail(seeds[i], "seeds[" + std::to_string(i) + "]",
               "seed " + std::to_string(v) + " is given twice");
      s.seeds.push_back(v);
    }
  }
  if (const YAML::Node strides = root["strides"]; strides.IsDefined() && r.ok()) {
    s.strides.clear();
    if (!strides.IsSequence() || strides.size() == 0)
      r.Fail(strides, "strides", "expected a list of frame strides (integers >= 1)");
    std::set<int> seen;
    for (size_t i = 0; r.ok() && i < strides.size(); ++i) {
      int v = 0;
      if (r.ReadInt(strides[i], YamlReader::Item("strides", i), 1, kIntMax, &v) &&
          !seen.insert(v).second)
        r.Fail(strides[i], "strides[" + std::to_string(i) + "]",
               "stride " + std::to_string(v) + " is given twice");
      s.strides.push_back(v);
    }
  }
  if (r.ok()) CheckRunsCanRun(s, root, &r);
  if (!r.Report(error)) return false;
  *suite = s;
  return true;
}

bool LoadSuite(const std::string& path, Suite* suite, std::string* error) {
  std::string text;
  if (!sim::ReadInputFile(path, "YAML suite file", &text, error)) return false;
  if (!ParseSuite(text, path, fs::absolute(path).parent_path().string(), suite, error))
    return false;
  suite->source_path = path;
  return true;
}

std::string Fnv1aHex(const std::string& text) {
  uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::vector<SuiteRun> ExpandSuite(const Suite& suite) {
  std::vector<SuiteRun> runs;
  std::map<std::string, std::string> scene_ids;  // absolute scene path -> "name#content hash"
  for (const auto& sc : suite.scenarios) {
    std::string& scene_id = scene_ids[sc.scenario.scene_path];
    if (scene_id.empty()) {
      bool ok = false;
      const std::string content = ReadWholeFile(sc.scenario.scene_path, &ok);
      scene_id = fs::path(sc.scenario.scene_path).filename().string() + "#" + Fnv1aHex(content);
    }
    const std::vector<uint64_t> seeds =
        suite.seeds.empty() ? std::vector<uint64_t>{sc.scenario.seed} : suite.seeds;
    for (const auto& cfg : suite.configs) {
      // What the run's hash sees of the configuration: the VO options, or the external program.
      const std::string vo_yaml = cfg.external ? "" : VoConfigToYaml(cfg.options);
      // The program enters as the suite file names it (not resolved), so the hash is portable.
      ExternalEstimator portable_estimator = cfg.estimator;
      if (cfg.external && !portable_estimator.program_given.empty())
        portable_estimator.command[0] = portable_estimator.program_given;
      const std::string config_text =
          cfg.external ? "external:\n" + ExternalEstimatorJson(portable_estimator).dump() + "\n"
                       : "vo:\n" + vo_yaml;
      for (uint64_t seed : seeds) {
        for (int stride : suite.strides) {
          SuiteRun run;
          run.index = static_cast<int>(runs.size());
          run.scenario = sc.name;
          run.config = cfg.name;
          run.seed = seed;
          run.stride = stride;
          run.max_frames = sc.max_frames;
          run.id = sc.name + "__" + cfg.name + "__s" + std::to_string(seed) + "__k" +
                   std::to_string(stride);
          sim::Scenario scenario = sc.scenario;
          scenario.seed = seed;
          scenario.name = run.id;
          run.scenario_yaml = sim::ScenarioToYaml(scenario);
          run.vo_yaml = vo_yaml;
          run.external = cfg.external;
          run.estimator = cfg.estimator;
          // The hash sees the scene by name and content, so it is the same on every machine.
          sim::Scenario portable = scenario;
          portable.scene_path = scene_id;
          run.spec_hash = Fnv1aHex("scenario:\n" + sim::ScenarioToYaml(portable) + config_text +
                                   "stride: " + std::to_string(stride) +
                                   "\nmax_frames: " + std::to_string(sc.max_frames) + "\n");
          runs.push_back(run);
        }
      }
    }
  }
  return runs;
}

bool ParseShard(const std::string& text, Shard* shard, std::string* error) {
  static const std::regex kShard("([0-9]{1,6})/([0-9]{1,6})");
  std::smatch m;
  if (std::regex_match(text, m, kShard)) {
    const int i = std::stoi(m[1]), n = std::stoi(m[2]);
    if (n >= 1 && i >= 1 && i <= n) {
      *shard = {i, n};
      return true;
    }
  }
  *error = "--shard: expected i/N with 1 <= i <= N (e.g. 2/4, or ${SLURM_ARRAY_TASK_ID}/4), got '" +
           text + "'";
  return false;
}

}  // namespace harness
