// The report builder (validation/report/report.hpp): every file written into a new directory,
// summary.json parsing back with the comparison's numbers, CSV tables matching the metrics
// exactly, report.md's verdicts, plots present when gnuplot is (and a completed report saying so
// when it is not), sections for later work, name clashes, and write failures that leave nothing
// half-written.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "validation/report/report.hpp"

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() /
           ("redmax_report_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::permissions(path, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path, ec);
  }
};

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// a: three columns; b: the same plus an offset of 0.5 on "knee", reordered, "extra" added
Comparison makeComparison(const std::string& name, double knee_offset, const Tolerance& tol) {
  const int n = 101;
  std::vector<double> t(n);
  MatX A(n, 3), B(n, 4);
  for (int i = 0; i < n; ++i) {
    t[i] = i / 100.0;
    const double h = 40 * std::sin(2 * kPi * t[i]), k = 20 * std::cos(2 * kPi * t[i]), p = 0;
    A.row(i) << h, k, p;
    B.row(i) << k - knee_offset, 1.0, h, p;
  }
  const Table a = makeTable("a", {"hip_moment", "knee_moment", "pelvis_tx_force"}, t, A);
  const Table b = makeTable("b", {"knee_moment", "extra", "hip_moment", "pelvis_tx_force"}, t, B);
  CompareOptions opt;
  opt.tolerance = tol;
  return compareTables(name, a, "core", b, "opensim", opt);
}

TEST(ReportWriter, WritesEveryFileAndSummaryParsesBack) {
  TempDir tmp;
  const fs::path dir = tmp.path / "nested" / "report";  // parents are created
  Report rep(dir.string());
  const Comparison c = makeComparison("core_vs_opensim", 0.5, {1e-9, 0.05, 1e-9, 0.05});
  rep.setInput("model", "gait.osim");
  rep.setInput("rows", 101);
  rep.addWallTime("core_id", 0.25);
  rep.addWallTime("core_id", 0.5);  // accumulates
  rep.addComparison(c, "moment [N m]");
  JsonValue& sweep = rep.section("sweeps")["tibia"];
  sweep["fraction"] = std::vector<double>{0, 0.4, 0.8};
  rep.section("sweeps")["note"] = "second call returns the same section";
  rep.addCheck("converter warnings", true, "none");
  const ReportFiles files = rep.write();

  for (const char* f : {"summary.json", "report.md", "core_vs_opensim_metrics.csv", "core_vs_opensim_series.csv"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;
    EXPECT_GT(fs::file_size(dir / f), 0u) << f;
  }
  EXPECT_EQ(files.written.back(), (dir / "summary.json").string());  // summary.json last

  const JsonValue s = JsonValue::parse(readFile(dir / "summary.json"));
  EXPECT_EQ(s.at("format").asString(), "redmax-validation-report");
  EXPECT_TRUE(s.at("passed").asBool());
  EXPECT_EQ(s.at("inputs").at("model").asString(), "gait.osim");
  EXPECT_EQ(s.at("wall_times_s").at("core_id").asNumber(), 0.75);
  const JsonValue& jc = s.at("comparisons").at(0);
  EXPECT_EQ(jc.at("name").asString(), "core_vs_opensim");
  EXPECT_EQ(jc.at("a").asString(), "core");
  EXPECT_EQ(jc.at("reference").asString(), "opensim");
  EXPECT_EQ(jc.at("samples").asNumber(), 101.0);
  EXPECT_EQ(jc.at("tolerance").at("rms_rel").asNumber(), 0.05);
  EXPECT_EQ(jc.at("missing").at("only_in_b").at(0).asString(), "extra");
  EXPECT_EQ(jc.at("columns").size(), 3u);
  // knee: constant offset 0.5 -> rms 0.5; the reference 20 cos(2 pi t) - 0.5 peaks at 20.5
  const JsonValue& knee = jc.at("columns").at(1);
  EXPECT_EQ(knee.at("name").asString(), "knee_moment");
  EXPECT_NEAR(knee.at("rms").asNumber(), 0.5, 1e-13);
  EXPECT_NEAR(knee.at("peak_ref").asNumber(), 20.5, 1e-13);
  EXPECT_NEAR(knee.at("rms_rel").asNumber(), 0.5 / 20.5, 1e-13);
  EXPECT_EQ(jc.at("worst_column").at("name").asString(), "knee_moment");
  // the zero column: relative errors 0, not null
  EXPECT_EQ(jc.at("columns").at(2).at("rms_rel").asNumber(), 0.0);
  EXPECT_EQ(s.at("sweeps").at("tibia").at("fraction").at(2).asNumber(), 0.8);
  EXPECT_EQ(s.at("sweeps").at("note").asString(), "second call returns the same section");
  EXPECT_TRUE(s.at("checks").at(0).at("passed").asBool());

  // metrics CSV: one row per column, numbers identical to the comparison's
  const CsvTable m = parseCsv(readFile(dir / "core_vs_opensim_metrics.csv"));
  ASSERT_EQ(m.rows.size(), 3u);
  EXPECT_EQ(m.header[3], "rms");
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(m.rows[k][0], c.metrics[k].name);
    EXPECT_EQ(std::stod(m.rows[k][3]), c.metrics[k].rms);
    EXPECT_EQ(std::stod(m.rows[k][5]), c.metrics[k].max_abs);
    EXPECT_EQ(m.rows[k].back(), "PASS");
  }
  // series CSV: time, then a, b, diff per column
  const CsvTable ser = parseCsv(readFile(dir / "core_vs_opensim_series.csv"));
  ASSERT_EQ(ser.rows.size(), 101u);
  ASSERT_EQ(ser.header.size(), 1u + 3 * 3);
  EXPECT_EQ(ser.header[4], "knee_moment:core");
  EXPECT_EQ(ser.header[6], "knee_moment:diff");
  EXPECT_EQ(std::stod(ser.rows[10][6]), c.a(10, 1) - c.b(10, 1));

  const std::string md = readFile(dir / "report.md");
  EXPECT_NE(md.find("Overall: **PASS**"), std::string::npos);
  EXPECT_NE(md.find("`knee_moment`"), std::string::npos);
  EXPECT_NE(md.find("Only in opensim: `extra`"), std::string::npos);

  // plots: present and non-empty with gnuplot, otherwise the report says they were skipped
  const auto gp = findGnuplot();
  if (gp.available) {
    ASSERT_EQ(files.plots.size(), 2u) << (files.plot_errors.empty() ? "" : files.plot_errors[0]);
    for (const auto& p : files.plots) EXPECT_GT(fs::file_size(p), 1000u) << p;
    EXPECT_EQ(jc.at("files").at("plots").size(), 2u);
    const std::string overlay = jc.at("files").at("plots").at(0).asString();
    EXPECT_NE(md.find("](" + overlay + ")"), std::string::npos);  // linked from report.md
  } else {
    std::printf("gnuplot unavailable (%s): plot files not checked\n", gp.why_not.c_str());
    EXPECT_TRUE(files.plots_skipped);
    EXPECT_NE(md.find("Plots were skipped"), std::string::npos);
  }
  // no temporary file is left
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }
}

