#include "harness/tune.h"

#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "harness/interrupt.h"
#include "harness/metric_registry.h"
#include "harness/output_folder.h"
#include "harness/overrides.h"
#include "harness/path_names.h"
#include "harness/pipeline.h"
#include "harness/plots/plots.h"
#include "harness/progress.h"
#include "harness/render.h"
#include "harness/run.h"
#include "harness/trajectory_io.h"
#include "harness/vo_config.h"
#include "sim/simulator.h"
#include "sim/yaml_input.h"

namespace harness {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Integer grids up to this many points are checked value by value against the VO config reader
// when the file is loaded (catches e.g. even NCC windows); larger ones at min, max and between.
constexpr long kMaxGridPointsChecked = 64;
// An interior point of a real parameter's range that is no integer for the usual ranges: a
// real parameter on an integer option is refused at load time rather than mid-search.
constexpr double kInteriorProbe = 0.3719;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

std::string Fixed(double v, int precision) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(precision);
  s << v;
  return s.str();
}

std::string Short(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

std::vector<std::string> SplitDots(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string p;
  while (std::getline(ss, p, '.')) parts.push_back(p);
  return parts;
}

// The node at a dotted path of `node` (undefined when there is none).
YAML::Node FindDotted(const YAML::Node& node, const std::vector<std::string>& parts, size_t i) {
  if (i == parts.size()) return node;
  if (!node.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node child = node[parts[i]];
  if (!child.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
  return FindDotted(child, parts, i + 1);
}

using sim::YamlReader;

// "train" / "validation" lists.
bool ReadScenarios(YamlReader& r, const YAML::Node& root, const std::string& what,
                   const std::string& base_dir, std::vector<TuneScenario>* out) {
  const YAML::Node list = root[what];
  if (!list.IsDefined() || list.IsNull() || (list.IsSequence() && list.size() == 0))
    return r.Fail(list.IsDefined() ? list : root, what,
                  "needs at least one scenario (the " + what + " set is empty)");
  if (!list.IsSequence()) return r.Fail(list, what, "expected a list of scenarios");
  for (size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string where = YamlReader::Item(what, i);
    if (!r.CheckKeys(n, where, {"name", "scenario", "set", "max_frames"})) return false;
    TuneScenario s;
    s.line = n.Mark().line + 1;
    if (!r.Require(n, where, "scenario", "a built-in scenario name or a scenario file") ||
        !r.String(n, where, "scenario", &s.scenario_arg, false))
      return false;
    const fs::path relative = fs::path(base_dir) / s.scenario_arg;
    const std::string arg = fs::path(s.scenario_arg).is_relative() && fs::exists(relative)
                                ? relative.string()
                                : s.scenario_arg;
    sim::Scenario base;
    std::string why;
    if (!ResolveScenario(arg, &base, &why)) return r.Fail(n["scenario"], where + ".scenario", why);
    const YAML::Node set = n["set"];
    if (set.IsDefined() && !set.IsNull() && !set.IsMap())
      return r.Fail(set, where + ".set", "expected a mapping of scenario keys to values");
    if (!ApplyScenarioOverrides(base, set, kOverridesSource, &s.scenario, &why))
      return r.SetError(OverrideErrorAt(r.Where(set.IsDefined() ? set : n), where + ".set", why));
    if (const std::string closed = ClosedLoopProblem(s.scenario, "tune"); !closed.empty())
      return r.Fail(n["scenario"], where + ".scenario", closed);
    s.set_yaml = set.IsDefined() && !set.IsNull() ? FlowYaml(set) : "{}";
    s.name = what + "_" + std::to_string(i);
    if (!r.String(n, where, "name", &s.name, false)) return false;
    if (YamlReader::Has(n, "max_frames")) {
      if (!r.ReadWholeNumber(n["max_frames"], where + ".max_frames", 0, 1000000, &s.max_frames))
        return false;
      if (s.max_frames == 1)
        return r.Fail(n["max_frames"], where + ".max_frames", "needs >= 2 frames (or 0 = all)");
    }
    s.scenario.name = s.name;
    out->push_back(s);
  }
  return true;
}

// The text of a value as the VO override sees it: integers without a decimal point, reals as
// the shortest text that reads back to the same double.
std::string ValueText(const Parameter& p, double v) {
  if (p.type == ParameterType::kInt) return std::to_string(static_cast<long long>(v));
  return FormatDouble(v);
}

// One parameter's value set on `overrides` (dotted key -> YAML value).
void SetOverride(const Parameter& p, double value, const YAML::Node& base_yaml,
                 YAML::Node* overrides) {
  if (p.type == ParameterType::kScale) {
    YAML::Node list(YAML::NodeType::Sequence);
    const YAML::Node base = FindDotted(base_yaml, SplitDots(p.key), 0);
    for (const auto& x : base) list.push_back(FormatDouble(x.as<double>() * value));
    (*overrides)[p.key] = list;
  } else {
    (*overrides)[p.key] = ValueText(p, value);
  }
}

bool ApplyValues(const std::vector<Parameter>& parameters, const vo::OdometryOptions& base,
                 const std::vector<double>& values, const std::string& source,
                 vo::OdometryOptions* options, std::string* error) {
  const YAML::Node base_yaml = YAML::Load(VoConfigToYaml(base));
  YAML::Node overrides(YAML::NodeType::Map);
  for (size_t i = 0; i < parameters.size(); ++i)
    SetOverride(parameters[i], values[i], base_yaml, &overrides);
  vo::OdometryOptions o = base;
  if (!ApplyVoOverrides(overrides, source, &o, error)) return false;
  *options = o;
  return true;
}

bool ReadParameters(YamlReader& r, const YAML::Node& root, TuneSpec* spec) {
  const YAML::Node list = root["parameters"];
  if (!list.IsDefined() || list.IsNull() || (list.IsSequence() && list.size() == 0))
    return r.Fail(list.IsDefined() ? list : root, "parameters", "needs at least one parameter");
  if (!list.IsSequence()) return r.Fail(list, "parameters", "expected a list");
  const YAML::Node base_yaml = YAML::Load(VoConfigToYaml(spec->base_options));
  std::set<std::string> seen;
  for (size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string where = YamlReader::Item("parameters", i);
    if (!r.CheckKeys(n, where, {"key", "min", "max", "type", "log", "step"})) return false;
    Parameter p;
    if (!r.Require(n, where, "key", "the VO option's dotted key") ||
        !r.Require(n, where, "min", "the lower end of the range") ||
        !r.Require(n, where, "max", "the upper end of the range") ||
        !r.String(n, where, "key", &p.key, false) || !r.Double(n, where, "min", &p.min) ||
        !r.Double(n, where, "max", &p.max)) {
      return false;
    }
    // Messages about the parameter as a whole: at the list item, naming its VO key.
    const std::string who = "'" + p.key + "': ";
    if (YamlReader::Has(n, "type")) {
      std::string type;
      if (!r.String(n, where, "type", &type, false)) return false;
      if (!ParseParameterType(type, &p.type))
        return r.Fail(n["type"], where + ".type",
                      "expected real, int or scale, got '" + type + "'");
    }
    if (!r.Bool(n, where, "log", &p.log)) return false;
    if (YamlReader::Has(n, "step") &&
        !r.ReadWholeNumber(n["step"], where + ".step", 1, 1000000, &p.step))
      return false;
    std::string why;
    if (!p.IsValid(&why)) return r.Fail(n, where, why);  // names the parameter
    if (!seen.insert(p.key).second) return r.Fail(n["key"], where + ".key", who + "given twice");

    // The key against the VO config reader: known, of the right kind, start value in range.
    const YAML::Node option = FindDotted(base_yaml, SplitDots(p.key), 0);
    if (!option.IsDefined())
      return r.Fail(n["key"], where + ".key",
                    who + "not a VO option key (see a run folder's vo_options.yaml for the keys)");
    double start = 1.0;
    if (p.type == ParameterType::kScale) {
      bool numeric_list = option.IsSequence() && option.size() > 0;
      for (const auto& x : option) numeric_list = numeric_list && ParseDouble(x.Scalar(), &start);
      if (!numeric_list)
        return r.Fail(n["key"], where + ".key",
                      who +
                          "type scale needs a list-valued option (such as "
                          "tracker.matcher.gabor.wavelengths_px), this one holds " +
                          FlowYaml(option));
      start = 1.0;
    } else if (!option.IsScalar() || !ParseDouble(option.Scalar(), &start)) {
      return r.Fail(n["key"], where + ".key",
                    who + "not a numeric VO option (it holds " + FlowYaml(option) + ")" +
                        (option.IsSequence() ? "; use type: scale" : ""));
    }
    if (!IsAttainable(p, start))
      return r.Fail(
          n, where,
          who + "the base configuration's value " + Short(start) + " is outside [" + Short(p.min) +
              ", " + Short(p.max) + "]" +
              (p.type == ParameterType::kInt ? " or off the grid of step " + std::to_string(p.step)
                                             : "") +
              "; the search starts there, widen the range");

    // Values the search can take, each alone on the base options.
    std::vector<double> probes;
    if (p.type == ParameterType::kInt &&
        static_cast<long>((p.max - p.min) / p.step) + 1 <= kMaxGridPointsChecked) {
      for (double v = p.min; v <= p.max; v += p.step) probes.push_back(v);
    } else {
      probes = {p.min, p.max, UnitToValue(p, kInteriorProbe)};
    }
    for (double v : probes) {
      vo::OdometryOptions o;
      if (!ApplyValues({p}, spec->base_options, {v}, r.source() + " " + where, &o, &why)) {
        const bool integer_option = p.type == ParameterType::kReal && v != std::round(v) &&
                                    why.find("integer") != std::string::npos;
        return r.Fail(n, where,
                      who + "the VO options refuse the value " + Short(v) + " of the range: " +
                          why + (integer_option ? " (an integer option needs type: int)" : ""));
      }
    }
    spec->parameters.push_back(p);
    spec->start_values.push_back(start);
  }
  return true;
}

bool ReadObjective(YamlReader& r, const YAML::Node& root, TuneObjective* objective) {
  const YAML::Node n = root["objective"];
  if (!n.IsDefined() || n.IsNull()) return true;
  if (!r.CheckKeys(n, "objective", {"metric", "lost_frame_penalty", "aggregate"})) return false;
  if (!r.String(n, "objective", "metric", &objective->metric, false)) return false;
  if (YamlReader::Has(n, "metric")) {
    const MetricInfo* metric = FindMetric(objective->metric);
    if (metric == nullptr || !metric->tune_objective)
      return r.Fail(n["metric"], "objective.metric",
                    "unknown metric '" + objective->metric + "' (expected " +
                        ListOfNames(TuneObjectiveMetrics()) + ")");
  }
  if (!r.Double(n, "objective", "lost_frame_penalty", &objective->lost_frame_penalty) ||
      !r.Check(objective->lost_frame_penalty >= 0, n, "objective", "lost_frame_penalty",
               "expected >= 0"))
    return false;
  return r.Enum<std::string>(n, "objective", "aggregate", {{"mean", "mean"}, {"max", "max"}},
                             &objective->aggregate);
}

bool ReadOptimizer(YamlReader& r, const YAML::Node& root, OptimizerOptions* optimizer) {
  const YAML::Node n = root["optimizer"];
  if (!n.IsDefined() || n.IsNull()) return true;
  if (!r.CheckKeys(n, "optimizer",
                   {"algorithm", "max_evals", "seed", "initial_step", "xtol_abs"}) ||
      !r.String(n, "optimizer", "algorithm", &optimizer->algorithm, false) ||
      (YamlReader::Has(n, "max_evals") && !r.ReadWholeNumber(n["max_evals"], "optimizer.max_evals",
                                                             1, 1000000, &optimizer->max_evals)) ||
      !r.Uint64(n, "optimizer", "seed", &optimizer->seed) ||
      !r.Double(n, "optimizer", "initial_step", &optimizer->initial_step) ||
      !r.Double(n, "optimizer", "xtol_abs", &optimizer->xtol_abs))
    return false;
  std::string why;
  if (!optimizer->IsValid(&why)) return r.Fail(n, "optimizer", why);
  return true;
}

// harness/plots/tune_plot.py DIR PNG with Debian's python3 (the one python3-matplotlib is for).
bool RunTunePlot(const std::string& dir, const std::string& png, std::string* error) {
  return RunPythonScript("tune_plot.py", {dir, png}, error);
}

std::string ColumnName(const Parameter& p) {
  return p.type == ParameterType::kScale ? p.key + ":scale" : p.key;
}

std::string EvaluationsCsv(const TuneSpec& spec, const OptimizationResult& result,
                           const std::vector<std::vector<SequenceScore>>& scores) {
  std::ostringstream csv;
  csv << "eval,origin";
  for (const Parameter& p : spec.parameters) csv << "," << ColumnName(p);
  for (const TuneScenario& s : spec.train)
    csv << "," << s.name << ":" << spec.objective.metric << "," << s.name << ":lost_frames";
  csv << ",objective,best_objective\n";
  double best = 0.0;
  for (const Evaluation& e : result.evaluations) {
    best = e.index == 0 ? e.score : std::min(best, e.score);
    csv << e.index << "," << e.origin;
    for (size_t i = 0; i < e.values.size(); ++i)
      csv << "," << ValueText(spec.parameters[i], e.values[i]);
    for (const SequenceScore& s : scores[e.index])
      csv << "," << FormatDouble(s.metric) << "," << s.lost_frames;
    csv << "," << FormatDouble(e.score) << "," << FormatDouble(best) << "\n";
  }
  return csv.str();
}

std::string ScoresCsv(const TuneSpec& spec, const TuneSummary& summary) {
  const std::string& m = spec.objective.metric;
  std::ostringstream csv;
  csv << "scenario,set,frames,default_" << m << ",default_lost_frames,default_score,tuned_" << m
      << ",tuned_lost_frames,tuned_score\n";
  for (const TuneScenarioResult& r : summary.scenarios) {
    csv << r.name << "," << (r.train ? "train" : "validation") << "," << r.frames << ","
        << FormatDouble(r.base.metric) << "," << r.base.lost_frames << ","
        << FormatDouble(r.base.score) << "," << FormatDouble(r.tuned.metric) << ","
        << r.tuned.lost_frames << "," << FormatDouble(r.tuned.score) << "\n";
  }
  return csv.str();
}

nlohmann::json ScoreJson(const SequenceScore& s, const std::string& metric) {
  nlohmann::json j;
  j[metric] = s.metric;
  j["lost_frames"] = s.lost_frames;
  j["score"] = s.score;
  j["ate_rmse_m"] = s.metrics.ate_rmse_m;
  j["end_pose_error_m"] = s.metrics.end_pose_error_m;
  j["drift_pct"] = s.metrics.drift_pct;
  return j;
}

std::string SummaryJson(const TuneSpec& spec, const TuneSummary& s, const OptimizerOptions& opt) {
  nlohmann::json j;
  const OptimizationResult& r = s.optimization;
  j["name"] = spec.name;
  j["tune_file"] = spec.source_path;
  j["base_config"] = spec.base_config_path;
  j["objective"] = {{"metric", spec.objective.metric},
                    {"lost_frame_penalty", spec.objective.lost_frame_penalty},
                    {"aggregate", spec.objective.aggregate}};
  j["optimizer"] = {{"algorithm", opt.algorithm},
                    {"max_evals", opt.max_evals},
                    {"seed", opt.seed},
                    {"evaluations", r.evaluations.size()},
                    {"optimizer_calls", r.optimizer_calls},
                    {"restarts", r.restarts},
                    {"stop_reason", r.stop_reason},
                    {"best_eval", r.best_index},
                    {"best_origin", r.best().origin}};
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    const Parameter& p = spec.parameters[i];
    j["parameters"].push_back({{"key", p.key},
                               {"type", ToString(p.type)},
                               {"min", p.min},
                               {"max", p.max},
                               {"log", p.log},
                               {"step", p.step},
                               {"default", spec.start_values[i]},
                               {"tuned", r.best().values[i]}});
  }
  j["train"] = {{"default", s.train_base}, {"tuned", s.train_tuned}};
  j["validation"] = {{"default", s.validation_base}, {"tuned", s.validation_tuned}};
  for (const TuneScenarioResult& sc : s.scenarios) {
    j["scenarios"].push_back({{"name", sc.name},
                              {"set", sc.train ? "train" : "validation"},
                              {"frames", sc.frames},
                              {"default", ScoreJson(sc.base, spec.objective.metric)},
                              {"tuned", ScoreJson(sc.tuned, spec.objective.metric)}});
  }
  j["timing_s"] = {
      {"simulate", s.simulate_s},
      {"search", s.search_s},
      {"validation", s.validation_s},
      {"total", s.wall_s},
      {"per_evaluation", r.evaluations.empty() ? 0.0 : s.search_s / r.evaluations.size()}};
  return j.dump(2) + "\n";
}

std::string Change(double before, double after) {
  if (before == 0.0) return "";
  return (after <= before ? "" : "+") + Fixed(100.0 * (after - before) / before, 1) + " %";
}

std::string ReportMarkdown(const TuneSpec& spec, const TuneSummary& s, const OptimizerOptions& opt,
                           bool has_plot) {
  const OptimizationResult& r = s.optimization;
  const std::string& metric = spec.objective.metric;
  std::ostringstream md;
  md << "# vobench tune: " << spec.name << "\n\n";
  md << "Tune file `" << (spec.source_path.empty() ? "(text)" : spec.source_path)
     << "` (copied as `tune.yaml`); default = "
     << (spec.base_config_path.empty() ? "the library defaults" : "`" + spec.base_config_path + "`")
     << ". Optimizer " << opt.algorithm << ", seed " << opt.seed << ": " << r.evaluations.size()
     << " evaluations (budget " << opt.max_evals << ", " << r.restarts << " restarts; "
     << r.stop_reason << "). Run time " << Fixed(s.wall_s, 0) << " s (simulation "
     << Fixed(s.simulate_s, 0) << " s, search " << Fixed(s.search_s, 0)
     << " s = " << Fixed(r.evaluations.empty() ? 0.0 : s.search_s / r.evaluations.size(), 1)
     << " s per evaluation, validation " << Fixed(s.validation_s, 0) << " s).\n\n";
  md << "Score of a scenario = " << metric << " + " << Short(spec.objective.lost_frame_penalty)
     << " × lost frames (smaller is better); objective = " << spec.objective.aggregate
     << " over the scenarios of a set. The search sees only the training set.\n\n";
  md << "## Default vs tuned\n\n";
  md << "| scenario | set | frames | default " << metric << " | default lost | tuned " << metric
     << " | tuned lost | default score | tuned score | change |\n";
  md << "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const TuneScenarioResult& sc : s.scenarios) {
    md << "| " << sc.name << " | " << (sc.train ? "train" : "validation") << " | " << sc.frames
       << " | " << Fixed(sc.base.metric, 5) << " | " << sc.base.lost_frames << " | "
       << Fixed(sc.tuned.metric, 5) << " | " << sc.tuned.lost_frames << " | "
       << Fixed(sc.base.score, 5) << " | " << Fixed(sc.tuned.score, 5) << " | "
       << Change(sc.base.score, sc.tuned.score) << " |\n";
  }
  md << "| **training (" << spec.objective.aggregate << ")** | | | | | | | **"
     << Fixed(s.train_base, 5) << "** | **" << Fixed(s.train_tuned, 5) << "** | "
     << Change(s.train_base, s.train_tuned) << " |\n";
  md << "| **validation (" << spec.objective.aggregate << ")** | | | | | | | **"
     << Fixed(s.validation_base, 5) << "** | **" << Fixed(s.validation_tuned, 5) << "** | "
     << Change(s.validation_base, s.validation_tuned) << " |\n\n";
  if (r.best_index == 0) {
    md << "The search found nothing better than the default on the training set: the tuned "
          "configuration is the default.\n\n";
  } else {
    md << "On the validation set the tuned configuration is "
       << (s.validation_tuned < s.validation_base
               ? "**better** than the default"
               : (s.validation_tuned == s.validation_base
                      ? "**as good as** the default"
                      : "**worse** than the default "
                        "(the gain on training does not carry over)"))
       << " (" << Fixed(s.validation_base, 5) << " -> " << Fixed(s.validation_tuned, 5) << ").";
    // Per scenario, so a mean carried by one scenario is not mistaken for a general gain.
    for (const bool train : {true, false}) {
      std::vector<std::string> better, worse;
      for (const TuneScenarioResult& sc : s.scenarios) {
        if (sc.train != train) continue;
        if (sc.tuned.score < sc.base.score) better.push_back(sc.name);
        if (sc.tuned.score > sc.base.score)
          worse.push_back(sc.name + " " + Change(sc.base.score, sc.tuned.score));
      }
      md << " " << (train ? "Training" : "Validation") << " scenarios: better on " << better.size()
         << ", worse on " << worse.size();
      for (size_t i = 0; i < worse.size(); ++i) md << (i == 0 ? " (" : ", ") << worse[i];
      md << (worse.empty() ? "." : ").");
    }
    md << "\n\n";
  }
  md << "## Parameters\n\n";
  md << "| key | type | range | default | tuned |\n| --- | --- | --- | ---: | ---: |\n";
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    const Parameter& p = spec.parameters[i];
    md << "| `" << p.key << "` | " << ToString(p.type) << (p.log ? ", log" : "")
       << (p.type == ParameterType::kInt && p.step != 1 ? ", step " + std::to_string(p.step) : "")
       << " | [" << Short(p.min) << ", " << Short(p.max) << "] | " << Short(spec.start_values[i])
       << " | " << Short(r.best().values[i]) << " |\n";
  }
  md << "\nBest at evaluation " << r.best_index << " (" << r.best().origin
     << "); `best_vo.yaml` holds the tuned options (`vobench run --config best_vo.yaml`), "
        "`evaluations.csv` every evaluation.\n\n";
  if (has_plot) md << "![objective per evaluation](objective.png)\n\n";
  md << "## Scenarios\n\n| scenario | set | scenario file | overrides | max frames |\n"
        "| --- | --- | --- | --- | ---: |\n";
  for (const auto* list : {&spec.train, &spec.validation}) {
    for (const TuneScenario& sc : *list) {
      md << "| " << sc.name << " | " << (list == &spec.train ? "train" : "validation") << " | "
         << sc.scenario_arg << " | `" << sc.set_yaml << "` | "
         << (sc.max_frames > 0 ? std::to_string(sc.max_frames) : "all") << " |\n";
    }
  }
  return md.str();
}

}  // namespace

