// The whole report on synthetic tables (validation/report/demo_report.hpp): the engines agree to
// round-off, the OpenSim-3.x-style reference is matched by name across its other column order,
// its missing and extra columns are reported, its known errors (+0.5 offset on the knee, +2% on
// the ankle) come out of the metrics, and every file, section and (with gnuplot) plot exists.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "validation/report/demo_report.hpp"

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

const ColumnMetrics& column(const Comparison& c, const std::string& name) {
  for (const auto& m : c.metrics) {
    if (m.name == name) return m;
  }
  throw std::runtime_error("no column " + name);
}

// removed however the test ends
struct TempDir {
  fs::path path = fs::temp_directory_path() / ("redmax_demo_report_" + std::to_string(::getpid()));
  TempDir() { fs::remove_all(path); }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

TEST(ReportDemo, RunsTheWholeReportOnSyntheticTables) {
  const TempDir tmp;
  const fs::path& dir = tmp.path;
  const DemoReportResult r = writeDemoReport(dir.string());

  // engines: core + 1e-12 sin(6 pi t) -> rms 1e-12 / sqrt(2) on every column (trapezoid, whole
  // periods), up to the rounding of the sum (half an ulp of values up to 90: 7e-15)
  EXPECT_TRUE(r.engines.passed);
  for (const auto& m : r.engines.metrics) {
    EXPECT_NEAR(m.rms, 1e-12 / std::sqrt(2.0), 2e-14) << m.name;
    EXPECT_NEAR(m.max_abs, 1e-12, 2e-14) << m.name;
  }

  // reference: matched by name, grid = core's rows inside [0.01, 0.99]
  const Comparison& ref = r.reference;
  EXPECT_EQ(ref.columns, (std::vector<std::string>{"hip_flexion_r_moment", "knee_angle_r_moment",
                                                    "ankle_angle_r_moment"}));
  EXPECT_EQ(ref.only_in_a, (std::vector<std::string>{"pelvis_tx_force"}));
  EXPECT_EQ(ref.only_in_b, (std::vector<std::string>{"lumbar_extension_moment"}));
  EXPECT_DOUBLE_EQ(ref.t_begin, 0.01);
  EXPECT_DOUBLE_EQ(ref.t_end, 0.99);
  EXPECT_EQ(ref.time.size(), 197u);
  // the knee's +0.5 offset is the mean difference, up to the interpolation error of the
  // reference (rows every 0.01 s: 30 (2 pi)^2 0.01^2 / 8 ~ 0.015) and its 8-decimal file rounding
  const auto& knee = column(ref, "knee_angle_r_moment");
  EXPECT_NEAR(knee.mean, -0.5, 0.015);
  EXPECT_NEAR(knee.rms, 0.5, 0.015);
  // the ankle is 2% larger in the reference: the worst difference is 2% of |80 sin + 10| at its
  // peak 90, i.e. 1.8, and max/peak = 0.02 / 1.02, up to the interpolation error
  // 1.02 * 80 (4 pi)^2 0.01^2 / 8 = 0.16, i.e. 0.0018 of the peak 91.8
  const auto& ankle = column(ref, "ankle_angle_r_moment");
  EXPECT_NEAR(ankle.max_rel, 0.02 / 1.02, 2e-3);
  EXPECT_TRUE(ref.passed);
  EXPECT_TRUE(r.passed);

  // files
  for (const char* f : {"summary.json", "report.md", "core_vs_simbody_metrics.csv", "core_vs_simbody_series.csv",
                        "core_vs_reference_metrics.csv", "core_vs_reference_series.csv", "sweep_tibia.csv",
                        "demo_reference.sto"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;
  }
  const JsonValue s = JsonValue::parse(readFile(dir / "summary.json"));
  EXPECT_TRUE(s.at("passed").asBool());
  EXPECT_EQ(s.at("comparisons").size(), 2u);
  EXPECT_EQ(s.at("comparisons").at(1).at("worst_column").at("name").asString(), "knee_angle_r_moment");
  EXPECT_EQ(s.at("sweeps").at("tibia_mass_transfer").at("fraction").size(), 9u);
  EXPECT_EQ(s.at("work_precision").at("integrators").at(1).at("name").asString(), "rk45");
  EXPECT_EQ(s.at("overlays").at(0).at("series").size(), 3u);

  const auto gp = findGnuplot();
  if (gp.available) {
    // 2 comparisons x (overlay + difference) + the three-way overlay + sweep + work-precision
    EXPECT_EQ(r.files.plots.size(), 7u) << (r.files.plot_errors.empty() ? "" : r.files.plot_errors[0]);
    for (const auto& p : r.files.plots) EXPECT_GT(fs::file_size(p), 1000u) << p;
    EXPECT_EQ(s.at("plots").at("drawn").asNumber(), 7.0);
  } else {
    std::printf("gnuplot unavailable (%s): plot files not checked\n", gp.why_not.c_str());
    EXPECT_TRUE(s.at("plots").at("skipped").asBool());
  }
}

TEST(ReportDemo, DemoTablesAreWellFormed) {
  const auto t = makeDemoTables(11);
  ASSERT_EQ(t.size(), 3u);
  for (const auto& tab : t) EXPECT_NO_THROW(checkTable(tab, tab.name));
  EXPECT_THROW(makeDemoTables(1), CompareError);
}

}  // namespace
}  // namespace redmax::validation
