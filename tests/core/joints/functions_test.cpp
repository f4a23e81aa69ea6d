// Axis functions: gradients and Hessians against finite differences; SimmSpline and the natural
// spline against splines built independently from their defining equations; OpenSim's endpoint
// and extrapolation rules; bad input.
#include "core/joints/functions.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <random>

#include "tests/core/joints/joint_test_util.hpp"

namespace redmax {
namespace {

using namespace redmax::test;

// gradient vs central differences of the value, Hessian vs central differences of the gradient
void expectDerivativesMatchFd(const AxisFunction& f, const VecJ& x) {
  const FunctionValue v = [&] {
    FunctionValue r;
    f.evaluate(x, 2, r);
    return r;
  }();
  ASSERT_EQ(v.gradient.size(), f.numArgs());
  ASSERT_EQ(v.hessian.rows(), f.numArgs());
  for (int i = 0; i < f.numArgs(); ++i) {
    VecJ xp = x, xm = x;
    xp[i] += kH;
    xm[i] -= kH;
    EXPECT_NEAR(v.gradient[i], (f.value(xp) - f.value(xm)) / (2 * kH), kFdTol * (1 + std::abs(v.gradient[i])))
        << f.typeName() << " at " << x.transpose();
    const VecJ dg = (f.gradient(xp) - f.gradient(xm)) / (2 * kH);
    EXPECT_TRUE(nearRel(VecJ(v.hessian.col(i)), dg, kFdTol)) << f.typeName() << " at " << x.transpose();
  }
}

// a piecewise cubic p_i(x) = a_i + b_i dx + c_i dx^2 + d_i dx^3, solved densely from its
// defining equations; `ends` adds the two end conditions as rows of (A, rhs)
struct DenseSpline {
  std::vector<double> x;
  VecX coef;  // 4 per piece
  double eval(double t, int order) const {
    const int n = static_cast<int>(x.size());
    int k = 0;
    while (k < n - 2 && t > x[k + 1]) ++k;
    const double dx = t - x[k];
    const double a = coef[4 * k], b = coef[4 * k + 1], c = coef[4 * k + 2], d = coef[4 * k + 3];
    if (order == 0) return a + dx * (b + dx * (c + dx * d));
    if (order == 1) return b + dx * (2 * c + 3 * d * dx);
    return 2 * c + 6 * d * dx;
  }
};

enum class Ends { NotAKnotThirdDerivative, Natural };

// third derivative of the cubic interpolating 4 points (6 x its leading coefficient)
double cubicThirdDerivative(const double* x, const double* y) {
  Eigen::Matrix4d V;
  Vec4 r;
  for (int i = 0; i < 4; ++i) {
    V.row(i) << 1, x[i], x[i] * x[i], x[i] * x[i] * x[i];
    r[i] = y[i];
  }
  return 6.0 * V.fullPivLu().solve(r)[3];
}

DenseSpline denseSpline(const std::vector<double>& x, const std::vector<double>& y, Ends ends) {
  const int n = static_cast<int>(x.size()), m = 4 * (n - 1);
  MatX A = MatX::Zero(m, m);
  VecX r = VecX::Zero(m);
  int row = 0;
  for (int i = 0; i < n - 1; ++i) {
    const double h = x[i + 1] - x[i];
    A(row, 4 * i) = 1;  // p_i(x_i) = y_i
    r[row++] = y[i];
    A.row(row).segment(4 * i, 4) << 1, h, h * h, h * h * h;  // p_i(x_{i+1}) = y_{i+1}
    r[row++] = y[i + 1];
    if (i + 1 < n - 1) {  // C1 and C2 at x_{i+1}
      A.row(row).segment(4 * i, 4) << 0, 1, 2 * h, 3 * h * h;
      A(row++, 4 * (i + 1) + 1) = -1;
      A.row(row).segment(4 * i, 4) << 0, 0, 2, 6 * h;
      A(row++, 4 * (i + 1) + 2) = -2;
    }
  }
  const double hl = x[n - 1] - x[n - 2];
  if (ends == Ends::Natural) {
    A(row++, 2) = 1;  // p_0''(x_0) = 0
    A.row(row++).segment(4 * (n - 2), 4) << 0, 0, 2, 6 * hl;  // p_last''(x_{n-1}) = 0
  } else {
    A(row, 3) = 6;  // p_0''' = third derivative of the cubic through the first four points
    r[row++] = cubicThirdDerivative(&x[0], &y[0]);
    A(row, 4 * (n - 2) + 3) = 6;
    r[row++] = cubicThirdDerivative(&x[n - 4], &y[n - 4]);
  }
  EXPECT_EQ(row, m);
  return DenseSpline{x, A.fullPivLu().solve(r)};
}

double val(const UnivariateFunction& f, double x, int order) {
  double v, d1, d2;
  f.evaluate1(x, v, d1, d2);
  return order == 0 ? v : order == 1 ? d1 : d2;
}

TEST(AxisFunctions, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(71);
  std::vector<AxisFunctionPtr> fs{
      std::make_shared<const ConstantFunction>(2.5, 2),
      std::make_shared<const LinearFunction>(std::vector<double>{0.5, -2.0, 1.5, 0.3}),
      std::make_shared<const PolynomialFunction>(std::vector<double>{0.2, -1.0, 0.5, 2.0, -0.7}),
      std::make_shared<const NaturalCubicSpline>(std::vector<double>{-1, -0.2, 0.5, 1.1, 2},
                                                 std::vector<double>{0.3, -0.4, 0.8, 0.1, 0.6}),
      std::make_shared<const SimmSpline>(std::vector<double>{-1, 1}, std::vector<double>{0.2, -0.6}),
      std::make_shared<const SimmSpline>(std::vector<double>{-1, 0.3, 1.4}, std::vector<double>{0.2, -0.6, 0.9}),
      std::make_shared<const SimmSpline>(std::vector<double>{-1.2, -0.5, 0.1, 0.9, 1.6},
                                         std::vector<double>{0.0, 0.4, -0.3, 0.5, 0.2})};
  fs.push_back(std::make_shared<const MultiplierFunction>(fs.back(), -1.7));
  fs.push_back(std::make_shared<const MultiplierFunction>(fs[1], 0.4));
  for (const auto& f : fs)
    for (int t = 0; t < 8; ++t) expectDerivativesMatchFd(*f, randomVecJ(f->numArgs(), rng, -2.5, 2.5));
}

TEST(AxisFunctions, LinearPolynomialConstantValues) {
  const LinearFunction lin(std::vector<double>{0.5, -2.0, 0.3});  // [slopes..., intercept]
  EXPECT_EQ(lin.numArgs(), 2);
  EXPECT_DOUBLE_EQ(lin.value(VecJ(Vec2(2.0, 1.0))), 0.5 * 2 - 2 * 1 + 0.3);
  const PolynomialFunction p({2.0, -3.0, 1.0});  // decreasing powers: 2x^2 - 3x + 1
  EXPECT_DOUBLE_EQ(val(p, 1.5, 0), 2 * 2.25 - 4.5 + 1);
  EXPECT_DOUBLE_EQ(val(p, 1.5, 1), 4 * 1.5 - 3);
  EXPECT_DOUBLE_EQ(val(p, 1.5, 2), 4.0);
  const ConstantFunction c(-0.25);
  EXPECT_EQ(c.numArgs(), 0);
  EXPECT_EQ(c.value(VecJ(0)), -0.25);
  const MultiplierFunction m(std::make_shared<const PolynomialFunction>(p), 3.0);
  EXPECT_DOUBLE_EQ(m.value(VecJ::Constant(1, 1.5)), 3 * val(p, 1.5, 0));
}

TEST(SimmSpline, TwoPointsIsALine) {
  const SimmSpline s({0.5, 2.0}, {1.0, -2.0});
  const double slope = -3.0 / 1.5;
  for (double x : {-1.0, 0.5, 0.9, 1.7, 2.0, 3.5}) {
    EXPECT_NEAR(val(s, x, 0), 1.0 + slope * (x - 0.5), 1e-15);
    EXPECT_NEAR(val(s, x, 1), slope, 1e-15);
    EXPECT_EQ(val(s, x, 2), 0.0);
  }
}

TEST(SimmSpline, ThreePointsIsTheParabola) {
  const std::vector<double> x{-1.0, 0.2, 1.5}, y{0.7, -0.4, 1.1};
  const SimmSpline s(x, y);
  // Lagrange form of the parabola through the three points
  auto L = [&](double t, int order) {
    double v = 0;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      const double den = (x[i] - x[j]) * (x[i] - x[k]);
      const double num = order == 0 ? (t - x[j]) * (t - x[k]) : order == 1 ? 2 * t - x[j] - x[k] : 2.0;
      v += y[i] * num / den;
    }
    return v;
  };
  for (double t : {-0.9, -0.3, 0.2, 0.6, 1.4}) {
    for (int o = 0; o < 3; ++o) EXPECT_NEAR(val(s, t, o), L(t, o), 1e-13) << t << " order " << o;
  }
  // outside: linear with the parabola's end slopes, zero second derivative
  EXPECT_NEAR(val(s, 2.5, 0), y[2] + L(1.5, 1) * 1.0, 1e-13);
  EXPECT_NEAR(val(s, -1.5, 0), y[0] - L(-1.0, 1) * 0.5, 1e-13);
  EXPECT_NEAR(val(s, -1.5, 1), L(-1.0, 1), 1e-13);
  EXPECT_EQ(val(s, 2.5, 2), 0.0);
}

TEST(SimmSpline, FivePointsMatchesForsytheMalcolmMolerEquations) {
  const std::vector<double> x{-1.2, -0.5, 0.1, 0.9, 1.6}, y{0.0, 0.4, -0.3, 0.5, 0.2};
  const SimmSpline s(x, y);
  const DenseSpline ref = denseSpline(x, y, Ends::NotAKnotThirdDerivative);
  for (double t : {-1.1, -0.8, -0.5, -0.2, 0.1, 0.4, 0.9, 1.2, 1.55}) {
    for (int o = 0; o < 3; ++o)
      EXPECT_NEAR(val(s, t, o), ref.eval(t, o), 1e-12 * (1 + std::abs(ref.eval(t, o)))) << t << " order " << o;
  }
  // knots are interpolated
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(val(s, x[i], 0), y[i], 1e-15);
  // outside: linear extrapolation with the end slopes, second derivative 0
  const double b0 = ref.eval(x[0], 1), bn = ref.eval(x[4], 1);
  EXPECT_NEAR(val(s, -2.0, 0), y[0] + (-2.0 - x[0]) * b0, 1e-12);
  EXPECT_NEAR(val(s, 2.3, 0), y[4] + (2.3 - x[4]) * bn, 1e-12);
  EXPECT_NEAR(val(s, 2.3, 1), bn, 1e-12);
  EXPECT_EQ(val(s, -2.0, 2), 0.0);
  EXPECT_EQ(val(s, 2.3, 2), 0.0);
}

TEST(SimmSpline, EndpointRuleWithin2e13) {
  const std::vector<double> x{0.0, 0.5, 1.0, 1.5, 2.0}, y{0.3, 0.9, -0.2, 0.4, 1.0};
  const SimmSpline s(x, y);
  const DenseSpline ref = denseSpline(x, y, Ends::NotAKnotThirdDerivative);
  // just inside an end: the end value exactly, the end slope and the end second derivative
  EXPECT_EQ(val(s, 1e-13, 0), y[0]);
  EXPECT_NEAR(val(s, 1e-13, 1), ref.eval(0.0, 1), 1e-12);
  EXPECT_NEAR(val(s, 1e-13, 2), ref.eval(0.0, 2), 1e-12);
  EXPECT_EQ(val(s, 2.0 - 1e-13, 0), y[4]);
  EXPECT_NEAR(val(s, 2.0 - 1e-13, 2), ref.eval(2.0, 2), 1e-12);
  // beyond 2e-13 inside, the polynomial (differs from y_end by slope * dx)
  EXPECT_NE(val(s, 3e-13, 0), y[0]);
  // just outside: extrapolation, second derivative 0
  EXPECT_EQ(val(s, -1e-13, 2), 0.0);
}

TEST(NaturalCubicSpline, MatchesNaturalEndEquations) {
  const std::vector<double> x{-1.0, -0.2, 0.5, 1.1, 2.0}, y{0.3, -0.4, 0.8, 0.1, 0.6};
  const NaturalCubicSpline s(x, y);
  const DenseSpline ref = denseSpline(x, y, Ends::Natural);
  for (double t : {-0.9, -0.2, 0.0, 0.5, 0.8, 1.1, 1.9}) {
    for (int o = 0; o < 3; ++o)
      EXPECT_NEAR(val(s, t, o), ref.eval(t, o), 1e-12 * (1 + std::abs(ref.eval(t, o)))) << t << " order " << o;
  }
  EXPECT_NEAR(val(s, x[0], 2), 0.0, 1e-13);
  EXPECT_NEAR(val(s, x[4], 2), 0.0, 1e-13);
  EXPECT_NEAR(val(s, 3.0, 0), y[4] + 1.0 * ref.eval(x[4], 1), 1e-12);
  EXPECT_NEAR(val(s, -2.0, 1), ref.eval(x[0], 1), 1e-12);
  EXPECT_EQ(val(s, -2.0, 2), 0.0);
  const NaturalCubicSpline line({0, 2}, {1, 5});
  EXPECT_NEAR(val(line, 3.0, 0), 7.0, 1e-15);
}

TEST(AxisFunctions, BadInputThrows) {
  EXPECT_THROW(SimmSpline({0.0}, {1.0}), JointError);
  EXPECT_THROW(SimmSpline({0.0, 1.0, 2.0}, {1.0, 2.0}), JointError);
  EXPECT_THROW(SimmSpline({0.0, 2.0, 1.0}, {1.0, 2.0, 3.0}), JointError);
  EXPECT_THROW(SimmSpline({0.0, std::nan(""), 1.0}, {1.0, 2.0, 3.0}), JointError);
  EXPECT_NO_THROW(SimmSpline({0.0, 1.0, 1.0, 2.0}, {0.0, 1.0, 1.0, 0.0}));  // OpenSim's 1e-7 floor
  EXPECT_THROW(NaturalCubicSpline({0.0, 1.0, 1.0}, {1.0, 2.0, 3.0}), JointError);
  EXPECT_THROW(LinearFunction(std::vector<double>{}), JointError);
  EXPECT_THROW(LinearFunction(std::vector<double>(8, 1.0)), JointError);
  EXPECT_THROW(PolynomialFunction({}), JointError);
  EXPECT_THROW(MultiplierFunction(nullptr, 2.0), JointError);
  EXPECT_THROW(ConstantFunction(1.0, 7), JointError);
}

}  // namespace
}  // namespace redmax
