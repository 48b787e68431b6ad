// Plots through the matplotlib scripts beside this file, harness/plots/*.py (python3-matplotlib
// from Debian, run with /usr/bin/python3; installed under <prefix>/share/vobench/harness/plots).
#pragma once

#include <string>
#include <vector>

#include "sim/scene_walls.h"

namespace harness {

// Runs `plot.py ARGS...`; false (with *error) when python3 or matplotlib is missing or the
// script fails. Plots are an extra: callers warn and go on.
bool RunPlot(const std::vector<std::string>& args, std::string* error);

// Runs harness/plots/SCRIPT (a matplotlib script of ours, in sim::DataDir()) with ARGS under
// Debian's python3 (the one python3-matplotlib is installed for, not another python on PATH);
// false with *error (the script's output) when it cannot start or fails.
bool RunPythonScript(const std::string& script, const std::vector<std::string>& args,
                     std::string* error);

// The top-down outline of a scene for `plot.py trajectory --outline-file`: CSV with the header
// `wall,x0_m,y0_m,x1_m,y1_m` and one row per wall of finite length (its two ends in the world,
// metres), in the order of the scene's geoms.
std::string SceneOutlineCsv(const std::vector<sim::SceneWall>& walls);

// `plot.py trajectory GT_TUM EST_TUM PNG`, outlined by the walls of the MJCF scene `scene_path`
// ("" = no outline; the outline goes through a file next to the PNG, removed afterwards). A
// closed-loop run's `navigation_csv` (run_folder.h) adds the robot's believed and driven paths.
bool RunTrajectoryPlot(const std::string& gt_tum, const std::string& est_tum,
                       const std::string& png, const std::string& scene_path, std::string* error,
                       const std::string& navigation_csv = "");

// `s` quoted for the POSIX shell (as it is when it holds only safe characters).
std::string ShellQuoted(const std::string& s);

}  // namespace harness
