// Natural interpolating splines of odd degree (converter/signal/natural_spline.hpp): analytic
// natural splines reproduced exactly, interpolation, derivatives against central differences,
// continuity, natural end conditions and extrapolation degree.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "converter/signal/natural_spline.hpp"

namespace redmax::signal {
namespace {

// strictly increasing, mildly non-uniform abscissae starting at x0, steps in [0.5, 1.5]*h
std::vector<double> randomKnots(int n, std::mt19937& rng, double h = 0.1, double x0 = -0.3) {
  std::uniform_real_distribution<double> step(0.5 * h, 1.5 * h);
  std::vector<double> x(n);
  x[0] = x0;
  for (int i = 1; i < n; ++i) x[i] = x[i - 1] + step(rng);
  return x;
}

double maxAbs(const std::vector<double>& v) {
  double m = 0;
  for (double a : v) m = std::max(m, std::abs(a));
  return m;
}

// analytic natural spline of degree 2m-1 with knots xi:
//   s(x) = sum_i alpha_i |x - xi_i|^(2m-1) + sum_k beta_k x^k  (k < m),
// with sum_i alpha_i xi_i^k = 0 for k < m: it is C^(2m-2), of degree 2m-1 between knots, and of
// degree m-1 outside [xi_1, xi_n] (the classic representation of natural splines)
struct AnalyticNaturalSpline {
  using VecL = Eigen::Matrix<long double, Eigen::Dynamic, 1>;
  using MatL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  int m;
  std::vector<double> xi;
  VecL alpha, beta;

  AnalyticNaturalSpline(int m_in, std::vector<double> knots, std::mt19937& rng) : m(m_in), xi(std::move(knots)) {
    const int n = static_cast<int>(xi.size());
    std::normal_distribution<double> nd;
    VecL a(n);
    for (int i = 0; i < n; ++i) a[i] = nd(rng);
    // project onto the null space of the moment conditions V^T alpha = 0, in long double: a
    // violation would add |x|^(2m-1-k) growth outside the data and spoil the reference there
    MatL V(n, m);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < m; ++k) V(i, k) = std::pow(static_cast<long double>(xi[i]), k);
    const Eigen::HouseholderQR<MatL> qr(V);
    const MatL Q = qr.householderQ() * MatL::Identity(n, m);
    alpha = a - Q * (Q.transpose() * a);
    beta.resize(m);
    for (int k = 0; k < m; ++k) beta[k] = nd(rng);
  }

