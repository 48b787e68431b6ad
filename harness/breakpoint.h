// `vobench breakpoint`: the breaking point of a perturbation. One scenario key (or the run's
// frame stride) is varied over a range until a metric of the run crosses a value:
//
//   vobench breakpoint l_hallway --vary noise.pixel_sigma --range 0,20
//       --until 'end_pose_error_pct>2' [--seeds 3 --aggregate worst]
//
// The search. A coarse scan evaluates `scan_points` values spread evenly over [LO, HI] (both
// ends included), then bisects the first interval whose low end is not crossed and whose high
// end is, until it is at most `tolerance` wide (an integer key: until its ends are neighbours
// or `tolerance` apart). The threshold is reported as that bracket [lo, hi] (lo: the largest
// value evaluated that is not crossed below the first crossing, hi: the smallest crossed one)
// and its midpoint. The scan sees every scan point, so a metric that is not monotone in the key
// (crossed at a value, not crossed at a larger one) is reported (`monotone: false`, the values
// that went back below the condition); the bisection then works on the first crossing. A
// condition crossed already at LO is status "crossed_at_low" (the threshold is <= LO), one
// crossed nowhere in the range "not_crossed" (> HI). The search is deterministic: the points
// evaluated depend only on the range, scan, tolerance and the outcomes.
//
// A point. Each value is run once per seed (the scenario's `seed`, seed + 1, ...: --seeds N),
// with the run machinery of `vobench run` (built-in VO) or of a suite's external configuration
// (an external estimator, suite/external.h); each run writes its run folder under
// points/p<NN>_s<SEED>/ in the output folder, so every evaluated point can be looked at as a
// run. The point's value is the seeds' mean (default) or worst (the largest for > and >=, the
// smallest for < and <=). A point counts as crossed when the value meets the condition, or when
// any of its runs failed (the run could not finish, the external command failed or wrote no
// trajectory) or lost tracking (more than `max_lost_frames` lost frames; lost frames are counted
// by the built-in VO only). A metric that is null for a run (it does not apply to it, e.g. a %
// of a path shorter than 1 m) is an error naming the reason: the metric must apply at every
// point for a threshold to mean anything.
//
// Output folder (written as DIR.partial-* and moved into place; an existing DIR is replaced
// only if it holds an earlier breakpoint result, output_folder.h):
//   breakpoint.json   the call (command, scenario, key, range, condition, options), the result
//                     (status, threshold, bracket, monotone) and every evaluated point (value of
//                     the key, phase scan|bisect, per-seed metric, lost frames, failures, the
//                     aggregate, crossed); the same call gives the same file except "timing"
//   points.csv        one row per evaluated point, in the order evaluated
//   breakpoint.png    the metric against the key: the points, the condition's line, the bracket
//   report.md         the result and the table of points
//   points/           the run folder of every run (without plots)
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "harness/suite/external.h"
#include "sim/scenario.h"
#include "vo/odometry.h"

