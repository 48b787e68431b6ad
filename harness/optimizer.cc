#include "harness/optimizer.h"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "vo/ransac.h"  // vo::SplitMix64

namespace harness {
namespace {

// NLopt runs may call the objective at points already evaluated (cache hits, which cost
// nothing); this caps NLopt's own call count per run so such loops end.
constexpr int kNloptCallsPerEvaluation = 100;
// Restarts that bring no new evaluation in a row before a local search gives up.
constexpr int kMaxStaleRestarts = 3;

std::string Num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

bool NloptAlgorithmFromName(const std::string& name, nlopt_algorithm* algorithm) {
  const bool derivative_free = name.rfind("LN_", 0) == 0 || name.rfind("GN_", 0) == 0;
  if (!derivative_free || name.find("AUGLAG") != std::string::npos ||
      name.find("MLSL") != std::string::npos) {
    return false;
  }
  const int a = static_cast<int>(nlopt_algorithm_from_string(name.c_str()));
  if (a < 0 || a >= NLOPT_NUM_ALGORITHMS) return false;
  *algorithm = static_cast<nlopt_algorithm>(a);
  return true;
}

// Number of grid points of an integer parameter minus one.
long GridSteps(const Parameter& p) {
  return static_cast<long>(std::floor((p.max - p.min) / p.step + 1e-9));
}

// The state of one minimisation: cache, bookkeeping, the objective's failure.
struct Search {
  Search(const std::vector<Parameter>& parameters, const OptimizerOptions& options,
         const Objective& objective, const EvaluationCallback& on_evaluation,
         OptimizationResult* result)
      : parameters(parameters),
        options(options),
        objective(objective),
        on_evaluation(on_evaluation),
        result(result) {}

  const std::vector<Parameter>& parameters;
  const OptimizerOptions& options;
  const Objective& objective;
  const EvaluationCallback& on_evaluation;
  OptimizationResult* result;
  std::map<std::vector<double>, double> cache;
  std::string origin;  // label of the evaluations of the current phase
  bool failed = false;
  std::string error;
  // NLopt run state.
  nlopt_opt opt = nullptr;
  std::vector<double> x0;                          // the run's start (unit box)
  const std::vector<double>* x0_values = nullptr;  // exact values at x0 (or null)

  bool BudgetUsed() const {
    return static_cast<int>(result->evaluations.size()) >= options.max_evals;
  }

  // Score of `values` from the cache; false when not evaluated yet.
  bool Cached(const std::vector<double>& values, double* score) const {
    const auto it = cache.find(values);
    if (it == cache.end()) return false;
    *score = it->second;
    return true;
  }

  // Evaluates `values` (not cached, budget left). False when the objective failed.
  bool Evaluate(const std::vector<double>& values, double* score) {
    double s = 0.0;
    std::string why;
    if (!objective(values, &s, &why)) {
      failed = true;
      error = why.empty() ? std::string("the objective failed") : why;
      return false;
    }
    if (!std::isfinite(s)) s = kFailedScore;
    cache.emplace(values, s);
    Evaluation e;
    e.index = static_cast<int>(result->evaluations.size());
    e.origin = origin;
    e.values = values;
    e.score = s;
    result->evaluations.push_back(e);
    if (s < result->evaluations[result->best_index].score) result->best_index = e.index;
    if (on_evaluation) on_evaluation(result->evaluations.back(), result->best(), options.max_evals);
    *score = s;
    return true;
  }

