// Column matching by name and alignment over the overlapping time range
// (validation/compare/time_series.hpp): reordered and missing columns, duplicate labels, the
// overlap and window, OpenSim's 8-decimal time rounding, linear interpolation against its
// analytic error (h^2/4 at midpoints for t^2), natural cubic interpolation, uniform grids,
// three-way alignment, and input errors.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "validation/compare/metrics.hpp"

namespace redmax::validation {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<double> grid(int n, double t0, double t1) {
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) t[i] = t0 + (t1 - t0) * i / (n - 1);
  return t;
}

// a table whose column j holds f_j(t)
template <class... F>
Table tableOf(const std::string& name, const std::vector<std::string>& labels, const std::vector<double>& t, F... f) {
  MatX d(static_cast<Eigen::Index>(t.size()), static_cast<Eigen::Index>(labels.size()));
  for (size_t i = 0; i < t.size(); ++i) {
    int j = 0;
    ((d(static_cast<Eigen::Index>(i), j++) = f(t[i])), ...);
  }
  return makeTable(name, labels, t, d);
}

TEST(CompareAlign, MatchesColumnsByNameAcrossOrderAndReportsMissing) {
  const auto t = grid(3, 0, 1);
  const Table a = makeTable("a", {"x", "y", "z"}, t, MatX::Zero(3, 3));
  const Table b = makeTable("b", {"z", "w", "x"}, t, MatX::Zero(3, 3));
  const auto m = matchColumns({&a, &b});
  ASSERT_EQ(m.common, (std::vector<std::string>{"x", "z"}));  // a's order
  EXPECT_EQ(m.index[0], (std::vector<int>{0, 2}));
  EXPECT_EQ(m.index[1], (std::vector<int>{2, 0}));
  EXPECT_EQ(m.missing[0], (std::vector<std::string>{"w"}));
  EXPECT_EQ(m.missing[1], (std::vector<std::string>{"y"}));
  EXPECT_TRUE(m.warnings.empty());
}

TEST(CompareAlign, DuplicateLabelUsesTheFirstAndWarns) {
  const auto t = grid(3, 0, 1);
  const Table a = makeTable("a", {"x", "x"}, t, MatX::Zero(3, 2));
  const Table b = makeTable("b", {"x"}, t, MatX::Zero(3, 1));
  const auto m = matchColumns({&a, &b});
  ASSERT_EQ(m.common.size(), 1u);
  EXPECT_EQ(m.index[0][0], 0);
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_NE(m.warnings[0].find("more than once"), std::string::npos);
}

TEST(CompareAlign, ReorderedColumnsCompareByName) {
  // the same functions in another column order: zero error by name, large error by position
  const auto t = grid(101, 0, 1);
  auto f1 = [](double x) { return std::sin(2 * kPi * x); };
  auto f2 = [](double x) { return 3 + x * x; };
  auto f3 = [](double x) { return -2 * x; };
  const Table a = tableOf("a", {"hip", "knee", "ankle"}, t, f1, f2, f3);
  const Table b = tableOf("b", {"ankle", "hip", "extra", "knee"}, t, f3, f1, f2, f2);  // OpenSim 3.x order
  const auto c = compareTables("ab", a, "a", b, "b");
  ASSERT_EQ(c.columns, (std::vector<std::string>{"hip", "knee", "ankle"}));
  for (const auto& m : c.metrics) {
    EXPECT_EQ(m.rms, 0.0) << m.name;
    EXPECT_EQ(m.max_abs, 0.0) << m.name;
  }
  EXPECT_TRUE(c.passed);
  EXPECT_TRUE(c.only_in_a.empty());
  EXPECT_EQ(c.only_in_b, (std::vector<std::string>{"extra"}));
}

TEST(CompareAlign, OverlappingRangeAndGridRows) {
  // a on [0, 2] every 0.01, b on [0.5, 1.5]: the grid is a's rows in [0.5, 1.5]
  const auto ta = grid(201, 0, 2), tb = grid(11, 0.5, 1.5);
  auto f = [](double x) { return 1 + 2 * x; };  // linear: interpolation is exact
  const Table a = tableOf("a", {"c"}, ta, f), b = tableOf("b", {"c"}, tb, f);
  const auto al = alignTables({&a, &b}, {"a", "b"});
  EXPECT_DOUBLE_EQ(al.t_begin, 0.5);
  EXPECT_DOUBLE_EQ(al.t_end, 1.5);
  ASSERT_EQ(al.time.size(), 101u);
  EXPECT_DOUBLE_EQ(al.time.front(), 0.5);
  EXPECT_DOUBLE_EQ(al.time.back(), 1.5);
  for (size_t i = 0; i < al.time.size(); ++i) {
    EXPECT_NEAR(al.values[1](static_cast<Eigen::Index>(i), 0), f(al.time[i]), 1e-13);
    EXPECT_EQ(al.values[0](static_cast<Eigen::Index>(i), 0), a.data(static_cast<Eigen::Index>(i) + 50, 0));
  }
  // b's rows as the grid instead
  AlignOptions opt;
  opt.grid_table = 1;
  const auto al_b = alignTables({&a, &b}, {"a", "b"}, opt);
  EXPECT_EQ(al_b.time, tb);
  // a window narrows the range further
  opt.grid_table = 0;
  opt.t0 = 0.8;
  opt.t1 = 1.0;
  const auto al_w = alignTables({&a, &b}, {"a", "b"}, opt);
  EXPECT_DOUBLE_EQ(al_w.t_begin, 0.8);
  EXPECT_DOUBLE_EQ(al_w.t_end, 1.0);
  EXPECT_EQ(al_w.time.size(), 21u);
}

