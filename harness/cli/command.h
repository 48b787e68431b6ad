// The vobench command line: the one pattern every subcommand follows, and the plumbing the
// subcommands share (integer bounds with readable messages, CLI11's errors mapped to vobench's
// exit codes: README, "Exit codes").
//
// Adding a subcommand NAME: harness/cli/NAME_command.{h,cc} with one function,
//   Command AddNameCommand(CLI::App& app);
// that adds the subcommand to `app` with its options (and nested subcommands), binds them to
// arguments the returned action owns (a struct held by the lambda), and returns the subcommand
// with that action; then one line in harness/main.cc adds it (the order of those lines is the
// order of `vobench --help`). main parses the whole command line, sets up logging and runs the
// action of the subcommand given. The action prints its results on stdout and its errors as
// one line on stderr, "vobench NAME: MESSAGE", and returns the exit code (kExit*).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace harness {

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;    // the command ran and failed (a run, a check, a write)
constexpr int kExitBadInput = 2;  // bad arguments or input files; nothing was written

// One subcommand of vobench, as its Add...Command function made it.
struct Command {
  CLI::App* app = nullptr;   // the subcommand, owned by the parent app; parsed() when given
  std::function<int()> run;  // runs it on the parsed arguments; returns the exit code
};

// Prints "vobench COMMAND: MESSAGE" on stderr (one line) and returns exit_code: the end of an
// action that fails, `return PrintFailure("suite", kExitBadInput, error);`.
int PrintFailure(const char* command, int exit_code, const std::string& message);

// The default of -j (suite, check): the hardware threads, at least 1.
int DefaultJobs();

// Runs the command the parsed command line gave (the first of `commands` whose app was
// parsed) and returns its exit code; kExitOk when none was given.
int RunGivenCommand(const std::vector<Command>& commands);

// An integer option's bound: "--stride: must be >= 1, got 0", or "expected an integer >= 1,
// got 'x'" for text that is not an integer. Replaces CLI::PositiveNumber and friends, whose
// messages print the double range ("Value 0 not in range 0.000000 to 1797693...").
CLI::Validator AtLeast(long min);
// A value that is not empty ("--out ''" names no folder).
CLI::Validator NonEmpty();

// Parses the command line. Returns -1 when the command should run; otherwise the exit code to
// return at once: 0 after --help, 2 after any argument error (printed as one line on stderr,
// "vobench SUBCOMMAND: MESSAGE (see vobench SUBCOMMAND --help)").
int ParseCommandLine(CLI::App& app, int argc, char** argv);

}  // namespace harness
