#include "harness/plots.h"

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>

namespace harness {

namespace {
std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
}  // namespace

bool RunPlot(const std::vector<std::string>& args, std::string* error) {
  const std::string script = std::string(VOBENCH_SOURCE_DIR) + "/harness/plot.py";
  // Debian's interpreter: python3-matplotlib is installed for it, not for other pythons on PATH.
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::string cmd = python + " " + Quote(script);
  for (const auto& a : args) cmd += " " + Quote(a);
  cmd += " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) {
    *error = "cannot start " + python;
    return false;
  }
  std::string out;
  char buf[1024];
  while (fgets(buf, sizeof(buf), pipe)) out += buf;
  const int status = pclose(pipe);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    *error = "plot.py " + (args.empty() ? std::string() : args[0]) + " failed: " + out;
    return false;
  }
  return true;
}

}  // namespace harness
