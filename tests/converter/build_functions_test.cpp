// FunctionDesc -> core AxisFunction (converter/build/functions_to_core.hpp): every OpenSim function
// type against values worked out by hand from docs/opensim_compatibility.md §4, gradients and
// Hessians against central differences of the values (h = 1e-6, relative 1e-6 in nearRel's
// sense), and the errors (file:line and owner in the message).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "converter/build/functions_to_core.hpp"
#include "converter/signal/natural_spline.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::osim {
namespace {

constexpr double kH = 1e-6;
constexpr double kFdTol = 1e-6;

FunctionDesc desc(FunctionKind kind, const char* type) {
  FunctionDesc f;
  f.kind = kind;
  f.type = f.written_type = type;
  f.line = 42;
  return f;
}

AxisFunctionPtr make(const FunctionDesc& f, int n = 1) { return makeCoreFunction(f, n, "m.osim", "test"); }

double value(const AxisFunctionPtr& f, double x) { return f->value(VecJ::Constant(1, x)); }
double d1(const AxisFunctionPtr& f, double x) { return f->gradient(VecJ::Constant(1, x))[0]; }
double d2(const AxisFunctionPtr& f, double x) { return f->hessian(VecJ::Constant(1, x))(0, 0); }

// gradient and Hessian against central differences at x (any number of arguments)
void expectDerivativesMatchDifferences(const AxisFunctionPtr& f, const VecJ& x) {
  const int n = f->numArgs();
  FunctionValue v;
  f->evaluate(x, 2, v);
  VecJ g_fd(n);
  MatJ H_fd(n, n);
  for (int k = 0; k < n; ++k) {
    VecJ xp = x, xm = x;
    xp[k] += kH;
    xm[k] -= kH;
    g_fd[k] = (f->value(xp) - f->value(xm)) / (2 * kH);
    H_fd.col(k) = (f->gradient(xp) - f->gradient(xm)) / (2 * kH);
  }
  EXPECT_TRUE(nearRel(v.gradient, g_fd, kFdTol))
      << f->typeName() << " at " << x.transpose() << ": " << v.gradient.transpose() << " vs "
      << g_fd.transpose();
  EXPECT_TRUE(nearRel(v.hessian, H_fd, kFdTol))
      << f->typeName() << " at " << x.transpose() << ":\n" << v.hessian << "\nvs\n" << H_fd;
}

TEST(BuildFunctions, ConstantTakesTheCallersArgumentCount) {
  auto f = desc(FunctionKind::Constant, "Constant");
  f.value = 0.3;
  for (int n : {0, 1, 3}) {
    const AxisFunctionPtr c = make(f, n);
    EXPECT_EQ(c->numArgs(), n);
    FunctionValue v;
    c->evaluate(VecJ::Ones(n), 2, v);
    EXPECT_EQ(v.value, 0.3);
    EXPECT_TRUE(v.gradient.isZero(0.0));
    EXPECT_TRUE(v.hessian.isZero(0.0));
  }
}

TEST(BuildFunctions, LinearFunctionWithSeveralArguments) {
  auto f = desc(FunctionKind::Linear, "LinearFunction");
  f.coefficients = {2.0, -0.5, 0.25, 0.1};  // 2 x0 - 0.5 x1 + 0.25 x2 + 0.1
  const AxisFunctionPtr g = make(f, 3);
  EXPECT_NEAR(g->value(Vec3(1.0, 2.0, -4.0)), 2.0 - 1.0 - 1.0 + 0.1, 1e-15);
  expectDerivativesMatchDifferences(g, Vec3(0.3, -0.2, 0.7));
  EXPECT_THROW(make(f, 1), ConvertError);  // 3 slopes, 1 argument
}

TEST(BuildFunctions, PolynomialInDecreasingPowers) {
  auto f = desc(FunctionKind::Polynomial, "PolynomialFunction");
  f.coefficients = {0.5, -1.0, 2.0, 3.0};  // 0.5 x^3 - x^2 + 2 x + 3
  const AxisFunctionPtr p = make(f);
  const double x = 1.7;
  EXPECT_NEAR(value(p, x), 0.5 * x * x * x - x * x + 2 * x + 3, 1e-13);
  EXPECT_NEAR(d1(p, x), 1.5 * x * x - 2 * x + 2, 1e-13);
  EXPECT_NEAR(d2(p, x), 3 * x - 2, 1e-13);
}

TEST(BuildFunctions, SimmSplineInterpolatesAndExtrapolatesLinearly) {
  auto f = desc(FunctionKind::SimmSpline, "SimmSpline");
  f.x = {-1.0, -0.2, 0.4, 1.1, 2.0};
  f.y = {0.3, -0.5, 0.2, 0.9, 0.1};
  const AxisFunctionPtr s = make(f);
  for (size_t i = 0; i < f.x.size(); ++i) EXPECT_NEAR(value(s, f.x[i]), f.y[i], 1e-14);
  // outside: linear with the end slope, second derivative 0
  EXPECT_NEAR(value(s, 3.0), value(s, 2.0) + d1(s, 2.0) * 1.0, 1e-13);
  EXPECT_EQ(d2(s, 3.0), 0.0);
  for (double x : {-0.7, 0.0, 0.9, 1.6}) expectDerivativesMatchDifferences(s, VecJ::Constant(1, x));
}

TEST(BuildFunctions, GcvSplineIsTheNaturalInterpolatingSplineOfItsDegree) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int h = 1; h <= 4; ++h) {
    auto f = desc(FunctionKind::GCVSpline, "GCVSpline");
    f.half_order = h;
    double x = 0.0;
    for (int i = 0; i < 12; ++i) {
      x += 0.1 + 0.2 * std::abs(u(rng));
      f.x.push_back(x);
      f.y.push_back(std::sin(2 * x) + 0.1 * u(rng));
    }
    f.coefficients = {1e9, 1e9};  // stored coefficients are ignored, as OpenSim ignores them
    const AxisFunctionPtr s = make(f);
    const signal::NaturalSpline ref(2 * h - 1, f.x, f.y);
    for (size_t i = 0; i < f.x.size(); ++i) EXPECT_NEAR(value(s, f.x[i]), f.y[i], 1e-12) << h;
    for (double t : {f.x[0] - 0.3, 0.5 * (f.x[3] + f.x[4]), f.x.back() + 0.2}) {
      EXPECT_NEAR(value(s, t), ref.calcValue(t), 1e-14);
      EXPECT_NEAR(d1(s, t), ref.calcDerivative(1, t), 1e-12);
      EXPECT_NEAR(d2(s, t), ref.calcDerivative(2, t), 1e-10);
    }
    // the cubic and higher ones are C2: the Hessian is the derivative of the gradient
    if (h >= 2) expectDerivativesMatchDifferences(s, VecJ::Constant(1, 0.5 * (f.x[5] + f.x[6])));
  }
  auto smooth = desc(FunctionKind::GCVSpline, "GCVSpline");
  smooth.half_order = 2;
  smooth.x = {0, 1, 2, 3, 4};
  smooth.y = {0, 1, 0, 1, 0};
  smooth.error_variance = 0.01;
  EXPECT_THROW(make(smooth), ConvertError);  // smoothing is not reproduced
}

