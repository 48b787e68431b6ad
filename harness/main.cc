// vobench: the command-line front of the test bench. Every subcommand is in
// harness/cli/NAME_command.{h,cc}, made by its Add...Command (the pattern they follow:
// harness/cli/command.h); this file sets up the process, adds them and runs the one given.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <opencv2/core/utility.hpp>
#include <vector>

#include "harness/cli/breakpoint_command.h"
#include "harness/cli/check_command.h"
#include "harness/cli/command.h"
#include "harness/cli/eval_command.h"
#include "harness/cli/match_eval_command.h"
#include "harness/cli/render_command.h"
#include "harness/cli/run_command.h"
#include "harness/cli/scene_command.h"
#include "harness/cli/score_command.h"
#include "harness/cli/suite_command.h"
#include "harness/cli/tune_command.h"
#include "harness/interrupt.h"

int main(int argc, char** argv) {
  // The VO runs on one thread (the timings vobench reports are single-threaded, as the speed
  // target asks); OpenCV's own thread pool would otherwise split StereoBM and filters.
  cv::setNumThreads(1);
  // Ctrl-C / SIGTERM: the commands stop at the next frame, remove their work folders and exit
  // with 128 + the signal (harness/interrupt.h).
  const harness::ScopedInterruptHandlers interrupt_handlers;
  CLI::App app{"vobench: simulation-in-the-loop test bench for stereo visual odometry"};
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Debug logging");

  // In the order of `vobench --help`.
  const std::vector<harness::Command> commands = {
      harness::AddRenderCommand(app),    harness::AddSceneCommand(app),
      harness::AddMatchEvalCommand(app), harness::AddRunCommand(app),
      harness::AddEvalCommand(app),      harness::AddScoreCommand(app),
      harness::AddTuneCommand(app),      harness::AddBreakpointCommand(app),
      harness::AddSuiteCommand(app),  // suite, suite merge
      harness::AddCheckCommand(app)};

  // Argument errors exit with 2 (one line on stderr), --help with 0; the command runs after the
  // parse and gives its own exit code.
  int rc = harness::ParseCommandLine(app, argc, argv);
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  spdlog::set_pattern("[%l] %v");
  if (rc < 0) rc = harness::RunGivenCommand(commands);
  // A command stopped by SIGINT/SIGTERM has said so and removed its work; the exit status tells
  // the shell which signal (130, 143).
  if (rc != 0 && harness::InterruptSignal() != 0) rc = harness::InterruptExitCode();
  return rc;
}
