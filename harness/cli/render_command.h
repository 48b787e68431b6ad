// `vobench render`: simulate a scenario and write its stereo sequence as a dataset folder
// (harness/render.h does the work).
//   vobench render [SCENARIO] --out DIR [--format kitti|euroc|tum] [--overwrite] [-q]
// Exit status: 0 written; 1 the simulation or the writing failed (nothing is left at --out);
// 2 a bad scenario or argument.
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

// Adds `render` to `app` (the pattern of every subcommand: harness/cli/command.h).
Command AddRenderCommand(CLI::App& app);

}  // namespace harness
