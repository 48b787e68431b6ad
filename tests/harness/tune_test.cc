// `vobench tune`: the optimiser wrapper against known minima (NLopt and random search), the
// tune file reader (strict, messages naming file and key), and the command end to end on a
// tiny scenario: never worse than the start, deterministic, best_vo.yaml loadable, scores the
// same as `vobench run`, bad files refused with nothing written.
#include "harness/tune.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "harness/optimizer.h"
#include "harness/render.h"
#include "harness/run.h"
#include "harness/vo_config.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

using vobench_test::CommandResult;
using vobench_test::ReadAll;
using vobench_test::RunVobench;

namespace fs = std::filesystem;
using harness::Evaluation;
using harness::OptimizationResult;
using harness::OptimizerOptions;
using harness::Parameter;
using harness::ParameterType;
using vobench_test::TempDir;
using vobench_test::WriteText;

// --- The optimiser on a known function -------------------------------------------------------

// f(a, b, n) = (log10 a − log10 3)² + (b − 0.7)² + ((n − 13) / 10)²: minimum 0 at a = 3 (searched
// on a log scale over [0.01, 100]), b = 0.7 (real, [−2, 2]), n = 13 (integer, [0, 20]).
constexpr double kOptA = 3.0, kOptB = 0.7, kOptN = 13.0;

std::vector<Parameter> QuadraticParameters() {
  Parameter a{"a", ParameterType::kReal, 0.01, 100.0, true, 1};
  Parameter b{"b", ParameterType::kReal, -2.0, 2.0, false, 1};
  Parameter n{"n", ParameterType::kInt, 0.0, 20.0, false, 1};
  return {a, b, n};
}

double Quadratic(const std::vector<double>& v) {
  const double da = std::log10(v[0]) - std::log10(kOptA);
  return da * da + (v[1] - kOptB) * (v[1] - kOptB) + std::pow((v[2] - kOptN) / 10.0, 2);
}

harness::Objective CountingQuadratic(int* calls) {
  return [calls](const std::vector<double>& v, double* score, std::string*) {
    ++*calls;
    EXPECT_EQ(v[2], std::round(v[2])) << "integer parameter not rounded";
    *score = Quadratic(v);
    return true;
  };
}

const std::vector<double> kStart = {1.0, 0.0, 5.0};

TEST(OptimizerTest, UnitMappingIsLinearOrLogAndRoundsIntegersToTheGrid) {
  const Parameter lin{"x", ParameterType::kReal, 2.0, 6.0, false, 1};
  EXPECT_DOUBLE_EQ(harness::UnitToValue(lin, 0.25), 3.0);
  EXPECT_DOUBLE_EQ(harness::ValueToUnit(lin, 3.0), 0.25);
  EXPECT_DOUBLE_EQ(harness::UnitToValue(lin, -1.0), 2.0);  // clamped
  EXPECT_DOUBLE_EQ(harness::UnitToValue(lin, 2.0), 6.0);
  const Parameter lg{"y", ParameterType::kReal, 1.0, 100.0, true, 1};
  EXPECT_NEAR(harness::UnitToValue(lg, 0.5), 10.0, 1e-12);
  EXPECT_NEAR(harness::ValueToUnit(lg, 10.0), 0.5, 1e-12);
  const Parameter odd{"w", ParameterType::kInt, 5.0, 21.0, false, 2};  // 5, 7, ..., 21
  EXPECT_EQ(harness::UnitToValue(odd, 0.0), 5.0);
  EXPECT_EQ(harness::UnitToValue(odd, 1.0), 21.0);
  EXPECT_EQ(harness::UnitToValue(odd, 0.37), 11.0);  // 5 + 0.37·16 = 10.92 -> 11
  EXPECT_EQ(harness::UnitToValue(odd, 0.44), 13.0);  // 12.04 -> grid 13 (k = 3.52 -> 4)
  EXPECT_TRUE(harness::IsAttainable(odd, 9.0));
  EXPECT_FALSE(harness::IsAttainable(odd, 10.0));
  EXPECT_FALSE(harness::IsAttainable(odd, 23.0));
  const Parameter uneven{"k", ParameterType::kInt, 0.0, 10.0, false, 3};  // 0, 3, 6, 9
  EXPECT_EQ(harness::UnitToValue(uneven, 1.0), 9.0);
}

