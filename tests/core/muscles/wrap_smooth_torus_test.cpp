// The smooth model on tori: the exact library's construction (the centre-circle point nearest the
// line, found by the library's search and differentiated by Newton steps over dual numbers, then
// the smooth quadrant cylinder in its frame); equal to the library outside the band, J and Jdot
// against central differences, C1/C2 across the band.
#include <gtest/gtest.h>

#include <random>

#include "core/muscles/wrap/smooth.hpp"
#include "tests/core/muscles/wrap_smooth_fd.hpp"

namespace redmax {
namespace {

bool nearRel(const MatX& a, const MatX& b, double tol) { return (a - b).norm() <= tol * (1.0 + b.norm()); }

bool insideTube(const WrapSurface& s, const Vec3& p, double margin) {
  const double rho = p.head<2>().norm() - s.outer_radius;
  return std::sqrt(rho * rho + p[2] * p[2]) < s.inner_radius + margin;
}

std::vector<WrapSurface> tori() { return {WrapSurface::makeTorus(0.3, 1.2), WrapSurface::makeTorus(0.4, 1.0, 1, 1)}; }

TEST(WrapSmoothTorus, EqualsExactLibraryAwayFromTheTransition) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-2.0, 2.0), ua(0.0, 1.0);
  const SmoothWrapOptions opt{0.015};
  for (const WrapSurface& s : tori()) {
    int wrapped = 0, straight = 0;
    double worst = 0.0;
    for (int k = 0; k < 4000; ++k) {
      const Vec3 p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
      if (insideTube(s, p1, 0.0) || insideTube(s, p2, 0.0)) continue;
      const double alpha = ua(rng);
      const WrapResult r = calcWrap(s, p1, p2);
      const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, p1, p2, alpha, Vec3::Zero(), Vec3::Zero(), opt);
      if (sp.weight != 0.0 && sp.weight != 1.0) continue;  // inside the band
      (r.wraps() ? wrapped : straight)++;
      EXPECT_EQ(sp.weight == 1.0, r.wraps()) << "d " << sp.penetration;
      const Vec3 exact = calcWrappedPathPoint(s, r, p1, p2, alpha);
      const Vec3 smooth = calcSmoothWrapPoint(s, p1, p2, alpha, opt);
      worst = std::max(worst, (smooth - exact).norm());
      // the library ends its search at a root of its residual to ~1e-14, or at a stationary point
      // of it that it locates only to ~1e-9 (the residual is flat there)
      EXPECT_LE((smooth - exact).norm(), 1e-6) << "d " << sp.penetration << " alpha " << alpha;
      EXPECT_LE((sp.x - smooth).norm(), 1e-12);
    }
    EXPECT_GT(wrapped, 300);
    EXPECT_GT(straight, 300);
    std::printf("torus %g/%g quadrant %d: %d wrapped, %d straight samples, max |smooth - exact| %.2e m\n",
                s.inner_radius, s.outer_radius, s.quadrant_sign, wrapped, straight, worst);
  }
}

TEST(WrapSmoothTorus, JacobianAndJdotMatchCentralDifferences) {
  std::mt19937 rng(37);
  std::uniform_real_distribution<double> u(-2.0, 2.0), ua(0.05, 0.95), uv(-1.0, 1.0);
  const SmoothWrapOptions opt{0.2};  // a wide band so that many samples land inside it
  for (const WrapSurface& s : tori()) {
    int in_band = 0, wrapped = 0, tested = 0;
    for (int k = 0; k < 6000 && tested < 200; ++k) {
      const Vec3 p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
      const Vec3 v1(uv(rng), uv(rng), uv(rng)), v2(uv(rng), uv(rng), uv(rng));
      const double alpha = ua(rng);
      // end points at least half a tube radius off the tube (the tangent construction's
      // derivatives grow without bound as an end point nears the surface)
      if (insideTube(s, p1, 0.5 * s.inner_radius) || insideTube(s, p2, 0.5 * s.inner_radius)) continue;
      const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, p1, p2, alpha, v1, v2, opt);
      if (sp.weight == 0.0 && k % 4 != 0) continue;  // mostly wrapped and band cases
      // a small step: the construction's third derivatives are large here (the differences'
      // truncation error falls as h^2 down to 1e-8 at this step, measured); skip a stencil that
      // straddles a piece boundary or lies next to a singular configuration of the library's search
      const test::SmoothWrapFd fd = test::calcSmoothWrapFd(s, p1, p2, alpha, v1, v2, opt, 1e-6, 3e-7);
      if (!fd.converged) continue;
      ++tested;
      if (sp.weight > 0.0 && sp.weight < 1.0) ++in_band;
      if (sp.weight == 1.0) ++wrapped;
      EXPECT_TRUE(nearRel(sp.J, fd.J, 1e-6)) << "w " << sp.weight << "\n" << sp.J << "\n" << fd.J;
      EXPECT_TRUE(nearRel(sp.Jdot, fd.Jdot, 1e-6)) << "w " << sp.weight << "\n" << sp.Jdot << "\n" << fd.Jdot;
    }
    EXPECT_GE(tested, 150);
    EXPECT_GE(in_band, 10);
    EXPECT_GE(wrapped, 50);
  }
}

