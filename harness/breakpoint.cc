#include "harness/breakpoint.h"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "harness/interrupt.h"
#include "harness/metric_registry.h"
#include "harness/output_folder.h"
#include "harness/overrides.h"
#include "harness/plots/plots.h"
#include "harness/run.h"
#include "harness/trajectory_io.h"

namespace harness {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

constexpr char kStrideKey[] = "stride";

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// The text of a value of the key: whole numbers without a decimal point for an integer key,
// reals as the shortest text that reads back to the same double.
std::string ValueText(double x, bool integer) {
  if (integer) return std::to_string(static_cast<long long>(std::llround(x)));
  return FormatDouble(x);
}

// Every numeric scalar of a YAML map as a dotted key (lists, such as the path, left out).
void NumericKeys(const YAML::Node& node, const std::string& prefix,
                 std::vector<std::string>* keys) {
  if (!node.IsMap()) return;
  for (const auto& kv : node) {
    const std::string key = prefix + kv.first.as<std::string>();
    double v = 0.0;
    if (kv.second.IsMap())
      NumericKeys(kv.second, key + ".", keys);
    else if (kv.second.IsScalar() && ParseDouble(kv.second.Scalar(), &v))
      keys->push_back(key);
  }
}

// The scenario with the key set to x (a scenario key; not stride) and the noise seed.
bool ScenarioAt(const BreakpointSpec& spec, double x, uint64_t seed, sim::Scenario* scenario,
                std::string* error) {
  YAML::Node overrides(YAML::NodeType::Map);
  if (spec.key != kStrideKey) overrides[spec.key] = ValueText(x, spec.integer);
  overrides["seed"] = std::to_string(seed);
  return ApplyScenarioOverrides(spec.scenario, overrides, "--vary " + spec.key, scenario, error);
}

// The scenario reader's message about the overrides without its place in the generated text
// ("--vary k (overrides of l_hallway):13: key 'k': expected ..." -> "key 'k': expected ...").
std::string ReaderMessage(const std::string& why) {
  const size_t key = why.find(": key '");
  return key == std::string::npos ? why : why.substr(key + 2);
}

// Replaces every occurrence of `from` in `text` by `to` (the work folder's name by the output
// folder's in failure messages, so breakpoint.json does not depend on the process).
std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// stdout goes to stderr while it lives: the external run's log lines and its command's output
// are progress, and stdout keeps the command's result.
class StdoutToStderr {
 public:
  StdoutToStderr() {
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    if (saved_ >= 0) dup2(STDERR_FILENO, STDOUT_FILENO);
  }
  ~StdoutToStderr() {
    std::fflush(stdout);
    if (saved_ >= 0) {
      dup2(saved_, STDOUT_FILENO);
      close(saved_);
    }
  }
  StdoutToStderr(const StdoutToStderr&) = delete;
  StdoutToStderr& operator=(const StdoutToStderr&) = delete;

