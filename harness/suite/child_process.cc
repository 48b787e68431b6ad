#include "harness/suite/child_process.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>

#include "harness/interrupt.h"
#include "harness/plots/plots.h"
#include "harness/suite/folder.h"

namespace harness::suite_internal {

namespace fs = std::filesystem;

std::string CommandLine(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + ShellQuoted(a);
  return s;
}

bool Spawn(const std::vector<std::string>& argv, const std::string& log_path, pid_t* pid,
           std::string* error) {
  if (access(argv[0].c_str(), X_OK) != 0) {
    *error = argv[0] + ": cannot start: " + std::strerror(errno);
    return false;
  }
  // Everything the child needs is prepared before fork(): after it, only async-signal-safe
  // calls (the parent may have threads).
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const char* log = log_path.c_str();
  const pid_t parent = getpid();
  sigset_t all, old_mask;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &old_mask);  // no handler runs in the child before exec
  const pid_t child = fork();
  if (child == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);                  // the parent died before prctl
    for (const int sig : kSignals) signal(sig, SIG_DFL);  // the parent's recording handlers
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    const int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0 || dup2(fd, STDOUT_FILENO) < 0 || dup2(fd, STDERR_FILENO) < 0) _exit(126);
    if (fd != STDOUT_FILENO && fd != STDERR_FILENO) close(fd);
    execv(args[0], args.data());
    static const char kExecFailed[] = "vobench suite: exec of the run failed\n";
    (void)!write(STDERR_FILENO, kExecFailed, sizeof(kExecFailed) - 1);
    _exit(127);
  }
  const int fork_errno = errno;
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  if (child < 0) {
    *error = argv[0] + ": cannot start: " + std::strerror(fork_errno);
    return false;
  }
  setpgid(child, child);  // also here: no race with kill(-child) below
  *pid = child;
  return true;
}

std::string Tail(const fs::path& path, int lines) {
  bool ok = false;
  const std::string text = ReadWholeFile(path, &ok);
  if (!ok) return "(no log)\n";
  std::vector<std::string> all;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) all.push_back(line);
  std::string tail;
  for (size_t i = all.size() > static_cast<size_t>(lines) ? all.size() - lines : 0; i < all.size();
       ++i)
    tail += all[i] + "\n";
  return tail;
}

std::string ExitText(int status) {
  if (WIFEXITED(status)) return "exit status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status))
    return std::string("killed by signal ") + std::to_string(WTERMSIG(status)) + " (" +
           strsignal(WTERMSIG(status)) + ")";
  return "ended with wait status " + std::to_string(status);
}

}  // namespace harness::suite_internal
