#include "harness/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace harness {

Progress::Progress(std::string label, int total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

void Progress::Update(int done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? done / elapsed : 0.0;
  const int total = std::max(total_, done);
  if (tty_) {
    if (now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    const double frac = total > 0 ? static_cast<double>(done) / total : 0.0;
    const int width = 30;
    const int filled = static_cast<int>(frac * width);
    std::string bar(filled, '#');
    bar.resize(width, '.');
    const double eta = rate > 0 ? (total - done) / rate : 0.0;
    std::fprintf(stderr, "\r%s [%s] %d/%s%d  %.1f/s  ETA %.0f s   ", label_.c_str(), bar.c_str(),
                 done, total_ > 0 ? "~" : "", total, rate, eta);
    std::fflush(stderr);
  } else if (total_ > 0) {
    const int decile = std::min(10, 10 * done / std::max(total, 1));
    if (decile != last_decile_) {
      last_decile_ = decile;
      std::fprintf(stderr, "%s: %d/~%d (%.1f/s)\n", label_.c_str(), done, total, rate);
    }
  }
}

void Progress::Finish(int done) {
  if (!enabled_) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "%s%s: %d done in %.1f s (%.1f/s)\n", tty_ ? "\r" : "", label_.c_str(), done,
               elapsed, elapsed > 0 ? done / elapsed : 0.0);
}

}  // namespace harness