bool ParseTuneSpec(const std::string& yaml_text, const std::string& source_name,
                   const std::string& base_dir, TuneSpec* spec, std::string* error) {
  YamlReader r(source_name);
  if (!r.Parse(yaml_text)) return r.Report(error);
  YAML::Node root = r.root();  // not const: a missing key reads as undefined, not invalid
  if (!root.IsMap()) {
    *error = source_name + ": expected a YAML mapping (name, train, validation, parameters, ...)";
    return false;
  }
  TuneSpec s;
  s.text = yaml_text;
  s.name = fs::path(source_name).stem().string();
  // A suite's external configuration (harness/suite/external.h) is another program: its
  // parameters are its own, out of reach of tune, which searches this VO's options.
  for (const char* key : {"external", "configs"})
    if (YamlReader::Has(root, key)) {
      r.Fail(root[key], key,
             "tune searches this VO's options (parameters, base_config); an external "
             "program's parameters cannot be tuned here: score it in a suite (configs: "
             "external:) or `vobench score`");
      return r.Report(error);
    }
  if (!r.CheckKeys(
          root, "",
          {"name", "base_config", "train", "validation", "parameters", "objective", "optimizer"}) ||
      !r.String(root, "", "name", &s.name, false))
    return r.Report(error);
  std::string name_error;
  if (!CheckPathName(s.name, "tune name", &name_error)) {
    r.Fail(root["name"].IsDefined() ? root["name"] : root, "name", name_error);
    return r.Report(error);
  }
  if (root["base_config"].IsDefined() && !root["base_config"].IsNull()) {
    std::string path;
    if (!r.String(root, "", "base_config", &path, false)) return r.Report(error);
    s.base_config_path = fs::path(path).is_relative() ? (fs::path(base_dir) / path).string() : path;
    std::string why;
    if (!LoadVoConfig(s.base_config_path, &s.base_options, &why)) {
      r.Fail(root["base_config"], "base_config", why);
      return r.Report(error);
    }
  }
  if (!ReadScenarios(r, root, "train", base_dir, &s.train) ||
      !ReadScenarios(r, root, "validation", base_dir, &s.validation)) {
    return r.Report(error);
  }
  // Names unique; validation scenarios differ from every training one.
  const auto where = [&](const TuneScenario& sc, const std::string& list, size_t i) {
    return source_name + ":" + std::to_string(sc.line) + ": key '" + YamlReader::Item(list, i) +
           "': ";
  };
  std::set<std::string> names;
  for (const std::string list : {"train", "validation"}) {
    const std::vector<TuneScenario>& scenarios = list == "train" ? s.train : s.validation;
    for (size_t i = 0; i < scenarios.size(); ++i) {
      if (!names.insert(scenarios[i].name).second) {
        *error = where(scenarios[i], list, i) + "scenario name '" + scenarios[i].name +
                 "' is used twice (names must be unique across train and validation)";
        return false;
      }
    }
  }
  for (size_t i = 0; i < s.validation.size(); ++i) {
    const TuneScenario& v = s.validation[i];
    sim::Scenario a = v.scenario;
    a.name.clear();
    for (const TuneScenario& t : s.train) {
      sim::Scenario b = t.scenario;
      b.name.clear();
      if (v.max_frames == t.max_frames && sim::ScenarioToYaml(a) == sim::ScenarioToYaml(b)) {
        *error = where(v, "validation", i) + "validation scenario '" + v.name +
                 "' is the same as training scenario '" + t.name +
                 "' (validation needs other scenarios, e.g. other textures.seed or seed)";
        return false;
      }
    }
  }
  if (!ReadParameters(r, root, &s) || !ReadObjective(r, root, &s.objective) ||
      !ReadOptimizer(r, root, &s.optimizer)) {
    return r.Report(error);
  }
  *spec = s;
  return true;
}

