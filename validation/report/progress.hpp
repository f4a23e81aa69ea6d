#pragma once
// Progress reporting for long harness work (batches of trials, mass sweeps, work-precision runs):
// one status line with count, percent, elapsed time and ETA on stderr. On a terminal the line is
// rewritten in place a few times a second; otherwise (a log file, CI) a line is printed only every
// log_interval_s and at the end, so logs stay short. Thread-safe: workers may call advance().
#include <cstdio>
#include <functional>
#include <mutex>
#include <string>

namespace redmax::validation {

/// "0.42s", "12.3s", "1m05s", "2h03m" ("?" for a negative or non-finite value)
std::string formatDuration(double seconds);

/// "label: 42/100 (42.0%), 1m05s elapsed, ETA 1m30s"; with total <= 0 (unknown):
/// "label: 42 done, 1m05s elapsed". The ETA assumes a constant rate ("ETA ?" before any is done).
std::string formatProgressLine(const std::string& label, long done, long total, double elapsed_s);

struct ProgressOptions {
  std::FILE* stream = stderr;   ///< where lines go; nullptr: silent
  int tty = -1;                 ///< -1: ask isatty(stream); 0 or 1: force (tests)
  double tty_interval_s = 0.2;  ///< least time between redraws on a terminal
  double log_interval_s = 30;   ///< least time between lines elsewhere
  std::function<double()> clock;  ///< seconds since any fixed origin (default: steady clock)
};

/// A progress counter that prints as described above.
class Progress {
 public:
  Progress(std::string label, long total, ProgressOptions opt = {});
  ~Progress();  ///< finish() if it was not called
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// count n more units done (may print)
  void advance(long n = 1);
  /// set the number done (may print)
  void set(long done);
  /// print the final line (once; later calls do nothing)
  void finish();

  long done() const;
  long total() const { return total_; }
  double elapsedSeconds() const;
  /// lines printed so far (tests: the throttling)
  int linesPrinted() const;

 private:
  void maybePrint(bool final_line);  // caller holds mutex_
  double now() const;

  std::string label_;
  long total_ = 0;
  ProgressOptions opt_;
  bool tty_ = false;
  mutable std::mutex mutex_;
  long done_ = 0;
  double t_start_ = 0, t_last_print_ = 0;
  int lines_ = 0;
  bool finished_ = false;
};

/// Wall-clock seconds since construction (steady clock), for the report's wall times.
class Stopwatch {
 public:
  Stopwatch();
  double seconds() const;
  void restart();

 private:
  double t0_ = 0;
};

}  // namespace redmax::validation