 private:
  int saved_ = -1;
};

// One run of a point.
struct SeedRun {
  uint64_t seed = 0;
  std::string folder;  // relative to the output folder
  double metric = std::numeric_limits<double>::quiet_NaN();
  int lost_frames = -1;  // -1: not counted (external estimators)
  bool failed = false;
  std::string failure;  // why it failed
};

struct PointRecord {
  int index = 0;
  double x = 0.0;
  std::string phase;
  std::vector<SeedRun> runs;
  PointOutcome outcome;
  double wall_s = 0.0;
};

// A metric's value in a metrics.json of an external run: false with *error when it is not
// there, NaN (and the reason) when it is null.
bool ExternalMetric(const std::string& run_dir, const std::string& metric, double* value,
                    std::string* reason, std::string* error) {
  std::ifstream in(run_dir + "/metrics.json");
  json metrics = json::parse(in, nullptr, false);
  if (metrics.is_discarded()) {
    *error = run_dir + "/metrics.json: cannot be read";
    return false;
  }
  const json* v = FindMetricValue(metrics, metric);
  if (v == nullptr) {
    *error = "the external estimator's metrics.json has no '" + metric +
             "' (an external run is scored on the trajectory's accuracy metrics and frames)";
    return false;
  }
  *value = v->is_number() ? v->get<double>() : std::nan("");
  const json* r = FindMetricValue(metrics, metric + "_reason");
  *reason = r != nullptr && r->is_string() ? r->get<std::string>() : "";
  return true;
}

// Runs every seed of the point at x into `work`/points/ and sets its outcome.
bool EvaluatePointRuns(const BreakpointSpec& spec, const std::string& work,
                       const std::string& out_dir, PointRecord* p, std::string* error) {
  char name[32];
  std::vector<double> values;
  bool failed = false, lost = false;
  for (int s = 0; s < spec.seeds; ++s) {
    SeedRun r;
    r.seed = spec.scenario.seed + static_cast<uint64_t>(s);
    std::snprintf(name, sizeof(name), "p%02d_s%llu", p->index,
                  static_cast<unsigned long long>(r.seed));
    r.folder = std::string("points/") + name;
    const std::string run_dir = work + "/" + r.folder;
    sim::Scenario scenario;
    if (!ScenarioAt(spec, p->x, r.seed, &scenario, error)) return false;
    const int stride = spec.key == kStrideKey ? static_cast<int>(std::llround(p->x)) : spec.stride;
    std::string why, reason;
    bool ok;
    if (spec.external_arg.empty()) {
      RunOptions options;
      options.out_dir = run_dir;
      options.progress = false;
      options.plots = false;
      options.max_frames = spec.max_frames;
      options.frame_stride = stride;
      RunSummary summary;
      ok = RunScenario(scenario, spec.vo_options, options, &summary, &why);
      if (ok) {
        const MetricInfo* m = FindMetric(spec.until.metric);
        const json v = m->value(summary);
        r.metric = v.is_number() ? v.get<double>() : std::nan("");
        if (!v.is_number()) reason = NotApplicableReason(*m, summary);
        r.lost_frames = summary.lost_frames;
      }
    } else {
      ExternalRunSpec run;
      run.id = name;
      run.scenario_path = work + "/specs/" + name + ".scenario.yaml";
      run.stride = stride;
      run.max_frames = spec.max_frames;
      run.estimator = spec.estimator;
      fs::create_directories(work + "/specs");
      if (!WriteTextFile(run.scenario_path, sim::ScenarioToYaml(scenario), error)) return false;
      {
        const StdoutToStderr redirect;
        ok = RunExternalRun(run, run_dir, "", &why);
      }
      if (ok && !ExternalMetric(run_dir, spec.until.metric, &r.metric, &reason, error))
        return false;
    }
    if (InterruptSignal() != 0) {
      *error = "interrupted";
      return false;
    }
    if (!ok) {
      r.failed = true;
      r.failure = ReplaceAll(why, work, out_dir);
      failed = true;
    } else if (!std::isfinite(r.metric)) {
      *error = spec.until.metric + " is null for " + spec.key + "=" +
               ValueText(p->x, spec.integer) + " (seed " + std::to_string(r.seed) +
               "): " + (reason.empty() ? "not applicable to the run" : reason) +
               "; a breaking point needs a metric that applies at every point";
      return false;
    } else {
      values.push_back(r.metric);
      if (spec.max_lost_frames >= 0 && r.lost_frames > spec.max_lost_frames) lost = true;
    }
    p->runs.push_back(r);
  }
  PointOutcome& o = p->outcome;
  if (!values.empty()) {
    if (spec.aggregate == "worst") {
      o.value = spec.until.HigherIsWorse() ? *std::max_element(values.begin(), values.end())
                                           : *std::min_element(values.begin(), values.end());
    } else {
      double sum = 0.0;
      for (double v : values) sum += v;
      o.value = sum / static_cast<double>(values.size());
    }
  }
  o.crossed = failed || lost || spec.until.Met(o.value);
  return true;
}

std::string Why(const BreakpointSpec& spec, const PointRecord& p) {
  int failed = 0, lost = 0;
  for (const SeedRun& r : p.runs) {
    failed += r.failed ? 1 : 0;
    lost += !r.failed && spec.max_lost_frames >= 0 && r.lost_frames > spec.max_lost_frames;
  }
  std::string why;
  if (failed > 0) why += std::to_string(failed) + " run(s) failed";
  if (lost > 0)
    why += std::string(why.empty() ? "" : ", ") + std::to_string(lost) +
           " run(s) lost tracking (> " + std::to_string(spec.max_lost_frames) + " lost frames)";
  if (why.empty()) why = p.outcome.crossed ? "condition met" : "condition not met";
  return why;
}

json NumberOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json BreakpointJson(const BreakpointSpec& spec, const std::string& out_dir,
                    const std::vector<PointRecord>& points, const SearchResult& search,
                    double wall_s) {
  json j;
  j["command"] = BreakpointCommand(spec, out_dir);
  j["scenario"] = spec.scenario.name;
  j["scenario_arg"] = spec.scenario_arg;
  j["vary"] = {{"key", spec.key},
               {"integer", spec.integer},
               {"range", {spec.lo, spec.hi}},
               {"scan_points", spec.search.scan_points},
               {"tolerance", spec.search.tolerance},
               {"max_evals", spec.search.max_evals}};
  j["until"] = {{"metric", spec.until.metric},
                {"op", spec.until.op},
                {"value", spec.until.value},
                {"text", spec.until.Text()}};
  if (spec.external_arg.empty()) {
    j["estimator"] = {
        {"kind", "built-in VO"},
        {"config", spec.config_path.empty() ? json(nullptr) : json(spec.config_path)}};
  } else {
    j["estimator"] = {
        {"kind", "external"}, {"external", spec.external_arg}, {"command", spec.estimator.command}};
  }
  json seeds = json::array();
  for (int s = 0; s < spec.seeds; ++s) seeds.push_back(spec.scenario.seed + s);
  j["seeds"] = seeds;
  j["aggregate"] = spec.aggregate;
  j["max_frames"] = spec.max_frames;
  j["stride"] = spec.key == kStrideKey ? json(nullptr) : json(spec.stride);
  j["max_lost_frames"] = spec.max_lost_frames;
  json result;
  result["status"] = search.status;
  result["threshold"] = NumberOrNull(search.threshold);
  result["bracket"] = std::isfinite(search.bracket_lo)
                          ? json::array({search.bracket_lo, search.bracket_hi})
                          : json(nullptr);
  result["tolerance_reached"] = search.tolerance_reached;
  result["monotone"] = search.monotone;
  result["uncrossed_after_crossing"] = search.uncrossed_after_crossing;
  result["evaluations"] = points.size();
  j["result"] = result;
  json list = json::array();
  json times = json::array();
  for (const PointRecord& p : points) {
    json pj;
    pj["index"] = p.index;
    pj["phase"] = p.phase;
    pj["x"] = p.x;
    pj["value"] = NumberOrNull(p.outcome.value);
    pj["crossed"] = p.outcome.crossed;
    pj["why"] = Why(spec, p);
    json runs = json::array();
    for (const SeedRun& r : p.runs) {
      json rj;
      rj["seed"] = r.seed;
      rj["folder"] = r.folder;
      rj["metric"] = NumberOrNull(r.metric);
      rj["lost_frames"] = r.lost_frames >= 0 ? json(r.lost_frames) : json(nullptr);
      rj["failed"] = r.failed;
      if (r.failed) rj["failure"] = r.failure;
      runs.push_back(rj);
    }
    pj["runs"] = runs;
    list.push_back(pj);
    times.push_back(p.wall_s);
  }
  j["points"] = list;
  j["timing"] = {{"wall_s", wall_s}, {"point_wall_s", times}};
  return j;
}

std::string PointsCsv(const BreakpointSpec& spec, const std::vector<PointRecord>& points) {
  std::ostringstream csv;
  csv << "index,phase," << spec.key << "," << spec.until.metric << ",crossed,failed_runs,"
      << "max_lost_frames";
  for (int s = 0; s < spec.seeds; ++s)
    csv << ",s" << (spec.scenario.seed + s) << ":" << spec.until.metric;
  csv << "\n";
  for (const PointRecord& p : points) {
    int failed = 0, lost = -1;
    for (const SeedRun& r : p.runs) {
      failed += r.failed ? 1 : 0;
      lost = std::max(lost, r.lost_frames);
    }
    csv << p.index << "," << p.phase << "," << ValueText(p.x, spec.integer) << ","
        << (std::isfinite(p.outcome.value) ? FormatDouble(p.outcome.value) : "") << ","
        << (p.outcome.crossed ? 1 : 0) << "," << failed << ","
        << (lost >= 0 ? std::to_string(lost) : "");
    for (const SeedRun& r : p.runs)
      csv << "," << (std::isfinite(r.metric) ? FormatDouble(r.metric) : "");
    csv << "\n";
  }
  return csv.str();
}

// "threshold ≈ 7.5 (bracket [6.875, 8.125])" and the like.
std::string ResultLine(const BreakpointSpec& spec, const SearchResult& s) {
  const std::string k = spec.key;
  if (s.status == "crossed_at_low")
    return spec.until.Text() + " already at " + k + "=" + ValueText(spec.lo, spec.integer) +
           ": the breaking point is at or below the range";
  if (s.status == "not_crossed")
    return spec.until.Text() + " nowhere in " + k + " in [" + ValueText(spec.lo, spec.integer) +
           ", " + ValueText(spec.hi, spec.integer) + "]: the breaking point is above the range";
  std::ostringstream line;
  line << spec.until.Text() << " from " << k << " in (" << ValueText(s.bracket_lo, spec.integer)
       << ", " << ValueText(s.bracket_hi, spec.integer) << "], threshold ~ "
       << FormatDouble(s.threshold);
  if (!s.tolerance_reached) line << " (tolerance not reached: --max-evals ended the search)";
  return line.str();
}

std::string ReportMarkdown(const BreakpointSpec& spec, const std::vector<PointRecord>& points,
                           const SearchResult& s, const std::string& out_dir, bool has_plot) {
  std::ostringstream md;
  md << "# Breaking point: " << spec.scenario.name << ", " << spec.key << " until "
     << spec.until.Text() << "\n\n";
  md << "```\n" << BreakpointCommand(spec, out_dir) << "\n```\n\n";
  md << "**" << ResultLine(spec, s) << "**\n\n";
  if (!s.monotone) {
    md << "Not monotone: the condition was met, then not met again at " << spec.key << " =";
    for (double x : s.uncrossed_after_crossing) md << " " << ValueText(x, spec.integer);
    md << " (the bisection worked on the first crossing).\n\n";
  }
  md << "- estimator: "
     << (spec.external_arg.empty()
             ? "the built-in VO" + (spec.config_path.empty() ? "" : " with " + spec.config_path)
             : "external configuration " + spec.external_arg)
     << "\n";
  md << "- seeds: " << spec.seeds << " (from " << spec.scenario.seed
     << "), point value = " << (spec.aggregate == "worst" ? "the worst seed" : "the seeds' mean")
     << "\n";
  md << "- a run that fails, or loses more than " << spec.max_lost_frames
     << " frames (built-in VO), counts as crossed"
     << (spec.max_lost_frames < 0 ? " (lost frames ignored: --max-lost-frames -1)" : "") << "\n";
  md << "- frames: " << (spec.max_frames > 0 ? std::to_string(spec.max_frames) : "all")
     << (spec.key == kStrideKey ? "" : ", stride " + std::to_string(spec.stride)) << "\n";
  md << "- search: " << spec.search.scan_points << "-point scan over ["
     << ValueText(spec.lo, spec.integer) << ", " << ValueText(spec.hi, spec.integer)
     << "], bisection to a bracket of " << FormatDouble(spec.search.tolerance) << "; "
     << points.size() << " evaluations\n\n";
  if (has_plot) md << "![breakpoint](breakpoint.png)\n\n";
  md << "| # | phase | " << spec.key << " | " << spec.until.metric << " | crossed | why |\n";
  md << "|---|---|---|---|---|---|\n";
  for (const PointRecord& p : points)
    md << "| " << p.index << " | " << p.phase << " | " << ValueText(p.x, spec.integer) << " | "
       << (std::isfinite(p.outcome.value) ? FormatDouble(p.outcome.value) : "n/a") << " | "
       << (p.outcome.crossed ? "yes" : "no") << " | " << Why(spec, p) << " |\n";
  md << "\nEvery run's folder is under points/ (run folders of `vobench run`, without plots).\n";
  return md.str();
}

}  // namespace

