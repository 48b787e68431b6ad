// The command-line side of suites and regression checks:
//   vobench suite FILE [-j N] [--out DIR] [--shard i/N] [--force] [--plots] [-q]
//   vobench suite merge --out DIR SHARD_DIR...
//   vobench check [--baseline results/baseline.json] [--suite FILE] [--config VO.yaml]
//                 [--set key=value]... [--out DIR] [-j N] [--update] [-q]
// Exit status: 0 all runs finished (check: nothing worse than the baseline); 1 a run failed or
// is missing (check: a metric is worse, or a run failed); 2 bad input (nothing was written).
#pragma once

#include <CLI/CLI.hpp>

namespace harness {

// Adds the `suite` (with `merge`) and `check` subcommands to `app`. They run from their CLI11
// callbacks and end a failing command with CLI::RuntimeError(exit status), which CLI11_PARSE
// turns into main's return value.
void AddSuiteCommands(CLI::App& app);

}  // namespace harness
