// The child processes of a suite (`vobench run`, one per run): starting one with its output
// into a log, and the text of how it ended. Not part of the suite API.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace harness::suite_internal {

// argv as one shell-quoted line (for the records of a run).
std::string CommandLine(const std::vector<std::string>& argv);

// Starts argv with stdout and stderr into `log_path`. The child leads a process group of its
// own (a Ctrl-C on the terminal reaches only this process, which stops the children itself) and
// is killed by the kernel when this process dies, however it dies (PR_SET_PDEATHSIG SIGKILL):
// no orphan goes on writing into a work folder that a resumed suite reuses.
bool Spawn(const std::vector<std::string>& argv, const std::string& log_path, pid_t* pid,
           std::string* error);

// The last `lines` lines of the file ("(no log)\n" when it cannot be read).
std::string Tail(const std::filesystem::path& path, int lines);

// How a child ended, from its wait status: "exit status 1", "killed by signal 9 (Killed)".
std::string ExitText(int status);

}  // namespace harness::suite_internal