TEST(OptimizerTest, ParametersAndOptionsAreChecked) {
  std::string error;
  EXPECT_FALSE((Parameter{"p", ParameterType::kReal, 3.0, 3.0, false, 1}.IsValid(&error)));
  EXPECT_NE(error.find("'p'"), std::string::npos) << error;
  EXPECT_FALSE((Parameter{"p", ParameterType::kReal, 0.0, 3.0, true, 1}.IsValid(&error)));
  EXPECT_FALSE((Parameter{"p", ParameterType::kInt, 0.5, 3.0, false, 1}.IsValid(&error)));
  EXPECT_FALSE((Parameter{"p", ParameterType::kReal, 0.0, 3.0, false, 2}.IsValid(&error)));
  OptimizerOptions o;
  o.algorithm = "LD_LBFGS";  // needs gradients
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("LN_SBPLX"), std::string::npos) << error;  // lists the accepted ones
  o.algorithm = "LN_AUGLAG";                                      // needs a subsidiary optimiser
  EXPECT_FALSE(o.IsValid(&error));
  o.algorithm = "no_such";
  EXPECT_FALSE(o.IsValid(&error));
  for (const char* name :
       {"random", "LN_SBPLX", "LN_BOBYQA", "LN_COBYLA", "GN_DIRECT_L", "GN_CRS2_LM"})
    EXPECT_TRUE(harness::IsSupportedAlgorithm(name)) << name;
  // A start outside the box is refused.
  OptimizationResult r;
  int calls = 0;
  o = OptimizerOptions();
  EXPECT_FALSE(harness::Minimize(QuadraticParameters(), {1.0, 0.0, 5.5}, o,
                                 CountingQuadratic(&calls), &r, &error));
  EXPECT_NE(error.find("'n'"), std::string::npos) << error;
  EXPECT_EQ(calls, 0);
}

class NloptAlgorithmTest : public ::testing::TestWithParam<const char*> {};

TEST_P(NloptAlgorithmTest, FindsTheMinimumOfAShiftedQuadratic) {
  OptimizerOptions o;
  o.algorithm = GetParam();
  o.max_evals = 400;
  o.seed = 5;
  o.xtol_abs = 1e-6;
  int calls = 0;
  OptimizationResult r;
  std::string error;
  ASSERT_TRUE(
      harness::Minimize(QuadraticParameters(), kStart, o, CountingQuadratic(&calls), &r, &error))
      << error;
  const Evaluation& best = r.best();
  EXPECT_NEAR(best.values[0], kOptA, 0.02 * kOptA) << r.stop_reason;
  EXPECT_NEAR(best.values[1], kOptB, 0.01);
  EXPECT_EQ(best.values[2], kOptN);
  EXPECT_LT(best.score, 1e-4);
  // Bookkeeping: the start first and exact, one objective call per distinct evaluation.
  EXPECT_EQ(r.evaluations[0].values, kStart);
  EXPECT_EQ(r.evaluations[0].origin, "start");
  EXPECT_EQ(static_cast<int>(r.evaluations.size()), calls);
  EXPECT_LE(calls, o.max_evals);
  EXPECT_GE(r.optimizer_calls, calls);
}

INSTANTIATE_TEST_SUITE_P(Nlopt, NloptAlgorithmTest,
                         ::testing::Values("LN_SBPLX", "LN_BOBYQA", "LN_COBYLA", "LN_NELDERMEAD",
                                           "GN_DIRECT_L"));

