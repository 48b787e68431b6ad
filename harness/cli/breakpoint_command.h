// `vobench breakpoint`: the value of one scenario key (or the frame stride) at which a metric
// of the run crosses a value, by a coarse scan and a bisection (harness/breakpoint.h):
//   vobench breakpoint SCENARIO --vary KEY --range LO,HI --until 'METRIC>VALUE'
//       [--config VO.yaml | --external SUITE.yaml:CONFIG] [--seeds N --aggregate mean|worst]
//       [--max-frames N] [--stride K] [--max-lost-frames N] [--tolerance T] [--scan N]
//       [--max-evals N] [--out DIR]
// Exit status: 0 done (also when the range holds no crossing: the result says so), 1 a metric
// that is null at a point, an output folder that cannot be written, 2 bad arguments (the key,
// range, metric or condition; nothing is written).
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

Command AddBreakpointCommand(CLI::App& app);

}  // namespace harness
