// `vobench match-eval`: every matcher's precision, recall and F1 per frame stride against the
// simulator's ground truth (harness/match_eval.h does the work).
//   vobench match-eval [SCENARIO] [--strides 1,2,3,5,8] [--matchers A,B...]
//                      [--prediction motion_prior|none] [--out DIR] [--max-frames N] [-q]
// Exit status: 0 written; 1 the simulation, the evaluation or the writing failed (nothing is
// left at --out); 2 a bad scenario or argument.
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

// Adds `match-eval` to `app` (the pattern of every subcommand: harness/cli/command.h).
Command AddMatchEvalCommand(CLI::App& app);

}  // namespace harness