TEST(BuildFunctions, MultiplierScalesItsFunctionAndPassesArguments) {
  auto inner = desc(FunctionKind::SimmSpline, "SimmSpline");
  inner.x = {0.0, 1.0, 2.0, 3.0};
  inner.y = {0.0, 0.5, 0.2, 1.0};
  auto f = desc(FunctionKind::Multiplier, "MultiplierFunction");
  f.scale = -2.5;
  f.inner = {inner};
  const AxisFunctionPtr m = make(f), s = make(inner);
  EXPECT_NEAR(value(m, 1.3), -2.5 * value(s, 1.3), 1e-15);
  EXPECT_NEAR(d2(m, 1.3), -2.5 * d2(s, 1.3), 1e-13);
  // a Multiplier of a Constant takes as many arguments as the caller gives
  auto c = desc(FunctionKind::Constant, "Constant");
  c.value = 0.4;
  f.inner = {c};
  const AxisFunctionPtr mc = make(f, 2);
  EXPECT_EQ(mc->numArgs(), 2);
  EXPECT_NEAR(mc->value(Vec2(1.0, 1.0)), -1.0, 1e-15);
}

TEST(BuildFunctions, PiecewiseLinearFollowsOpenSimsRules) {
  auto f = desc(FunctionKind::PiecewiseLinear, "PiecewiseLinearFunction");
  f.x = {0.0, 1.0, 3.0, 4.0};
  f.y = {1.0, 3.0, 2.0, 2.5};
  const AxisFunctionPtr p = make(f);
  EXPECT_NEAR(value(p, 0.5), 2.0, 1e-15);
  EXPECT_NEAR(d1(p, 0.5), 2.0, 1e-15);
  EXPECT_NEAR(value(p, 2.0), 2.5, 1e-15);
  EXPECT_NEAR(d1(p, 2.0), -0.5, 1e-15);
  // extrapolation with the end slopes; the last slope is the last segment's
  EXPECT_NEAR(value(p, -1.0), -1.0, 1e-15);
  EXPECT_NEAR(value(p, 5.0), 3.0, 1e-15);
  EXPECT_NEAR(d1(p, 5.0), 0.5, 1e-15);
  // at the ends (within 2e-13): the end value and end slope
  EXPECT_EQ(value(p, 4.0 - 1e-13), 2.5);
  EXPECT_EQ(d1(p, 0.0), 2.0);
  EXPECT_EQ(d2(p, 2.0), 0.0);
  // a zero-length interval uses OpenSim's 1e-7 floor instead of dividing by zero
  f.x = {0.0, 1.0, 1.0, 2.0};
  f.y = {0.0, 1.0, 1.0 + 1e-8, 2.0};
  EXPECT_NEAR(make(f)->gradient(VecJ::Constant(1, 0.5))[0], 1.0, 1e-15);
  f.x = {0.0};
  f.y = {1.0};
  EXPECT_THROW(make(f), ConvertError);  // one point has no slope (OpenSim would read garbage)
}