TEST(OptimizerTest, RandomSearchFindsTheMinimumAndIsSeeded) {
  OptimizerOptions o;
  o.algorithm = "random";
  o.max_evals = 1500;
  o.seed = 3;
  int calls = 0;
  OptimizationResult r, again, other;
  std::string error;
  ASSERT_TRUE(
      harness::Minimize(QuadraticParameters(), kStart, o, CountingQuadratic(&calls), &r, &error))
      << error;
  EXPECT_EQ(static_cast<int>(r.evaluations.size()), o.max_evals);
  EXPECT_EQ(calls, o.max_evals);
  EXPECT_NEAR(r.best().values[0], kOptA, 0.25 * kOptA);
  EXPECT_NEAR(r.best().values[1], kOptB, 0.1);
  EXPECT_NEAR(r.best().values[2], kOptN, 1.0);
  EXPECT_LT(r.best().score, 0.02);
  // Same seed: the same points in the same order, bit for bit; another seed: other points.
  ASSERT_TRUE(harness::Minimize(QuadraticParameters(), kStart, o, CountingQuadratic(&calls), &again,
                                &error));
  ASSERT_EQ(again.evaluations.size(), r.evaluations.size());
  for (size_t i = 0; i < r.evaluations.size(); ++i) {
    EXPECT_EQ(again.evaluations[i].values, r.evaluations[i].values) << i;
    EXPECT_EQ(again.evaluations[i].score, r.evaluations[i].score) << i;
  }
  o.seed = 4;
  ASSERT_TRUE(harness::Minimize(QuadraticParameters(), kStart, o, CountingQuadratic(&calls), &other,
                                &error));
  EXPECT_NE(other.evaluations[1].values, r.evaluations[1].values);
}

TEST(OptimizerTest, StochasticNloptAlgorithmIsRepeatableForASeed) {
  OptimizerOptions o;
  o.algorithm = "GN_CRS2_LM";
  o.max_evals = 150;
  o.seed = 11;
  int calls = 0;
  OptimizationResult a, b;
  std::string error;
  ASSERT_TRUE(
      harness::Minimize(QuadraticParameters(), kStart, o, CountingQuadratic(&calls), &a, &error));
  ASSERT_TRUE(
      harness::Minimize(QuadraticParameters(), kStart, o, CountingQuadratic(&calls), &b, &error));
  ASSERT_EQ(a.evaluations.size(), b.evaluations.size());
  for (size_t i = 0; i < a.evaluations.size(); ++i)
    EXPECT_EQ(a.evaluations[i].values, b.evaluations[i].values) << i;
  EXPECT_LT(a.best().score, a.evaluations[0].score);
}

TEST(OptimizerTest, NeverWorseThanTheStartAndCachesRepeatedPoints) {
  // Started at the optimum: nothing beats it, the best is evaluation 0.
  OptimizerOptions o;
  o.max_evals = 30;
  int calls = 0;
  OptimizationResult r;
  std::string error;
  ASSERT_TRUE(harness::Minimize(QuadraticParameters(), {kOptA, kOptB, kOptN}, o,
                                CountingQuadratic(&calls), &r, &error));
  EXPECT_EQ(r.best_index, 0);
  EXPECT_EQ(r.best().score, 0.0);
  // One integer parameter with three values and a budget of ten: three evaluations, no repeats.
  const std::vector<Parameter> small = {{"k", ParameterType::kInt, 1.0, 3.0, false, 1}};
  for (const char* algorithm : {"random", "LN_SBPLX"}) {
    o.algorithm = algorithm;
    o.max_evals = 10;
    calls = 0;
    ASSERT_TRUE(harness::Minimize(
        small, {1.0}, o,
        [&](const std::vector<double>& v, double* score, std::string*) {
          ++calls;
          *score = std::abs(v[0] - 2.0);
          return true;
        },
        &r, &error))
        << error;
    EXPECT_LE(calls, 3) << algorithm;
    EXPECT_EQ(static_cast<int>(r.evaluations.size()), calls) << algorithm;
    EXPECT_GT(r.optimizer_calls, calls) << algorithm;
    if (std::string(algorithm) == "random") {
      EXPECT_EQ(r.best().values[0], 2.0);
      EXPECT_NE(r.stop_reason.find("fewer points"), std::string::npos) << r.stop_reason;
    }
  }
}

TEST(OptimizerTest, AFailingObjectiveAbortsWithItsError) {
  OptimizerOptions o;
  o.max_evals = 20;
  OptimizationResult r;
  std::string error;
  int calls = 0;
  EXPECT_FALSE(harness::Minimize(
      QuadraticParameters(), kStart, o,
      [&](const std::vector<double>& v, double* score, std::string* why) {
        if (++calls == 3) {
          *why = "boom";
          return false;
        }
        *score = Quadratic(v);
        return true;
      },
      &r, &error));
  EXPECT_EQ(error, "boom");
  EXPECT_EQ(r.evaluations.size(), 2u);
}