namespace harness {

// The condition of --until: "METRIC>VALUE" with >, <, >= or <=.
struct UntilCondition {
  std::string metric;  // a numeric metric of the registry (metric_registry.h)
  std::string op;      // ">", "<", ">=", "<="
  double value = 0.0;
  bool Met(double x) const;    // x op value (false for NaN)
  bool HigherIsWorse() const;  // > and >=: the worst of several values is the largest
  std::string Text() const;    // "end_pose_error_pct>2"
};

// Parses --until; the error says what was expected (and names the known metrics for an unknown
// one). Spaces around the parts are allowed.
bool ParseUntil(const std::string& text, UntilCondition* until, std::string* error);
// Parses --range "LO,HI" (two finite numbers, LO < HI).
bool ParseRange(const std::string& text, double* lo, double* hi, std::string* error);
// The metrics --until accepts: the registry's numeric ones (not the *_reason texts, flags or
// names), in registry order.
std::vector<std::string> BreakpointMetrics();

// --- The search, on any function of the key -------------------------------------------------

struct PointOutcome {
  double value = std::numeric_limits<double>::quiet_NaN();  // the point's metric (aggregate)
  bool crossed = false;  // the condition is met, or a run failed or lost tracking
};

struct SearchOptions {
  double lo = 0.0, hi = 1.0;  // the range, lo < hi
  int scan_points = 5;        // >= 2, both ends included
  double tolerance = 0.0;     // bracket width to reach, > 0 (integer: at least 1)
  int max_evals = 40;         // stop (with a wider bracket) after this many evaluations, >= 2
  bool integer = false;       // the key takes whole numbers only (lo, hi whole)
};

struct SearchPoint {
  double x = 0.0;
  std::string phase;  // "scan" or "bisect"
  PointOutcome outcome;
};

struct SearchResult {
  std::vector<SearchPoint> points;  // in the order evaluated
  std::string status;  // "bracketed", "crossed_at_low", "not_crossed", "no_evaluations"
  double bracket_lo = std::numeric_limits<double>::quiet_NaN();  // "bracketed" only
  double bracket_hi = std::numeric_limits<double>::quiet_NaN();
  double threshold = std::numeric_limits<double>::quiet_NaN();  // the bracket's midpoint
  bool tolerance_reached = false;  // the bracket is as narrow as asked (else max_evals ended it)
  bool monotone = true;            // no scan point went back below the condition
  std::vector<double> uncrossed_after_crossing;  // the scan values that did (monotone false)
};

// Evaluates the key at x; false (with *error) aborts the search (an error, not a crossing).
using EvaluatePoint =
    std::function<bool(double x, const std::string& phase, PointOutcome*, std::string* error)>;

// The scan and bisection (see the file comment). False when `options` are invalid or an
// evaluation aborted.
bool FindBreakpoint(const SearchOptions& options, const EvaluatePoint& evaluate,
                    SearchResult* result, std::string* error);

// --- The command -------------------------------------------------------------------------

struct BreakpointSpec {
  std::string scenario_arg;   // as given (file or built-in name)
  sim::Scenario scenario;     // resolved
  std::string key;            // a numeric scenario key (dotted) or "stride"
  bool integer = false;       // the key takes whole numbers (stride, integer scenario keys)
  double lo = 0.0, hi = 0.0;  // --range
  std::string range_text;     // as given
  UntilCondition until;
  std::string config_path;  // --config ("" = library defaults)
  vo::OdometryOptions vo_options;
  std::string external_arg;        // --external SUITE.yaml:CONFIG ("" = the built-in VO)
  ExternalEstimator estimator;     // when external_arg is given
  int seeds = 1;                   // >= 1
  std::string aggregate = "mean";  // "mean" | "worst"
  int max_frames = 0;              // source frames per run (0 = all)
  int stride = 1;                  // the runs' stride (when the key is not "stride")
  int max_lost_frames = 0;         // more lost frames than this: crossed (< 0: never)
  SearchOptions search;            // lo/hi/integer filled by PrepareBreakpoint
  double tolerance_given = 0.0;    // --tolerance (0 = default: (HI - LO) / 32)
};

// Checks everything before anything runs: the key is a numeric scenario key (or stride) whose
// scenario parser accepts LO and HI, whole numbers for an integer key; the range, metric and
// options. Fills spec->integer and spec->search. Errors name the option.
bool PrepareBreakpoint(BreakpointSpec* spec, std::string* error);

struct BreakpointOptions {
  std::string out_dir;
  bool progress = true;  // one line per evaluated point on stderr
  bool plots = true;     // breakpoint.png (python3-matplotlib)
};

struct BreakpointResult {
  SearchResult search;
  double wall_s = 0.0;
};

// Runs the search (a run per point and seed) and writes the output folder.
bool RunBreakpoint(const BreakpointSpec& spec, const BreakpointOptions& options,
                   BreakpointResult* result, std::string* error);

// The result in one line: "end_pose_error_pct>2 from noise.pixel_sigma in (6.25, 6.875],
// threshold ~ 6.5625", or where the range holds no crossing.
std::string BreakpointResultLine(const BreakpointSpec& spec, const SearchResult& search);

// The command line that reproduces `spec` ("vobench breakpoint ..."), for breakpoint.json and
// the report.
std::string BreakpointCommand(const BreakpointSpec& spec, const std::string& out_dir);

}  // namespace harness
