#include "harness/check.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <vector>

namespace harness {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

bool IsCheckedMetric(const std::string& name) {
  const MetricInfo* m = FindMetric(name);
  return m != nullptr && m->check_tolerance >= 0;
}

// NaN is written as null (JSON has no NaN).
json NumberOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::string Num(double v, int prec = 4) {
  if (!std::isfinite(v)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", prec, v);
  return buf;
}

std::string Signed(double v, int prec = 4) {
  if (!std::isfinite(v)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%+.*f", prec, v);
  return buf;
}

}  // namespace

Baseline DefaultBaselineRule() {
  Baseline b;
  b.tolerance_rule =
      "Runs are bit-for-bit deterministic on one machine (same build, same numbers), so a "
      "tolerance is "
      "not noise: it is how much worse a metric may get before the check fails. tolerance = "
      "max(relative_tolerance * |baseline|, absolute_tolerance[metric]): 25 % of the value absorbs "
      "other compilers, CPUs and library versions and small intended trade-offs; the absolute "
      "floor "
      "keeps near-zero metrics (a few mm on a short path) from failing on sub-millimetre changes. "
      "Improvements never fail; re-record with `vobench check --update`.";
  b.relative_tolerance = 0.25;
  for (const std::string& name : CheckedMetrics())
    b.absolute_tolerance[name] = FindMetric(name)->check_tolerance;
  return b;
}

bool LoadBaseline(const std::string& path, Baseline* baseline, std::string* error) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    *error = path + ": is a folder, not a baseline file (name the JSON file, e.g. " +
             "results/baseline.json)";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = path + ": cannot read the baseline file: " + std::strerror(errno);
    return false;
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) {
    *error = path + ": cannot read the baseline file";
    return false;
  }
  // A key twice in one object: nlohmann keeps the last silently; a baseline with two entries of
  // one run (a merge gone wrong) must not check only one of them.
  std::vector<std::set<std::string>> keys;  // the keys seen in each open object
  std::string duplicate;
  const json::parser_callback_t on_event = [&](int /*depth*/, json::parse_event_t event,
                                               json& parsed) {
    if (event == json::parse_event_t::object_start) keys.emplace_back();
    if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    if (event == json::parse_event_t::key && !keys.empty() &&
        !keys.back().insert(parsed.get<std::string>()).second && duplicate.empty())
      duplicate = parsed.get<std::string>();
    return true;
  };
  json j;
  try {
    j = json::parse(text, on_event);
  } catch (const std::exception& e) {
    *error = path + ": malformed JSON: " + e.what();
    return false;
  }
  if (!duplicate.empty()) {
    *error = path + ": key '" + duplicate + "': appears twice in one object (a JSON reader keeps " +
             "one of them silently); remove one";
    return false;
  }
  Baseline b;
  auto fail = [&](const std::string& key, const std::string& what) {
    *error = path + ": key '" + key + "': " + what;
    return false;
  };
  if (!j.is_object()) return fail("", "expected a JSON object");
  for (const auto& [k, v] : j.items())
    if (k != "suite" && k != "tolerance_rule" && k != "relative_tolerance" &&
        k != "absolute_tolerance" && k != "runs")
      return fail(k,
                  "unknown key (expected suite, tolerance_rule, relative_tolerance, "
                  "absolute_tolerance, runs)");
  if (!j.contains("suite") || !j["suite"].is_string() || j["suite"].get<std::string>().empty())
    return fail("suite", "required: the suite file, relative to the baseline file");
  b.suite = j["suite"].get<std::string>();
  fs::path suite_path = b.suite;
  if (suite_path.is_relative()) suite_path = fs::path(path).parent_path() / suite_path;
  b.suite_path = suite_path.lexically_normal().string();
  if (j.contains("tolerance_rule")) {
    if (!j["tolerance_rule"].is_string()) return fail("tolerance_rule", "expected a string");
    b.tolerance_rule = j["tolerance_rule"].get<std::string>();
  }
  if (j.contains("relative_tolerance")) {
    if (!j["relative_tolerance"].is_number() || !(j["relative_tolerance"].get<double>() >= 0))
      return fail("relative_tolerance", "expected a number >= 0");
    b.relative_tolerance = j["relative_tolerance"].get<double>();
  }
  if (j.contains("absolute_tolerance")) {
    if (!j["absolute_tolerance"].is_object())
      return fail("absolute_tolerance", "expected an object {metric: value}");
    for (const auto& [k, v] : j["absolute_tolerance"].items()) {
      if (!IsCheckedMetric(k)) return fail("absolute_tolerance." + k, "not a checked metric");
      if (!v.is_number() || !(v.get<double>() >= 0))
        return fail("absolute_tolerance." + k, "expected a number >= 0");
      b.absolute_tolerance[k] = v.get<double>();
    }
  }
  if (!j.contains("runs") || !j["runs"].is_object() || j["runs"].empty())
    return fail("runs",
                "required: an object {run id: {metric: {value, tolerance, lower_is_better}}}");
  for (const auto& [id, metrics] : j["runs"].items()) {
    BaselineRun run;
    run.id = id;
    if (!metrics.is_object() || metrics.empty())
      return fail("runs." + id, "expected an object of metrics");
    for (const auto& [name, m] : metrics.items()) {
      const std::string key = "runs." + id + "." + name;
      if (!IsCheckedMetric(name))
        return fail(key, "not a checked metric (timing is never checked)");
      if (!m.is_object()) return fail(key, "expected {value, tolerance, lower_is_better}");
      for (const auto& [k, v] : m.items())
        if (k != "value" && k != "tolerance" && k != "lower_is_better")
          return fail(key + "." + k, "unknown key (expected value, tolerance, lower_is_better)");
      BaselineMetric bm;
      bm.name = name;
      if (!m.contains("value") || !(m["value"].is_number() || m["value"].is_null()))
        return fail(key + ".value",
                    "expected a number (or null: the run is expected to give no value)");
      bm.value = m["value"].is_null() ? std::nan("") : m["value"].get<double>();
      if (!m["value"].is_null() && !std::isfinite(bm.value))
        return fail(key + ".value", "expected a finite number");
      if (!m.contains("tolerance") || !m["tolerance"].is_number() ||
          !(m["tolerance"].get<double>() >= 0))
        return fail(key + ".tolerance", "expected a number >= 0");
      bm.tolerance = m["tolerance"].get<double>();
      if (m.contains("lower_is_better")) {
        if (!m["lower_is_better"].is_boolean())
          return fail(key + ".lower_is_better", "expected true or false");
        bm.lower_is_better = m["lower_is_better"].get<bool>();
      }
      run.metrics.push_back(bm);
    }
    b.runs.push_back(run);
  }
  *baseline = b;
  return true;
}

