#include "harness/cli/scene_command.h"

#include <mujoco/mujoco.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "sim/floor_plan.h"

namespace harness {
namespace {

namespace fs = std::filesystem;

struct SceneArgs {
  std::string plan;
  std::string out;
  bool overwrite = false;
};

int RunScene(const SceneArgs& a) {
  std::string error;
  sim::FloorPlan plan;
  if (!sim::LoadFloorPlan(a.plan, &plan, &error))
    return PrintFailure("scene", kExitBadInput, error);
  if (fs::exists(a.out) && (!a.overwrite || !fs::is_regular_file(a.out)))
    return PrintFailure("scene", kExitBadInput,
                        "--out " + a.out +
                            (fs::is_regular_file(a.out) ? ": exists (use --overwrite)"
                                                        : ": exists and is not a file"));
  // The generated scene must load (as a scenario would load it) before anything is written.
  mjModel* m = sim::LoadSceneModel(a.plan, &error);
  if (!m) return PrintFailure("scene", kExitBadInput, error);
  const int nsurfaces = m->ngeom;
  mj_deleteModel(m);
  const fs::path out_dir = fs::absolute(a.out).parent_path();
  const std::string include = fs::relative(plan.robot_path, out_dir).generic_string();
  const std::string xml = sim::FloorPlanToMjcf(plan, include.empty() ? plan.robot_path : include);
  const std::string tmp = a.out + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << xml;
    if (!f.good()) {
      std::error_code ec;
      fs::remove(tmp, ec);
      return PrintFailure("scene", kExitFailed, "cannot write " + a.out);
    }
  }
  std::error_code ec;
  fs::rename(tmp, a.out, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return PrintFailure("scene", kExitFailed, "cannot write " + a.out);
  }
  std::printf("floor plan      %s (%zu spaces, %zu doors, %zu boxes)\n", a.plan.c_str(),
              plan.spaces.size(), plan.doors.size(), plan.boxes.size());
  std::printf("scene           %s (%d geoms with the robot's, robot %s)\n", a.out.c_str(),
              nsurfaces, include.c_str());
  return kExitOk;
}

}  // namespace

Command AddSceneCommand(CLI::App& app) {
  auto a = std::make_shared<SceneArgs>();
  CLI::App* scene = app.add_subcommand(
      "scene", "Write the MJCF scene a floor plan generates (scenes/README.md: the plan format)");
  scene->add_option("plan", a->plan, "Floor-plan YAML file")->required();
  scene->add_option("--out,-o", a->out, "Output MJCF file (must not exist unless --overwrite)")
      ->required()
      ->check(NonEmpty());
  scene->add_flag("--overwrite", a->overwrite, "Replace an existing output file");
  return {scene, [a] { return RunScene(*a); }};
}

}  // namespace harness