bool LoadTuneSpec(const std::string& path, TuneSpec* spec, std::string* error) {
  std::string text;
  if (!sim::ReadInputFile(path, "YAML tune file", &text, error)) return false;
  if (!ParseTuneSpec(text, path, fs::path(path).parent_path().string(), spec, error)) return false;
  spec->source_path = path;
  return true;
}

bool ApplyParameters(const TuneSpec& spec, const std::vector<double>& values,
                     vo::OdometryOptions* options, std::string* error) {
  if (values.size() != spec.parameters.size()) {
    *error = "expected " + std::to_string(spec.parameters.size()) + " parameter values, got " +
             std::to_string(values.size());
    return false;
  }
  return ApplyValues(spec.parameters, spec.base_options, values,
                     (spec.source_path.empty() ? spec.name : spec.source_path) + " parameters",
                     options, error);
}

bool SimulateTuneScenario(const TuneScenario& scenario, bool progress, TuneSequence* sequence,
                          std::string* error) {
  StereoSequence simulated;
  if (!OpenScenarioSequence(scenario.scenario, &simulated, error)) {
    *error = scenario.name + ": " + *error;
    return false;
  }
  sequence->name = scenario.name;
  sequence->camera = simulated.camera;
  sequence->axle_behind_camera_m = simulated.axle_behind_camera_m;
  sequence->camera_pitch_deg = simulated.camera_pitch_deg;
  sequence->has_gyro = SequenceGyro(simulated, &sequence->gyro);
  const FrameSource without_depth = [&](DatasetFrame* frame, std::string* err) {
    if (!simulated.next(frame, err)) return false;
    frame->depth_m = cv::Mat();  // not needed: the score uses the poses only
    return true;
  };
  if (!ReadAllFrames(without_depth, scenario.max_frames, simulated.expected_frames,
                     "simulate " + scenario.name, progress, "", &sequence->frames, error)) {
    *error = scenario.name + ": " + *error;  // RunTune words the message of an interrupt
    return false;
  }
  if (sequence->frames.size() < 2) {
    *error = scenario.name + ": the simulation gave fewer than 2 frames";
    return false;
  }
  return true;
}