std::string BaselineJson(const Baseline& b) {
  json j;
  j["suite"] = b.suite;
  j["tolerance_rule"] = b.tolerance_rule;
  j["relative_tolerance"] = b.relative_tolerance;
  j["absolute_tolerance"] = json::object();
  for (const std::string& m : CheckedMetrics())
    if (b.absolute_tolerance.count(m)) j["absolute_tolerance"][m] = b.absolute_tolerance.at(m);
  j["runs"] = json::object();
  for (const auto& run : b.runs) {
    json r = json::object();
    for (const auto& m : run.metrics) {
      json e;
      e["value"] = NumberOrNull(m.value);
      e["tolerance"] = m.tolerance;
      e["lower_is_better"] = m.lower_is_better;
      r[m.name] = e;
    }
    j["runs"][run.id] = r;
  }
  return j.dump(2) + "\n";
}

bool MakeBaseline(const SuiteResult& result, const Baseline& rule, Baseline* baseline,
                  std::string* error) {
  Baseline b = rule;
  b.runs.clear();
  for (const auto& row : result.rows) {
    if (row.status != "ok") {
      *error = "run " + row.run.id + " " + row.status + "; a baseline needs every run finished";
      return false;
    }
    BaselineRun run;
    run.id = row.run.id;
    for (const std::string& name : CheckedMetrics()) {
      BaselineMetric m;
      m.name = name;
      m.lower_is_better = FindMetric(name)->better != Better::kHigher;
      const auto* v = FindMetricValue(row.metrics, name);
      m.value = v != nullptr && v->is_number() ? v->get<double>() : std::nan("");
      const double abs_tol =
          rule.absolute_tolerance.count(name) ? rule.absolute_tolerance.at(name) : 0.0;
      m.tolerance = std::isfinite(m.value)
                        ? std::max(rule.relative_tolerance * std::fabs(m.value), abs_tol)
                        : abs_tol;
      // Round the tolerance up to 3 significant digits, so the file stays readable.
      if (m.tolerance > 0) {
        const double scale = std::pow(10.0, std::floor(std::log10(m.tolerance)) - 2);
        char text[32];
        std::snprintf(text, sizeof(text), "%.3g", std::ceil(m.tolerance / scale - 1e-9) * scale);
        m.tolerance = std::stod(text);
      }
      run.metrics.push_back(m);
    }
    b.runs.push_back(run);
  }
  if (b.runs.empty()) {
    *error = "the suite has no runs";
    return false;
  }
  *baseline = b;
  return true;
}

