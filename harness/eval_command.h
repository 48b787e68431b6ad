// The `vobench eval` subcommand's command-line set-up (see eval.h for what it does):
//   vobench eval --dataset DIR --format kitti|euroc|tum [--gt FILE] [--config VO.yaml]
//                [--out DIR] [--max-frames N] [--max-difference S] [--no-plots] [-q]
// Exit status: 0 done, 1 the dataset or the run failed (message names the file), 2 bad
// arguments or VO config. Nothing is written to --out on failure.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>

#include "harness/run.h"

namespace harness {

class EvalCommand {
 public:
  using PrintTable = std::function<void(const RunSummary& summary, const std::string& out_dir)>;

  // Runs the parsed command; print_table prints the run table shared with `vobench run`.
  int Run(const PrintTable& print_table) const;

  CLI::App* app = nullptr;  // the subcommand: true (`*app`) when it was given

  // Bound to the command-line options.
  std::string dataset;
  std::string format;
  std::string gt;
  std::string config;
  std::string out;  // default out/eval/<dataset folder name>
  int max_frames = 0;
  double max_difference_s = 0.0;
  bool no_plots = false;
  bool quiet = false;
};

// Adds the `eval` subcommand to `app`; the returned object holds its options and runs it.
std::shared_ptr<EvalCommand> AddEvalCommand(CLI::App& app);

}  // namespace harness