TEST(ReportWriter, CompletesWithoutGnuplot) {
  TempDir tmp;
  ReportOptions opt;
  opt.gnuplot = "/nonexistent/gnuplot";
  Report rep(tmp.path.string(), opt);
  rep.addComparison(makeComparison("cmp", 0.1, {}), "");
  const auto files = rep.write();
  EXPECT_TRUE(files.plots_skipped);
  EXPECT_TRUE(files.plots.empty());
  const JsonValue s = JsonValue::parse(readFile(tmp.path / "summary.json"));
  EXPECT_TRUE(s.at("plots").at("skipped").asBool());
  EXPECT_NE(s.at("plots").at("note").asString().find("not found"), std::string::npos);
  EXPECT_TRUE(s.at("comparisons").at(0).at("files").at("plots").isArray());
  EXPECT_NE(readFile(tmp.path / "report.md").find("Plots were skipped"), std::string::npos);
}

TEST(ReportWriter, FailingComparisonFailsTheReport) {
  TempDir tmp;
  ReportOptions opt;
  opt.gnuplot = "none";
  Report rep(tmp.path.string(), opt);
  rep.addComparison(makeComparison("tight", 0.5, {0, 1e-3, 0, 1e-3}));
  EXPECT_FALSE(rep.passed());
  rep.write();
  const JsonValue s = JsonValue::parse(readFile(tmp.path / "summary.json"));
  EXPECT_FALSE(s.at("passed").asBool());
  EXPECT_FALSE(s.at("comparisons").at(0).at("passed").asBool());
  EXPECT_EQ(s.at("comparisons").at(0).at("columns_failed").asNumber(), 1.0);
  const std::string md = readFile(tmp.path / "report.md");
  EXPECT_NE(md.find("Overall: **FAIL**"), std::string::npos);
  EXPECT_NE(md.find("### tight: FAIL"), std::string::npos);
  // a failed check fails the report too
  Report rep2((tmp.path / "two").string(), opt);
  rep2.addCheck("something", false, "went wrong");
  EXPECT_FALSE(rep2.passed());
}