bool UntilCondition::Met(double x) const {
  if (!std::isfinite(x)) return false;
  if (op == ">") return x > value;
  if (op == "<") return x < value;
  if (op == ">=") return x >= value;
  return x <= value;
}

bool UntilCondition::HigherIsWorse() const { return op == ">" || op == ">="; }

std::string UntilCondition::Text() const { return metric + op + FormatDouble(value); }

std::vector<std::string> BreakpointMetrics() {
  std::vector<std::string> keys;
  const RunSummary empty;
  for (const MetricInfo& m : RunMetrics()) {
    if (m.reason || m.group == MetricGroup::kTiming) continue;
    const json v = m.value(empty);
    if (v.is_number() || v.is_null()) keys.push_back(m.key);
  }
  return keys;
}

bool ParseUntil(const std::string& text, UntilCondition* until, std::string* error) {
  static const std::regex pattern(R"(^\s*([A-Za-z0-9_.]+)\s*(>=|<=|>|<)\s*(\S+)\s*$)");
  std::smatch m;
  if (!std::regex_match(text, m, pattern)) {
    *error = "--until '" + text +
             "': expected METRIC>VALUE, METRIC<VALUE, METRIC>=VALUE or METRIC<=VALUE "
             "(e.g. 'end_pose_error_pct>2')";
    return false;
  }
  UntilCondition u;
  u.metric = m[1];
  u.op = m[2];
  const std::vector<std::string> known = BreakpointMetrics();
  if (std::find(known.begin(), known.end(), u.metric) == known.end()) {
    *error = "--until: unknown metric '" + u.metric + "' (expected " + ListOfNames(known) + ")";
    return false;
  }
  if (!ParseDouble(m[3].str(), &u.value) || !std::isfinite(u.value)) {
    *error = "--until '" + text + "': '" + m[3].str() + "' is not a finite number";
    return false;
  }
  *until = u;
  return true;
}