TEST(CompareAlign, EightDecimalTimeRoundingStaysInside) {
  // an OpenSim file's last time printed as 0.99999999: a's row at 1.0 is still compared
  std::vector<double> tb = grid(11, 0, 1);
  tb.back() = 0.99999999;
  const auto ta = grid(101, 0, 1);
  auto f = [](double x) { return x; };
  const Table a = tableOf("a", {"c"}, ta, f), b = tableOf("b", {"c"}, tb, f);
  const auto al = alignTables({&a, &b}, {"a", "b"});
  EXPECT_EQ(al.time.size(), 101u);
  EXPECT_DOUBLE_EQ(al.time.back(), 1.0);
  // with no tolerance the last row drops out
  AlignOptions strict;
  strict.time_tolerance = 0;
  EXPECT_EQ(alignTables({&a, &b}, {"a", "b"}, strict).time.size(), 100u);
}

TEST(CompareAlign, LinearInterpolationErrorOfAParabolaIsHSquaredOverFour) {
  // b = t^2 sampled every h; a = t^2 exactly on a grid with the midpoints: the linear interpolant
  // overshoots by h^2/4 at every midpoint and is exact at b's rows
  const double h = 0.05;
  const auto tb = grid(21, 0, 1), ta = grid(41, 0, 1);
  auto sq = [](double x) { return x * x; };
  const Table a = tableOf("a", {"q"}, ta, sq), b = tableOf("b", {"q"}, tb, sq);
  const auto c = compareTables("ab", a, "a", b, "b");
  ASSERT_EQ(c.metrics.size(), 1u);
  EXPECT_NEAR(c.metrics[0].max_abs, h * h / 4, 1e-15);
  // a - b is -h^2/4 at the 20 midpoints and 0 at the 21 rows; trapezoid weights h/2 each except
  // the two ends (h/4): rms^2 = 20 (h/2) (h^2/4)^2 / 1
  EXPECT_NEAR(c.metrics[0].rms, std::sqrt(20 * (h / 2)) * h * h / 4, 1e-15);
  EXPECT_NEAR(c.metrics[0].mean, -20 * (h / 2) * h * h / 4, 1e-15);
}

TEST(CompareAlign, NaturalCubicBeatsLinearOnSmoothData) {
  const auto tb = grid(26, 0, 1), ta = grid(201, 0, 1);
  // f'' = 0 at both ends, as the natural end conditions assume
  auto f = [](double x) { return std::sin(2 * kPi * x) + 0.3 * std::sin(6 * kPi * x); };
  const Table a = tableOf("a", {"s"}, ta, f), b = tableOf("b", {"s"}, tb, f);
  CompareOptions lin, cub;
  cub.align.interpolation = Interpolation::NaturalCubic;
  const auto cl = compareTables("l", a, "a", b, "b", lin);
  const auto cc = compareTables("c", a, "a", b, "b", cub);
  EXPECT_EQ(cc.interpolation, Interpolation::NaturalCubic);
  // linear error ~ h^2 f''/8 = 0.04^2 * 50 / 8 ~ 1e-2; cubic is far smaller
  EXPECT_GT(cl.metrics[0].max_abs, 5e-3);
  EXPECT_LT(cc.metrics[0].max_abs, cl.metrics[0].max_abs / 20);
  // both pass through the samples: at b's rows the interpolated value is the sample itself
  const std::vector<double> col(b.data.col(0).data(), b.data.col(0).data() + b.data.rows());
  const auto at_rows = interpolateColumn(b.time, col, b.time, Interpolation::NaturalCubic);
  for (size_t i = 0; i < at_rows.size(); ++i) EXPECT_EQ(at_rows[i], col[i]);
}

TEST(CompareAlign, CubicFallsBackToLinearWithFewRows) {
  const std::vector<double> t = {0, 1, 2}, y = {0, 1, 4};
  bool fell_back = false;
  const auto v = interpolateColumn(t, y, {0.5, 1.5}, Interpolation::NaturalCubic, &fell_back);
  EXPECT_TRUE(fell_back);
  EXPECT_DOUBLE_EQ(v[0], 0.5);
  EXPECT_DOUBLE_EQ(v[1], 2.5);
  // and the alignment says so
  const Table a = makeTable("a", {"c"}, t, Eigen::Map<const MatX>(y.data(), 3, 1));
  AlignOptions opt;
  opt.interpolation = Interpolation::NaturalCubic;
  const auto al = alignTables({&a, &a}, {"a", "b"}, opt);
  EXPECT_FALSE(al.warnings.empty());
}

