// The smooth model's shared route (calcSmoothWrapPoints: one construction per segment over Jet
// numbers, all input directions in one pass) against the route it replaced (smooth_reference:
// nested duals, one pass per input direction, the whole construction per point): equal to
// round-off on every surface type, in the straight, band and wrapped regions, with the fraction
// as a seventh input and without it. The FD checks of J and Jdot stay in the per-surface tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "core/muscles/wrap/smooth.hpp"

namespace redmax {
namespace {

// max |a - b| over the entries relative to max |b| (at least 1: positions are O(1) here)
double relDiff(const MatX& a, const MatX& b) { return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff()); }

struct Case {
  const char* name;
  WrapSurface s;
  double width;
};

std::vector<Case> cases() {
  return {{"cylinder", WrapSurface::makeCylinder(0.5, 10.0), 0.1},
          {"quadrant cylinder", WrapSurface::makeCylinder(0.5, 10.0, 0, 1), 0.1},
          {"sphere", WrapSurface::makeSphere(0.6), 0.1},
          {"quadrant sphere", WrapSurface::makeSphere(0.6, 1, -1), 0.1},
          {"ellipsoid", WrapSurface::makeEllipsoid(Vec3(0.7, 0.5, 0.4)), 0.08},
          {"torus", WrapSurface::makeTorus(0.3, 1.2), 0.06}};
}

TEST(WrapSmoothShared, EqualsThePerPointNestedDualRoute) {
  std::mt19937 rng(18);
  std::uniform_real_distribution<double> u(-2.0, 2.0), uv(-1.0, 1.0);
  const std::vector<double> alphas{0.0, 0.05, 0.2, 0.35, 0.5, 0.65, 0.8, 0.95, 1.0};
  double worst = 0.0;
  for (const Case& c : cases()) {
    const SmoothWrapOptions opt{c.width};
    int straight = 0, band = 0, wrapped = 0;
    double worst_case = 0.0;
    for (int k = 0; k < 3000 && (straight < 20 || band < 20 || wrapped < 20); ++k) {
      const Vec3 p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
      const Vec3 v1(uv(rng), uv(rng), uv(rng)), v2(uv(rng), uv(rng), uv(rng));
      if (c.s.contains(p1) || c.s.contains(p2) || (p1 - p2).norm() < 0.1) continue;
      const double w = smooth_reference::calcSmoothWrapPointDerivatives(c.s, p1, p2, 0.5, v1, v2, opt).weight;
      int& bucket = w == 0.0 ? straight : w == 1.0 ? wrapped : band;
      if (bucket >= 20) continue;
      ++bucket;
      std::vector<double> alphadots(alphas.size());
      for (double& a : alphadots) a = uv(rng);
      // fraction fixed (6 inputs)
      WrapMassPoints mp;
      calcSmoothWrapPoints(c.s, p1, p2, v1, v2, alphas, {}, opt, mp);
      // fraction moving, with its derivative (7 inputs)
      WrapMassPoints mp7;
      std::vector<Vec3> xa, xad;
      calcSmoothWrapPoints(c.s, p1, p2, v1, v2, alphas, alphadots, opt, mp7, &xa, &xad);
      for (size_t a = 0; a < alphas.size(); ++a) {
        const SmoothWrapPoint r = smooth_reference::calcSmoothWrapPointDerivatives(c.s, p1, p2, alphas[a], v1, v2, opt);
        const SmoothWrapSegmentPoint r7 =
            smooth_reference::calcSmoothWrapSegmentPoint(c.s, p1, p2, alphas[a], v1, v2, alphadots[a], opt);
        Eigen::Matrix<double, 3, 7> J7, Jdot7;
        J7 << mp7.J[a], xa[a];
        Jdot7 << mp7.Jdot[a], xad[a];
        const double d = std::max({relDiff(mp.x[a], r.x), relDiff(mp.J[a], r.J), relDiff(mp.Jdot[a], r.Jdot),
                                   relDiff(mp7.x[a], r7.x), relDiff(J7, r7.J), relDiff(Jdot7, r7.Jdot)});
        worst_case = std::max(worst_case, d);
        // measured 1.6e-12 (one near-degenerate cylinder segment; the others <= 5.4e-14)
        EXPECT_LE(d, 5e-12) << c.name << " w " << w << " alpha " << alphas[a];
      }
      const SmoothWrapLength L = calcSmoothWrapLength(c.s, p1, p2, v1, v2, opt);
      const SmoothWrapLength Lr = smooth_reference::calcSmoothWrapLength(c.s, p1, p2, v1, v2, opt);
      const double dl = std::max({std::abs(L.length - Lr.length) / std::max(1.0, Lr.length), relDiff(L.J, Lr.J),
                                  relDiff(L.Jdot, Lr.Jdot)});
      worst_case = std::max(worst_case, dl);
      EXPECT_LE(dl, 5e-12) << c.name << " length, w " << w;
    }
    EXPECT_EQ(straight, 20) << c.name;
    EXPECT_EQ(band, 20) << c.name;
    EXPECT_EQ(wrapped, 20) << c.name;
    std::printf("%s: %d straight, %d band, %d wrapped segments x %zu points: max relative difference %.2e\n", c.name,
                straight, band, wrapped, alphas.size(), worst_case);
    worst = std::max(worst, worst_case);
  }
  std::printf("shared route vs per-point nested duals: max relative difference %.2e\n", worst);
}

}  // namespace
}  // namespace redmax