// Score of a sequence the VO never initialised on.
constexpr double kUnusableScore = 1e9;

bool ScoreSequence(const TuneSequence& sequence, const vo::OdometryOptions& options,
                   const TuneObjective& objective, SequenceScore* score, std::string* error) {
  std::string why;
  auto odometry = vo::StereoOdometry::Create(
      sequence.camera,
      vo::ResolvePlatform(options, sequence.axle_behind_camera_m, sequence.camera_pitch_deg), &why);
  if (!odometry) {
    *error = sequence.name + ": invalid VO options or camera: " + why;
    return false;
  }
  if (sequence.frames.size() < 2) {
    *error = sequence.name + ": fewer than 2 frames";
    return false;
  }
  if (sequence.has_gyro) odometry->SetGyro(sequence.gyro);
  // The run pipeline without the folder: no progress, no match statistics.
  RunFramesOptions run_options;
  run_options.progress = false;
  run_options.match_stats = false;
  RunRecords records;
  if (!RunFrames(sequence.name, FramesInMemory(sequence.frames), *odometry, run_options, &records,
                 &why)) {
    *error = sequence.name + ": " + why;  // RunTune words the message of an interrupt
    return false;
  }
  SequenceScore s;
  // Frames before the first one the VO initialised on have no pose (as in `run`): they are
  // penalised as lost frames and left out of the trajectory, anchored at that first frame.
  for (const FrameRecord& f : records.frames) s.lost_frames += vo::IsLostFrame(f.result) ? 1 : 0;
  if (records.frames.size() - FirstInitialisedFrame(records) < 2) {
    // never (or only at the last frame) initialised: the worst score
    s.metric = kUnusableScore;
    s.score = kUnusableScore;
    *score = s;
    return true;
  }
  RunSummary summary;
  if (!Summarize(records, &summary, error)) return false;
  s.metrics = summary.metrics;
  std::string not_applicable;
  if (!ObjectiveValue(summary, objective.metric, &s.metric, &not_applicable)) {
    *error = "unknown metric '" + objective.metric + "'";
    return false;
  }
  if (!std::isfinite(s.metric)) {  // null in metrics.json: the objective does not apply
    *error = "objective.metric " + objective.metric + " is null (not applicable) on " +
             records.name + ": " + (not_applicable.empty() ? "no value" : not_applicable) +
             "; choose another objective metric";
    return false;
  }
  s.score = s.metric + objective.lost_frame_penalty * s.lost_frames;
  *score = s;
  return true;
}