bool ParseRange(const std::string& text, double* lo, double* hi, std::string* error) {
  const size_t comma = text.find(',');
  double a = 0.0, b = 0.0;
  const auto trim = [](std::string s) {
    s.erase(0, s.find_first_not_of(" \t"));
    s.erase(s.find_last_not_of(" \t") + 1);
    return s;
  };
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos ||
      !ParseDouble(trim(text.substr(0, comma)), &a) ||
      !ParseDouble(trim(text.substr(comma + 1)), &b) || !std::isfinite(a) || !std::isfinite(b)) {
    *error = "--range '" + text + "': expected LO,HI (two numbers, e.g. 0,20)";
    return false;
  }
  if (!(a < b)) {
    *error = "--range '" + text + "': LO must be below HI";
    return false;
  }
  *lo = a;
  *hi = b;
  return true;
}

bool FindBreakpoint(const SearchOptions& o, const EvaluatePoint& evaluate, SearchResult* result,
                    std::string* error) {
  if (!(o.lo < o.hi) || !std::isfinite(o.lo) || !std::isfinite(o.hi)) {
    *error = "the range needs LO < HI";
    return false;
  }
  if (o.scan_points < 2) {
    *error = "--scan: needs at least 2 points (both ends of the range)";
    return false;
  }
  if (!(o.tolerance > 0)) {
    *error = "--tolerance: must be > 0";
    return false;
  }
  if (o.max_evals < o.scan_points) {
    *error = "--max-evals " + std::to_string(o.max_evals) + ": the scan alone takes " +
             std::to_string(o.scan_points) + " evaluations";
    return false;
  }
  if (o.integer && (o.lo != std::round(o.lo) || o.hi != std::round(o.hi))) {
    *error = "the range of an integer key needs whole numbers";
    return false;
  }
  SearchResult r;
  const auto eval = [&](double x, const char* phase, bool* crossed) {
    SearchPoint p;
    p.x = x;
    p.phase = phase;
    if (!evaluate(x, phase, &p.outcome, error)) return false;
    *crossed = p.outcome.crossed;
    r.points.push_back(p);
    return true;
  };

  // The scan: evenly spaced, both ends; an integer key on whole numbers (no value twice).
  std::vector<double> xs;
  for (int i = 0; i < o.scan_points; ++i) {
    double x = i == o.scan_points - 1 ? o.hi : o.lo + (o.hi - o.lo) * i / (o.scan_points - 1);
    if (o.integer) x = std::round(x);
    if (xs.empty() || x != xs.back()) xs.push_back(x);
  }
  std::vector<bool> crossed(xs.size());
  int first = -1;
  for (size_t i = 0; i < xs.size(); ++i) {
    bool c = false;
    if (!eval(xs[i], "scan", &c)) return false;
    crossed[i] = c;
    if (c && first < 0) first = static_cast<int>(i);
    if (!c && first >= 0) {
      r.monotone = false;
      r.uncrossed_after_crossing.push_back(xs[i]);
    }
  }
  if (first < 0) {
    r.status = "not_crossed";
  } else if (first == 0) {
    r.status = "crossed_at_low";
  } else {
    // Bisection of (lo, hi]: lo not crossed, hi crossed.
    double lo = xs[first - 1], hi = xs[first];
    const double tolerance = o.integer ? std::max(1.0, o.tolerance) : o.tolerance;
    while (hi - lo > tolerance && static_cast<int>(r.points.size()) < o.max_evals) {
      const double mid = o.integer ? std::floor((lo + hi) / 2) : lo + (hi - lo) / 2;
      if (mid <= lo || mid >= hi) break;  // neighbouring doubles
      bool c = false;
      if (!eval(mid, "bisect", &c)) return false;
      (c ? hi : lo) = mid;
    }
    r.status = "bracketed";
    r.bracket_lo = lo;
    r.bracket_hi = hi;
    r.threshold = lo + (hi - lo) / 2;
    r.tolerance_reached = hi - lo <= tolerance;
  }
  if (r.status != "bracketed") r.tolerance_reached = false;
  *result = r;
  return true;
}

