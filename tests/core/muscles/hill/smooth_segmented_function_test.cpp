// OpenSim's quintic-Bezier curves (SmoothSegmentedFunctionFactory) against Millard 2013's curve
// properties, computed here: the values and slopes each curve is built to pass through, C1
// joins between its segments, linear extrapolation, the Bezier evaluated by de Casteljau's
// construction, and every derivative against central differences.
#include "core/muscles/hill/smooth_segmented_function.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/muscles/hill/parameters.hpp"
#include "tests/core/muscles/hill/hill_test_util.hpp"

namespace redmax::hill {
namespace {

using test::centralDifference;

// de Casteljau: repeated linear interpolation (independent of the Bernstein sum)
double deCasteljau(double u, std::array<double, 6> p) {
  for (int n = 5; n > 0; --n)
    for (int k = 0; k < n; ++k) p[k] = (1 - u) * p[k] + u * p[k + 1];
  return p[0];
}

// the defaults of Millard2012EquilibriumMuscle's curves (damped model: minimum value 0, slopes
// at v_max 0)
SmoothSegmentedFunction fal() { return makeFiberActiveForceLengthCurve(0.4441, 0.73, 1.0, 1.8123, 0.0, 0.8616, 1.0); }
SmoothSegmentedFunction fv() { return makeFiberForceVelocityCurve(1.4, 0.0, 0.25, 5.0, 0.0, 0.15, 0.6, 0.9); }
SmoothSegmentedFunction fvInv() {
  return makeFiberForceVelocityInverseCurve(1.4, 0.125, 0.25, 5.0, 0.075, 0.15, 0.6, 0.9);
}
SmoothSegmentedFunction fpe() { return makeFiberForceLengthCurve(0.0, 0.7, 0.2, 2.0 / 0.7, 0.75); }
SmoothSegmentedFunction fse() { return makeTendonForceLengthCurve(0.049, 1.375 / 0.049, 2.0 / 3.0, 0.5); }

TEST(SmoothSegmentedFunction, BezierMatchesDeCasteljau) {
  const std::array<double, 6> p = {0.3, -1.0, 2.0, 0.5, 4.0, 1.5};
  double worst = 0;
  for (double u = 0; u <= 1.0; u += 0.0625) {
    worst = std::max(worst, std::abs(quinticBezier(u, p) - deCasteljau(u, p)));
    const double fd1 = centralDifference([&](double x) { return deCasteljau(x, p); }, u, 1e-6);
    worst = std::max(worst, std::abs(quinticBezier(u, p, 1) - fd1) / 10);
  }
  EXPECT_LE(worst, 1e-8);
  EXPECT_EQ(quinticBezier(0, p), 0.3);
  EXPECT_EQ(quinticBezier(1, p), 1.5);
}

TEST(SmoothSegmentedFunction, CornersPassThroughTheirEndsWithTheirSlopes) {
  // a corner from (0, 0) slope 0 to (1, 2) slope 5, curviness scaled as OpenSim does
  const QuinticBezierSegment s = quinticBezierCorner(0, 0, 0, 1, 2, 5, scaleCurviness(0.5));
  EXPECT_EQ(s.x[0], 0.0);
  EXPECT_EQ(s.y[5], 2.0);
  // end slopes: the first and last control legs lie on the tangent lines
  EXPECT_NEAR((s.y[1] - s.y[0]) / (s.x[1] - s.x[0]), 0.0, 1e-15);
  EXPECT_NEAR((s.y[5] - s.y[4]) / (s.x[5] - s.x[4]), 5.0, 1e-12);
  // the tangents meet at C = (0.6, 0); the inner points sit at 0.1 + 0.8 c of the way to C
  EXPECT_NEAR(s.x[1], 0.5 * 0.6, 1e-15);
  EXPECT_NEAR(s.x[3], 1 + 0.5 * (0.6 - 1), 1e-15);
  // an impossible corner (parallel tangents whose meeting point lies beyond the chord) is refused
  EXPECT_THROW(quinticBezierCorner(0, 0, -1, 1, 1, -1, 0.5), MuscleModelError);
}

TEST(SmoothSegmentedFunction, ActiveForceLengthHasMillardsProperties) {
  const auto f = fal();
  // 1 at the optimal length with zero slope (the plateau's corner)
  EXPECT_NEAR(f.value(1.0), 1.0, 1e-14);
  EXPECT_NEAR(f.derivative(1.0), 0.0, 1e-12);
  // the minimum value (0) outside [min, max] active length, and flat there
  EXPECT_EQ(f.value(0.3), 0.0);
  EXPECT_EQ(f.value(2.0), 0.0);
  EXPECT_NEAR(f.value(0.4441), 0.0, 1e-15);
  EXPECT_NEAR(f.value(1.8123), 0.0, 1e-15);
  // below 1 everywhere else, above 0 inside
  for (double l = 0.46; l < 1.8; l += 0.01) {
    EXPECT_LE(f.value(l), 1.0 + 1e-14) << l;
    EXPECT_GT(f.value(l), 0.0) << l;
  }
  // the shallow ascending limb: slope 0.8616 at its midpoint x1s = 0.73 + 0.5 (0.95 - 0.73)
  EXPECT_NEAR(f.derivative(0.73 + 0.5 * (0.95 - 0.73)), 0.8616, 1e-12);
  // a minimum value raises both ends
  EXPECT_NEAR(makeFiberActiveForceLengthCurve(0.4441, 0.73, 1, 1.8123, 0.1, 0.8616, 1).value(0.2), 0.1, 1e-15);
}

TEST(SmoothSegmentedFunction, ForceVelocityHasMillardsProperties) {
  const auto f = fv();
  // (x is solved to OpenSim's tolerance 100 eps, so y to about slope x 100 eps)
  EXPECT_NEAR(f.value(0.0), 1.0, 2e-13);         // isometric
  EXPECT_NEAR(f.derivative(0.0), 5.0, 1e-10);    // isometric slope
  EXPECT_NEAR(f.value(-1.0), 0.0, 1e-15);        // no force at v_max shortening
  EXPECT_NEAR(f.value(1.0), 1.4, 1e-14);         // fmaxE at v_max lengthening
  EXPECT_NEAR(f.derivative(-1.0), 0.0, 1e-12);
  EXPECT_EQ(f.value(-1.5), 0.0);                 // linear (flat) beyond
  EXPECT_EQ(f.value(1.5), 1.4);
  // the "near" points: -0.9 at 0.5 (near + at) slope x 0.1, 0.9 at fmaxE - 0.1 x same
  EXPECT_NEAR(f.value(-0.9), 0.5 * 0.25 * 0.1, 1e-14);
  EXPECT_NEAR(f.derivative(-0.9), 0.25, 1e-10);
  EXPECT_NEAR(f.value(0.9), 1.4 - 0.5 * 0.15 * 0.1, 1e-14);
  // the inverse undoes the (invertible) curve with the same corners
  const auto g = makeFiberForceVelocityCurve(1.4, 0.125, 0.25, 5.0, 0.075, 0.15, 0.6, 0.9);
  const auto gi = fvInv();
  for (double v = -0.99; v < 1.0; v += 0.0331) EXPECT_NEAR(gi.value(g.value(v)), v, 1e-12) << v;
  EXPECT_NEAR(gi.derivative(g.value(0.3)) * g.derivative(0.3), 1.0, 1e-10);
}

TEST(SmoothSegmentedFunction, PassiveAndTendonCurvesHaveMillardsProperties) {
  const auto p = fpe();
  EXPECT_EQ(p.value(0.9), 0.0);  // slack below 1 + strain_at_zero_force
  EXPECT_NEAR(p.value(1.0), 0.0, 1e-15);
  EXPECT_NEAR(p.value(1.7), 1.0, 1e-14);  // 1 at 1 + strain_at_one_norm_force
  EXPECT_NEAR(p.derivative(1.7), 2.0 / 0.7, 1e-10);
  EXPECT_NEAR(p.value(1.8), 1.0 + 0.1 * 2.0 / 0.7, 1e-13);  // linear beyond
  const auto t = fse();
  const double k = 1.375 / 0.049;
  EXPECT_EQ(t.value(0.99), 0.0);
  EXPECT_NEAR(t.value(1.0), 0.0, 1e-15);
  EXPECT_NEAR(t.derivative(1.0), 0.0, 1e-12);
  // the toe ends at force 2/3 on the line of slope k through (1.049, 1); linear from there
  const double x_toe = (2.0 / 3.0 - 1) / k + 1.049;
  EXPECT_NEAR(t.value(x_toe), 2.0 / 3.0, 1e-14);
  EXPECT_NEAR(t.derivative(x_toe), k, 1e-9);
  EXPECT_NEAR(t.value(1.049), 1.0, 1e-13);
  EXPECT_NEAR(t.derivative(1.06), k, 0);
  // monotone
  for (double x = 1.0; x < 1.06; x += 0.0005) EXPECT_GE(t.derivative(x), 0.0) << x;
}

TEST(SmoothSegmentedFunction, DerivativesMatchCentralDifferencesAndSegmentsJoinC1) {
  struct Case {
    const char* name;
    SmoothSegmentedFunction f;
    double lo, hi;
  };
  const Case cases[] = {{"fal", fal(), 0.3, 2.0},      {"fv", fv(), -1.2, 1.2},  {"fvInv", fvInv(), -0.1, 1.5},
                        {"fpe", fpe(), 0.9, 1.9},      {"fse", fse(), 0.98, 1.07}};
  for (const Case& c : cases) {
    double worst = 0;
    for (int i = 0; i <= 400; ++i) {
      const double x = c.lo + (c.hi - c.lo) * (i + 0.37) / 401.0;
      const double fd = centralDifference([&](double y) { return c.f.value(y); }, x, 1e-6);
      worst = std::max(worst, std::abs(c.f.derivative(x) - fd) / (1 + std::abs(fd)));
    }
    EXPECT_LE(worst, 2e-6) << c.name;  // measured: 1.1e-6 (fse, slope 28), the others below
    // value and slope continuous where segments meet
    for (size_t s = 0; s + 1 < c.f.segments().size(); ++s) {
      const double xj = c.f.segments()[s].x[5];
      EXPECT_NEAR(c.f.value(xj - 1e-10), c.f.value(xj + 1e-10), 1e-8) << c.name << " joint " << s;
      EXPECT_NEAR(c.f.derivative(xj - 1e-9), c.f.derivative(xj + 1e-9), 1e-5 * (1 + std::abs(c.f.derivative(xj))))
          << c.name << " joint " << s;
    }
  }
}

TEST(SmoothSegmentedFunction, RefusesParametersOpenSimRefuses) {
  const auto refuses = [](auto make, const std::string& property) {
    try {
      make();
    } catch (const MuscleParameterError& e) {
      return e.property() == property;
    }
    return false;
  };
  EXPECT_TRUE(refuses([] { return makeFiberActiveForceLengthCurve(0.8, 0.73, 1, 1.8, 0, 0.86, 1); },
                      "transition_norm_fiber_length"));
  EXPECT_TRUE(refuses([] { return makeFiberActiveForceLengthCurve(0.44, 0.73, 1, 0.9, 0, 0.86, 1); },
                      "max_norm_active_fiber_length"));
  EXPECT_TRUE(refuses([] { return makeFiberActiveForceLengthCurve(0.44, 0.73, 1, 1.8, 0, 5.0, 1); },
                      "shallow_ascending_slope"));
  EXPECT_TRUE(refuses([] { return makeFiberForceVelocityCurve(0.9, 0, 0.25, 5, 0, 0.15, 0.6, 0.9); },
                      "max_eccentric_velocity_force_multiplier"));
  EXPECT_TRUE(refuses([] { return makeFiberForceVelocityCurve(1.4, 0, 0.25, 0.5, 0, 0.15, 0.6, 0.9); },
                      "isometric_slope"));
  EXPECT_TRUE(refuses([] { return makeFiberForceVelocityCurve(1.4, 0, 0.25, 5, 0, 0.15, 1.6, 0.9); },
                      "concentric_curviness"));
  EXPECT_TRUE(refuses([] { return makeFiberForceLengthCurve(0.7, 0.6, 0.2, 3, 0.75); }, "strain_at_one_norm_force"));
  EXPECT_TRUE(refuses([] { return makeFiberForceLengthCurve(0, 0.7, 0.2, 1.0, 0.75); }, "stiffness_at_one_norm_force"));
  EXPECT_TRUE(refuses([] { return makeTendonForceLengthCurve(-0.049, 28, 0.66, 0.5); }, "strain_at_one_norm_force"));
  EXPECT_TRUE(refuses([] { return makeTendonForceLengthCurve(0.049, 28, 1.2, 0.5); }, "norm_force_at_toe_end"));
  EXPECT_TRUE(refuses([] { return makeTendonForceLengthCurve(0.049, 10, 0.66, 0.5); }, "stiffness_at_one_norm_force"));
  EXPECT_FALSE(refuses([] { return makeTendonForceLengthCurve(0.049, 28, 0.66, 0.5); }, "curviness"));
}

}  // namespace
}  // namespace redmax::hill