// the insertion moves so that the line through the torus's hole approaches the tube's inner side
// and wraps on it; the first and second derivatives along the sweep are continuous at both edges
// of the band, where the exact library's derivative jumps
TEST(WrapSmoothTorus, C2AcrossBothEdgesOfTheBand) {
  const WrapSurface s = WrapSurface::makeTorus(0.3, 1.2);
  const double width = 0.02, alpha = 0.3;
  const Vec3 p1(0.8, 0.05, 1.0), p2_0(0.5, -0.05, -1.0), dir(0.6, 0.0, 0.0);
  auto p2 = [&](double t) { Vec3 q = p2_0 + t * dir; return q; };
  auto pen = [&](double t) { return calcWrapPenetration(s, p1, p2(t)); };
  ASSERT_LT(pen(0.0), 0.0);
  ASSERT_GT(pen(1.0), width);
  auto where = [&](double target) { return test::whereAlong(pen, target); };
  auto derivs = [&](double t, Vec3& x1, Vec3& x2) {
    const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, p1, p2(t), alpha, Vec3::Zero(), dir, SmoothWrapOptions{width});
    x1 = sp.J.rightCols<3>() * dir;
    x2 = sp.Jdot.rightCols<3>() * dir;
  };
  for (double edge : {0.0, width}) {
    const double t0 = where(edge);
    const test::EdgeGaps g = test::edgeGaps(derivs, t0);
    ASSERT_TRUE(g.finite);
    const double *gap1 = g.gap1, *gap2 = g.gap2, x2 = g.x2;
    // the gaps shrink with the distance from the edge (no jump)
    EXPECT_LT(gap1[1], 1e-6) << "edge " << edge;
    EXPECT_LT(gap2[1], 1e-2 * (1.0 + x2)) << "edge " << edge;
    EXPECT_LE(gap1[1], 0.15 * gap1[0] + 1e-15);
    EXPECT_LE(gap2[1], 0.15 * gap2[0] + 1e-12);
    const double t_out = edge == 0.0 ? t0 - 1e-7 : t0 + 1e-7;
    const WrapResult r = calcWrap(s, p1, p2(t_out));
    EXPECT_LE((calcSmoothWrapPoint(s, p1, p2(t_out), alpha, SmoothWrapOptions{width}) -
               calcWrappedPathPoint(s, r, p1, p2(t_out), alpha)).norm(), 1e-10);
  }
  // the library's derivative along the sweep jumps at the contact change
  const double t0 = where(0.0), h = 1e-6;
  auto exact = [&](double t) { return calcWrappedPathPoint(s, calcWrap(s, p1, p2(t)), p1, p2(t), alpha); };
  const Vec3 left = (exact(t0 - 1e-7) - exact(t0 - 1e-7 - h)) / h;
  const Vec3 right = (exact(t0 + 1e-7 + h) - exact(t0 + 1e-7)) / h;
  EXPECT_GT((left - right).norm(), 1e-2);
}

TEST(WrapSmoothTorus, AcceptedWithPositiveRadiiAndRefusesInsidePoints) {
  EXPECT_EQ(smoothWrapUnsupportedReason(WrapSurface::makeTorus(0.1, 1.0)), "");
  EXPECT_NE(smoothWrapUnsupportedReason(WrapSurface::makeTorus(0.0, 1.0)), "");
  // an end point inside the tube
  EXPECT_THROW(calcSmoothWrapPoint(WrapSurface::makeTorus(0.1, 1.0), Vec3(1.05, 0, 0), Vec3(-2, 0, 0), 0.5),
               std::invalid_argument);
}

}  // namespace
}  // namespace redmax
