// `vobench eval`: the VO on a recorded stereo sequence (see eval.h for what it does):
//   vobench eval --dataset DIR --format kitti|euroc|tum [--gt FILE] [--config VO.yaml]
//                [--out DIR] [--max-frames N] [--max-difference S] [--no-plots] [-q]
// Exit status: 0 done, 1 the dataset or the run failed (message names the file), 2 bad
// arguments or VO config. Nothing is written to --out on failure.
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

// Adds `eval` to `app` (the pattern of every subcommand: harness/cli/command.h).
Command AddEvalCommand(CLI::App& app);

}  // namespace harness
