#include "harness/suite.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "harness/interrupt.h"
#include "harness/metric_registry.h"
#include "harness/output_folder.h"
#include "harness/overrides.h"
#include "harness/path_names.h"
#include "harness/plots/plots.h"
#include "harness/progress.h"
#include "harness/trajectory_io.h"
#include "harness/vo_config.h"
#include "sim/yaml_input.h"

namespace harness {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

constexpr int kFailedLogTailLines = 40;  // lines of the child's log kept in <id>.failed.txt
constexpr auto kWaitPoll = std::chrono::milliseconds(50);  // child-status polling period

// ---------------------------------------------------------------------------------------------
// Suite file reading.

using sim::YamlReader;
constexpr int kIntMax = std::numeric_limits<int>::max();

// A name that becomes part of a run id, and so of a folder name (CheckPathName, the one path
// rule) and of an unquoted summary.csv cell: also letters, digits, '_', '.', '-' only, and no
// "__" (the separator of the id's parts).
bool CheckRunIdPart(const std::string& name, const std::string& what, std::string* why) {
  if (!CheckPathName(name, what, why)) return false;
  static const std::regex kName("[A-Za-z0-9_.-]+");
  if (std::regex_match(name, kName) && name.find("__") == std::string::npos) return true;
  *why = what + " '" + name + "': expected letters, digits, '_', '.', '-' (no '__')";
  return false;
}

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

std::string ReadWholeFile(const fs::path& path, bool* ok) {
  std::ifstream in(path, std::ios::binary);
  *ok = static_cast<bool>(in);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
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
      CheckOverrideKeys(set, YAML::Load(sim::ScenarioToYaml(base)), key + ".set", "scenario", &r);
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
    r.CheckKeys(e, key, {"name", "config", "set"});
    SuiteConfig c;
    if (!r.Require(e, key, "name", "the configuration's name") ||
        !r.String(e, key, "name", &c.name, false))
      break;
    if (!CheckRunIdPart(c.name, "configuration name", &name_error))
      r.Fail(e["name"], key + ".name", name_error);
    if (r.ok() && !names.insert(c.name).second)
      r.Fail(e["name"], key + ".name", "configuration name '" + c.name + "' is used twice");
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
      const std::string vo_yaml = VoConfigToYaml(cfg.options);
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
          // The hash sees the scene by name and content, so it is the same on every machine.
          sim::Scenario portable = scenario;
          portable.scene_path = scene_id;
          run.spec_hash = Fnv1aHex("scenario:\n" + sim::ScenarioToYaml(portable) + "vo:\n" +
                                   vo_yaml + "stride: " + std::to_string(stride) +
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

bool WriteFileAtomically(const std::string& path, const std::string& text, std::string* error) {
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  if (!WriteTextFile(tmp, text, error)) return false;
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    *error = path + ": cannot write: " + ec.message();
    return false;
  }
  return true;
}

namespace {

// ---------------------------------------------------------------------------------------------
// The output folder.

json Manifest(const Suite& suite, const std::vector<SuiteRun>& runs, const Shard& shard) {
  json j;
  j["suite"] = suite.name;
  j["source"] = suite.source_path;
  j["shard"] = std::to_string(shard.index) + "/" + std::to_string(shard.count);
  j["runs"] = json::array();
  for (const auto& r : runs) {
    json e;
    e["index"] = r.index;
    e["id"] = r.id;
    e["scenario"] = r.scenario;
    e["config"] = r.config;
    e["seed"] = r.seed;
    e["stride"] = r.stride;
    e["max_frames"] = r.max_frames;
    e["spec_hash"] = r.spec_hash;
    j["runs"].push_back(e);
  }
  return j;
}

bool ReadJsonFile(const fs::path& path, json* out, std::string* error) {
  bool ok = false;
  const std::string text = ReadWholeFile(path, &ok);
  if (!ok) {
    *error = path.string() + ": cannot read";
    return false;
  }
  try {
    *out = json::parse(text);
  } catch (const json::exception& e) {
    *error = path.string() + ": malformed JSON: " + e.what();
    return false;
  }
  return true;
}

// Runs listed in a manifest (suite.json), checked for the fields the summary needs.
bool ReadManifest(const fs::path& dir, std::string* name, std::vector<SuiteRun>* runs,
                  std::string* error) {
  json j;
  if (!ReadJsonFile(dir / "suite.json", &j, error)) return false;
  try {
    *name = j.at("suite").get<std::string>();
    runs->clear();
    for (const auto& e : j.at("runs")) {
      SuiteRun r;
      r.index = e.at("index").get<int>();
      r.id = e.at("id").get<std::string>();
      r.scenario = e.at("scenario").get<std::string>();
      r.config = e.at("config").get<std::string>();
      r.seed = e.at("seed").get<uint64_t>();
      r.stride = e.at("stride").get<int>();
      r.max_frames = e.at("max_frames").get<int>();
      r.spec_hash = e.at("spec_hash").get<std::string>();
      std::string why;
      if (r.index != static_cast<int>(runs->size()) ||
          !CheckRunIdPart(r.scenario, "scenario name", &why) ||
          !CheckRunIdPart(r.config, "configuration name", &why) ||
          !CheckPathName(r.id, "run id", &why))
        throw std::runtime_error("run " + r.id + " is out of order or malformed" +
                                 (why.empty() ? "" : ": " + why));
      runs->push_back(r);
    }
  } catch (const std::exception& e) {
    *error = (dir / "suite.json").string() + ": not a vobench suite manifest: " + e.what();
    return false;
  }
  return true;
}

// A folder that may become a suite output folder: absent, empty, or a marked suite folder
// (output_folder.h) of `name`; one without suite.json yet is being created by a shard started
// at the same time.
bool CheckOutDir(const fs::path& dir, const std::string& name, std::string* error) {
  if (!CheckReplaceable(dir.string(), "suite", error)) return false;
  if (!fs::exists(dir / "suite.json")) return true;
  std::string other;
  std::vector<SuiteRun> runs;
  if (!ReadManifest(dir, &other, &runs, error)) return false;
  if (other != name) {
    *error =
        dir.string() + ": holds suite '" + other + "', not '" + name + "'; choose another --out";
    return false;
  }
  return true;
}

// A run folder finished for this spec: suite_run.json with the same hash, and metrics.json.
bool IsFinished(const fs::path& run_dir, const std::string& spec_hash, json* stamp = nullptr) {
  if (!fs::is_regular_file(run_dir / "metrics.json")) return false;
  json j;
  std::string error;
  if (!ReadJsonFile(run_dir / "suite_run.json", &j, &error)) return false;
  if (!j.contains("spec_hash") || j["spec_hash"] != spec_hash) return false;
  if (stamp) *stamp = j;
  return true;
}

// The folder under tmp/ where this process's children write: one per shard, so shards that share
// an output folder never remove each other's runs in progress.
fs::path WorkDir(const fs::path& out, const std::string& tag) { return out / "tmp" / tag; }
std::string ShardTag(const Shard& shard) {
  return "shard" + std::to_string(shard.index) + "of" + std::to_string(shard.count);
}

// Removes `work` (this process's folder under tmp/, and tmp/ when it is then empty) and every
// *.partial* entry in runs/: leftovers of interrupted runs.
void RemoveLeftovers(const fs::path& out, const fs::path& work) {
  std::error_code ec;
  fs::remove_all(work, ec);
  fs::remove(out / "tmp", ec);  // only if empty
  std::vector<fs::path> partial;  // only folders vobench marked as its own
  for (fs::directory_iterator it(out / "runs", ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename().string().find(".partial") != std::string::npos &&
        HasFolderMarker(it->path().string()))
      partial.push_back(it->path());
  for (const auto& p : partial) fs::remove_all(p, ec);
}

bool MakeDirs(const fs::path& out, std::string* error) {
  std::error_code ec;
  for (const char* sub : {"runs", "specs", "logs"}) {
    fs::create_directories(out / sub, ec);
    if (ec) {
      *error = (out / sub).string() + ": cannot create: " + ec.message();
      return false;
    }
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// Child processes.

std::string CommandLine(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + ShellQuoted(a);
  return s;
}

// Starts argv with stdout and stderr into `log_path`. The child leads a process group of its
// own (a Ctrl-C on the terminal reaches only this process, which stops the children itself) and
// is killed by the kernel when this process dies, however it dies (PR_SET_PDEATHSIG SIGKILL):
// no orphan goes on writing into a work folder that a resumed suite reuses.
bool Spawn(const std::vector<std::string>& argv, const std::string& log_path, pid_t* pid,
           std::string* error) {
  if (access(argv[0].c_str(), X_OK) != 0) {
    *error = argv[0] + ": cannot start: " + std::strerror(errno);
    return false;
  }
  // Everything the child needs is prepared before fork(): after it, only async-signal-safe
  // calls (the parent may have threads).
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const char* log = log_path.c_str();
  const pid_t parent = getpid();
  sigset_t all, old_mask;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &old_mask);  // no handler runs in the child before exec
  const pid_t child = fork();
  if (child == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the parent died before prctl
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    const int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0 || dup2(fd, STDOUT_FILENO) < 0 || dup2(fd, STDERR_FILENO) < 0) _exit(126);
    if (fd != STDOUT_FILENO && fd != STDERR_FILENO) close(fd);
    execv(args[0], args.data());
    static const char kExecFailed[] = "vobench suite: exec of the run failed\n";
    (void)!write(STDERR_FILENO, kExecFailed, sizeof(kExecFailed) - 1);
    _exit(127);
  }
  const int fork_errno = errno;
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  if (child < 0) {
    *error = argv[0] + ": cannot start: " + std::strerror(fork_errno);
    return false;
  }
  setpgid(child, child);  // also here: no race with kill(-child) below
  *pid = child;
  return true;
}

std::string Tail(const fs::path& path, int lines) {
  bool ok = false;
  const std::string text = ReadWholeFile(path, &ok);
  if (!ok) return "(no log)\n";
  std::vector<std::string> all;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) all.push_back(line);
  std::string tail;
  for (size_t i = all.size() > static_cast<size_t>(lines) ? all.size() - lines : 0; i < all.size();
       ++i)
    tail += all[i] + "\n";
  return tail;
}

std::string ExitText(int status) {
  if (WIFEXITED(status)) return "exit status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status))
    return std::string("killed by signal ") + std::to_string(WTERMSIG(status)) + " (" +
           strsignal(WTERMSIG(status)) + ")";
  return "ended with wait status " + std::to_string(status);
}

struct Job {
  SuiteRun run;
  std::vector<std::string> argv;
  fs::path tmp;  // the child's --out (moved to runs/<id> when finished)
  std::chrono::steady_clock::time_point start;
};

// After a child ended: publish its run folder or record the failure.
bool FinishJob(const fs::path& out, const Job& job, int status, double wall_s, bool* ok,
               std::string* error) {
  const SuiteRun& r = job.run;
  const fs::path tmp = job.tmp, dst = out / "runs" / r.id;
  const fs::path failed = out / "runs" / (r.id + ".failed.txt");
  std::error_code ec;
  *ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && fs::is_regular_file(tmp / "metrics.json");
  if (*ok) {
    json stamp;
    stamp["id"] = r.id;
    stamp["index"] = r.index;
    stamp["spec_hash"] = r.spec_hash;
    stamp["scenario"] = r.scenario;
    stamp["config"] = r.config;
    stamp["seed"] = r.seed;
    stamp["stride"] = r.stride;
    stamp["max_frames"] = r.max_frames;
    stamp["wall_s"] = wall_s;
    stamp["command"] = CommandLine(job.argv);
    if (!WriteTextFile((tmp / "suite_run.json").string(), stamp.dump(2) + "\n", error))
      return false;
    // runs/<id> is replaced only when it is a vobench run folder (output_folder.h).
    if (!ReplaceFolder(tmp.string(), dst.string(), "run", error)) return false;
    fs::remove(failed, ec);
    return true;
  }
  fs::remove_all(tmp, ec);
  fs::remove_all(tmp.string() + ".partial", ec);
  std::string text =
      "run " + r.id + " failed: " + ExitText(status) +
      (WIFEXITED(status) && WEXITSTATUS(status) == 0 ? " but wrote no metrics.json" : "") + "\n";
  text += "command: " + CommandLine(job.argv) + "\n";
  text += "log: " + (out / "logs" / (r.id + ".log")).string() + "\n";
  text +=
      "--- last lines of the log ---\n" + Tail(out / "logs" / (r.id + ".log"), kFailedLogTailLines);
  return WriteFileAtomically(failed.string(), text, error);
}

std::vector<std::string> RunArgv(const std::string& binary, const fs::path& out,
                                 const fs::path& tmp, const SuiteRun& r, bool plots) {
  std::vector<std::string> argv = {binary,
                                   "run",
                                   (out / "specs" / (r.id + ".scenario.yaml")).string(),
                                   "--config",
                                   (out / "specs" / (r.id + ".vo.yaml")).string(),
                                   "--out",
                                   tmp.string(),
                                   "--max-frames",
                                   std::to_string(r.max_frames),
                                   "--stride",
                                   std::to_string(r.stride),
                                   "-q"};
  if (!plots) argv.push_back("--no-plots");
  return argv;
}

// ---------------------------------------------------------------------------------------------
// Summary.

std::string CsvCell(const json& v) {
  if (v.is_null()) return "nan";
  if (v.is_boolean()) return v.get<bool>() ? "1" : "0";
  if (v.is_number_integer() || v.is_number_unsigned()) return v.dump();
  if (v.is_number()) return FormatDouble(v.get<double>());
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

double Number(const json& metrics, const std::string& key) {
  const json* v = FindMetricValue(metrics, key);
  return v != nullptr && v->is_number() ? v->get<double>() : std::nan("");
}

std::string Fixed(double v, int prec) {
  if (!std::isfinite(v)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", prec, v);
  return buf;
}

double MedianOf(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Rows for `runs` (those in `shard`) from what is on disk in `out`.
std::vector<SuiteRow> CollectRows(const fs::path& out, const std::vector<SuiteRun>& runs,
                                  const Shard& shard) {
  std::vector<SuiteRow> rows;
  for (const auto& r : runs) {
    if (!shard.Contains(r.index)) continue;
    SuiteRow row;
    row.run = r;
    json stamp, metrics;
    std::string error;
    if (IsFinished(out / "runs" / r.id, r.spec_hash, &stamp) &&
        ReadJsonFile(out / "runs" / r.id / "metrics.json", &metrics, &error)) {
      row.status = "ok";
      row.metrics = metrics;
      row.wall_s = stamp.value("wall_s", 0.0);
    } else if (fs::exists(out / "runs" / (r.id + ".failed.txt"))) {
      row.status = "failed";
    } else {
      row.status = "missing";
    }
    rows.push_back(row);
  }
  return rows;
}

void Count(SuiteResult* result) {
  result->failed = result->missing = 0;
  for (const auto& row : result->rows) {
    result->failed += row.status == "failed";
    result->missing += row.status == "missing";
  }
}

std::string SummaryCsv(const std::vector<SuiteRow>& rows) {
  std::ostringstream csv;
  const auto& cols = SuiteSummaryColumns();
  for (size_t i = 0; i < cols.size(); ++i) csv << (i ? "," : "") << cols[i];
  csv << "\n";
  for (const auto& row : rows) {
    const SuiteRun& r = row.run;
    csv << r.id << "," << r.scenario << "," << r.config << "," << r.seed << "," << r.stride << ","
        << r.max_frames << "," << row.status;
    for (size_t i = 7; i < cols.size(); ++i) {
      csv << ",";
      if (row.status != "ok") continue;
      if (cols[i] == "wall_s")
        csv << Fixed(row.wall_s, 1);
      else if (const nlohmann::json* v = FindMetricValue(row.metrics, cols[i]))
        csv << CsvCell(*v);
    }
    csv << "\n";
  }
  return csv.str();
}

struct ConfigAggregate {
  std::string config;
  int ok = 0, total = 0;
  double epe_pct_median = 0, epe_pct_max = 0, ate_median = 0, drift_median = 0, ms_median = 0;
  long lost_total = 0;
};

std::vector<ConfigAggregate> Aggregates(const std::vector<SuiteRow>& rows) {
  std::vector<ConfigAggregate> out;
  std::vector<std::string> order;
  for (const auto& row : rows)
    if (std::find(order.begin(), order.end(), row.run.config) == order.end())
      order.push_back(row.run.config);
  for (const auto& c : order) {
    ConfigAggregate a;
    a.config = c;
    std::vector<double> epe, ate, drift, ms;
    a.epe_pct_max = std::nan("");
    for (const auto& row : rows) {
      if (row.run.config != c) continue;
      ++a.total;
      if (row.status != "ok") continue;
      ++a.ok;
      epe.push_back(Number(row.metrics, "end_pose_error_pct"));
      ate.push_back(Number(row.metrics, "ate_rmse_m"));
      drift.push_back(Number(row.metrics, "drift_pct"));
      ms.push_back(Number(row.metrics, "vo_ms_median"));
      a.lost_total += static_cast<long>(Number(row.metrics, "lost_frames"));
      if (std::isfinite(epe.back()) && !(a.epe_pct_max >= epe.back())) a.epe_pct_max = epe.back();
    }
    a.epe_pct_median = MedianOf(epe);
    a.ate_median = MedianOf(ate);
    a.drift_median = MedianOf(drift);
    a.ms_median = MedianOf(ms);
    out.push_back(a);
  }
  return out;
}

std::string SummaryMarkdown(const std::string& name, const SuiteResult& result, bool has_plot) {
  const auto& rows = result.rows;
  std::ostringstream md;
  md << "# Suite `" << name << "`\n\n";
  md << rows.size() << " runs: " << rows.size() - result.failed - result.missing << " ok, "
     << result.failed << " failed, " << result.missing
     << " missing. One row per run in `summary.csv` (every metric of "
     << "`metrics.json`); each run's folder is `runs/<id>/`. Accuracy columns are deterministic; "
        "the ms "
     << "and wall-time columns depend on the machine and its load.\n\n";

  md << "## Per configuration\n\nMedians over every scenario, seed and stride of the "
        "configuration.\n\n";
  md << "| configuration | runs ok | end-pose error median (% of path) | worst (%) | ATE RMSE "
        "median (m) | "
        "drift median (%) | lost frames (sum) | VO ms/frame (median) |\n| --- | --- | --- | --- | "
        "--- | --- | --- | --- |\n";
  for (const auto& a : Aggregates(rows))
    md << "| " << a.config << " | " << a.ok << "/" << a.total << " | " << Fixed(a.epe_pct_median, 3)
       << " | " << Fixed(a.epe_pct_max, 3) << " | " << Fixed(a.ate_median, 4) << " | "
       << Fixed(a.drift_median, 3) << " | " << a.lost_total << " | " << Fixed(a.ms_median, 1)
       << " |\n";

  // Pivot: end-pose error (%) per scenario/seed/stride (rows) and configuration (columns).
  std::vector<std::string> configs, variants;
  std::map<std::pair<std::string, std::string>, std::string> cell;
  for (const auto& row : rows) {
    const SuiteRun& r = row.run;
    const std::string variant = r.scenario + " (seed " + std::to_string(r.seed) + ", stride " +
                                std::to_string(r.stride) + ")";
    if (std::find(configs.begin(), configs.end(), r.config) == configs.end())
      configs.push_back(r.config);
    if (std::find(variants.begin(), variants.end(), variant) == variants.end())
      variants.push_back(variant);
    cell[{variant, r.config}] = row.status != "ok"
                                    ? row.status
                                    : Fixed(Number(row.metrics, "end_pose_error_pct"), 3) + " / " +
                                          Fixed(Number(row.metrics, "ate_rmse_m"), 4);
  }
  md << "\n## End-pose error (% of path) / ATE RMSE (m) by scenario and configuration\n\n| "
        "scenario |";
  for (const auto& c : configs) md << " " << c << " |";
  md << "\n| ---";
  for (size_t i = 0; i < configs.size(); ++i) md << " | ---";
  md << " |\n";
  for (const auto& v : variants) {
    md << "| " << v << " |";
    for (const auto& c : configs) md << " " << (cell.count({v, c}) ? cell[{v, c}] : "") << " |";
    md << "\n";
  }
  if (has_plot) md << "\n![summary](summary.png)\n";

  md << "\n## Runs\n\n| run | status | frames | path (m) | end-pose error (m) | (%) | ATE RMSE (m) "
        "| drift (%) | "
        "lost | VO ms median | p95 | wall (s) |\n| --- | --- | --- | --- | --- | --- | --- | --- | "
        "--- | --- | --- | --- |\n";
  for (const auto& row : rows) {
    md << "| " << row.run.id << " | " << row.status << " |";
    if (row.status != "ok") {
      md << " | | | | | | | | | |\n";
      continue;
    }
    const json& m = row.metrics;
    md << " " << CsvCell(m.value("frames", json())) << " | " << Fixed(Number(m, "path_length_m"), 3)
       << " | " << Fixed(Number(m, "end_pose_error_m"), 4) << " | "
       << Fixed(Number(m, "end_pose_error_pct"), 3) << " | " << Fixed(Number(m, "ate_rmse_m"), 4)
       << " | " << Fixed(Number(m, "drift_pct"), 3) << " | "
       << CsvCell(m.value("lost_frames", json())) << " | " << Fixed(Number(m, "vo_ms_median"), 2)
       << " | " << Fixed(Number(m, "vo_ms_p95"), 2) << " | " << Fixed(row.wall_s, 1) << " |\n";
  }
  return md.str();
}

// harness/suite_plot.py SUMMARY_CSV PNG (Debian's python3 with matplotlib).
bool RunSuitePlot(const std::string& csv, const std::string& png, std::string* error) {
  std::vector<std::string> args = {csv, png};
  for (const char* key : {"end_pose_error_pct", "ate_rmse_m"}) {  // the two panels
    args.insert(args.end(), {"--panel", key, PlotLabel(*FindMetric(key))});
  }
  return RunPythonScript("suite_plot.py", args, error);
}

bool WriteSummary(const fs::path& out, const std::string& name, const SuiteResult& result,
                  std::string* error) {
  const std::string csv = SummaryCsv(result.rows);
  if (!WriteFileAtomically((out / "summary.csv").string(), csv, error)) return false;
  // The plot is drawn into a temporary file and renamed; a missing matplotlib only warns.
  std::string plot_error;
  const fs::path tmp_png = out / ("summary.tmp" + std::to_string(::getpid()) + ".png");
  bool has_plot = RunSuitePlot((out / "summary.csv").string(), tmp_png.string(), &plot_error);
  std::error_code ec;
  if (has_plot) {
    fs::rename(tmp_png, out / "summary.png", ec);
    has_plot = !ec;
  } else {
    fs::remove(tmp_png, ec);
    std::fprintf(stderr, "warning: summary plot not made: %s\n", plot_error.c_str());
  }
  return WriteFileAtomically((out / "summary.md").string(), SummaryMarkdown(name, result, has_plot),
                             error);
}

// The run's effective inputs, as its child process reads them.
bool WriteSpecs(const fs::path& out, const SuiteRun& r, std::string* error) {
  return WriteFileAtomically((out / "specs" / (r.id + ".scenario.yaml")).string(), r.scenario_yaml,
                             error) &&
         WriteFileAtomically((out / "specs" / (r.id + ".vo.yaml")).string(), r.vo_yaml, error);
}

std::string SelfExecutable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("/proc/self/exe") : p.string();
}

}  // namespace

const std::vector<std::string>& SuiteTimingColumns() {
  static const std::vector<std::string> kColumns = [] {
    std::vector<std::string> c;
    for (const MetricInfo& m : RunMetrics())
      if (m.csv && m.group == MetricGroup::kTiming) c.push_back(m.key);
    c.push_back("wall_s");
    return c;
  }();
  return kColumns;
}

const std::vector<std::string>& SuiteSummaryColumns() {
  static const std::vector<std::string> kColumns = [] {
    std::vector<std::string> c = {"id",     "scenario",   "config", "seed",
                                  "stride", "max_frames", "status"};
    for (const MetricInfo& m : RunMetrics())
      if (m.csv && m.group != MetricGroup::kTiming) c.push_back(m.key);
    for (const std::string& t : SuiteTimingColumns()) c.push_back(t);
    return c;
  }();
  return kColumns;
}

std::string SuiteTableText(const SuiteResult& result) {
  size_t w = 4;
  for (const auto& row : result.rows) w = std::max(w, row.run.id.size());
  std::ostringstream t;
  char buf[512];
  std::snprintf(buf, sizeof(buf), "%-*s %-7s %6s %10s %8s %9s %8s %5s %8s\n", static_cast<int>(w),
                "run", "status", "frames", "end-pose m", "(%)", "ATE m", "drift %", "lost",
                "ms/frame");
  t << buf;
  for (const auto& row : result.rows) {
    const json& m = row.metrics;
    if (row.status == "ok")
      std::snprintf(
          buf, sizeof(buf), "%-*s %-7s %6s %10s %8s %9s %8s %5s %8s\n", static_cast<int>(w),
          row.run.id.c_str(), "ok", CsvCell(m.value("frames", json())).c_str(),
          Fixed(Number(m, "end_pose_error_m"), 4).c_str(),
          Fixed(Number(m, "end_pose_error_pct"), 2).c_str(),
          Fixed(Number(m, "ate_rmse_m"), 4).c_str(), Fixed(Number(m, "drift_pct"), 2).c_str(),
          CsvCell(m.value("lost_frames", json())).c_str(),
          Fixed(Number(m, "vo_ms_median"), 1).c_str());
    else
      std::snprintf(buf, sizeof(buf), "%-*s %-7s\n", static_cast<int>(w), row.run.id.c_str(),
                    row.status.c_str());
    t << buf;
  }
  t << "\nper configuration (medians over its runs):\n";
  std::snprintf(buf, sizeof(buf), "%-20s %7s %14s %9s %8s %5s %8s\n", "config", "ok",
                "end-pose % med", "ATE m", "drift %", "lost", "ms/frame");
  t << buf;
  for (const auto& a : Aggregates(result.rows)) {
    std::snprintf(buf, sizeof(buf), "%-20s %3d/%-3d %14s %9s %8s %5ld %8s\n", a.config.c_str(),
                  a.ok, a.total, Fixed(a.epe_pct_median, 3).c_str(), Fixed(a.ate_median, 4).c_str(),
                  Fixed(a.drift_median, 2).c_str(), a.lost_total, Fixed(a.ms_median, 1).c_str());
    t << buf;
  }
  return t.str();
}

bool RunSuite(const Suite& suite, const SuiteOptions& options, SuiteResult* result,
              std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  *result = SuiteResult();
  if (options.jobs < 1) {
    *error = "-j: expected at least 1 job, got " + std::to_string(options.jobs);
    return false;
  }
  if (options.out_dir.empty()) {
    *error = "no output folder";
    return false;
  }
  const fs::path out = options.out_dir;
  const std::string shard_tag = ShardTag(options.shard);
  if (!CheckPathName(suite.name, "suite name", error) ||
      !CheckPathName(shard_tag, "shard tag", error))
    return false;
  const std::vector<SuiteRun> runs = ExpandSuite(suite);
  // The manifest first: a folder with suite.json is recognised as this suite's on resume.
  std::error_code ec;
  // A marked suite folder (created with its marker, or an earlier one of this suite), and the
  // lock of this shard in it: a second `suite` on the same folder and shard fails at once.
  FolderLock shard_lock;
  if (!CheckOutDir(out, suite.name, error) || !AdoptFolder(out.string(), "suite", error) ||
      !shard_lock.Acquire((out / ("." + shard_tag + ".lock")).string(),
                          out.string() + " (shard " + shard_tag + ")", error))
    return false;
  if (!WriteFileAtomically((out / "suite.json").string(),
                           Manifest(suite, runs, options.shard).dump(2) + "\n", error) ||
      !WriteFileAtomically((out / "suite.yaml").string(), suite.source_text, error) ||
      !MakeDirs(out, error))
    return false;
  const fs::path work = WorkDir(out, shard_tag);
  RemoveLeftovers(out, work);
  fs::create_directories(work, ec);
  if (ec) {
    *error = work.string() + ": cannot create: " + ec.message();
    return false;
  }

  // What to run: this shard's runs that are not finished for their spec.
  std::deque<Job> queue;
  const std::string binary =
      options.vobench_binary.empty() ? SelfExecutable() : options.vobench_binary;
  for (const auto& r : runs) {
    if (!options.shard.Contains(r.index)) continue;
    if (!WriteSpecs(out, r, error)) return false;
    if (!options.force && IsFinished(out / "runs" / r.id, r.spec_hash)) {
      ++result->kept;
      continue;
    }
    queue.push_back({r, RunArgv(binary, out, work / r.id, r, options.run_plots), work / r.id, {}});
  }
  const int total = static_cast<int>(queue.size());
  if (options.progress)
    std::fprintf(
        stderr,
        "suite %s: %d runs in this part, %d finished before (kept), %d to run, %d at once\n",
        suite.name.c_str(), total + result->kept, result->kept, total, options.jobs);

  ScopedInterruptHandlers interrupt_handlers;
  // A progress bar on a terminal; a line per finished run (with the ETA) in any case.
  const bool tty = isatty(STDERR_FILENO) != 0;
  Progress progress("suite " + suite.name, total, options.progress && tty);
  const auto runs_start = std::chrono::steady_clock::now();
  std::map<pid_t, Job> running;
  std::set<std::string> ran_now;
  int done = 0;
  bool fatal = false;
  while ((!queue.empty() || !running.empty()) && !fatal) {
    if (InterruptSignal() != 0) break;
    while (!queue.empty() && static_cast<int>(running.size()) < options.jobs) {
      Job job = queue.front();
      queue.pop_front();
      std::error_code ec;
      fs::remove_all(job.tmp, ec);
      fs::remove_all(job.tmp.string() + ".partial", ec);
      job.start = std::chrono::steady_clock::now();
      pid_t pid = 0;
      if (!Spawn(job.argv, (out / "logs" / (job.run.id + ".log")).string(), &pid, error)) {
        fatal = true;
        break;
      }
      running.emplace(pid, job);
    }
    int status = 0;
    // Poll our own children only (a host program may have others).
    auto it = running.begin();
    for (; it != running.end(); ++it)
      if (waitpid(it->first, &status, WNOHANG) == it->first) break;
    if (it == running.end()) {
      std::this_thread::sleep_for(kWaitPoll);
      continue;
    }
    const Job job = it->second;
    running.erase(it);
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - job.start).count();
    bool ok = false;
    if (!FinishJob(out, job, status, wall_s, &ok, error)) {
      fatal = true;
      break;
    }
    ++done;
    ran_now.insert(job.run.id);
    if (options.progress || !ok) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - runs_start).count();
      std::fprintf(
          stderr, "%s[%d/%d] %-6s %6.1f s  %s%s  (ETA %.0f s)\n",
          tty && options.progress ? "\r\033[K" : "", done, total, ok ? "ok" : "FAILED", wall_s,
          job.run.id.c_str(),
          ok ? "" : ("; see " + (out / "runs" / (job.run.id + ".failed.txt")).string()).c_str(),
          elapsed / done * (total - done));
    }
    progress.Update(done);
  }
  if (InterruptSignal() != 0 || fatal) {
    // Stop the children (their process groups: plots included); their unfinished folders under
    // tmp/ are removed (resume redoes them).
    for (const auto& [pid, job] : running) kill(-pid, SIGTERM);
    for (const auto& [pid, job] : running) {
      int status = 0;
      waitpid(pid, &status, 0);
    }
    RemoveLeftovers(out, work);
    if (!fatal)
      *error = std::string("interrupted by signal ") + std::to_string(InterruptSignal()) +
               " after " + std::to_string(done) + " of " + std::to_string(total) +
               " runs; the finished ones are kept: run the same command again to resume";
    return false;
  }
  progress.Finish(done);
  RemoveLeftovers(out, work);

  result->rows = CollectRows(out, runs, options.shard);
  for (auto& row : result->rows) {
    row.ran_now = ran_now.count(row.run.id) > 0;
    result->ran += row.ran_now && row.status == "ok";
  }
  Count(result);
  result->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return WriteSummary(out, suite.name, *result, error);
}

bool MergeSuiteShards(const std::vector<std::string>& shard_dirs, const std::string& out_dir,
                      SuiteResult* result, std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  *result = SuiteResult();
  if (shard_dirs.empty()) {
    *error = "merge: no shard folders given";
    return false;
  }
  std::string name;
  std::vector<SuiteRun> runs;
  for (size_t k = 0; k < shard_dirs.size(); ++k) {
    std::string n;
    std::vector<SuiteRun> r;
    if (!fs::exists(fs::path(shard_dirs[k]) / "suite.json")) {
      *error = shard_dirs[k] + ": not a vobench suite folder (no suite.json)";
      return false;
    }
    if (!ReadManifest(shard_dirs[k], &n, &r, error)) return false;
    std::error_code ec;
    if (fs::exists(out_dir) && fs::equivalent(shard_dirs[k], out_dir, ec)) {
      *error = out_dir + ": the merge output must not be one of the shard folders";
      return false;
    }
    if (k == 0) {
      name = n;
      runs = r;
      continue;
    }
    if (n != name) {
      *error = shard_dirs[k] + ": holds suite '" + n + "', but " + shard_dirs[0] + " holds '" +
               name + "'";
      return false;
    }
    if (r.size() != runs.size()) {
      *error = shard_dirs[k] + ": suite '" + n + "' has " + std::to_string(r.size()) +
               " runs there but " + std::to_string(runs.size()) + " in " + shard_dirs[0] +
               " (different suite files?)";
      return false;
    }
    for (size_t i = 0; i < r.size(); ++i)
      if (r[i].id != runs[i].id || r[i].spec_hash != runs[i].spec_hash) {
        *error = shard_dirs[k] + ": run " + std::to_string(i) + " is " + r[i].id + " (spec " +
                 r[i].spec_hash + ") but " + runs[i].id + " (spec " + runs[i].spec_hash + ") in " +
                 shard_dirs[0] + " (different suite files or inputs?)";
        return false;
      }
  }
  const fs::path out = out_dir;
  FolderLock merge_lock;
  if (!CheckOutDir(out, name, error) || !AdoptFolder(out.string(), "suite", error) ||
      !merge_lock.Acquire((out / ".merge.lock").string(), out.string() + " (merge)", error) ||
      !MakeDirs(out, error))
    return false;
  const fs::path work = WorkDir(out, "merge");
  RemoveLeftovers(out, work);
  for (const auto& r : runs) {
    std::error_code ec;
    const fs::path dst = out / "runs" / r.id;
    if (IsFinished(dst, r.spec_hash)) continue;
    for (const auto& dir : shard_dirs) {
      const fs::path src = fs::path(dir) / "runs" / r.id;
      if (!IsFinished(src, r.spec_hash)) continue;
      // Copy under tmp/ and rename, so a merged run also appears only when complete.
      const fs::path tmp = work / r.id;
      fs::remove_all(tmp, ec);
      fs::create_directories(work, ec);
      if (!ec) fs::copy(src, tmp, fs::copy_options::recursive, ec);
      if (ec) {
        *error = dst.string() + ": cannot copy the run from " + src.string() + ": " + ec.message();
        return false;
      }
      if (!ReplaceFolder(tmp.string(), dst.string(), "run", error)) return false;
      fs::remove(out / "runs" / (r.id + ".failed.txt"), ec);
      break;
    }
    for (const auto& dir : shard_dirs) {
      const fs::path failed = fs::path(dir) / "runs" / (r.id + ".failed.txt");
      if (!IsFinished(dst, r.spec_hash) && fs::exists(failed)) {
        fs::copy_file(failed, out / "runs" / (r.id + ".failed.txt"),
                      fs::copy_options::overwrite_existing, ec);
        break;
      }
    }
    // The inputs and the log go along, where the shard has them.
    for (const auto& dir : shard_dirs) {
      const fs::path specs = fs::path(dir) / "specs";
      if (!fs::exists(specs / (r.id + ".scenario.yaml"))) continue;
      for (const std::string& f : {r.id + ".scenario.yaml", r.id + ".vo.yaml"})
        fs::copy_file(specs / f, out / "specs" / f, fs::copy_options::overwrite_existing, ec);
      if (fs::exists(fs::path(dir) / "logs" / (r.id + ".log")))
        fs::copy_file(fs::path(dir) / "logs" / (r.id + ".log"), out / "logs" / (r.id + ".log"),
                      fs::copy_options::overwrite_existing, ec);
      break;
    }
  }
  RemoveLeftovers(out, work);
  json manifest;
  if (!ReadJsonFile(fs::path(shard_dirs[0]) / "suite.json", &manifest, error)) return false;
  manifest["shard"] = "1/1";
  manifest["merged_from"] = shard_dirs;
  bool ok = false;
  const std::string suite_text = ReadWholeFile(fs::path(shard_dirs[0]) / "suite.yaml", &ok);
  if (!WriteFileAtomically((out / "suite.json").string(), manifest.dump(2) + "\n", error) ||
      (ok && !WriteFileAtomically((out / "suite.yaml").string(), suite_text, error)))
    return false;
  result->rows = CollectRows(out, runs, Shard());
  Count(result);
  result->kept = static_cast<int>(result->rows.size()) - result->failed - result->missing;
  result->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return WriteSummary(out, name, *result, error);
}

}  // namespace harness
