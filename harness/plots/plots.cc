#include "harness/plots/plots.h"

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

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
  const std::string path = sim::DataDir() + "/harness/plots/" + script;
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
    // The reason is the last line Python printed ("OSError: [Errno 28] No space left on
    // device"), not its traceback.
    std::string reason;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);)
      if (line.find_first_not_of(" \t\r") != std::string::npos) reason = line;
    if (reason.empty()) reason = "exit status " + std::to_string(WEXITSTATUS(status));
    *error = script + (args.empty() || script != "plot.py" ? std::string() : " " + args[0]) +
             " failed: " + reason;
    return false;
  }
  return true;
}

bool RunPlot(const std::vector<std::string>& args, std::string* error) {
  return RunPythonScript("plot.py", args, error);
}

std::string SceneOutlineCsv(const std::vector<sim::SceneWall>& walls) {
  std::string csv = "wall,x0_m,y0_m,x1_m,y1_m\n";
  char row[256];
  for (const sim::SceneWall& w : walls) {
    if (!std::isfinite(w.half_length_m)) continue;  // an infinite plane: no ends to draw
    const Eigen::Vector2d a = w.centre_xy - w.half_length_m * w.along_xy;
    const Eigen::Vector2d b = w.centre_xy + w.half_length_m * w.along_xy;
    std::snprintf(row, sizeof(row), ",%.9g,%.9g,%.9g,%.9g\n", a.x(), a.y(), b.x(), b.y());
    csv += w.name + row;
  }
  return csv;
}

bool RunTrajectoryPlot(const std::string& gt_tum, const std::string& est_tum,
                       const std::string& png, const std::string& scene_path, std::string* error,
                       const std::string& navigation_csv) {
  std::vector<std::string> args = {"trajectory", gt_tum, est_tum, png};
  if (!navigation_csv.empty()) {
    args.push_back("--navigation-file");
    args.push_back(navigation_csv);
  }
  if (scene_path.empty()) return RunPlot(args, error);
  std::vector<sim::SceneWall> walls;
  if (!sim::WallsOfScene(scene_path, &walls, error)) return false;
  const std::string outline = png + ".outline.csv";
  {
    std::ofstream out(outline);
    out << SceneOutlineCsv(walls);
    if (!out.flush()) {
      *error = outline + ": cannot write the scene outline";
      return false;
    }
  }
  args.push_back("--outline-file");
  args.push_back(outline);
  const bool ok = RunPlot(args, error);
  std::error_code ec;
  std::filesystem::remove(outline, ec);
  return ok;
}

}  // namespace harness