TEST(CompareAlign, UniformGridInterpolatesEveryTable) {
  const auto ta = grid(11, 0, 1), tb = grid(7, 0.2, 1.4);
  auto f = [](double x) { return 4 - x; };
  const Table a = tableOf("a", {"c"}, ta, f), b = tableOf("b", {"c"}, tb, f);
  AlignOptions opt;
  opt.grid_table = -1;
  opt.uniform_samples = 5;
  const auto al = alignTables({&a, &b}, {"a", "b"}, opt);
  ASSERT_EQ(al.time.size(), 5u);
  EXPECT_EQ(al.time.front(), 0.2);
  EXPECT_EQ(al.time.back(), 1.0);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(al.time[i], 0.2 + 0.2 * i, 1e-15);
    EXPECT_NEAR(al.values[0](i, 0), f(al.time[i]), 1e-14);
    EXPECT_NEAR(al.values[1](i, 0), f(al.time[i]), 1e-14);
  }
  const auto c = compareAligned("ab", al, 0, 1);
  EXPECT_EQ(c.grid, "uniform");
}

TEST(CompareAlign, ThreeTablesNamePairColumnsAThirdLacks) {
  const auto t = grid(5, 0, 1);
  const Table a = makeTable("a", {"x", "y"}, t, MatX::Ones(5, 2));
  const Table b = makeTable("b", {"y", "x"}, t, MatX::Ones(5, 2));
  const Table r = makeTable("r", {"x", "z"}, t, MatX::Ones(5, 2));
  const auto al = alignTables({&a, &b, &r}, {"a", "b", "r"});
  EXPECT_EQ(al.columns(), (std::vector<std::string>{"x"}));
  const auto ab = compareAligned("ab", al, 0, 1);
  EXPECT_TRUE(ab.only_in_a.empty());
  EXPECT_TRUE(ab.only_in_b.empty());
  bool warned = false;
  for (const auto& w : ab.warnings) warned = warned || w.find("'y'") != std::string::npos;
  EXPECT_TRUE(warned);
  const auto ar = compareAligned("ar", al, 0, 2);
  EXPECT_EQ(ar.only_in_a, (std::vector<std::string>{"y"}));
  EXPECT_EQ(ar.only_in_b, (std::vector<std::string>{"z"}));
  EXPECT_THROW(compareAligned("aa", al, 0, 0), CompareError);
  EXPECT_THROW(compareAligned("a3", al, 0, 3), CompareError);
}

TEST(CompareAlign, InputErrorsAreClear) {
  const auto t1 = grid(5, 0, 1), t2 = grid(5, 2, 3);
  const Table a = makeTable("a", {"x"}, t1, MatX::Ones(5, 1));
  const Table far = makeTable("b", {"x"}, t2, MatX::Ones(5, 1));
  const Table other = makeTable("c", {"y"}, t1, MatX::Ones(5, 1));
  try {
    compareTables("ab", a, "a", far, "b");
    FAIL() << "no overlap accepted";
  } catch (const CompareError& e) {
    EXPECT_NE(std::string(e.what()).find("do not overlap"), std::string::npos) << e.what();
  }
  try {
    compareTables("ac", a, "a", other, "c");
    FAIL() << "no common column accepted";
  } catch (const CompareError& e) {
    EXPECT_NE(std::string(e.what()).find("no column is common"), std::string::npos) << e.what();
  }
  Table back = a;
  back.time[3] = back.time[2];
  try {
    compareTables("ab", a, "a", back, "b");
    FAIL() << "repeated time accepted";
  } catch (const CompareError& e) {
    EXPECT_NE(std::string(e.what()).find("row 4"), std::string::npos) << e.what();
  }
  Table empty = makeTable("e", {"x"}, {}, MatX(0, 1));
  EXPECT_THROW(compareTables("ae", a, "a", empty, "e"), CompareError);
  Table ragged = a;
  ragged.data.resize(4, 1);
  EXPECT_THROW(compareTables("ar", a, "a", ragged, "r"), CompareError);
  EXPECT_THROW(makeTable("bad", {"x", "y"}, t1, MatX::Ones(5, 1)), CompareError);
  EXPECT_THROW(parseInterpolation("quadratic"), CompareError);
  EXPECT_EQ(parseInterpolation("cubic"), Interpolation::NaturalCubic);
  AlignOptions bad;
  bad.grid_table = 5;
  EXPECT_THROW(alignTables({&a, &a}, {"a", "b"}, bad), CompareError);
  EXPECT_THROW(alignTables({&a}, {"a", "b"}), CompareError);
}

}  // namespace
}  // namespace redmax::validation
