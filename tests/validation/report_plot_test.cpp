// Plots through gnuplot (validation/report/plot.hpp): the generated script (datablocks, quoting
// that keeps labels from injecting commands, log axes dropping non-positive points, empty
// panels), finding gnuplot or reporting why not, and, when gnuplot is installed, real PNG and SVG
// files, a failure that leaves nothing behind, and pagination of per-column grids.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "validation/report/plot.hpp"

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() /
           ("redmax_plot_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

PlotFigure twoPanelFigure() {
  PlotFigure fig;
  fig.title = "it's a test";
  const PlotLine a = makePlotLine("core", {0, 1, 2, 3}, {0, 1, 4, 9});
  const PlotLine b = makePlotLine("sim'body", {0, 1, 2, 3}, {0, 1.1, 4.1, NAN});
  fig.panels.push_back(makeXYPanel("hip_flexion_r_moment", "time [s]", "moment [N m]", {a, b}));
  const PlotLine c = makePlotLine("euler", {1e-6, 1e-4, 0, -1, 1e-2}, {10, 1, 5, 5, 0.1});
  fig.panels.push_back(makeLogLogPanel("work-precision", "error", "seconds", {c}));
  return fig;
}

TEST(ReportPlot, ScriptHoldsDataAndQuotesText) {
  const std::string s = makeGnuplotScript(twoPanelFigure(), "png", "/tmp/x.png.tmp");
  EXPECT_NE(s.find("set terminal pngcairo noenhanced"), std::string::npos);
  EXPECT_NE(s.find("set output '/tmp/x.png.tmp'"), std::string::npos);
  // single quotes doubled inside gnuplot's single-quoted strings
  EXPECT_NE(s.find("title 'it''s a test'"), std::string::npos);
  EXPECT_NE(s.find("title 'sim''body'"), std::string::npos);
  // datablocks; NaN breaks the line
  EXPECT_NE(s.find("$d_0_0 << EOD\n0 0\n1 1\n2 4\n3 9\nEOD\n"), std::string::npos);
  EXPECT_NE(s.find("3 NaN\n"), std::string::npos);
  // the log-log panel: zero and negative x become NaN rows
  EXPECT_NE(s.find("$d_1_0 << EOD\n1e-06 10\n1e-04 1\nNaN 5\nNaN 5\n0.01 0.1\nEOD\n"), std::string::npos);
  EXPECT_NE(s.find("set logscale x"), std::string::npos);
  EXPECT_NE(s.find("set multiplot layout 1,2"), std::string::npos);
  // svg terminal when asked
  EXPECT_NE(makeGnuplotScript(twoPanelFigure(), "svg", "x.svg").find("set terminal svg noenhanced"),
            std::string::npos);
}

TEST(ReportPlot, EmptyPanelSaysNoData) {
  PlotFigure fig;
  fig.panels.push_back(makeXYPanel("empty", "x", "y", {makePlotLine("nan only", {0, 1}, {NAN, NAN})}));
  const std::string s = makeGnuplotScript(fig, "png", "x.png");
  EXPECT_NE(s.find("'no data'"), std::string::npos);
  EXPECT_EQ(s.find("$d_0_0"), std::string::npos);
}

TEST(ReportPlot, ColumnGridPagination) {
  SeriesSet set;
  set.time = {0, 1};
  set.labels = {"a", "b"};
  for (int k = 0; k < 37; ++k) {
    char name[16];
    std::snprintf(name, sizeof name, "c%d", k);  // (GCC 12 warns falsely on "c" + to_string)
    set.columns.emplace_back(name);
  }
  set.values.assign(2, std::vector<std::vector<double>>(37, std::vector<double>{0, 1}));
  const auto figs = makeColumnGridFigures(set, "grid", "y", 16);
  ASSERT_EQ(figs.size(), 3u);
  EXPECT_EQ(figs[0].panels.size(), 16u);
  EXPECT_EQ(figs[2].panels.size(), 5u);
  EXPECT_EQ(figs[2].title, "grid (3/3)");
  EXPECT_EQ(figs[2].panels[4].title, "c36");
  ASSERT_EQ(figs[0].panels[0].lines.size(), 2u);
  EXPECT_EQ(figs[0].panels[0].lines[1].label, "b");
  EXPECT_EQ(figs[0].panels[0].lines[1].dash_type, 2);  // the second series is dashed
}

TEST(ReportPlot, MissingOrDisabledGnuplotIsReportedNotThrown) {
  const auto off = findGnuplot("none");
  EXPECT_FALSE(off.available);
  EXPECT_EQ(off.why_not, "plots disabled");
  const auto missing = findGnuplot("/nonexistent/dir/gnuplot");
  EXPECT_FALSE(missing.available);
  EXPECT_NE(missing.why_not.find("not found"), std::string::npos);
  // rendering with it fails softly and writes nothing
  TempDir dir;
  const auto out = renderPlot(missing, PlotFormat::Auto, twoPanelFigure(), (dir.path / "fig").string());
  EXPECT_FALSE(out.ok);
  EXPECT_FALSE(out.error.empty());
  EXPECT_TRUE(fs::is_empty(dir.path));
  // a file that exists but is not gnuplot
  const auto wrong = findGnuplot("/bin/false");
  EXPECT_FALSE(wrong.available);
}

TEST(ReportPlot, RendersPngAndSvgWhenGnuplotIsInstalled) {
  const auto gp = findGnuplot();
  if (!gp.available) {
    GTEST_SKIP() << "gnuplot unavailable (" << gp.why_not << "): image checks skipped";
  }
  TempDir dir;
  const auto png = renderPlot(gp, PlotFormat::Png, twoPanelFigure(), (dir.path / "fig").string());
  ASSERT_TRUE(png.ok) << png.error;
  const std::string ext = gp.pngcairo ? ".png" : ".svg";
  EXPECT_EQ(png.file, (dir.path / ("fig" + ext)).string());
  const std::string bytes = readFile(png.file);
  ASSERT_GT(bytes.size(), 1000u);
  if (gp.pngcairo) {
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  }
  if (gp.svg) {
    const auto svg = renderPlot(gp, PlotFormat::Svg, twoPanelFigure(), (dir.path / "fig").string());
    ASSERT_TRUE(svg.ok) << svg.error;
    const std::string text = readFile(svg.file);
    EXPECT_NE(text.find("<svg"), std::string::npos);
    EXPECT_NE(text.find("hip_flexion_r_moment"), std::string::npos);  // noenhanced: underscores kept
  }
  // only the images are left: no temporary file
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir.path)) {
    ++n;
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }
  EXPECT_EQ(n, gp.svg && gp.pngcairo ? 2 : 1);
}

TEST(ReportPlot, GnuplotFailureLeavesNoFile) {
  const auto gp = findGnuplot();
  if (!gp.available) {
    GTEST_SKIP() << "gnuplot unavailable (" << gp.why_not << ")";
  }
  TempDir dir;
  // the output directory does not exist: gnuplot cannot open its output
  const auto out = renderPlot(gp, PlotFormat::Auto, twoPanelFigure(), (dir.path / "no_such_dir" / "fig").string());
  EXPECT_FALSE(out.ok);
  EXPECT_NE(out.error.find("gnuplot"), std::string::npos) << out.error;
  EXPECT_TRUE(fs::is_empty(dir.path));
}

}  // namespace
}  // namespace redmax::validation