TEST(BuildFunctions, PiecewiseConstantTakesTheLeftKnot) {
  auto f = desc(FunctionKind::PiecewiseConstant, "PiecewiseConstantFunction");
  f.x = {0.0, 1.0, 2.0};
  f.y = {5.0, 6.0, 7.0};
  const AxisFunctionPtr p = make(f);
  EXPECT_EQ(value(p, -3.0), 5.0);
  EXPECT_EQ(value(p, 0.5), 5.0);
  EXPECT_EQ(value(p, 1.5), 6.0);
  EXPECT_EQ(value(p, 2.0), 7.0);
  EXPECT_EQ(value(p, 9.0), 7.0);
  EXPECT_EQ(d1(p, 1.5), 0.0);
}

TEST(BuildFunctions, SineAndItsDerivatives) {
  auto f = desc(FunctionKind::Sine, "Sine");
  f.amplitude = 1.5;
  f.omega = 2.0;
  f.phase = 0.3;
  f.offset = -0.2;
  const AxisFunctionPtr s = make(f);
  const double x = 0.7;
  EXPECT_NEAR(value(s, x), 1.5 * std::sin(2 * x + 0.3) - 0.2, 1e-15);
  EXPECT_NEAR(d1(s, x), 3.0 * std::cos(2 * x + 0.3), 1e-14);
  EXPECT_NEAR(d2(s, x), -6.0 * std::sin(2 * x + 0.3), 1e-14);
}

