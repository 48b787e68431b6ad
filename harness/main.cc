// vobench: the command-line front of the test bench. Every subcommand is in
// harness/cli/NAME_command.{h,cc} (the pattern they follow: harness/cli/command.h).
#include <CLI/CLI.hpp>
#include <opencv2/core/utility.hpp>
#include <spdlog/spdlog.h>

#include "harness/cli/command.h"
#include "harness/cli/eval_command.h"
#include "harness/cli/match_eval_command.h"
#include "harness/cli/render_command.h"
#include "harness/cli/run_command.h"
#include "harness/cli/tune_command.h"
#include "harness/interrupt.h"
#include "harness/suite_cli.h"

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

  const harness::Command render = harness::AddRenderCommand(app);
  const harness::Command match_eval = harness::AddMatchEvalCommand(app);
  const harness::Command run = harness::AddRunCommand(app);
  const harness::Command eval = harness::AddEvalCommand(app);
  const harness::Command tune = harness::AddTuneCommand(app);
  harness::AddSuiteCommands(app);  // suite, suite merge, check

  // Argument errors exit with 2 (one line on stderr); suite, suite merge and check run inside
  // the parse (their callbacks) and give their own exit codes.
  int rc = harness::ParseCommandLine(app, argc, argv);
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  spdlog::set_pattern("[%l] %v");
  if (rc < 0) {
    if (render.app->parsed()) rc = render.run();
    else if (run.app->parsed()) rc = run.run();
    else if (eval.app->parsed()) rc = eval.run();
    else if (tune.app->parsed()) rc = tune.run();
    else if (match_eval.app->parsed()) rc = match_eval.run();
    else rc = 0;
  }
  // A command stopped by SIGINT/SIGTERM has said so and removed its work; the exit status tells
  // the shell which signal (130, 143).
  if (rc != 0 && harness::InterruptSignal() != 0) rc = harness::InterruptExitCode();
  return rc;
}
