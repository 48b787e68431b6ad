// vobench: the command-line front of the test bench.
//   vobench render SCENARIO --out DIR [--format kitti|euroc]
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "harness/render.h"

namespace {

int RunRender(const std::string& scenario_arg, const std::string& out, const std::string& format,
              bool overwrite, bool quiet) {
  std::string error;
  sim::Scenario scenario;
  if (!harness::ResolveScenario(scenario_arg, &scenario, &error)) {
    std::fprintf(stderr, "vobench render: %s\n", error.c_str());
    return 2;
  }
  harness::RenderOptions options;
  if (!harness::ParseDatasetFormat(format, &options.format)) {
    std::fprintf(stderr, "vobench render: --format: expected kitti or euroc, got '%s'\n", format.c_str());
    return 2;
  }
  options.overwrite = overwrite;
  options.progress = !quiet;
  harness::RenderSummary s;
  if (!harness::RenderScenario(scenario, out, options, &s, &error)) {
    std::fprintf(stderr, "vobench render: %s\n", error.c_str());
    return 1;
  }
  std::printf("scenario        %s\n", scenario.name.c_str());
  std::printf("output          %s (%s layout)\n", out.c_str(), harness::DatasetFormatName(options.format));
  std::printf("frames          %d (%.1f s at %.1f Hz)\n", s.frames, s.sim_time_s, scenario.rate_hz);
  std::printf("image size      %dx%d, baseline %.3f m\n", scenario.camera.width, scenario.camera.height,
              scenario.camera.baseline_m);
  std::printf("path length     %.3f m\n", s.path_length_m);
  std::printf("render speed    %.1f stereo frames/s (with depth, incl. physics and writing)\n", s.frames_per_s);
  std::printf("GL renderer     %s\n", s.gl_renderer.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vobench: simulation-in-the-loop test bench for stereo visual odometry"};
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Debug logging");

  std::string scenario = "l_hallway", out, format = "kitti";
  bool overwrite = false, quiet = false;
  CLI::App* render = app.add_subcommand("render", "Simulate a scenario and write its stereo sequence (KITTI layout, optionally EuRoC)");
  render->add_option("scenario", scenario, "Scenario YAML file or built-in name (l_hallway, plain_corridor)")->capture_default_str();
  render->add_option("--out,-o", out, "Output folder (must not exist unless --overwrite)")->required();
  render->add_option("--format", format, "Dataset layout: kitti or euroc (euroc writes both)")->capture_default_str();
  render->add_flag("--overwrite", overwrite, "Replace an existing output folder");
  render->add_flag("-q,--quiet", quiet, "No progress display");

  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  spdlog::set_pattern("[%l] %v");
  if (*render) return RunRender(scenario, out, format, overwrite, quiet);
  return 0;
}
