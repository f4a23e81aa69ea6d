// Progress lines (validation/report/progress.hpp): exact formatting of durations, percent and ETA;
// throttling on a log (non-terminal) stream and on a terminal, with an injected clock; the final
// line printed once; counting from several threads.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "validation/report/progress.hpp"

namespace redmax::validation {
namespace {

std::string contentsOf(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  char buf[256];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  return s;
}

int countOf(const std::string& s, const std::string& what) {
  int n = 0;
  for (size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

TEST(ReportProgress, FormatsDurations) {
  EXPECT_EQ(formatDuration(0.4237), "0.42s");
  EXPECT_EQ(formatDuration(12.34), "12.3s");
  EXPECT_EQ(formatDuration(65), "1m05s");
  EXPECT_EQ(formatDuration(3599.4), "59m59s");
  EXPECT_EQ(formatDuration(7380), "2h03m");
  EXPECT_EQ(formatDuration(-1), "?");
}

TEST(ReportProgress, FormatsLinesWithEta) {
  // 25 of 100 in 10 s: 75 left at 2.5 per second -> 30 s
  EXPECT_EQ(formatProgressLine("sweep", 25, 100, 10), "sweep: 25/100 (25.0%), 10.0s elapsed, ETA 30.0s");
  EXPECT_EQ(formatProgressLine("sweep", 0, 8, 1), "sweep: 0/8 (0.0%), 1.00s elapsed, ETA ?");
  EXPECT_EQ(formatProgressLine("sweep", 8, 8, 90), "sweep: 8/8 (100.0%), 1m30s elapsed");
  EXPECT_EQ(formatProgressLine("batch", 7, 0, 3), "batch: 7 done, 3.00s elapsed");
}

TEST(ReportProgress, LogStreamPrintsOnlyOccasionally) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  double now = 0;
  ProgressOptions opt;
  opt.stream = f;
  opt.tty = 0;
  opt.log_interval_s = 30;
  opt.clock = [&] { return now; };
  {
    Progress p("trials", 100, opt);
    // 100 steps one second apart: lines at t = 30, 60, 90, and the final one
    for (int i = 0; i < 100; ++i) {
      now += 1;
      p.advance();
    }
    EXPECT_EQ(p.linesPrinted(), 3);
    p.finish();
    p.finish();  // once only
    EXPECT_EQ(p.linesPrinted(), 4);
    EXPECT_EQ(p.done(), 100);
  }
  const std::string s = contentsOf(f);
  std::fclose(f);
  EXPECT_EQ(countOf(s, "\n"), 4);
  EXPECT_EQ(countOf(s, "\r"), 0);  // no terminal control on a log
  EXPECT_NE(s.find("trials: 30/100 (30.0%), 30.0s elapsed, ETA 1m10s\n"), std::string::npos) << s;
  EXPECT_NE(s.find("trials: 100/100 (100.0%), 1m40s elapsed\n"), std::string::npos) << s;
}

TEST(ReportProgress, TerminalRedrawsInPlace) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  double now = 0;
  ProgressOptions opt;
  opt.stream = f;
  opt.tty = 1;
  opt.tty_interval_s = 0.25;
  opt.clock = [&] { return now; };
  {
    Progress p("sweep", 10, opt);
    for (int i = 0; i < 10; ++i) {
      now += 0.125;  // redraw every second step (binary fractions: exact sums)
      p.advance();
    }
    EXPECT_EQ(p.linesPrinted(), 5);
  }  // the destructor prints the final line
  const std::string s = contentsOf(f);
  std::fclose(f);
  EXPECT_EQ(countOf(s, "\r\033[K"), 6);
  EXPECT_EQ(countOf(s, "\n"), 1);  // only the final line ends the line
  EXPECT_EQ(s.back(), '\n');
}

TEST(ReportProgress, SilentStreamAndThreads) {
  ProgressOptions opt;
  opt.stream = nullptr;
  Progress p("work", 4000, opt);
  std::vector<std::thread> workers;
  for (int w = 0; w < 4; ++w) {
    workers.emplace_back([&p] {
      for (int i = 0; i < 1000; ++i) p.advance();
    });
  }
  for (auto& t : workers) t.join();
  EXPECT_EQ(p.done(), 4000);
  p.finish();
  EXPECT_EQ(p.linesPrinted(), 0);
}

}  // namespace
}  // namespace redmax::validation
