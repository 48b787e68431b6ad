// Plots through harness/plot.py (python3-matplotlib from Debian, run with /usr/bin/python3).
#pragma once

#include <string>
#include <vector>

namespace harness {

// Runs `plot.py ARGS...`; false (with *error) when python3 or matplotlib is missing or the
// script fails. Plots are an extra: callers warn and go on.
bool RunPlot(const std::vector<std::string>& args, std::string* error);

}  // namespace harness