bool PrepareBreakpoint(BreakpointSpec* spec, std::string* error) {
  BreakpointSpec& s = *spec;
  if (s.seeds < 1) {
    *error = "--seeds: must be >= 1";
    return false;
  }
  if (s.aggregate != "mean" && s.aggregate != "worst") {
    *error = "--aggregate: expected mean or worst, got '" + s.aggregate + "'";
    return false;
  }
  const YAML::Node doc = YAML::Load(sim::ScenarioToYaml(s.scenario));
  std::vector<std::string> keys;
  NumericKeys(doc, "", &keys);
  keys.erase(std::remove(keys.begin(), keys.end(), std::string("seed")), keys.end());
  if (s.key == kStrideKey) {
    s.integer = true;
    if (s.lo != std::round(s.lo) || s.hi != std::round(s.hi) || s.lo < 1) {
      *error = "--range: stride takes whole numbers >= 1, got " + s.range_text;
      return false;
    }
    if (const std::string problem = FrameBudgetProblem(sim::EstimatedFrames(s.scenario), true,
                                                       s.max_frames, static_cast<int>(s.hi));
        !problem.empty()) {
      *error = "--range: " + problem;
      return false;
    }
  } else {
    if (std::find(keys.begin(), keys.end(), s.key) == keys.end()) {
      *error = "--vary: '" + s.key + "' is not a numeric key of scenario " + s.scenario.name +
               " (expected stride or one of " + ListOfNames(keys) + ")";
      return false;
    }
    sim::Scenario probe;
    std::string why;
    for (const double x : {s.lo, s.hi}) {
      s.integer = false;
      if (!ScenarioAt(s, x, s.scenario.seed, &probe, &why)) {
        *error = "--range: " + s.key + "=" + FormatDouble(x) + " is refused: " + ReaderMessage(why);
        return false;
      }
    }
    // An integer key refuses a value between whole numbers that its rounding passes.
    const double inside = std::floor(s.lo) + 0.5 < s.hi ? std::floor(s.lo) + 0.5 : s.lo;
    if (inside != s.lo && !ScenarioAt(s, inside, s.scenario.seed, &probe, &why)) {
      s.integer = true;
      if (!ScenarioAt(s, std::round(inside), s.scenario.seed, &probe, &why)) {
        *error =
            "--range: " + s.key + "=" + FormatDouble(inside) + " is refused: " + ReaderMessage(why);
        return false;
      }
      if (s.lo != std::round(s.lo) || s.hi != std::round(s.hi)) {
        *error = "--range: " + s.key + " takes whole numbers, got " + s.range_text;
        return false;
      }
    }
    if (const std::string problem =
            FrameBudgetProblem(sim::EstimatedFrames(s.scenario), true, s.max_frames, s.stride);
        !problem.empty()) {
      *error = problem;
      return false;
    }
  }
  s.search.lo = s.lo;
  s.search.hi = s.hi;
  s.search.integer = s.integer;
  s.search.tolerance = s.tolerance_given > 0 ? s.tolerance_given : (s.hi - s.lo) / 32;
  if (s.integer) s.search.tolerance = std::max(1.0, std::round(s.search.tolerance));
  if (s.search.scan_points < 2) {
    *error = "--scan: needs at least 2 points (both ends of the range)";
    return false;
  }
  if (s.search.max_evals < s.search.scan_points) {
    *error = "--max-evals " + std::to_string(s.search.max_evals) + ": the scan alone takes " +
             std::to_string(s.search.scan_points) + " evaluations";
    return false;
  }
  return true;
}

