// External-load time interpolation (converter/signal/load_interpolant.hpp): OpenSim's choice by
// row count (constant, PiecewiseLinearFunction, natural cubic) and the PiecewiseLinearFunction
// rules (slopes with max(1e-7, dx), repeated last slope, end tolerance 2e-13, bisection).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "converter/signal/load_interpolant.hpp"

namespace redmax::signal {
namespace {

TEST(SignalLoad, OneRowIsConstant) {
  const LoadInterpolant f(std::vector<double>{0.7}, std::vector<double>{12.5});
  EXPECT_EQ(f.kind(), LoadInterpolant::Kind::Constant);
  for (double t : {-5.0, 0.7, 3.0}) {
    EXPECT_EQ(f.calcValue(t), 12.5);
    EXPECT_EQ(f.calcDerivative(1, t), 0.0);
    EXPECT_EQ(f.calcDerivative(2, t), 0.0);
  }
}

TEST(SignalLoad, TwoAndThreeRowsArePiecewiseLinear) {
  // two rows: one segment; the last slope repeats it; linear extrapolation both sides
  const LoadInterpolant two(std::vector<double>{1.0, 2.0}, std::vector<double>{3.0, 7.0});
  EXPECT_EQ(two.kind(), LoadInterpolant::Kind::PiecewiseLinear);
  EXPECT_DOUBLE_EQ(two.calcValue(1.25), 4.0);
  EXPECT_DOUBLE_EQ(two.calcValue(0.0), -1.0);
  EXPECT_DOUBLE_EQ(two.calcValue(3.0), 11.0);
  EXPECT_EQ(two.calcDerivative(1, 1.5), 4.0);
  EXPECT_EQ(two.calcDerivative(1, -10.0), 4.0);
  EXPECT_EQ(two.calcDerivative(2, 1.5), 0.0);

  // three rows: slopes 2 and -1; the last slope (used to the right) repeats -1
  const std::vector<double> x = {0.0, 1.0, 3.0}, y = {0.0, 2.0, 0.0};
  const LoadInterpolant three(x, y);
  EXPECT_EQ(three.kind(), LoadInterpolant::Kind::PiecewiseLinear);
  EXPECT_DOUBLE_EQ(three.calcValue(0.5), 1.0);
  EXPECT_DOUBLE_EQ(three.calcValue(2.0), 1.0);
  EXPECT_DOUBLE_EQ(three.calcValue(4.0), -1.0);
  EXPECT_DOUBLE_EQ(three.calcValue(-1.0), -2.0);
  EXPECT_EQ(three.calcDerivative(1, 0.5), 2.0);
  EXPECT_EQ(three.calcDerivative(1, 2.0), -1.0);
  EXPECT_EQ(three.calcDerivative(1, 5.0), -1.0);
  // at the interior knot OpenSim's bisection stops on the segment to its right
  EXPECT_EQ(three.calcDerivative(1, 1.0), -1.0);
  EXPECT_EQ(three.calcValue(1.0), 2.0);
  // within 2e-13 of an end: end value and end slope
  EXPECT_EQ(three.calcValue(3.0 - 1e-13), 0.0);
  EXPECT_EQ(three.calcDerivative(1, 1e-13), 2.0);
}

// a repeated time: the slope divides by 1e-7 rather than 0, as OpenSim's PiecewiseLinearFunction
TEST(SignalLoad, RepeatedTimeUsesTinyWidth) {
  const PiecewiseLinear f(std::vector<double>{0.0, 0.0, 1.0}, std::vector<double>{1.0, 2.0, 2.0});
  EXPECT_DOUBLE_EQ(f.calcDerivative(1, -1.0), 1.0 / 1e-7);
  EXPECT_EQ(f.calcDerivative(1, 0.5), 0.0);
  EXPECT_EQ(f.calcValue(0.5), 2.0);
}

// four or more rows: the natural cubic (GCVSpline degree 3, error variance 0), linear outside
TEST(SignalLoad, FourRowsOrMoreAreNaturalCubics) {
  std::mt19937 rng(21);
  std::normal_distribution<double> nd;
  for (int n : {4, 5, 60}) {
    std::vector<double> t(n), v(n);
    for (int i = 0; i < n; ++i) {
      t[i] = 0.3 + i / 600.0;
      v[i] = 500 * nd(rng);
    }
    const LoadInterpolant f(t, v);
    EXPECT_EQ(f.kind(), LoadInterpolant::Kind::NaturalCubic);
    const NaturalSpline s(3, t, v);
    for (int i = 0; i < n; ++i) EXPECT_NEAR(f.calcValue(t[i]), v[i], 1e-12 * 2000);
    for (double tt = t.front() - 0.01; tt < t.back() + 0.01; tt += 0.0007) {
      EXPECT_EQ(f.calcValue(tt), s.calcValue(tt));
      EXPECT_EQ(f.calcDerivative(1, tt), s.calcDerivative(1, tt));
    }
    // linear outside: zero second derivative, constant slope
    EXPECT_EQ(f.calcDerivative(2, t.back() + 0.5), 0.0);
    EXPECT_EQ(f.calcDerivative(1, t.front() - 0.5), f.calcDerivative(1, t.front() - 0.1));
  }
}

TEST(SignalLoad, RejectsBadInput) {
  EXPECT_THROW(LoadInterpolant(std::vector<double>{}, std::vector<double>{}), SignalError);
  EXPECT_THROW(LoadInterpolant(std::vector<double>{0, 1}, std::vector<double>{0}), SignalError);
  EXPECT_THROW(LoadInterpolant(std::vector<double>{1, 0}, std::vector<double>{0, 1}), SignalError);
  EXPECT_THROW(LoadInterpolant(std::vector<double>{0, 1, NAN}, std::vector<double>{0, 1, 2}), SignalError);
  // the cubic needs strictly increasing times (GCVSPL's ier = 2)
  EXPECT_THROW(LoadInterpolant(std::vector<double>{0, 1, 1, 2}, std::vector<double>{0, 1, 2, 3}), SignalError);
  EXPECT_THROW(LoadInterpolant().calcDerivative(-1, 0.0), SignalError);
}

// a real ground-reaction file (set E): the cubic passes through every sample of every column
TEST(SignalLoad, ThroughRealGroundReactionData) {
  const std::filesystem::path path =
      std::filesystem::path(REDMAX_SHARED_DIR) / "opensim/opensim-models/Pipelines/Gait2392_Simbody/subject01_walk1_grf.mot";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared OpenSim data not found: " << path;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("endheader", 0) == 0) break;
  std::getline(in, line);  // labels
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::istringstream rs(line);
    std::vector<double> r;
    for (double v; rs >> v;) r.push_back(v);
    if (!r.empty()) rows.push_back(r);
  }
  ASSERT_GT(rows.size(), 100u);
  const size_t nc = rows[0].size();
  std::vector<double> t;
  for (const auto& r : rows) t.push_back(r[0]);
  for (size_t c = 1; c < nc; ++c) {
    std::vector<double> v;
    double scale = 0;
    for (const auto& r : rows) {
      v.push_back(r[c]);
      scale = std::max(scale, std::abs(r[c]));
    }
    const LoadInterpolant f(t, v);
    ASSERT_EQ(f.kind(), LoadInterpolant::Kind::NaturalCubic);
    for (size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(f.calcValue(t[i]), v[i], 1e-12 * (1 + scale)) << "column " << c;
  }
}

}  // namespace
}  // namespace redmax::signal
