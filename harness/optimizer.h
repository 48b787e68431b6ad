// Derivative-free minimisation of an expensive function of a few named parameters in a box,
// for `vobench tune` (tune.h): seeded random search or one of NLopt's derivative-free
// algorithms (Debian's libnlopt; S. G. Johnson, "The NLopt nonlinear-optimization package").
//
// Search space. The optimiser works in the normalised box [0, 1]^d; coordinate u of a
// parameter maps to its value as
//   real, scale   v = min + u · (max − min)            log: v = min · (max / min)^u
//   int           the same real value, rounded to the nearest point of the grid
//                 min, min + step, min + 2·step, ... <= max (half away from zero).
// So integer parameters are rounded inside the objective: the optimiser sees a piecewise-
// constant function of u (local methods may stop early on a plateau; restarts help).
// kScale is a real factor the caller applies to every element of a list-valued option.
//
// Algorithms (OptimizerOptions::algorithm):
//   "random"   max_evals − 1 points drawn uniformly in [0, 1]^d after the start, from a
//              SplitMix64 generator seeded with `seed` (53-bit doubles, no std:: distributions,
//              so the points are the same on every platform and library).
//   NLopt      any derivative-free NLopt algorithm by its NLopt name without the "NLOPT_"
//              prefix: local LN_SBPLX, LN_BOBYQA, LN_COBYLA, LN_NELDERMEAD, LN_PRAXIS,
//              LN_NEWUOA_BOUND; global GN_DIRECT, GN_DIRECT_L, GN_DIRECT_L_RAND, GN_CRS2_LM,
//              GN_ISRES, GN_ESCH, ... (algorithms that need derivatives or a subsidiary local
//              optimiser, LD_*, GD_*, *AUGLAG*, *MLSL*, are refused). nlopt_srand(seed) is
//              called before each NLopt run, so stochastic ones are repeatable. A local (LN_)
//              run starts at the start values with a first step of initial_step (unit box);
//              when it converges (every coordinate moves less than xtol_abs) with budget left,
//              it restarts from a seeded uniform point of the box.
//
// Budget and bookkeeping. The start values are always evaluated first, exactly as given, so
// the best result is never worse than the start. Parameter vectors (after rounding) that were
// evaluated before are answered from a cache and do not count: max_evals is the number of
// distinct objective evaluations, the start included. The best evaluation is the one with the
// smallest score (the earliest among equals). Non-finite scores are replaced by kFailedScore.
//
// Determinism: for a deterministic objective, the same parameters, start, options and seed give
// the same evaluations in the same order, bit for bit.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace harness {

enum class ParameterType {
  kReal,   // a real value in [min, max]
  kInt,    // an integer on the grid min + k · step in [min, max]
  kScale,  // a real factor in [min, max] applied by the caller to every element of a list
};

// "real", "int", "scale".
const char* ToString(ParameterType type);
bool ParseParameterType(const std::string& name, ParameterType* type);

struct Parameter {
  std::string key;                            // name (tune: a dotted VO option key)
  ParameterType type = ParameterType::kReal;  // see ParameterType
  double min = 0.0;                           // lower bound, inclusive; an integer for kInt
  double max = 1.0;                           // upper bound, inclusive, > min; an integer for kInt
  bool log = false;                           // log-uniform mapping of u (needs min > 0)
  int step = 1;                               // kInt: grid step (>= 1, <= max − min)

  bool IsValid(std::string* error) const;
};

// u (clamped to [0, 1]) -> the parameter's value, rounded to the grid for kInt.
double UnitToValue(const Parameter& parameter, double u);
// Inverse of UnitToValue's real mapping, clamped to [0, 1] (exact up to rounding).
double ValueToUnit(const Parameter& parameter, double value);
// True when `value` is a value UnitToValue can return (in range; on the grid for kInt).
bool IsAttainable(const Parameter& parameter, double value);

struct OptimizerOptions {
  std::string algorithm = "LN_SBPLX";  // "random" or a derivative-free NLopt name (see above)
  int max_evals = 50;                  // distinct objective evaluations, the start included, >= 1
  uint64_t seed = 1;                   // random points, restarts, NLopt's stochastic algorithms
  double initial_step = 0.25;          // first step of local NLopt algorithms (unit box), in (0, 1]
  double xtol_abs = 1e-3;  // an NLopt run stops when every unit coordinate moves less than
                           // this (then a local one restarts), > 0

  bool IsValid(std::string* error) const;
};

// True for "random" and the derivative-free NLopt algorithms accepted (see above).
bool IsSupportedAlgorithm(const std::string& name);
// The accepted names, for messages: "random, LN_SBPLX, LN_BOBYQA, ...".
std::string SupportedAlgorithms();

// Stand-in for a non-finite score (NaN, inf) returned by the objective.
constexpr double kFailedScore = 1e9;

struct Evaluation {
  int index = 0;               // 0-based, in the order of evaluation
  std::string origin;          // "start", "random", "<ALGORITHM>", "<ALGORITHM> restart N"
  std::vector<double> values;  // parameter values, as given to the objective
  double score = 0.0;          // objective value (finite)
};

struct OptimizationResult {
  std::vector<Evaluation> evaluations;  // distinct evaluations, evaluations[0] = the start
  int best_index = 0;                   // index of the smallest score (earliest among equals)
  int optimizer_calls = 0;              // objective calls by the optimiser, cache hits included
  int restarts = 0;                     // restarts of a local NLopt algorithm
  std::string stop_reason;              // e.g. "budget of 50 evaluations used", NLopt's result

  const Evaluation& best() const { return evaluations[best_index]; }
};

// The objective: parameter values (one per parameter, in order) -> score (smaller is better).
// Returning false (with *error) aborts the minimisation with that error.
using Objective =
    std::function<bool(const std::vector<double>& values, double* score, std::string* error)>;
// Called after every distinct evaluation (for progress displays); may be null.
using EvaluationCallback =
    std::function<void(const Evaluation& evaluation, const Evaluation& best, int max_evals)>;

// Minimises `objective` over the box of `parameters` from `start_values` (one per parameter,
// attainable). False with *error for invalid parameters, options or start, or when the
// objective fails (the evaluations made so far are kept in *result).
bool Minimize(const std::vector<Parameter>& parameters, const std::vector<double>& start_values,
              const OptimizerOptions& options, const Objective& objective,
              OptimizationResult* result, std::string* error,
              const EvaluationCallback& on_evaluation = nullptr);

}  // namespace harness