double AggregateScores(const std::vector<SequenceScore>& scores, const TuneObjective& objective) {
  if (scores.empty()) return 0.0;
  double sum = 0.0, max = -std::numeric_limits<double>::infinity();
  for (const SequenceScore& s : scores) {
    sum += s.score;
    max = std::max(max, s.score);
  }
  return objective.aggregate == "max" ? max : sum / static_cast<double>(scores.size());
}

namespace {

// RunTune without the interrupt message; *evaluations counts the objective's evaluations.
bool RunTuneSteps(const TuneSpec& spec, const TuneOptions& options, TuneSummary* summary,
                  int* evaluations, std::string* error) {
  const auto start = Clock::now();
  const fs::path dir = options.out_dir;
  if (dir.empty()) {
    *error = "no output folder given";
    return false;
  }
  // The output folder first (locked, refused early when not vobench's), published at the end.
  OutputFolder folder;
  if (!folder.Create(dir.string(), "tune", error)) return false;
  OptimizerOptions opt = spec.optimizer;
  if (options.max_evals > 0) opt.max_evals = options.max_evals;
  if (!opt.IsValid(error)) return false;
  TuneSummary s;

  // 1. Simulate every scenario once, into memory.
  std::vector<TuneSequence> train(spec.train.size()), validation(spec.validation.size());
  for (size_t i = 0; i < spec.train.size(); ++i)
    if (!SimulateTuneScenario(spec.train[i], options.progress, &train[i], error)) return false;
  for (size_t i = 0; i < spec.validation.size(); ++i)
    if (!SimulateTuneScenario(spec.validation[i], options.progress, &validation[i], error))
      return false;
  s.simulate_s = Seconds(start);

  // 2. Search on the training set.
  const auto search_start = Clock::now();
  std::vector<std::vector<SequenceScore>> eval_scores;  // per evaluation, per training scenario
  const Objective objective = [&](const std::vector<double>& values, double* score,
                                  std::string* why) {
    vo::OdometryOptions o;
    if (!ApplyParameters(spec, values, &o, why)) return false;
    std::vector<SequenceScore> scores(train.size());
    for (size_t i = 0; i < train.size(); ++i)
      if (!ScoreSequence(train[i], o, spec.objective, &scores[i], why)) return false;
    *score = AggregateScores(scores, spec.objective);
    eval_scores.push_back(scores);
    *evaluations = static_cast<int>(eval_scores.size());
    return true;
  };
  auto last = Clock::now();
  const EvaluationCallback progress = [&](const Evaluation& e, const Evaluation& best,
                                          int max_evals) {
    if (!options.progress) return;
    std::fprintf(stderr, "tune %s  [%d/%d] eval %d  score %.6f  best %.6f (eval %d)  %s  %.1f s\n",
                 spec.name.c_str(), e.index + 1, max_evals, e.index, e.score, best.score,
                 best.index, e.origin.c_str(), Seconds(last));
    last = Clock::now();
  };
  if (!Minimize(spec.parameters, spec.start_values, opt, objective, &s.optimization, error,
                progress))
    return false;
  s.search_s = Seconds(search_start);
  const Evaluation& best = s.optimization.best();
  if (!ApplyParameters(spec, best.values, &s.best_options, error)) return false;

  // 3. Default vs tuned on both sets (training scores come from the search).
  const auto validation_start = Clock::now();
  for (size_t i = 0; i < train.size(); ++i) {
    TuneScenarioResult r;
    r.name = spec.train[i].name;
    r.train = true;
    r.frames = static_cast<int>(train[i].frames.size());
    r.base = eval_scores[0][i];
    r.tuned = eval_scores[best.index][i];
    s.scenarios.push_back(r);
  }
  std::vector<SequenceScore> val_base, val_tuned;
  vo::OdometryOptions base_options;
  if (!ApplyParameters(spec, spec.start_values, &base_options, error)) return false;
  for (size_t i = 0; i < validation.size(); ++i) {
    TuneScenarioResult r;
    r.name = spec.validation[i].name;
    r.train = false;
    r.frames = static_cast<int>(validation[i].frames.size());
    if (!ScoreSequence(validation[i], base_options, spec.objective, &r.base, error)) return false;
    if (best.index == 0) {
      r.tuned = r.base;
    } else if (!ScoreSequence(validation[i], s.best_options, spec.objective, &r.tuned, error)) {
      return false;
    }
    if (options.progress)
      std::fprintf(stderr, "validate %s: default %.6f, tuned %.6f\n", r.name.c_str(), r.base.score,
                   r.tuned.score);
    val_base.push_back(r.base);
    val_tuned.push_back(r.tuned);
    s.scenarios.push_back(r);
  }
  s.train_base = s.optimization.evaluations[0].score;
  s.train_tuned = best.score;
  s.validation_base = AggregateScores(val_base, spec.objective);
  s.validation_tuned = AggregateScores(val_tuned, spec.objective);
  s.validation_s = Seconds(validation_start);

  // 4. The output folder, written beside DIR and moved into place.
  const fs::path p = folder.path();
  if (!WriteTextFile((p / "best_vo.yaml").string(), VoConfigToYaml(s.best_options), error) ||
      !WriteTextFile((p / "base_vo.yaml").string(), VoConfigToYaml(base_options), error) ||
      !WriteTextFile((p / "evaluations.csv").string(),
                     EvaluationsCsv(spec, s.optimization, eval_scores), error) ||
      !WriteTextFile((p / "scores.csv").string(), ScoresCsv(spec, s), error) ||
      !WriteTextFile((p / "tune.yaml").string(), spec.text, error)) {
    return false;
  }
  s.wall_s = Seconds(start);
  if (!WriteTextFile((p / "summary.json").string(), SummaryJson(spec, s, opt), error)) return false;
  bool has_plot = false;
  if (options.plots) {
    std::string why;
    has_plot = RunTunePlot(p.string(), (p / "objective.png").string(), &why);
    if (!has_plot) std::fprintf(stderr, "warning: no plot: %s\n", why.c_str());
  }
  if (!WriteTextFile((p / "report.md").string(), ReportMarkdown(spec, s, opt, has_plot), error))
    return false;
  if (InterruptSignal() != 0) return false;  // nothing published yet
  if (!folder.Publish(error)) return false;
  *summary = s;
  return true;
}

}  // namespace