std::string BreakpointCommand(const BreakpointSpec& s, const std::string& out_dir) {
  std::ostringstream c;
  c << "vobench breakpoint " << ShellQuoted(s.scenario_arg) << " --vary " << s.key << " --range "
    << ShellQuoted(s.range_text) << " --until " << ShellQuoted(s.until.Text());
  if (!s.config_path.empty()) c << " --config " << ShellQuoted(s.config_path);
  if (!s.external_arg.empty()) c << " --external " << ShellQuoted(s.external_arg);
  if (s.seeds != 1) c << " --seeds " << s.seeds << " --aggregate " << s.aggregate;
  if (s.max_frames > 0) c << " --max-frames " << s.max_frames;
  if (s.key != kStrideKey && s.stride != 1) c << " --stride " << s.stride;
  if (s.max_lost_frames != 0) c << " --max-lost-frames " << s.max_lost_frames;
  if (s.tolerance_given > 0) c << " --tolerance " << FormatDouble(s.tolerance_given);
  if (s.search.scan_points != 5) c << " --scan " << s.search.scan_points;
  if (s.search.max_evals != 40) c << " --max-evals " << s.search.max_evals;
  c << " --out " << ShellQuoted(out_dir);
  return c.str();
}

bool RunBreakpoint(const BreakpointSpec& spec, const BreakpointOptions& options,
                   BreakpointResult* result, std::string* error) {
  const auto start = Clock::now();
  OutputFolder folder;
  if (!folder.Create(options.out_dir, "breakpoint", error)) return false;
  const std::string work = folder.path();
  std::vector<PointRecord> points;
  const EvaluatePoint evaluate = [&](double x, const std::string& phase, PointOutcome* outcome,
                                     std::string* why) {
    const auto point_start = Clock::now();
    PointRecord p;
    p.index = static_cast<int>(points.size());
    p.x = x;
    p.phase = phase;
    if (!EvaluatePointRuns(spec, work, folder.dir(), &p, why)) return false;
    p.wall_s = Seconds(point_start);
    if (options.progress)
      std::fprintf(
          stderr, "breakpoint %2d %-6s %s=%s: %s %.5g%s -> %s (%s, %.1f s)\n", p.index,
          p.phase.c_str(), spec.key.c_str(), ValueText(x, spec.integer).c_str(),
          spec.until.metric.c_str(), p.outcome.value,
          spec.seeds > 1
              ? (" (" + spec.aggregate + " of " + std::to_string(spec.seeds) + " seeds)").c_str()
              : "",
          p.outcome.crossed ? "crossed" : "not crossed", Why(spec, p).c_str(), p.wall_s);
    *outcome = p.outcome;
    points.push_back(p);
    return true;
  };
  SearchResult search;
  if (!FindBreakpoint(spec.search, evaluate, &search, error)) {
    if (InterruptSignal() != 0)
      *error =
          InterruptedMessage(static_cast<int>(points.size()), 0, "evaluations", options.out_dir);
    return false;
  }
  const double wall_s = Seconds(start);
  const fs::path p = work;
  if (!WriteTextFile((p / "breakpoint.json").string(),
                     BreakpointJson(spec, folder.dir(), points, search, wall_s).dump(2) + "\n",
                     error) ||
      !WriteTextFile((p / "points.csv").string(), PointsCsv(spec, points), error))
    return false;
  bool has_plot = false;
  if (options.plots) {
    std::string why;
    has_plot =
        RunPythonScript("breakpoint_plot.py", {p.string(), (p / "breakpoint.png").string()}, &why);
    if (!has_plot) std::fprintf(stderr, "warning: no plot: %s\n", why.c_str());
  }
  if (!WriteTextFile((p / "report.md").string(),
                     ReportMarkdown(spec, points, search, folder.dir(), has_plot), error))
    return false;
  if (InterruptSignal() != 0) return false;
  if (!folder.Publish(error)) return false;
  result->search = search;
  result->wall_s = wall_s;
  return true;
}

std::string BreakpointResultLine(const BreakpointSpec& spec, const SearchResult& search) {
  return ResultLine(spec, search);
}

}  // namespace harness
