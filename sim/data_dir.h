// Where vobench finds the files it ships: scenes/, suites/, the plot scripts
// (harness/plots/*.py) and results/baseline.json. The data folder has the same layout as the
// source tree, so one relative path names a file in both:
//   installed   <prefix>/share/vobench/   (`cmake --install`; found from the running executable,
//                                          <prefix>/bin/vobench -> <prefix>/share/vobench)
//   build tree  the source tree            (compiled in; the build's executables are not under a
//                                           prefix with share/vobench/scenes)
#pragma once

#include <string>

namespace sim {

// The data folder of the running program (absolute, no trailing '/'): DataDirFor(the target of
// /proc/self/exe, the source tree compiled in).
const std::string& DataDir();

// The data folder for an executable at `exe_path`: <exe dir>/../share/vobench when that holds
// scenes/, else `fallback`. (The lookup of DataDir, testable without installing.)
std::string DataDirFor(const std::string& exe_path, const std::string& fallback);

}  // namespace sim