  // d-th derivative, summed in long double so that the reference is more accurate than the fit
  double eval(double x, int d) const {
    const int p = 2 * m - 1;
    long double s = 0;
    for (size_t i = 0; i < xi.size() && d <= p; ++i) {
      const long double r = static_cast<long double>(x) - xi[i];
      // d^d/dx^d |r|^p = p!/(p-d)! |r|^(p-d) sign(r)^d
      long double f = 1;
      for (int k = 0; k < d; ++k) f *= p - k;
      const long double sg = (d % 2 == 0) ? 1.0L : (r >= 0 ? 1.0L : -1.0L);
      s += alpha[i] * f * std::pow(std::abs(r), static_cast<long double>(p - d)) * sg;
    }
    for (int k = d; k < m; ++k) {
      long double f = 1;
      for (int j = 0; j < d; ++j) f *= k - j;
      s += beta[k] * f * std::pow(static_cast<long double>(x), static_cast<long double>(k - d));
    }
    return static_cast<double>(s);
  }
};

TEST(SignalSpline, RejectsBadInput) {
  const std::vector<double> x = {0, 1, 2, 3, 4, 5}, y = {0, 1, 0, 1, 0, 1};
  EXPECT_THROW(NaturalSpline(4, x, y), SignalError);                        // even degree
  EXPECT_THROW(NaturalSpline(9, x, y), SignalError);                        // m = 5 not supported
  EXPECT_THROW(NaturalSpline(7, x, y), SignalError);                        // 6 < 2m = 8 points
  EXPECT_THROW(NaturalSpline(5, std::vector<double>{0, 1, 2, 3, 4}, std::vector<double>{0, 1, 2, 3, 4}),
               SignalError);  // 5 < 6 points
  EXPECT_THROW(NaturalSpline(3, x, std::vector<double>{0, 1, 2}), SignalError);  // size mismatch
  EXPECT_THROW(NaturalSpline(3, std::vector<double>{0, 1, 1, 2}, std::vector<double>{0, 1, 2, 3}), SignalError);
  EXPECT_THROW(NaturalSpline(3, std::vector<double>{0, 2, 1, 3}, std::vector<double>{0, 1, 2, 3}), SignalError);
  EXPECT_THROW(NaturalSpline(3, std::vector<double>{0, 1, 2, 3}, std::vector<double>{0, NAN, 2, 3}), SignalError);
  EXPECT_THROW(NaturalSpline().calcValue(0.0), SignalError);
  try {
    NaturalSpline(5, std::vector<double>{0, 1, 2, 3, 4, 4}, std::vector<double>{0, 1, 2, 3, 4, 5});
    FAIL();
  } catch (const SignalError& e) {
    EXPECT_NE(std::string(e.what()).find("strictly increasing"), std::string::npos) << e.what();
  }
  // exactly 2m points is enough
  EXPECT_NO_THROW(NaturalSpline(5, x, y));
}

// polynomials of degree <= m-1 are natural splines: reproduced everywhere, also outside the data
TEST(SignalSpline, ReproducesLowDegreePolynomialsEverywhere) {
  std::mt19937 rng(11);
  for (int m = 1; m <= 4; ++m) {
    const int n = 3 * m + 5;
    const std::vector<double> x = randomKnots(n, rng, 1.0, -0.5 * n);
    std::normal_distribution<double> nd;
    std::vector<double> c(m);
    for (double& v : c) v = nd(rng);
    auto poly = [&](double t, int d) {
      double s = 0;
      for (int k = d; k < m; ++k) {
        double f = 1;
        for (int j = 0; j < d; ++j) f *= k - j;
        s += c[k] * f * std::pow(t, k - d);
      }
      return s;
    };
    std::vector<double> y(x.size());
    for (size_t i = 0; i < x.size(); ++i) y[i] = poly(x[i], 0);
    const NaturalSpline s(2 * m - 1, x, y);
    double ymax = 0, hmin = 1e300;
    for (size_t i = 0; i < x.size(); ++i) {
      ymax = std::max(ymax, std::abs(y[i]));
      if (i > 0) hmin = std::min(hmin, x[i] - x[i - 1]);
    }
    for (double t = x.front() - 2.0; t <= x.back() + 2.0; t += 0.0173) {
      for (int d = 0; d <= 2 * m - 1; ++d) {
        // round-off of order d: eps-level data noise differentiated d times over hmin
        const double tol = (m <= 3 ? 1e-12 : 2e-11) * (std::abs(poly(t, d)) + ymax / std::pow(hmin, d));
        EXPECT_NEAR(s.calcDerivative(d, t), poly(t, d), tol) << "m " << m << " t " << t << " order " << d;
      }
    }
  }
}

// an analytic natural spline (degree 2m-1 between knots, natural ends) is reproduced exactly
// between the knots, with all derivatives, and outside the data
TEST(SignalSpline, ReproducesAnalyticNaturalSplines) {
  std::mt19937 rng(12);
  for (int m = 1; m <= 4; ++m) {
    for (int trial = 0; trial < 3; ++trial) {
      // unit spacing, centred: |x - xi|^(2m-1) stays moderate, so the reference itself is accurate
      const int n = 4 * m + 3 + trial * 7;
      const std::vector<double> x = randomKnots(n, rng, 1.0, -0.5 * n);
      const AnalyticNaturalSpline a(m, x, rng);
      std::vector<double> y(x.size());
      for (size_t i = 0; i < x.size(); ++i) y[i] = a.eval(x[i], 0);
      const NaturalSpline s(2 * m - 1, x, y);
      // round-off scale of order d: the data's rounding (eps max|y|) differentiated d times over
      // the shortest interval, plus the derivative's own range
      double ymax = 0, hmin = 1e300;
      for (size_t i = 0; i < x.size(); ++i) {
        ymax = std::max(ymax, std::abs(y[i]));
        if (i > 0) hmin = std::min(hmin, x[i] - x[i - 1]);
      }
      for (int d = 0; d <= 2 * m - 1; ++d) {
        double scale = 0, err = 0;
        for (double t = x.front() - 3.0; t <= x.back() + 3.0; t += 0.0731) {
          scale = std::max(scale, std::abs(a.eval(t, d)));
          err = std::max(err, std::abs(s.calcDerivative(d, t) - a.eval(t, d)));
        }
        const double ref = scale + ymax / std::pow(hmin, d);
        // measured: <= 8.8e-15 for m <= 3, <= 2.7e-12 for the septic (m = 4)
        const double tol = m <= 3 ? 1e-13 : 1e-11;
        EXPECT_LE(err, tol * ref) << "m " << m << " order " << d << " scale " << scale << " err/ref " << err / ref;
      }
    }
  }
}

TEST(SignalSpline, InterpolatesTheData) {
  std::mt19937 rng(13);
  std::normal_distribution<double> nd;
  for (int m = 1; m <= 4; ++m) {
    for (int n : {2 * m, 2 * m + 1, 57, 400}) {
      const std::vector<double> x = randomKnots(n, rng);
      std::vector<double> y(n);
      for (double& v : y) v = 100 * nd(rng);
      const NaturalSpline s(2 * m - 1, x, y);
      const double scale = maxAbs(y);
      for (int i = 0; i < n; ++i)
        EXPECT_LE(std::abs(s.calcValue(x[i]) - y[i]), 1e-12 * scale) << "m " << m << " n " << n << " i " << i;
    }
  }
}

// derivative k against a central difference of derivative k-1 (h = 1e-6), off the knots;
// central differences are accurate to ~h^2 * s''' and ~eps/h, so 1e-6 relative to the scale
TEST(SignalSpline, DerivativesMatchCentralDifferences) {
  std::mt19937 rng(14);
  std::normal_distribution<double> nd;
  std::uniform_real_distribution<double> ud(0.05, 0.95);
  const double h = 1e-6;
  for (int m = 1; m <= 4; ++m) {
    const std::vector<double> x = randomKnots(30, rng);
    std::vector<double> y(x.size());
    for (double& v : y) v = nd(rng);
    const NaturalSpline s(2 * m - 1, x, y);
    for (int d = 1; d <= 2 * m - 1; ++d) {
      double scale = 0;
      for (double t = x.front(); t <= x.back(); t += 0.001) scale = std::max(scale, std::abs(s.calcDerivative(d, t)));
      for (size_t i = 0; i + 1 < x.size(); ++i) {
        // a point well inside interval i, so t +- h stays in it
        const double t = x[i] + ud(rng) * (x[i + 1] - x[i]);
        const double fd = (s.calcDerivative(d - 1, t + h) - s.calcDerivative(d - 1, t - h)) / (2 * h);
        EXPECT_NEAR(s.calcDerivative(d, t), fd, 1e-6 * (1 + scale)) << "m " << m << " order " << d << " t " << t;
      }
      // outside the data too
      for (double t : {x.front() - 0.7, x.back() + 0.4}) {
        const double fd = (s.calcDerivative(d - 1, t + h) - s.calcDerivative(d - 1, t - h)) / (2 * h);
        EXPECT_NEAR(s.calcDerivative(d, t), fd, 1e-6 * (1 + scale)) << "outside, m " << m << " order " << d;
      }
    }
  }
}

// C^(2m-2) at interior knots and across the ends, natural end conditions, and a polynomial of
// degree m-1 outside the data (derivative m vanishes there)
TEST(SignalSpline, ContinuityNaturalEndsAndExtrapolationDegree) {
  std::mt19937 rng(15);
  std::normal_distribution<double> nd;
  const double e = 1e-9;
  for (int m = 1; m <= 4; ++m) {
    const std::vector<double> x = randomKnots(25, rng);
    std::vector<double> y(x.size());
    for (double& v : y) v = nd(rng);
    const NaturalSpline s(2 * m - 1, x, y);
    std::vector<double> scale(2 * m, 0.0);
    for (double t = x.front(); t <= x.back(); t += 0.001)
      for (int d = 0; d < 2 * m; ++d) scale[d] = std::max(scale[d], std::abs(s.calcDerivative(d, t)));
    // left and right limits agree for orders 0..2m-2 at every knot (ends included)
    for (size_t i = 0; i < x.size(); ++i)
      for (int d = 0; d <= 2 * m - 2; ++d) {
        const double lo = s.calcDerivative(d, x[i] - e), hi = s.calcDerivative(d, x[i] + e);
        // a jump of the next order's slope over 2e: allow that plus round-off
        const double tol = 1e-9 * (1 + scale[d]) + 4 * e * scale[d + 1];
        EXPECT_NEAR(lo, hi, tol) << "m " << m << " knot " << i << " order " << d;
      }
    // natural ends: s^(j) = 0 for j = m..2m-2 at both end knots (inside limits)
    for (int j = m; j <= 2 * m - 2; ++j) {
      EXPECT_NEAR(s.calcDerivative(j, x.front()), 0.0, 1e-9 * (1 + scale[j])) << "m " << m << " j " << j;
      EXPECT_NEAR(s.calcDerivative(j, x.back()), 0.0, 1e-9 * (1 + scale[j])) << "m " << m << " j " << j;
    }
    // outside: derivative m and above are exactly 0; value is the Taylor polynomial of degree m-1
    for (double t : {x.front() - 2.0, x.front() - 1e-3, x.back() + 1e-3, x.back() + 3.0}) {
      for (int d = m; d <= 2 * m - 1; ++d) EXPECT_EQ(s.calcDerivative(d, t), 0.0) << "m " << m << " d " << d;
      const double xe = t < x.front() ? x.front() : x.back();
      double taylor = 0, fact = 1;
      for (int j = 0; j < m; ++j) {
        if (j > 0) fact *= j;
        taylor += s.calcDerivative(j, xe) * std::pow(t - xe, j) / fact;
      }
      EXPECT_NEAR(s.calcValue(t), taylor, 1e-9 * (1 + std::abs(taylor))) << "m " << m << " t " << t;
    }
  }
}

// the cubic case against the textbook tridiagonal system for second derivatives M_i:
// h_{i-1} M_{i-1} + 2 (h_{i-1}+h_i) M_i + h_i M_{i+1} = 6 (d_i - d_{i-1}), M_0 = M_{n-1} = 0
TEST(SignalSpline, CubicMatchesTextbookMoments) {
  std::mt19937 rng(16);
  std::normal_distribution<double> nd;
  const std::vector<double> x = randomKnots(40, rng);
  const int n = static_cast<int>(x.size());
  std::vector<double> y(n);
  for (double& v : y) v = nd(rng);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  A(0, 0) = A(n - 1, n - 1) = 1;
  for (int i = 1; i + 1 < n; ++i) {
    const double h0 = x[i] - x[i - 1], h1 = x[i + 1] - x[i];
    A(i, i - 1) = h0;
    A(i, i) = 2 * (h0 + h1);
    A(i, i + 1) = h1;
    b[i] = 6 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
  }
  const Eigen::VectorXd M = A.partialPivLu().solve(b);
  const NaturalSpline s(3, x, y);
  for (int i = 0; i < n; ++i) EXPECT_NEAR(s.calcDerivative(2, x[i]), M[i], 1e-10 * (1 + M.cwiseAbs().maxCoeff()));
  // slope outside equals the end slope of the cubic: y' at x_0 = d_0 - h_0 (2 M_0 + M_1)/6
  const double slope0 = (y[1] - y[0]) / (x[1] - x[0]) - (x[1] - x[0]) * (2 * M[0] + M[1]) / 6;
  EXPECT_NEAR(s.calcDerivative(1, x[0] - 1.0), slope0, 1e-10 * (1 + std::abs(slope0)));
}

// calcDerivatives fills the same numbers as calcDerivative, one order at a time
TEST(SignalSpline, CalcDerivativesAgreesWithSingleOrders) {
  std::mt19937 rng(17);
  std::normal_distribution<double> nd;
  const std::vector<double> x = randomKnots(20, rng);
  std::vector<double> y(x.size());
  for (double& v : y) v = nd(rng);
  const NaturalSpline s(5, x, y);
  for (double t : {x.front() - 0.1, x.front(), 0.5 * (x[3] + x[4]), x[7], x.back(), x.back() + 0.2}) {
    double out[7];
    s.calcDerivatives(t, std::span<double>(out, 7));
    for (int d = 0; d < 7; ++d) EXPECT_EQ(out[d], s.calcDerivative(d, t)) << "t " << t << " d " << d;
    EXPECT_EQ(out[6], 0.0);  // above the degree
  }
}

}  // namespace
}  // namespace redmax::signal
