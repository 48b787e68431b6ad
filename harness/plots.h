// Plots through harness/plot.py (python3-matplotlib from Debian, run with /usr/bin/python3).
#pragma once

#include <string>
#include <vector>

namespace harness {

// Runs `plot.py ARGS...`; false (with *error) when python3 or matplotlib is missing or the
// script fails. Plots are an extra: callers warn and go on.
bool RunPlot(const std::vector<std::string>& args, std::string* error);

// Runs harness/SCRIPT (a matplotlib script of ours) with ARGS under Debian's python3 (the one
// python3-matplotlib is installed for, not another python on PATH); false with *error (the
// script's output) when it cannot start or fails.
bool RunPythonScript(const std::string& script, const std::vector<std::string>& args,
                     std::string* error);

// `s` quoted for the POSIX shell (as it is when it holds only safe characters).
std::string ShellQuoted(const std::string& s);

}  // namespace harness
