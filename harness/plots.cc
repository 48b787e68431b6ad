#include "harness/plots.h"

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>

#include "sim/data_dir.h"

namespace harness {

std::string ShellQuoted(const std::string& s) {
  const char* kSafe = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=:";
  if (!s.empty() && s.find_first_not_of(kSafe) == std::string::npos) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

bool RunPythonScript(const std::string& script, const std::vector<std::string>& args,
                     std::string* error) {
  const std::string path = sim::DataDir() + "/harness/" + script;
  const std::string python =
      std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::string cmd = python + " " + ShellQuoted(path);
  for (const auto& a : args) cmd += " " + ShellQuoted(a);
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
    *error = script + (args.empty() || script != "plot.py" ? std::string() : " " + args[0]) +
             " failed: " + out;
    return false;
  }
  return true;
}

bool RunPlot(const std::vector<std::string>& args, std::string* error) {
  return RunPythonScript("plot.py", args, error);
}

}  // namespace harness
