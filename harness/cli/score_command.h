// `vobench score`: the accuracy metrics of a trajectory file against a ground truth
// (harness/score.h), printed as `run` prints them and written as metrics.json:
//   vobench score --gt FILE --est FILE --format tum|kitti [--out DIR] [--max-difference S]
// Exit status: 0 done, 1 the output folder could not be written, 2 bad arguments or input
// files (the message names the file and line). Nothing is written to --out on failure.
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

Command AddScoreCommand(CLI::App& app);

}  // namespace harness
