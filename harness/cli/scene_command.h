// `vobench scene`: write the MJCF scene a floor plan generates (sim/floor_plan.h,
// scenes/README.md), to look at or edit by hand.
//   vobench scene PLAN.yaml --out scene.xml [--overwrite]
// The scene includes the plan's robot (robot_p2dx.xml by default) by its path relative to the
// output's folder, so the written file loads where it is. Exit status: 0 written; 1 the file
// could not be written; 2 a bad plan or argument (nothing written).
#pragma once

#include <CLI/CLI.hpp>

#include "harness/cli/command.h"

namespace harness {

// Adds `scene` to `app` (the pattern of every subcommand: harness/cli/command.h).
Command AddSceneCommand(CLI::App& app);

}  // namespace harness
