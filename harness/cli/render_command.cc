#include "harness/cli/render_command.h"

#include <cstdio>
#include <memory>
#include <string>

#include "harness/pipeline.h"
#include "harness/render.h"

namespace harness {
namespace {

struct RenderArgs {
  std::string scenario = "l_hallway";
  std::string out;
  std::string format = "kitti";
  bool overwrite = false;
  bool quiet = false;
};

int RunRender(const std::string& scenario_arg, const std::string& out, const std::string& format,
              bool overwrite, bool quiet) {
  std::string error;
  sim::Scenario scenario;
  if (!ResolveScenario(scenario_arg, &scenario, &error)) {
    std::fprintf(stderr, "vobench render: %s\n", error.c_str());
    return 2;
  }
  if (const std::string closed = ClosedLoopProblem(scenario, "render"); !closed.empty()) {
    std::fprintf(stderr, "vobench render: %s\n", closed.c_str());
    return 2;
  }
  RenderOptions options;
  if (!ParseDatasetFormat(format, &options.format)) {
    std::fprintf(stderr,
                 "vobench render: --format: expected kitti, euroc, tum or rosbag, got '%s'\n",
                 format.c_str());
    return 2;
  }
  if (options.format == DatasetFormat::kRosbag && !RosbagSupported()) {
    std::fprintf(stderr, "vobench render: --format rosbag: %s\n", RosbagUnavailable().c_str());
    return 2;
  }
  options.overwrite = overwrite;
  options.progress = !quiet;
  RenderSummary s;
  if (!RenderScenario(scenario, out, options, &s, &error)) {
    std::fprintf(stderr, "vobench render: %s\n", error.c_str());
    return 1;
  }
  std::printf("scenario        %s\n", scenario.name.c_str());
  std::printf("output          %s (%s layout)\n", out.c_str(), DatasetFormatName(options.format));
  if (options.format == DatasetFormat::kRosbag)
    std::printf("bag             %s\n", RosbagPathInDataset(out).c_str());
  std::printf("frames          %d (%.1f s at %.1f Hz)\n", s.frames, s.sim_time_s, scenario.rate_hz);
  std::printf("image size      %dx%d, baseline %.3f m\n", scenario.camera.width,
              scenario.camera.height, scenario.camera.baseline_m);
  std::printf("path length     %.3f m (camera, 3-D)\n", s.path_length_m);
  std::printf("base path       %.3f m (robot base, 2-D)\n", s.base_path_length_m);
  std::printf("render speed    %.1f stereo frames/s (with depth, incl. physics and writing)\n",
              s.frames_per_s);
  std::printf("GL renderer     %s\n", s.gl_renderer.c_str());
  return 0;
}

}  // namespace

Command AddRenderCommand(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* render = app.add_subcommand(
      "render",
      "Simulate a scenario and write its stereo sequence (KITTI layout, optionally EuRoC, TUM or "
      "a ROS bag)");
  render
      ->add_option("scenario", a->scenario,
                   "Scenario YAML file or built-in name (l_hallway, plain_corridor)")
      ->capture_default_str();
  render->add_option("--out,-o", a->out, "Output folder (must not exist unless --overwrite)")
      ->required();
  render
      ->add_option("--format", a->format,
                   "Dataset layout: kitti, euroc, tum or rosbag (the others also write kitti; "
                   "rosbag: OUT/<OUT's name>.bag, EuRoC's topics)")
      ->capture_default_str();
  render->add_flag("--overwrite", a->overwrite,
                   "Replace an existing output folder if it is a dataset vobench wrote");
  render->add_flag("-q,--quiet", a->quiet, "No progress display");
  return {render,
          [a] { return RunRender(a->scenario, a->out, a->format, a->overwrite, a->quiet); }};
}

}  // namespace harness
