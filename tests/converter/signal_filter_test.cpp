// OpenSim's signal primitives (converter/signal/opensim_signal.hpp): the Butterworth IIR against
// an independent bilinear transform and the analog magnitude response, zero phase, constants,
// odd-reflection padding, the accumulated resampling grid, findIndex and the time window.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "converter/signal/opensim_signal.hpp"

namespace redmax::signal {
namespace {

using Poly = std::vector<double>;  // coefficients of z^-k, k = 0..

Poly mul(const Poly& a, const Poly& b) {
  Poly c(a.size() + b.size() - 1, 0.0);
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  return c;
}
Poly add(Poly a, const Poly& b) {
  if (b.size() > a.size()) a.resize(b.size(), 0.0);
  for (size_t i = 0; i < b.size(); ++i) a[i] += b[i];
  return a;
}
Poly scale(Poly a, double s) {
  for (double& v : a) v *= s;
  return a;
}

// H(e^{i theta}) of the digital filter
std::complex<double> response(const Butterworth3& f, double theta) {
  std::complex<double> num = 0, den = 0;
  for (int k = 0; k < 4; ++k) {
    const std::complex<double> zk = std::polar(1.0, -k * theta);
    num += f.a[k] * zk;
    den += f.b[k] * zk;
  }
  return num / den;
}

// the coefficients are the bilinear transform s = (1 - z^-1) / (w (1 + z^-1)) of
// 1/((s+1)(s^2+s+1)), multiplied through by w^3 (1 + z^-1)^3 and normalized to b0 = 1
TEST(SignalFilter, CoefficientsAreTheBilinearButterworth) {
  for (double T : {0.01, 1.0 / 120, 1.0 / 60, 0.001}) {
    for (double fc : {0.5, 6.0, 10.0, 20.0}) {
      if (fc >= 0.5 / T) continue;
      const Butterworth3 f = makeButterworth3(T, fc);
      EXPECT_FALSE(f.clamped);
      const double w = std::tan(std::numbers::pi * fc * T);
      const Poly P = {1, 1}, M = {1, -1};  // 1 + z^-1, 1 - z^-1
      const Poly num = scale(mul(P, mul(P, P)), w * w * w);
      const Poly first = add(M, scale(P, w));                                                  // (s+1) w (1+z^-1)
      const Poly second = add(add(mul(M, M), scale(mul(M, P), w)), scale(mul(P, P), w * w));  // (s^2+s+1) w^2 (1+z^-1)^2
      const Poly den = mul(first, second);
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(f.a[k], num[k] / den[0], 1e-14 * (1 + std::abs(num[k] / den[0]))) << "a" << k << " T " << T;
        EXPECT_NEAR(f.b[k], den[k] / den[0], 1e-14 * (1 + std::abs(den[k] / den[0]))) << "b" << k << " T " << T;
      }
    }
  }
}

// |H|^2 = 1/(1 + (tan(theta/2)/w)^6) (a Butterworth under the prewarped map): 1 at DC, -3 dB per
// pass at fc, hence -6 dB after the forward-backward pass
TEST(SignalFilter, FrequencyResponseIsButterworth) {
  const double T = 1.0 / 60, fc = 6.0;
  const Butterworth3 f = makeButterworth3(T, fc);
  const double w = std::tan(std::numbers::pi * fc * T);
  EXPECT_NEAR(std::abs(response(f, 0.0)), 1.0, 1e-14);
  const double theta_c = 2 * std::numbers::pi * fc * T;
  EXPECT_NEAR(std::abs(response(f, theta_c)), 1.0 / std::sqrt(2.0), 1e-13);
  EXPECT_NEAR(20 * std::log10(std::norm(response(f, theta_c))), -6.0206, 1e-4);  // two passes
  for (double theta = 0.05; theta < std::numbers::pi; theta += 0.1) {
    const double expect = 1.0 / (1.0 + std::pow(std::tan(theta / 2) / w, 6));
    EXPECT_NEAR(std::norm(response(f, theta)), expect, 1e-13) << "theta " << theta;
  }
  // the clamp: fc >= 0.5/T becomes 0.49/T
  const Butterworth3 g = makeButterworth3(T, 40.0);
  EXPECT_TRUE(g.clamped);
  EXPECT_DOUBLE_EQ(g.cutoff_hz, 0.49 * 60);
  EXPECT_TRUE(makeButterworth3(T, 30.0).clamped);  // exactly Nyquist is clamped too
  EXPECT_FALSE(makeButterworth3(T, 29.9).clamped);
  EXPECT_THROW(makeButterworth3(0.0, 6.0), SignalError);
  EXPECT_THROW(makeButterworth3(T, NAN), SignalError);
  EXPECT_THROW(makeButterworth3(T, -1.0), SignalError);
}

// a sinusoid comes out scaled by |H|^2 with no phase shift once the start-up transient (poles
// decaying within ~10 samples here) has died out
TEST(SignalFilter, ZeroPhaseOnASinusoid) {
  const double T = 0.01, fc = 6.0;
  const int n = 2000;
  const Butterworth3 f = makeButterworth3(T, fc);
  for (double freq : {1.0, 4.0, 6.0, 9.0}) {
    std::vector<double> x(n);
    for (int i = 0; i < n; ++i) x[i] = std::sin(2 * std::numbers::pi * freq * i * T + 0.3);
    const std::vector<double> y = lowpassIIR(T, fc, x);
    const double gain = std::norm(response(f, 2 * std::numbers::pi * freq * T));
    double err = 0;
    for (int i = 400; i < n - 400; ++i) err = std::max(err, std::abs(y[i] - gain * x[i]));
    EXPECT_LT(err, 1e-12) << "freq " << freq << " gain " << gain;
  }
}

TEST(SignalFilter, PassesConstantsAndShortSignals) {
  for (double c : {0.0, 1.0, -3.7, 123.456}) {
    const std::vector<double> x(300, c);
    const std::vector<double> y = lowpassIIR(1.0 / 120, 6.0, x);
    for (double v : y) EXPECT_NEAR(v, c, 1e-13 * (1 + std::abs(c)));
  }
  // fewer than 4 samples: returned as is
  const std::vector<double> s3 = {1, 5, 2};
  EXPECT_EQ(lowpassIIR(0.01, 6.0, s3), s3);
  // 4 samples: the first three outputs of each pass are copies, the fourth is filtered
  const std::vector<double> s4 = {1, 5, 2, 7};
  EXPECT_NE(lowpassIIR(0.01, 6.0, s4), s4);
}

// Signal::Pad's odd reflection, written out
TEST(SignalFilter, PaddingIsOddReflection) {
  const std::vector<double> x = {1.0, 4.0, 2.0, 8.0, 5.0};
  const std::vector<double> p = padOddReflection(x, 2);
  const std::vector<double> expect = {2 * 1.0 - 2.0, 2 * 1.0 - 4.0, 1, 4, 2, 8, 5, 2 * 5.0 - 8.0, 2 * 5.0 - 2.0};
  EXPECT_EQ(p, expect);
  EXPECT_EQ(padOddReflection(x, 0), x);
  // the time column of a uniform grid continues the grid
  std::vector<double> t(11);
  for (int i = 0; i < 11; ++i) t[i] = 0.5 + i * 0.1;
  const std::vector<double> tp = padOddReflection(t, 5);
  ASSERT_EQ(tp.size(), 21u);
  for (int i = 0; i < 21; ++i) EXPECT_NEAR(tp[i], 0.5 + (i - 5) * 0.1, 1e-15) << i;
  // pad >= size: repeated reflections up to the requested length, middle unchanged
  const std::vector<double> q = padOddReflection(x, 7);
  ASSERT_EQ(q.size(), x.size() + 14);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_EQ(q[7 + i], x[i]);
  EXPECT_EQ(q[6], 2 * x[0] - x[1]);
  EXPECT_EQ(q[12], 2 * x[4] - x[3]);
  EXPECT_THROW(padOddReflection(std::vector<double>{1.0}, 1), SignalError);
  EXPECT_TRUE(padOddReflection(std::vector<double>{}, 3).empty());
}

// the grid is t_first + dt + dt + ... accumulated, stopping at the last t <= t_last
TEST(SignalFilter, ResampleGridAccumulates) {
  const std::vector<double> t = {0.39999934, 0.5, 0.71, 1.00000003};
  const double dt = 1.0 / 60;
  double used = 0;
  const std::vector<double> g = makeResampleGrid(t, dt, &used);
  EXPECT_EQ(used, dt);
  double acc = t.front();
  for (double v : g) {
    EXPECT_EQ(v, acc);  // bit-identical accumulation
    acc += dt;
  }
  EXPECT_LE(g.back(), t.back());
  EXPECT_GT(g.back() + dt, t.back());
  // more than 100000 steps: the step is raised to span/100000
  const std::vector<double> wide = {0.0, 10.0};
  const std::vector<double> gw = makeResampleGrid(wide, 1e-6, &used);
  EXPECT_EQ(used, 10.0 / 100000);
  EXPECT_NEAR(static_cast<double>(gw.size()), 100001.0, 1.0);
  EXPECT_THROW(makeResampleGrid(wide, 0.0), SignalError);
  EXPECT_THROW(makeResampleGrid(std::vector<double>{}, 0.1), SignalError);

  EXPECT_EQ(calcMinTimeStep(std::vector<double>{0.0, 0.3, 0.4, 0.9}), 0.4 - 0.3);
  EXPECT_TRUE(std::isinf(calcMinTimeStep(std::vector<double>{1.0})));
}

TEST(SignalFilter, FindIndexAndTimeWindow) {
  const std::vector<double> t = {0.0, 0.1, 0.2, 0.3};
  EXPECT_EQ(findIndex(t, -1.0), 0);
  EXPECT_EQ(findIndex(t, 0.0), 0);
  EXPECT_EQ(findIndex(t, 0.15), 1);
  EXPECT_EQ(findIndex(t, 0.2), 2);
  EXPECT_EQ(findIndex(t, 5.0), 3);
  // the first output row may lie before t0: the last row at or before it
  const TimeWindow w = selectTimeWindow(t, 0.05, 0.25);
  EXPECT_EQ(w.first_row, 0);
  EXPECT_EQ(w.last_row, 2);
  EXPECT_EQ(w.numRows(), 3);
  EXPECT_EQ(w.start_time, 0.05);
  EXPECT_EQ(w.end_time, 0.25);
  // an unbounded range is the whole grid
  const TimeWindow all = selectTimeWindow(t, -INFINITY, INFINITY);
  EXPECT_EQ(all.first_row, 0);
  EXPECT_EQ(all.last_row, 3);
  EXPECT_EQ(all.start_time, 0.0);
  EXPECT_EQ(all.end_time, 0.3);
  EXPECT_THROW(selectTimeWindow(t, 0.2, 0.1), SignalError);
  EXPECT_THROW(selectTimeWindow(std::vector<double>{}, 0.0, 1.0), SignalError);
  EXPECT_THROW(findIndex(std::vector<double>{}, 0.0), SignalError);
}

}  // namespace
}  // namespace redmax::signal