TEST(ReportWriter, NamesAndSectionsAreGuarded) {
  Report rep("/tmp/unused_never_written");
  rep.addComparison(makeComparison("cmp", 0.1, {}));
  EXPECT_THROW(rep.addComparison(makeComparison("cmp", 0.1, {})), std::invalid_argument);
  EXPECT_THROW(rep.addTable("cmp_metrics", CsvTable{}), std::invalid_argument);
  EXPECT_THROW(rep.addPlot("cmp_difference", PlotFigure{}), std::invalid_argument);
  EXPECT_NO_THROW(rep.addTable("cmp_overlay", CsvTable{}));  // a .csv beside the .png: no clash
  EXPECT_THROW(rep.section("comparisons"), std::invalid_argument);
  EXPECT_THROW(rep.section("passed"), std::invalid_argument);
  EXPECT_NO_THROW(rep.section("work_precision"));
  CsvTable ragged;
  ragged.header = {"a", "b"};
  ragged.addRow({"1"});
  EXPECT_THROW(rep.addTable("ragged", ragged), std::invalid_argument);
  EXPECT_EQ(sanitizeFileStem("core vs/opensim"), "core_vs_opensim");
  EXPECT_EQ(sanitizeFileStem("../x"), "_.._x");
  EXPECT_EQ(sanitizeFileStem(""), "_");
}

TEST(ReportWriter, DirectoryThatIsAFileFailsCleanly) {
  TempDir tmp;
  fs::create_directories(tmp.path);
  const fs::path file = tmp.path / "not_a_dir";
  std::ofstream(file) << "x";
  ReportOptions opt;
  opt.gnuplot = "none";
  Report rep(file.string(), opt);
  rep.addComparison(makeComparison("cmp", 0.1, {}));
  EXPECT_THROW(rep.write(), ReportError);
  EXPECT_EQ(readFile(file), "x");
}

TEST(ReportWriter, FailedWriteLeavesNothingHalfWritten) {
  // summary.json cannot be created (a directory holds its name): the write fails, earlier files
  // are complete, no temporary file remains, and summary.json (the completion marker) is absent
  TempDir tmp;
  fs::create_directories(tmp.path / "summary.json");
  ReportOptions opt;
  opt.gnuplot = "none";
  Report rep(tmp.path.string(), opt);
  const Comparison c = makeComparison("cmp", 0.1, {});
  rep.addComparison(c);
  try {
    rep.write();
    FAIL() << "write succeeded";
  } catch (const ReportError& e) {
    EXPECT_NE(std::string(e.what()).find("summary.json"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(tmp.path / "summary.json"));
  EXPECT_TRUE(fs::is_empty(tmp.path / "summary.json"));
  for (const auto& e : fs::directory_iterator(tmp.path)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }
  const CsvTable m = parseCsv(readFile(tmp.path / "cmp_metrics.csv"));
  EXPECT_EQ(m.rows.size(), c.metrics.size());
  EXPECT_EQ(parseCsv(readFile(tmp.path / "cmp_series.csv")).rows.size(), c.time.size());
}

TEST(ReportWriter, ReadOnlyDirectoryFailsWithoutPartialFiles) {
  TempDir tmp;
  fs::create_directories(tmp.path);
  fs::permissions(tmp.path, fs::perms::owner_read | fs::perms::owner_exec, fs::perm_options::replace);
  // root ignores permissions: then the situation cannot be produced this way
  const fs::path probe = tmp.path / "probe";
  if (std::ofstream(probe).good()) {
    fs::remove(probe);
    GTEST_SKIP() << "running with privileges that ignore a read-only directory (root); "
                    "FailedWriteLeavesNothingHalfWritten covers the failure path";
  }
  ReportOptions opt;
  opt.gnuplot = "none";
  Report rep(tmp.path.string(), opt);
  rep.addComparison(makeComparison("cmp", 0.1, {}));
  EXPECT_THROW(rep.write(), ReportError);
  EXPECT_TRUE(fs::is_empty(tmp.path));
}

}  // namespace
}  // namespace redmax::validation