// --- Tune files ------------------------------------------------------------------------------

// Tiny scenarios: the real hallway at 160×120, a few frames.
const char* kScenarioSet = "camera.width: 160, camera.height: 120, path: [[0, 0], [0.6, 0]]";

std::string TuneFileText(
    const std::string& max_frames = "6", const std::string& extra_parameters = "",
    const std::string& optimizer = "{algorithm: random, max_evals: 4, seed: 9}") {
  return std::string("name: tiny\n") +
         "train:\n"
         "  - {name: tr_a, scenario: l_hallway, set: {" +
         kScenarioSet + ", textures.seed: 3}, max_frames: " + max_frames +
         "}\n"
         "validation:\n"
         "  - {name: va_a, scenario: l_hallway, set: {" +
         kScenarioSet +
         ", textures.seed: 4, seed: 2}, "
         "max_frames: " +
         max_frames +
         "}\n"
         "parameters:\n"
         "  - {key: tracker.matcher.svd.sigma_px, min: 4, max: 30, log: true}\n"
         "  - {key: tracker.matcher.ncc.window_px, type: int, min: 5, max: 21, step: 2}\n"
         "  - {key: tracker.matcher.gabor.wavelengths_px, type: scale, min: 0.7, max: 1.5}\n"
         "  - {key: motion.ransac.inlier_threshold_px, min: 0.5, max: 5, log: true}\n" +
         extra_parameters +
         "objective: {metric: ate_rmse_m, lost_frame_penalty: 0.05, aggregate: mean}\n"
         "optimizer: " +
         optimizer + "\n";
}

TEST(TuneSpecTest, ReadsAValidFile) {
  harness::TuneSpec spec;
  std::string error;
  ASSERT_TRUE(harness::ParseTuneSpec(
      TuneFileText("6", "  - {key: back_end.window_frames, type: int, min: 3, max: 10}\n"),
      "t.yaml", ".", &spec, &error))
      << error;
  EXPECT_EQ(spec.name, "tiny");
  ASSERT_EQ(spec.train.size(), 1u);
  EXPECT_EQ(spec.train[0].scenario.camera.width, 160);
  EXPECT_EQ(spec.train[0].scenario.textures.seed, 3u);
  EXPECT_EQ(spec.train[0].scenario.name, "tr_a");
  EXPECT_EQ(spec.train[0].max_frames, 6);
  EXPECT_EQ(spec.validation[0].scenario.seed, 2u);
  ASSERT_EQ(spec.parameters.size(), 5u);
  EXPECT_EQ(spec.parameters[1].step, 2);
  EXPECT_EQ(spec.parameters[2].type, ParameterType::kScale);
  const vo::OdometryOptions defaults;
  EXPECT_EQ(spec.start_values,
            (std::vector<double>{defaults.tracker.matcher.svd.sigma_px, 11.0, 1.0,
                                 defaults.motion.ransac.inlier_threshold_px, 5.0}));
  EXPECT_EQ(spec.optimizer.algorithm, "random");
  EXPECT_EQ(spec.optimizer.max_evals, 4);
  // Applying values: scale multiplies the default wavelengths; the start gives the defaults.
  vo::OdometryOptions o;
  ASSERT_TRUE(harness::ApplyParameters(spec, {12.5, 9, 1.5, 3.0, 7}, &o, &error)) << error;
  EXPECT_EQ(o.tracker.matcher.svd.sigma_px, 12.5);
  EXPECT_EQ(o.tracker.matcher.ncc.window_px, 9);
  ASSERT_EQ(o.tracker.matcher.gabor.wavelengths_px.size(),
            defaults.tracker.matcher.gabor.wavelengths_px.size());
  for (size_t i = 0; i < o.tracker.matcher.gabor.wavelengths_px.size(); ++i)
    EXPECT_EQ(o.tracker.matcher.gabor.wavelengths_px[i],
              1.5 * defaults.tracker.matcher.gabor.wavelengths_px[i]);
  EXPECT_EQ(o.motion.ransac.inlier_threshold_px, 3.0);
  EXPECT_EQ(o.back_end.window_frames, 7);
  ASSERT_TRUE(harness::ApplyParameters(spec, spec.start_values, &o, &error)) << error;
  EXPECT_EQ(harness::VoConfigToYaml(o), harness::VoConfigToYaml(defaults));
}

