// `vobench tune`: a parameter search against ground truth (tune.h does the work).
//   vobench tune FILE [--out DIR] [--max-evals N] [--no-plots] [-q]
// Exit status: 0 on success, 2 for a bad tune file or arguments (nothing written), 1 when the
// run fails (nothing written).
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

// Adds `tune` to `app` (the pattern of every subcommand: harness/cli/command.h).
Command AddTuneCommand(CLI::App& app);

}  // namespace harness
