// `vobench suite`: a suite of runs (scenarios x VO configs x seeds x strides) as `vobench run`
// child processes, resumable, sharded, with a summary table (suite.h does the work); and
// `vobench suite merge`, the summary of a suite's shards.
//   vobench suite FILE [-j N] [--out DIR] [--shard i/N] [--force] [--plots] [-q]
//   vobench suite merge --out DIR SHARD_DIR...
// (and, hidden from --help, `vobench suite external SPEC --out DIR`: the child process of an
// external configuration's run, harness/suite/external.h).
// Exit status: 0 all runs finished; 1 a run failed or is missing; 2 bad input (nothing was
// written).
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

// Adds `suite`, with its subcommand `merge`, to `app` (the pattern of every subcommand:
// harness/cli/command.h); the action runs the one given.
Command AddSuiteCommand(CLI::App& app);

}  // namespace harness
