// SIGINT / SIGTERM / SIGHUP / SIGQUIT for the long commands (run, eval, render, match-eval,
// tune, suite, check): the handler only records the signal; the frame loops poll
// InterruptSignal(), stop, let their work folders and locks be removed (OutputFolder,
// DatasetWriter) and fail with InterruptedMessage(); main() then exits with InterruptExitCode()
// (128 + the signal: 130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP — a closed terminal or a
// dropped ssh session — and 131 for SIGQUIT, Ctrl-\, without a core dump). A second signal of
// the same kind kills at once (the handler resets itself).
#pragma once

#include <signal.h>

#include <array>
#include <string>

namespace harness {

// The signals handled: SIGINT, SIGTERM, SIGHUP, SIGQUIT.
inline constexpr std::array<int, 4> kSignals = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

// Installs the recording handler for kSignals for the object's lifetime and puts the
// earlier handlers back after it (nesting is fine). A signal that was ignored when the process
// started (nohup, a background job of a script) stays ignored.
class ScopedInterruptHandlers {
 public:
  ScopedInterruptHandlers();
  ~ScopedInterruptHandlers();
  ScopedInterruptHandlers(const ScopedInterruptHandlers&) = delete;
  ScopedInterruptHandlers& operator=(const ScopedInterruptHandlers&) = delete;

 private:
  std::array<struct sigaction, kSignals.size()> old_ = {};
};

// The first signal recorded by the handler (one of kSignals), 0 when none.
int InterruptSignal();

// 128 + InterruptSignal(), the exit status of a command stopped by the signal.
int InterruptExitCode();

// "interrupted after N of M frames; nothing was written to OUT" (`total` <= 0: "N frames";
// `unit` is plural: "frames", "evaluations").
std::string InterruptedMessage(int done, int total, const std::string& unit,
                               const std::string& out);

}  // namespace harness
