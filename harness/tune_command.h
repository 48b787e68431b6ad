// The `vobench tune` subcommand: command-line set-up and action (tune.h does the work).
//   vobench tune FILE [--out DIR] [--max-evals N] [--no-plots] [-q]
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace harness {

struct TuneCommandArgs {
  std::string file;   // the tune file (YAML, see tune.h)
  std::string out;    // output folder; "" = out/tune/<name>
  int max_evals = 0;  // > 0: replaces the file's optimizer.max_evals
  bool no_plots = false;
  bool quiet = false;
};

// Adds the subcommand to `app`; its arguments land in *args.
CLI::App* AddTuneCommand(CLI::App& app, TuneCommandArgs* args);

// Runs it: 0 on success, 2 for a bad tune file or arguments (nothing written), 1 when the run
// fails (nothing written).
int RunTuneCommand(const TuneCommandArgs& args);

}  // namespace harness