TEST(BuildFunctions, StepIsTheQuinticSmoothstep) {
  auto f = desc(FunctionKind::Step, "StepFunction");
  f.start_time = 1.0;
  f.end_time = 3.0;
  f.start_value = 2.0;
  f.end_value = -1.0;
  const AxisFunctionPtr s = make(f);
  EXPECT_EQ(value(s, 0.5), 2.0);
  EXPECT_EQ(value(s, 3.5), -1.0);
  EXPECT_NEAR(value(s, 2.0), 0.5, 1e-15);  // the midpoint
  const double t = 0.25;                    // x = 1.5
  EXPECT_NEAR(value(s, 1.5), 2.0 - 3.0 * (10 * t * t * t - 15 * t * t * t * t + 6 * std::pow(t, 5)),
              1e-15);
  for (double x : {1.2, 2.0, 2.9}) expectDerivativesMatchDifferences(s, VecJ::Constant(1, x));
  // C2 at the ends: first and second derivatives vanish there
  EXPECT_NEAR(d1(s, 1.0 + 1e-9), 0.0, 1e-12);
  EXPECT_NEAR(d2(s, 3.0 - 1e-9), 0.0, 1e-6);
  f.end_time = f.start_time;
  EXPECT_THROW(make(f), ConvertError);
}

TEST(BuildFunctions, MultivariatePolynomialUsesOpenSimsMonomialOrder) {
  // dimension 2, order 2: 1, y, y^2, x, x y, x^2 (argument 0 = x outermost)
  auto f = desc(FunctionKind::MultivariatePolynomial, "MultivariatePolynomialFunction");
  f.dimension = 2;
  f.order = 2;
  f.coefficients = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
  const AxisFunctionPtr p = make(f, 2);
  const double x = 0.7, y = -1.3;
  EXPECT_NEAR(p->value(Vec2(x, y)), 1 + 2 * y + 3 * y * y + 4 * x + 5 * x * y + 6 * x * x, 1e-14);
  expectDerivativesMatchDifferences(p, Vec2(x, y));
  // three arguments, order 3 (20 monomials)
  f.dimension = 3;
  f.order = 3;
  f.coefficients.clear();
  for (int i = 0; i < 20; ++i) f.coefficients.push_back(0.1 * (i + 1) * (i % 3 == 0 ? -1 : 1));
  const AxisFunctionPtr q = make(f, 3);
  expectDerivativesMatchDifferences(q, Vec3(0.4, -0.6, 1.1));
  // the last monomial is x^3: coefficient 20 * 0.1 = 2
  f.coefficients.assign(20, 0.0);
  f.coefficients.back() = 2.0;
  EXPECT_NEAR(make(f, 3)->value(Vec3(1.5, 7.0, 9.0)), 2.0 * 1.5 * 1.5 * 1.5, 1e-14);
  f.coefficients.pop_back();
  EXPECT_THROW(make(f, 3), ConvertError);
}

TEST(BuildFunctions, ErrorsNameFileLineAndOwner) {
  auto e = desc(FunctionKind::ExpressionBased, "ExpressionBasedFunction");
  e.expression = "2*x";
  try {
    makeCoreFunction(e, 1, "dir/model.osim", "CustomJoint 'knee' rotation1");
    FAIL() << "ExpressionBasedFunction was accepted";
  } catch (const ConvertError& err) {
    const std::string w = err.what();
    EXPECT_NE(w.find("dir/model.osim:42"), std::string::npos) << w;
    EXPECT_NE(w.find("CustomJoint 'knee' rotation1"), std::string::npos) << w;
    EXPECT_NE(w.find("ExpressionBasedFunction"), std::string::npos) << w;
  }
  // bad data from the file: a SimmSpline with decreasing x
  auto s = desc(FunctionKind::SimmSpline, "SimmSpline");
  s.x = {0.0, 2.0, 1.0};
  s.y = {0.0, 1.0, 2.0};
  try {
    makeCoreFunction(s, 1, "m.osim", "owner");
    FAIL() << "decreasing x was accepted";
  } catch (const ConvertError& err) {
    EXPECT_EQ(err.line(), 42);
    EXPECT_NE(std::string(err.what()).find("SimmSpline"), std::string::npos) << err.what();
  }
  // a one-argument type given two arguments
  auto sine = desc(FunctionKind::Sine, "Sine");
  EXPECT_THROW(makeCoreFunction(sine, 2, "m.osim", "owner"), ConvertError);
  EXPECT_THROW(makeCoreFunction(sine, 7, "m.osim", "owner"), ConvertError);
}

}  // namespace
}  // namespace redmax::osim
