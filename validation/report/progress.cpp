#include "validation/report/progress.hpp"

#include <chrono>
#include <cmath>
#include <unistd.h>

namespace redmax::validation {
namespace {

double steadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

std::string formatDuration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  char buf[32];
  if (s < 10) {
    std::snprintf(buf, sizeof buf, "%.2fs", s);
  } else if (s < 60) {
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  } else if (s < 3600) {
    const long t = std::lround(s);
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  } else {
    const long t = std::lround(s / 60);
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 60, t % 60);
  }
  return buf;
}

std::string formatProgressLine(const std::string& label, long done, long total, double elapsed_s) {
  char buf[64];
  std::string line = label + ": ";
  if (total <= 0) {
    return line + std::to_string(done) + " done, " + formatDuration(elapsed_s) + " elapsed";
  }
  std::snprintf(buf, sizeof buf, "%ld/%ld (%.1f%%)", done, total, 100.0 * static_cast<double>(done) / total);
  line += buf;
  line += ", " + formatDuration(elapsed_s) + " elapsed";
  if (done >= total) return line;
  // constant-rate estimate of the time left
  const double eta = done > 0 ? elapsed_s * static_cast<double>(total - done) / static_cast<double>(done) : -1;
  return line + ", ETA " + formatDuration(eta);
}

Progress::Progress(std::string label, long total, ProgressOptions opt)
    : label_(std::move(label)), total_(total), opt_(std::move(opt)) {
  tty_ = opt_.tty >= 0 ? opt_.tty == 1 : (opt_.stream && ::isatty(::fileno(opt_.stream)) == 1);
  t_start_ = t_last_print_ = now();
}

Progress::~Progress() {
  try {
    finish();
  } catch (...) {
    // a destructor never throws
  }
}

double Progress::now() const { return opt_.clock ? opt_.clock() : steadySeconds(); }

void Progress::advance(long n) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += n;
  maybePrint(false);
}

void Progress::set(long done) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = done;
  maybePrint(false);
}

void Progress::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  maybePrint(true);
  finished_ = true;
}

long Progress::done() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_;
}

double Progress::elapsedSeconds() const { return now() - t_start_; }

int Progress::linesPrinted() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return lines_;
}

void Progress::maybePrint(bool final_line) {
  if (finished_ || !opt_.stream) return;
  const double t = now();
  const double interval = tty_ ? opt_.tty_interval_s : opt_.log_interval_s;
  if (!final_line && t - t_last_print_ < interval) return;
  t_last_print_ = t;
  const std::string line = formatProgressLine(label_, done_, total_, t - t_start_);
  // on a terminal: return to the line start and clear it; a newline only at the end
  if (tty_) {
    std::fprintf(opt_.stream, "\r\033[K%s%s", line.c_str(), final_line ? "\n" : "");
  } else {
    std::fprintf(opt_.stream, "%s\n", line.c_str());
  }
  std::fflush(opt_.stream);
  ++lines_;
}

Stopwatch::Stopwatch() : t0_(steadySeconds()) {}
double Stopwatch::seconds() const { return steadySeconds() - t0_; }
void Stopwatch::restart() { t0_ = steadySeconds(); }

}  // namespace redmax::validation
