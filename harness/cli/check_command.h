// `vobench check`: the regression check, a suite re-run and compared with a baseline (check.h
// does the work).
//   vobench check [--baseline results/baseline.json] [--suite FILE] [--config VO.yaml]
//                 [--set key=value]... [--out DIR] [-j N] [--update] [-q]
// Exit status: 0 nothing worse than the baseline (--update: baseline written); 1 a metric is
// worse, or a run failed or is missing; 2 bad input (nothing was written).
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

// Adds `check` to `app` (the pattern of every subcommand: harness/cli/command.h).
Command AddCheckCommand(CLI::App& app);

}  // namespace harness