struct BadFile {
  const char* what;
  std::string text;
  std::vector<std::string> expected;  // substrings of the message (besides the file name)
};

std::vector<BadFile> BadFiles() {
  const std::string good = TuneFileText();
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  return {
      {"unknown top-level key", good + "paramters: []\n", {":13:", "'paramters'"}},
      {"unknown scenario key",
       replace("max_frames: 6}", "max_frame: 6}"),
       {":3:", "key 'train[0].max_frame': unknown key"}},
      {"unknown VO key",
       replace("tracker.matcher.svd.sigma_px", "tracker.matcher.svd.sigmaa"),
       {":7:", "'tracker.matcher.svd.sigmaa'", "not a VO option"}},
      {"min >= max",
       replace("min: 4, max: 30", "min: 30, max: 4"),
       {":7:", "tracker.matcher.svd.sigma_px", "min < max"}},
      {"empty training set",
       "name: x\ntrain: []\nvalidation: []\nparameters: []\n",
       {":2:", "'train'", "empty"}},
      {"validation equals training",
       replace("textures.seed: 4, seed: 2", "textures.seed: 3"),
       {":5:", "'va_a'", "'tr_a'"}},
      {"even NCC window",
       replace("min: 5, max: 21, step: 2", "min: 5, max: 21"),
       {":8:", "tracker.matcher.ncc.window_px", "value 6", "odd"}},
      {"real on an integer key",
       replace("type: int, min: 5, max: 21, step: 2", "min: 5, max: 21"),
       {":8:", "tracker.matcher.ncc.window_px"}},
      {"scale on a scalar key",
       replace("tracker.matcher.gabor.wavelengths_px", "motion.ransac.confidence"),
       {":9:", "motion.ransac.confidence", "list-valued"}},
      {"non-numeric key",
       replace("key: tracker.matcher.svd.sigma_px, min: 4, max: 30, log: true",
               "key: tracker.matcher.type, min: 0, max: 1"),
       {":7:", "tracker.matcher.type", "not a numeric"}},
      {"start outside the range",
       replace("min: 0.5, max: 5", "min: 2.5, max: 5"),
       {":10:", "motion.ransac.inlier_threshold_px", "outside"}},
      {"key given twice",
       good.substr(0, good.find("objective")) +
           "  - {key: tracker.matcher.svd.sigma_px, min: 5, max: 20}\n" +
           good.substr(good.find("objective")),
       {":11:", "tracker.matcher.svd.sigma_px", "twice"}},
      {"unknown metric", replace("metric: ate_rmse_m", "metric: ate"), {":11:", "'ate'"}},
      {"unknown algorithm", replace("algorithm: random", "algorithm: LN_FOO"), {":12:", "LN_FOO"}},
      {"bad scenario override",
       replace("textures.seed: 3}", "textures.seeed: 3}"),
       {":3:", "seeed"}},
      {"unknown scenario",
       replace("scenario: l_hallway", "scenario: no_such_hallway"),
       {":3:", "no_such_hallway"}},
      // Issue #11: duplicate keys (the first one won) and names that cannot name a folder.
      {"duplicate key",
       replace("name: tiny\n", "name: tiny\nname: other\n"),
       {":2:", "key 'name': duplicate (first at line 1)"}},
      {"name with a path in it",
       replace("name: tiny", "name: ../tiny"),
       {":1:", "tune name '../tiny': cannot name a folder: contains '..'"}},
      {"name like an option", replace("name: tiny", "name: -tiny"), {":1:", "starts with '-'"}},
      // Issue #36: an external program's parameters are not this VO's options.
      {"external program",
       replace("name: tiny\n", "name: tiny\nconfigs:\n  - name: x\n    external: {}\n"),
       {":3:", "'configs'", "external program's parameters cannot be tuned"}},
  };
}

