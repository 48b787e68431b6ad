// Command-line plumbing shared by the vobench commands: integer bounds with readable messages,
// and CLI11's errors mapped to vobench's exit codes (README, "Exit codes").
#pragma once

#include <CLI/CLI.hpp>

namespace harness {

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;    // the command ran and failed (a run, a check, a write)
constexpr int kExitBadInput = 2;  // bad arguments or input files; nothing was written

// An integer option's bound: "--stride: must be >= 1, got 0", or "expected an integer >= 1,
// got 'x'" for text that is not an integer. Replaces CLI::PositiveNumber and friends, whose
// messages print the double range ("Value 0 not in range 0.000000 to 1797693...").
CLI::Validator AtLeast(long min);

// Parses the command line. Returns -1 when the command should run; otherwise the exit code to
// return at once: 0 after --help, 2 after any argument error (printed as one line on stderr,
// "vobench SUBCOMMAND: MESSAGE (see vobench SUBCOMMAND --help)"), or the code of a
// CLI::RuntimeError thrown by a subcommand callback (its message is already printed).
int ParseCommandLine(CLI::App& app, int argc, char** argv);

}  // namespace harness
