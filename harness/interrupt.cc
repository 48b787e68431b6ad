#include "harness/interrupt.h"

#include <signal.h>

#include <atomic>

namespace harness {
namespace {

std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the handler needs a lock-free flag");

void OnSignal(int sig) {
  int expected = 0;
  g_signal.compare_exchange_strong(expected, sig);  // keep the first signal
}

}  // namespace

ScopedInterruptHandlers::ScopedInterruptHandlers() {
  struct sigaction sa = {};
  sa.sa_handler = OnSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND | SA_RESTART;  // a second Ctrl-C gets the default: ends at once
  for (size_t i = 0; i < kSignals.size(); ++i) {
    sigaction(kSignals[i], nullptr, &old_[i]);
    if (old_[i].sa_handler != SIG_IGN) sigaction(kSignals[i], &sa, nullptr);
  }
}

ScopedInterruptHandlers::~ScopedInterruptHandlers() {
  for (size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &old_[i], nullptr);
}

int InterruptSignal() { return g_signal.load(); }

int InterruptExitCode() { return 128 + g_signal.load(); }

std::string InterruptedMessage(int done, int total, const std::string& unit,
                               const std::string& out) {
  std::string text = "interrupted after " + std::to_string(done);
  if (total > 0) text += " of " + std::to_string(total);
  return text + " " + unit + "; nothing was written to " + out;
}

}  // namespace harness