TEST(TuneSpecTest, BadFilesAreRefusedWithFileLineAndKey) {
  for (const BadFile& bad : BadFiles()) {
    harness::TuneSpec spec;
    std::string error;
    EXPECT_FALSE(harness::ParseTuneSpec(bad.text, "bad_tune.yaml", ".", &spec, &error)) << bad.what;
    EXPECT_EQ(error.rfind("bad_tune.yaml", 0), 0u) << bad.what << ": " << error;
    for (const std::string& e : bad.expected)
      EXPECT_NE(error.find(e), std::string::npos)
          << bad.what << ": '" << e << "' not in: " << error;
  }
}

// --- The command -----------------------------------------------------------------------------

TEST(TuneCommandTest, BadTuneFilesFailWithTheirMessageAndWriteNothing) {
  if (!fs::exists(VOBENCH_BINARY)) GTEST_SKIP() << "vobench not built: " << VOBENCH_BINARY;
  TempDir dir("tune_bad");
  for (const BadFile& bad : BadFiles()) {
    const std::string file = dir / "bad_tune.yaml";
    WriteText(file, bad.text);
    const std::string out = dir / "out";
    const CommandResult r = RunVobench("tune " + file + " -q --out " + out);
    EXPECT_EQ(r.exit_code, 2) << bad.what << ": " << r.output;
    EXPECT_NE(r.output.find(file), std::string::npos) << bad.what << ": " << r.output;
    for (const std::string& e : bad.expected)
      EXPECT_NE(r.output.find(e), std::string::npos)
          << bad.what << ": '" << e << "' not in: " << r.output;
    EXPECT_FALSE(fs::exists(out)) << bad.what;
    EXPECT_FALSE(fs::exists(out + ".partial")) << bad.what;
  }
  const CommandResult missing =
      RunVobench("tune " + (dir / "none.yaml") + " -q --out " + (dir / "out"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("none.yaml"), std::string::npos) << missing.output;
  // An existing folder that is not a tune result is not replaced (refused before simulating).
  const std::string file = dir / "tune.yaml";
  WriteText(file, TuneFileText());
  fs::create_directories(dir / "taken");
  WriteText(dir / "taken/keep.txt", "x");
  const CommandResult taken = RunVobench("tune " + file + " -q --out " + (dir / "taken"));
  EXPECT_EQ(taken.exit_code, 1);
  EXPECT_NE(taken.output.find("not a vobench tune folder"), std::string::npos) << taken.output;
  EXPECT_TRUE(fs::exists(dir / "taken/keep.txt"));
}

// An objective that does not apply to a sequence (null in metrics.json: a percentage of a path
// shorter than 1 m) is an error naming the metric, the sequence and the reason, not a crash;
// nothing is published.
TEST(TuneCommandTest, ANullObjectiveIsAnErrorWithItsReason) {
  if (!fs::exists(VOBENCH_BINARY)) GTEST_SKIP() << "vobench not built: " << VOBENCH_BINARY;
  TempDir dir("tune_null");
  std::string text = TuneFileText("4");
  const std::string from = "metric: ate_rmse_m";
  text.replace(text.find(from), from.size(), "metric: end_pose_error_pct");
  const std::string file = dir / "tune.yaml";
  WriteText(file, text);
  const CommandResult r = RunVobench("tune " + file + " -q --no-plots --out " + (dir / "out"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("objective.metric end_pose_error_pct is null (not applicable) on tr_a: "
                          "ground-truth path"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("shorter than 1.000 m"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(TuneCommandTest, TunesDeterministicallyAndWritesALoadableBestConfig) {
  if (!fs::exists(VOBENCH_BINARY)) GTEST_SKIP() << "vobench not built: " << VOBENCH_BINARY;
  TempDir dir("tune_run");
  const std::string file = dir / "tiny.yaml";
  WriteText(file, TuneFileText());
  const std::string out1 = dir / "out1", out2 = dir / "out2";
  const CommandResult r1 = RunVobench("tune " + file + " -q --no-plots --out " + out1);
  ASSERT_EQ(r1.exit_code, 0) << r1.output;
  EXPECT_NE(r1.output.find("validation"), std::string::npos) << r1.output;  // the summary table
  for (const char* f : {"best_vo.yaml", "base_vo.yaml", "evaluations.csv", "scores.csv",
                        "summary.json", "report.md", "tune.yaml"})
    EXPECT_TRUE(fs::exists(fs::path(out1) / f)) << f;
  EXPECT_FALSE(fs::exists(out1 + ".partial"));

  // Deterministic: the same file and seed give identical evaluations and best config.
  const CommandResult r2 = RunVobench("tune " + file + " -q --no-plots --out " + out2);
  ASSERT_EQ(r2.exit_code, 0) << r2.output;
  for (const char* f : {"evaluations.csv", "best_vo.yaml", "scores.csv"})
    EXPECT_EQ(ReadAll(fs::path(out1) / f), ReadAll(fs::path(out2) / f)) << f;

  // Evaluations: a header and one row per evaluation, the start first.
  std::vector<std::string> lines;
  {
    std::istringstream csv(ReadAll(fs::path(out1) / "evaluations.csv"));
    for (std::string l; std::getline(csv, l);) lines.push_back(l);
  }
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0],
            "eval,origin,tracker.matcher.svd.sigma_px,tracker.matcher.ncc.window_px,tracker."
            "matcher.gabor.wavelengths_px:scale,"
            "motion.ransac.inlier_threshold_px,tr_a:ate_rmse_m,tr_a:lost_frames,objective,best_"
            "objective");
  EXPECT_EQ(lines[1].rfind("0,start,10,11,1,2,", 0), 0u) << lines[1];

  // Never worse than the start on training; the tuned values are the best evaluation's.
  const nlohmann::json j = ReadJson(out1 + "/summary.json");
  EXPECT_LE(j["train"]["tuned"].get<double>(), j["train"]["default"].get<double>());
  const int best = j["optimizer"]["best_eval"].get<int>();
  EXPECT_EQ(j["optimizer"]["evaluations"].get<int>(), 4);

  // best_vo.yaml loads with the VO config reader and holds the best parameters.
  harness::TuneSpec spec;
  std::string error;
  ASSERT_TRUE(harness::LoadTuneSpec(file, &spec, &error)) << error;
  std::vector<double> values;
  for (const auto& p : j["parameters"]) values.push_back(p["tuned"].get<double>());
  vo::OdometryOptions expected, loaded;
  ASSERT_TRUE(harness::ApplyParameters(spec, values, &expected, &error)) << error;
  ASSERT_TRUE(harness::LoadVoConfig(out1 + "/best_vo.yaml", &loaded, &error)) << error;
  EXPECT_EQ(harness::VoConfigToYaml(loaded), harness::VoConfigToYaml(expected));
  EXPECT_EQ(loaded.tracker.matcher.svd.sigma_px, values[0]);
  EXPECT_EQ(loaded.tracker.matcher.ncc.window_px, static_cast<int>(values[1]));
  EXPECT_EQ(loaded.motion.ransac.inlier_threshold_px, values[3]);
  std::istringstream row(lines[1 + best]);
  std::string cell;
  std::vector<std::string> cells;
  while (std::getline(row, cell, ',')) cells.push_back(cell);
  EXPECT_EQ(std::stod(cells[2]), values[0]);
  EXPECT_EQ(std::stod(cells.back()), j["train"]["tuned"].get<double>());

  // The scores are those of `vobench run`: default options on the training scenario.
  harness::RunOptions run;
  run.out_dir = dir / "run";
  run.progress = false;
  run.plots = false;
  run.max_frames = spec.train[0].max_frames;
  harness::RunSummary s;
  ASSERT_TRUE(harness::RunScenario(spec.train[0].scenario, spec.base_options, run, &s, &error))
      << error;
  EXPECT_EQ(j["scenarios"][0]["default"]["ate_rmse_m"].get<double>(), s.metrics.ate_rmse_m);
  EXPECT_EQ(j["scenarios"][0]["default"]["lost_frames"].get<int>(), s.lost_frames);
  EXPECT_EQ(j["scenarios"][0]["frames"].get<int>(), s.metrics.frames);
}

}  // namespace
