// `vobench run`: the VO on a simulated scenario (or a KITTI-layout dataset folder), compared
// with the ground truth, into a run folder (harness/run.h does the work).
//   vobench run [SCENARIO] [--config VO.yaml] [--dataset DIR] [--out DIR] [--max-frames N]
//               [--stride K] [--no-plots] [-q]
// Exit status: 0 done; 1 the run failed (nothing is written to --out); 2 a bad scenario, VO
// config or argument.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "harness/cli/command.h"
#include "harness/pipeline.h"

namespace harness {

// Adds `run` to `app` (the pattern of every subcommand: harness/cli/command.h).
Command AddRunCommand(CLI::App& app);

// The run table on stdout (frames, errors, drift, VO time per frame) that `run` and `eval`
// print for a finished run written to `out`.
void PrintRunTable(const RunSummary& s, const std::string& out);

}  // namespace harness