bool RunTune(const TuneSpec& spec, const TuneOptions& options, TuneSummary* summary,
             std::string* error) {
  int evaluations = 0;
  if (RunTuneSteps(spec, options, summary, &evaluations, error)) return true;
  if (InterruptSignal() != 0) {
    const int max_evals = options.max_evals > 0 ? options.max_evals : spec.optimizer.max_evals;
    *error = InterruptedMessage(evaluations, max_evals, "evaluations", options.out_dir);
  }
  return false;
}

std::string TuneSummaryTable(const TuneSpec& spec, const TuneSummary& s) {
  const std::string m = spec.objective.metric.substr(0, 22);
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof(line), "%-18s %-10s %6s | %22s %5s %9s | %22s %5s %9s | %8s\n",
                "scenario", "set", "frames", ("default " + m).c_str(), "lost", "score",
                ("tuned " + m).c_str(), "lost", "score", "change");
  out << line;
  for (const TuneScenarioResult& r : s.scenarios) {
    std::snprintf(line, sizeof(line),
                  "%-18s %-10s %6d | %22.5f %5d %9.5f | %22.5f %5d %9.5f | %8s\n", r.name.c_str(),
                  r.train ? "train" : "validation", r.frames, r.base.metric, r.base.lost_frames,
                  r.base.score, r.tuned.metric, r.tuned.lost_frames, r.tuned.score,
                  Change(r.base.score, r.tuned.score).c_str());
    out << line;
  }
  const std::string objective = "objective (" + spec.objective.aggregate + ")";
  for (const bool train : {true, false}) {
    const double base = train ? s.train_base : s.validation_base;
    const double tuned = train ? s.train_tuned : s.validation_tuned;
    std::snprintf(line, sizeof(line), "%-18s %-10s %6s | %22s %5s %9.5f | %22s %5s %9.5f | %8s\n",
                  objective.c_str(), train ? "train" : "validation", "", "", "", base, "", "",
                  tuned, Change(base, tuned).c_str());
    out << line;
  }
  out << "parameters (default -> tuned):\n";
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    std::snprintf(line, sizeof(line), "  %-36s %10s -> %s\n",
                  ColumnName(spec.parameters[i]).c_str(), Short(spec.start_values[i]).c_str(),
                  Short(s.optimization.best().values[i]).c_str());
    out << line;
  }
  return out.str();
}

}  // namespace harness