CheckReport CompareToBaseline(const Baseline& baseline, const SuiteResult& result) {
  CheckReport report;
  for (const auto& run : baseline.runs) {
    const SuiteRow* row = nullptr;
    for (const auto& r : result.rows)
      if (r.run.id == run.id) row = &r;
    if (!row || row->status != "ok") {
      CheckRow c;
      c.run = run.id;
      c.verdict = !row ? "MISSING" : row->status == "failed" ? "FAILED" : "MISSING";
      c.baseline = c.now = c.tolerance = std::nan("");
      report.rows.push_back(c);
      ++report.worse;
      continue;
    }
    for (const auto& m : run.metrics) {
      CheckRow c;
      c.run = run.id;
      c.metric = m.name;
      c.baseline = m.value;
      c.tolerance = m.tolerance;
      const auto& v = row->metrics.contains(m.name) ? row->metrics[m.name] : nlohmann::json();
      c.now = v.is_number() ? v.get<double>() : std::nan("");
      const double worsening = m.lower_is_better ? c.now - c.baseline : c.baseline - c.now;
      if (!std::isfinite(c.baseline)) {
        // null in the baseline: the run is expected to give no value either (a metric that
        // does not apply). A value now is a change the baseline must record, not a pass.
        c.verdict = std::isfinite(c.now) ? "WORSE" : "OK";
        if (std::isfinite(c.now)) {
          ++report.worse;
          c.note = "(the baseline has null: no value expected; record it with --update)";
        }
      } else if (!std::isfinite(c.now) || worsening > c.tolerance) {
        c.verdict = "WORSE";
        ++report.worse;
        if (!std::isfinite(c.now)) {  // null (not applicable) or absent in the run
          std::string why = "no value in the run's metrics.json";
          const MetricInfo* info = FindMetric(m.name);
          if (v.is_null() && info != nullptr) {
            why = "null (not applicable) in the run's metrics.json";
            const auto& reg = RunMetrics();
            for (auto it = std::find_if(reg.begin(), reg.end(),
                                        [&](const MetricInfo& r) { return r.key == m.name; });
                 it != reg.end(); ++it) {
              if (!it->reason) continue;
              if (const nlohmann::json* r = FindMetricValue(row->metrics, it->key);
                  r != nullptr && r->is_string())
                why += ": " + r->get<std::string>();
              break;
            }
          }
          c.note = "(now " + why + "; the baseline has a number)";
        }
      } else if (-worsening > c.tolerance) {
        c.verdict = "BETTER";
        ++report.better;
      } else {
        c.verdict = "OK";
      }
      report.rows.push_back(c);
    }
  }
  for (const auto& r : result.rows) {
    const bool known = std::any_of(baseline.runs.begin(), baseline.runs.end(),
                                   [&](const BaselineRun& b) { return b.id == r.run.id; });
    if (known) continue;
    CheckRow c;
    c.run = r.run.id;
    c.verdict = "NEW";
    c.baseline = c.now = c.tolerance = std::nan("");
    report.rows.push_back(c);
    ++report.worse;
  }
  return report;
}

std::string CheckTableText(const CheckReport& report, bool only_moved) {
  size_t w = 3;
  for (const auto& r : report.rows) w = std::max(w, r.run.size());
  std::ostringstream t;
  char buf[512];
  std::snprintf(buf, sizeof(buf), "%-*s %-22s %10s %10s %10s %10s  %s\n", static_cast<int>(w),
                "run", "metric", "baseline", "now", "delta", "tolerance", "result");
  t << buf;
  for (const auto& r : report.rows) {
    if (only_moved && r.verdict == "OK" && r.now == r.baseline) continue;
    if (r.metric.empty()) {
      const char* why = r.verdict == "NEW" ? "(not in the baseline: run `vobench check --update`)"
                        : r.verdict == "FAILED" ? "(the run failed; see its .failed.txt)"
                                                : "(no result)";
      std::snprintf(buf, sizeof(buf), "%-*s %-22s %10s %10s %10s %10s  %s %s\n",
                    static_cast<int>(w), r.run.c_str(), "-", "", "", "", "", r.verdict.c_str(),
                    why);
    } else {
      std::snprintf(buf, sizeof(buf), "%-*s %-22s %10s %10s %10s %10s  %s\n", static_cast<int>(w),
                    r.run.c_str(), r.metric.c_str(), Num(r.baseline).c_str(), Num(r.now).c_str(),
                    Signed(r.now - r.baseline).c_str(), Num(r.tolerance).c_str(),
                    (r.verdict + (r.note.empty() ? "" : " " + r.note)).c_str());
    }
    t << buf;
  }
  return t.str();
}

std::string CheckTableMarkdown(const CheckReport& report) {
  std::ostringstream md;
  md << "| run | metric | baseline | now | delta | tolerance | result |\n| --- | --- | --- | --- | "
        "--- | --- | --- |\n";
  for (const auto& r : report.rows) {
    if (r.metric.empty())
      md << "| " << r.run << " | - | | | | | " << r.verdict << " |\n";
    else
      md << "| " << r.run << " | " << r.metric << " | " << Num(r.baseline) << " | " << Num(r.now)
         << " | " << Signed(r.now - r.baseline) << " | " << Num(r.tolerance) << " | " << r.verdict
         << " |\n";
  }
  return md.str();
}

}  // namespace harness
