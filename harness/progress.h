// A one-line progress display on stderr for long runs ("render  123/430  28%  12.3 fps  ETA 25 s").
// Redraws in place on a terminal; on a pipe or log file it prints a line every 10 %.
#pragma once

#include <chrono>
#include <string>

namespace harness {

class Progress {
 public:
  // `total` may be an estimate (0 = unknown); `enabled` = false makes every call a no-op.
  Progress(std::string label, int total, bool enabled = true);
  // Reports that `done` items are finished.
  void Update(int done);
  // Changes the expected total (e.g. once it is known).
  void set_total(int total) { total_ = total; }
  // Final line with the count and the rate.
  void Finish(int done);

 private:
  std::string label_;
  int total_;
  bool enabled_;
  bool tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace harness
