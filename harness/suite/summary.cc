#include "harness/suite/summary.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <utility>

#include "harness/metric_registry.h"
#include "harness/plots/plots.h"
#include "harness/suite/folder.h"
#include "harness/trajectory_io.h"

namespace harness {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using suite_internal::IsFinished;
using suite_internal::ReadJsonFile;

std::string CsvCell(const json& v) {
  if (v.is_null()) return "nan";
  if (v.is_boolean()) return v.get<bool>() ? "1" : "0";
  if (v.is_number_integer() || v.is_number_unsigned()) return v.dump();
  if (v.is_number()) return FormatDouble(v.get<double>());
  if (v.is_string()) {  // RFC 4180: quoted when it holds a comma, a quote or a line break
    const std::string text = v.get<std::string>();
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
  }
  return v.dump();
}

double Number(const json& metrics, const std::string& key) {
  const json* v = FindMetricValue(metrics, key);
  return v != nullptr && v->is_number() ? v->get<double>() : std::nan("");
}

std::string Fixed(double v, int prec) {
  if (!std::isfinite(v)) return "n/a";  // null or missing: not applicable to the run
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
      const double lost = Number(row.metrics, "lost_frames");  // nan: an external program's
      if (std::isfinite(lost)) a.lost_total += static_cast<long>(lost);
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

// harness/plots/suite_plot.py SUMMARY_CSV PNG (Debian's python3 with matplotlib).
bool RunSuitePlot(const std::string& csv, const std::string& png, std::string* error) {
  std::vector<std::string> args = {csv, png};
  for (const char* key : {"end_pose_error_pct", "ate_rmse_m"}) {  // the two panels
    args.insert(args.end(), {"--panel", key, PlotLabel(*FindMetric(key))});
  }
  return RunPythonScript("suite_plot.py", args, error);
}

}  // namespace

std::vector<SuiteRow> CollectSuiteRows(const fs::path& out, const std::vector<SuiteRun>& runs,
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

void CountFailedAndMissing(SuiteResult* result) {
  result->failed = result->missing = 0;
  for (const auto& row : result->rows) {
    result->failed += row.status == "failed";
    result->missing += row.status == "missing";
  }
}

bool WriteSuiteSummary(const fs::path& out, const std::string& name, const SuiteResult& result,
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

const std::vector<std::string>& SuiteTimingColumns() {
  static const std::vector<std::string> kColumns = [] {
    std::vector<std::string> c;
    for (const MetricInfo& m : RunMetrics())
      if (m.group == MetricGroup::kTiming) c.push_back(m.key);
    // An external configuration's command (suite/external.h): its wall time and peak memory.
    c.push_back("command_wall_s");
    c.push_back("command_peak_rss_mb");
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
      if (m.group != MetricGroup::kTiming) c.push_back(m.key);
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

}  // namespace harness
