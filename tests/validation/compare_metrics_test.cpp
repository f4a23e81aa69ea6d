// Per-column metrics (validation/compare/metrics.hpp) on analytic cases: sinusoids over whole
// periods, where the trapezoid rule gives the exact mean square (it is exact for trigonometric
// polynomials of degree below the number of intervals), constant offsets, hand-computed
// non-uniform grids, zero references, NaN samples, tolerance boundaries and the worst column.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/spatial/se3.hpp"
#include "validation/compare/metrics.hpp"

namespace redmax::validation {
namespace {

constexpr double kPi = 3.14159265358979323846;

// n points over [0, T] including both ends
std::vector<double> grid(int n, double T = 1.0) {
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) t[i] = T * i / (n - 1);
  return t;
}

template <class F>
std::vector<double> sample(const std::vector<double>& t, F f) {
  std::vector<double> v;
  for (double x : t) v.push_back(f(x));
  return v;
}

bool nearScalar(double a, double b, double tol) { return std::abs(a - b) <= tol * (1 + std::abs(b)); }

TEST(CompareMetrics, SinusoidPlusOffsetHasAnalyticRms) {
  // d = c + B sin(2 pi k t + phi) over whole periods: rms^2 = c^2 + B^2/2, mean = c
  const auto t = grid(201);
  const double B = 0.3, c = 0.1, phi = 0.7;
  const auto b = sample(t, [](double x) { return 50 * std::sin(2 * kPi * x) + 10; });
  for (int k : {1, 3, 7}) {
    const auto a = sample(t, [&](double x) { return 50 * std::sin(2 * kPi * x) + 10 + c + B * std::sin(2 * kPi * k * x + phi); });
    const auto m = calcColumnMetrics("col", t, a, b);
    EXPECT_TRUE(nearScalar(m.rms, std::sqrt(c * c + 0.5 * B * B), 1e-12)) << k << " " << m.rms;
    EXPECT_TRUE(nearScalar(m.mean, c, 1e-12)) << k << " " << m.mean;
    // peak |b| = 60 at t = 0.25 (a grid point)
    EXPECT_TRUE(nearScalar(m.peak_ref, 60, 1e-14));
    EXPECT_TRUE(nearScalar(m.rms_rel, m.rms / 60, 1e-14));
    EXPECT_EQ(m.samples, 201);
    EXPECT_EQ(m.non_finite, 0);
  }
}

TEST(CompareMetrics, MaxAbsAndItsTime) {
  // d = B sin(2 pi t) peaks at t = 0.25 (grid point 50 of 201): max = B exactly there
  const auto t = grid(201);
  const auto b = sample(t, [](double) { return 2.0; });
  const auto a = sample(t, [](double x) { return 2.0 + 0.4 * std::sin(2 * kPi * x); });
  const auto m = calcColumnMetrics("col", t, a, b);
  EXPECT_TRUE(nearScalar(m.max_abs, 0.4, 1e-14));
  EXPECT_DOUBLE_EQ(m.t_max_abs, 0.25);
  EXPECT_TRUE(nearScalar(m.max_rel, 0.2, 1e-14));  // peak |b| = 2
  // rms of a sinusoid over one period: B / sqrt(2)
  EXPECT_TRUE(nearScalar(m.rms, 0.4 / std::sqrt(2.0), 1e-13));
}

TEST(CompareMetrics, SampleWeightingOnAPeriodicGrid) {
  // N points per period without the end point: the sample mean of sin^2 is exactly 1/2
  const int N = 64;
  std::vector<double> t(N);
  for (int i = 0; i < N; ++i) t[i] = static_cast<double>(i) / N;
  const auto b = sample(t, [](double) { return 1.0; });
  const auto a = sample(t, [](double x) { return 1.0 + 0.8 * std::cos(2 * kPi * 5 * x); });
  const auto m = calcColumnMetrics("col", t, a, b, {}, RmsWeighting::Samples);
  EXPECT_TRUE(nearScalar(m.rms, 0.8 / std::sqrt(2.0), 1e-13)) << m.rms;
}

TEST(CompareMetrics, NonUniformGridTrapezoidAgainstSamples) {
  // t = {0, 1, 3}, d = {0, 2, 0}: trapezoid weights {0.5, 1.5, 1}, so rms^2 = 1.5 * 4 / 3 = 2;
  // the plain sample mean gives 4 / 3
  const std::vector<double> t = {0, 1, 3}, b = {5, 5, 5}, a = {5, 7, 5};
  EXPECT_TRUE(nearScalar(calcColumnMetrics("c", t, a, b).rms, std::sqrt(2.0), 1e-15));
  EXPECT_TRUE(nearScalar(calcColumnMetrics("c", t, a, b, {}, RmsWeighting::Samples).rms, std::sqrt(4.0 / 3.0), 1e-15));
  // mean with the same weights: 1.5 * 2 / 3 = 1
  EXPECT_TRUE(nearScalar(calcColumnMetrics("c", t, a, b).mean, 1.0, 1e-15));
}

TEST(CompareMetrics, SingleSample) {
  const auto m = calcColumnMetrics("c", {0.5}, {3.0}, {1.0});
  EXPECT_DOUBLE_EQ(m.rms, 2.0);
  EXPECT_DOUBLE_EQ(m.max_abs, 2.0);
  EXPECT_DOUBLE_EQ(m.t_max_abs, 0.5);
  EXPECT_DOUBLE_EQ(m.peak_ref, 1.0);
}

TEST(CompareMetrics, ZeroReferenceUsesTheAbsoluteFloor) {
  const auto t = grid(11);
  const std::vector<double> zero(11, 0.0);
  // identical zeros: relative errors are 0, and the column passes even with no floor
  const auto same = calcColumnMetrics("locked", t, zero, zero, {0, 1e-3, 0, 1e-2});
  EXPECT_EQ(same.rms_rel, 0.0);
  EXPECT_EQ(same.max_rel, 0.0);
  EXPECT_EQ(same.usage, 0.0);
  EXPECT_TRUE(same.passed);
  // round-off against a zero reference: relative error infinite; passes only with an absolute floor
  const std::vector<double> tiny(11, 1e-13);
  const auto no_floor = calcColumnMetrics("locked", t, tiny, zero, {0, 1e-3, 0, 1e-2});
  EXPECT_TRUE(std::isinf(no_floor.rms_rel));
  EXPECT_FALSE(no_floor.passed);
  const auto floor = calcColumnMetrics("locked", t, tiny, zero, {1e-9, 1e-3, 1e-9, 1e-2});
  EXPECT_TRUE(floor.passed);
  EXPECT_TRUE(nearScalar(floor.usage, 1e-4, 1e-12));  // 1e-13 / 1e-9
}

TEST(CompareMetrics, ToleranceBoundaries) {
  // constant offset 0.5 against a reference of peak 10: rms = max = 0.5, rel = 0.05
  const auto t = grid(21);
  const std::vector<double> b(21, 10.0), a(21, 10.5);
  const auto at_limit = calcColumnMetrics("c", t, a, b, {0, 0.05, 0, 0.05});
  EXPECT_TRUE(nearScalar(at_limit.usage, 1.0, 1e-14));
  EXPECT_TRUE(at_limit.passed);  // equality passes
  const auto rms_too_big = calcColumnMetrics("c", t, a, b, {0, 0.0499, 0, 1});
  EXPECT_FALSE(rms_too_big.passed);
  EXPECT_GT(rms_too_big.usage, 1.0);
  const auto max_too_big = calcColumnMetrics("c", t, a, b, {0, 1, 0, 0.0499});
  EXPECT_FALSE(max_too_big.passed);
  // the absolute part adds to the relative part: 0.25 + 0.025 * 10 = 0.5
  EXPECT_TRUE(calcColumnMetrics("c", t, a, b, {0.25, 0.025, 0.25, 0.025}).passed);
  EXPECT_FALSE(calcColumnMetrics("c", t, a, b, {0.24, 0.025, 0.25, 0.025}).passed);
}

TEST(CompareMetrics, NonFiniteSamplesAreCountedAndFail) {
  const auto t = grid(5);
  std::vector<double> a = {1, 1, std::numeric_limits<double>::quiet_NaN(), 1, 1}, b(5, 1.0);
  const auto m = calcColumnMetrics("c", t, a, b, {1, 1, 1, 1});
  EXPECT_EQ(m.non_finite, 1);
  EXPECT_EQ(m.samples, 4);
  EXPECT_EQ(m.rms, 0.0);  // the finite samples agree
  EXPECT_FALSE(m.passed);
  // all non-finite: metrics NaN, fails
  const std::vector<double> nan(5, std::numeric_limits<double>::quiet_NaN());
  const auto all = calcColumnMetrics("c", t, nan, b);
  EXPECT_EQ(all.samples, 0);
  EXPECT_TRUE(std::isnan(all.rms));
  EXPECT_FALSE(all.passed);
}

TEST(CompareMetrics, BadInputThrows) {
  EXPECT_THROW(calcColumnMetrics("c", {0, 1}, {1}, {1, 2}), CompareError);
  EXPECT_THROW(calcColumnMetrics("c", {}, {}, {}), CompareError);
  EXPECT_THROW(calcColumnMetrics("c", {0, 1}, {1, 1}, {1, 1}, {-1, 0, 0, 0}), CompareError);
}

TEST(CompareMetrics, WorstColumnAndVerdict) {
  // three columns with offsets 0.01, 0.5, 0.1 on references of peak 1, 100, 1
  const auto t = grid(51);
  MatX A(51, 3), B(51, 3);
  for (int i = 0; i < 51; ++i) {
    B.row(i) << std::sin(2 * kPi * t[i]), 100 * std::cos(2 * kPi * t[i]), std::sin(4 * kPi * t[i]);
    A.row(i) = B.row(i);
    A(i, 0) += 0.01;
    A(i, 1) += 0.5;
    A(i, 2) += 0.1;
  }
  const Table a = makeTable("a", {"x", "y", "z"}, t, A);
  const Table b = makeTable("b", {"x", "y", "z"}, t, B);
  CompareOptions opt;
  opt.tolerance = {0, 0.05, 0, 0.2};
  const auto c = compareTables("cmp", a, "a", b, "b", opt);
  ASSERT_EQ(c.metrics.size(), 3u);
  // rel rms: 0.01, 0.005, 0.1 -> z is worst and fails the RMS tolerance (0.1 > 0.05)
  EXPECT_EQ(c.metrics[c.worst].name, "z");
  EXPECT_TRUE(c.metrics[0].passed);
  EXPECT_TRUE(c.metrics[1].passed);
  EXPECT_FALSE(c.metrics[2].passed);
  EXPECT_FALSE(c.passed);
  const auto rank = c.rankWorstFirst();
  EXPECT_EQ(c.metrics[rank[0]].name, "z");
  EXPECT_EQ(c.metrics[rank[1]].name, "x");
  EXPECT_EQ(c.metrics[rank[2]].name, "y");
  // a per-column tolerance lets z pass
  opt.column_tolerance["z"] = {0, 0.2, 0, 0.2};
  const auto c2 = compareTables("cmp", a, "a", b, "b", opt);
  EXPECT_TRUE(c2.passed);
  EXPECT_EQ(c2.metrics[2].tolerance.rms_rel, 0.2);
  EXPECT_EQ(c2.tolerance.rms_rel, 0.05);
  // a tolerance for an unknown column is warned about
  opt.column_tolerance["nope"] = {};
  const auto c3 = compareTables("cmp", a, "a", b, "b", opt);
  bool warned = false;
  for (const auto& w : c3.warnings) warned = warned || w.find("'nope'") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(CompareMetrics, MissingColumnsFailOnlyWhenAsked) {
  const auto t = grid(5);
  const Table a = makeTable("a", {"x", "y"}, t, MatX::Ones(5, 2));
  const Table b = makeTable("b", {"x"}, t, MatX::Ones(5, 1));
  CompareOptions opt;
  const auto c = compareTables("cmp", a, "a", b, "b", opt);
  EXPECT_TRUE(c.passed);
  ASSERT_EQ(c.only_in_a.size(), 1u);
  EXPECT_EQ(c.only_in_a[0], "y");
  EXPECT_TRUE(c.only_in_b.empty());
  opt.missing_columns_fail = true;
  EXPECT_FALSE(compareTables("cmp", a, "a", b, "b", opt).passed);
}

}  // namespace
}  // namespace redmax::validation