  std::vector<double> ToValues(const double* u) const {
    std::vector<double> values(parameters.size());
    const bool at_x0 = x0_values != nullptr && std::equal(x0.begin(), x0.end(), u);
    for (size_t i = 0; i < parameters.size(); ++i)
      values[i] = at_x0 ? (*x0_values)[i] : UnitToValue(parameters[i], u[i]);
    return values;
  }
};

double NloptObjective(unsigned n, const double* x, double* /*grad*/, void* data) {
  Search& s = *static_cast<Search*>(data);
  (void)n;
  ++s.result->optimizer_calls;
  const std::vector<double> values = s.ToValues(x);
  double score = 0.0;
  if (s.Cached(values, &score)) return score;
  if (s.BudgetUsed() || !s.Evaluate(values, &score)) {
    nlopt_force_stop(s.opt);
    return s.result->best().score;
  }
  return score;
}

bool RunNlopt(nlopt_algorithm algorithm, Search* search, std::string* error) {
  OptimizationResult& result = *search->result;
  const OptimizerOptions& options = search->options;
  const unsigned n = static_cast<unsigned>(search->parameters.size());
  const bool local = options.algorithm.rfind("LN_", 0) == 0;
  vo::SplitMix64 restart_rng(options.seed);
  int stale = 0;
  for (int run = 0;; ++run) {
    search->origin = options.algorithm + (run == 0 ? "" : " restart " + std::to_string(run));
    nlopt_opt opt = nlopt_create(algorithm, n);
    if (opt == nullptr) {
      *error =
          "NLopt cannot create " + options.algorithm + " in " + std::to_string(n) + " dimensions";
      return false;
    }
    search->opt = opt;
    nlopt_set_lower_bounds1(opt, 0.0);
    nlopt_set_upper_bounds1(opt, 1.0);
    nlopt_set_min_objective(opt, NloptObjective, search);
    nlopt_set_xtol_abs1(opt, options.xtol_abs);
    nlopt_set_maxeval(opt, kNloptCallsPerEvaluation * options.max_evals + 100);
    if (local) nlopt_set_initial_step1(opt, options.initial_step);
    nlopt_srand(options.seed + static_cast<uint64_t>(run));
    const size_t evaluations_before = result.evaluations.size();
    std::vector<double> x = search->x0;
    double f = 0.0;
    const nlopt_result r = nlopt_optimize(opt, x.data(), &f);
    nlopt_destroy(opt);
    search->opt = nullptr;
    if (search->failed) {
      *error = search->error;
      return false;
    }
    if (search->BudgetUsed()) {
      result.stop_reason = "budget of " + std::to_string(options.max_evals) + " evaluations used";
      return true;
    }
    if (r < 0 && r != NLOPT_FORCED_STOP && r != NLOPT_ROUNDOFF_LIMITED) {
      *error = "NLopt " + options.algorithm + " failed: " + nlopt_result_to_string(r) +
               (r == NLOPT_INVALID_ARGS && options.algorithm == "LN_BOBYQA" && n < 2
                    ? " (LN_BOBYQA needs at least 2 parameters)"
                    : "");
      return false;
    }
    result.stop_reason = std::string("NLopt ") + nlopt_result_to_string(r) + " after " +
                         std::to_string(result.evaluations.size()) + " evaluations";
    if (!local) return true;
    stale = result.evaluations.size() == evaluations_before ? stale + 1 : 0;
    if (stale >= kMaxStaleRestarts) {
      result.stop_reason += " (restarts found no new points)";
      return true;
    }
    // Converged with budget left: restart from a seeded uniform point of the box.
    for (double& u : search->x0) u = restart_rng.Uniform();
    search->x0_values = nullptr;
    ++result.restarts;
  }
}

bool RunRandom(Search* search) {
  OptimizationResult& result = *search->result;
  const OptimizerOptions& options = search->options;
  vo::SplitMix64 rng(options.seed);
  search->origin = "random";
  const long max_draws = static_cast<long>(kNloptCallsPerEvaluation) * options.max_evals + 100;
  std::vector<double> u(search->parameters.size());
  for (long draw = 0; draw < max_draws && !search->BudgetUsed(); ++draw) {
    for (double& x : u) x = rng.Uniform();
    const std::vector<double> values = search->ToValues(u.data());
    ++result.optimizer_calls;
    double score = 0.0;
    if (search->Cached(values, &score)) continue;
    if (!search->Evaluate(values, &score)) return false;
  }
  result.stop_reason = search->BudgetUsed()
                           ? "budget of " + std::to_string(options.max_evals) + " evaluations used"
                           : "no new points after " + std::to_string(max_draws) +
                                 " draws (the box holds fewer points than the budget)";
  return true;
}

}  // namespace

const char* ToString(ParameterType type) {
  switch (type) {
    case ParameterType::kReal:
      return "real";
    case ParameterType::kInt:
      return "int";
    case ParameterType::kScale:
      return "scale";
  }
  return "?";
}

bool ParseParameterType(const std::string& name, ParameterType* type) {
  for (ParameterType t : {ParameterType::kReal, ParameterType::kInt, ParameterType::kScale}) {
    if (name == ToString(t)) {
      *type = t;
      return true;
    }
  }
  return false;
}

bool Parameter::IsValid(std::string* error) const {
  const std::string who = "parameter '" + key + "': ";
  if (!std::isfinite(min) || !std::isfinite(max) || !(min < max)) {
    *error = who + "needs finite min < max, got min " + Num(min) + ", max " + Num(max);
    return false;
  }
  if (log && !(min > 0.0)) {
    *error = who + "log scale needs min > 0, got " + Num(min);
    return false;
  }
  if (type == ParameterType::kInt) {
    if (min != std::round(min) || max != std::round(max)) {
      *error = who + "type int needs integer min and max, got " + Num(min) + ", " + Num(max);
      return false;
    }
    if (step < 1 || step > max - min) {
      *error = who + "step must be in [1, max - min], got " + std::to_string(step);
      return false;
    }
  } else if (step != 1) {
    *error = who + "step applies to type int only";
    return false;
  }
  return true;
}

double UnitToValue(const Parameter& p, double u) {
  u = std::clamp(u, 0.0, 1.0);
  double v = p.log ? p.min * std::pow(p.max / p.min, u) : p.min + u * (p.max - p.min);
  if (p.type == ParameterType::kInt) {
    const long k =
        std::clamp(static_cast<long>(std::round((v - p.min) / p.step)), 0L, GridSteps(p));
    return p.min + static_cast<double>(k) * p.step;
  }
  return std::clamp(v, p.min, p.max);
}

double ValueToUnit(const Parameter& p, double value) {
  const double u =
      p.log ? std::log(value / p.min) / std::log(p.max / p.min) : (value - p.min) / (p.max - p.min);
  return std::isfinite(u) ? std::clamp(u, 0.0, 1.0) : 0.0;
}

bool IsAttainable(const Parameter& p, double value) {
  if (!std::isfinite(value) || value < p.min || value > p.max) return false;
  if (p.type != ParameterType::kInt) return true;
  const double k = (value - p.min) / p.step;
  return k == std::round(k);
}

bool OptimizerOptions::IsValid(std::string* error) const {
  if (!IsSupportedAlgorithm(algorithm)) {
    *error = "unknown or unsupported optimizer algorithm '" + algorithm + "' (expected one of " +
             SupportedAlgorithms() + ")";
    return false;
  }
  if (max_evals < 1) {
    *error = "max_evals must be >= 1, got " + std::to_string(max_evals);
    return false;
  }
  if (!(initial_step > 0.0 && initial_step <= 1.0)) {
    *error = "initial_step must be in (0, 1], got " + Num(initial_step);
    return false;
  }
  if (!(xtol_abs > 0.0 && std::isfinite(xtol_abs))) {
    *error = "xtol_abs must be > 0, got " + Num(xtol_abs);
    return false;
  }
  return true;
}

bool IsSupportedAlgorithm(const std::string& name) {
  nlopt_algorithm a;
  return name == "random" || NloptAlgorithmFromName(name, &a);
}

std::string SupportedAlgorithms() {
  std::string names = "random";
  for (int i = 0; i < NLOPT_NUM_ALGORITHMS; ++i) {
    const char* name = nlopt_algorithm_to_string(static_cast<nlopt_algorithm>(i));
    nlopt_algorithm a;
    if (name != nullptr && NloptAlgorithmFromName(name, &a)) names += std::string(", ") + name;
  }
  return names;
}

bool Minimize(const std::vector<Parameter>& parameters, const std::vector<double>& start_values,
              const OptimizerOptions& options, const Objective& objective,
              OptimizationResult* result, std::string* error,
              const EvaluationCallback& on_evaluation) {
  *result = OptimizationResult();
  if (parameters.empty()) {
    *error = "no parameters to optimise";
    return false;
  }
  for (const Parameter& p : parameters)
    if (!p.IsValid(error)) return false;
  if (!options.IsValid(error)) return false;
  if (start_values.size() != parameters.size()) {
    *error = "expected " + std::to_string(parameters.size()) + " start values, got " +
             std::to_string(start_values.size());
    return false;
  }
  for (size_t i = 0; i < parameters.size(); ++i) {
    if (!IsAttainable(parameters[i], start_values[i])) {
      const Parameter& p = parameters[i];
      *error = "parameter '" + p.key + "': the start value " + Num(start_values[i]) +
               " is outside [" + Num(p.min) + ", " + Num(p.max) + "]" +
               (p.type == ParameterType::kInt ? " or off the grid of step " + std::to_string(p.step)
                                              : "");
      return false;
    }
  }

  Search search(parameters, options, objective, on_evaluation, result);
  search.origin = "start";
  ++result->optimizer_calls;
  double score = 0.0;
  if (!search.Evaluate(start_values, &score)) {
    *error = search.error;
    return false;
  }
  if (search.BudgetUsed()) {
    result->stop_reason = "budget of " + std::to_string(options.max_evals) + " evaluations used";
    return true;
  }
  if (options.algorithm == "random") {
    if (!RunRandom(&search)) {
      *error = search.error;
      return false;
    }
    return true;
  }
  nlopt_algorithm algorithm;
  NloptAlgorithmFromName(options.algorithm, &algorithm);
  search.x0.resize(parameters.size());
  for (size_t i = 0; i < parameters.size(); ++i)
    search.x0[i] = ValueToUnit(parameters[i], start_values[i]);
  search.x0_values = &start_values;
  return RunNlopt(algorithm, &search, error);
}

}  // namespace harness
