// The analytic smooth wrap model: equal to the exact library away from the transition band, C1
// and C2 across both edges of the band (where the exact library's Jacobian jumps), and its
// Jacobian and Jdot against central differences.
#include <gtest/gtest.h>

#include <random>

#include "core/muscles/wrap/smooth.hpp"
#include "tests/core/muscles/wrap_smooth_fd.hpp"

namespace redmax {
namespace {

bool nearRel(const MatX& a, const MatX& b, double tol) { return (a - b).norm() <= tol * (1.0 + b.norm()); }

std::vector<WrapSurface> surfaces() {
  // a long cylinder: its finite-length cut-off is not part of the smooth model
  return {WrapSurface::makeCylinder(0.8, 100.0), WrapSurface::makeSphere(0.8), WrapSurface::makeCylinder(0.8, 100.0, 0, -1)};
}

TEST(WrapSmooth, EqualsExactLibraryAwayFromTheTransition) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-2.5, 2.5), ua(0.0, 1.0);
  const SmoothWrapOptions opt{0.04};
  for (const WrapSurface& s : surfaces()) {
    int wrapped = 0, straight = 0;
    for (int k = 0; k < 4000; ++k) {
      const Vec3 p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
      const double alpha = ua(rng);
      const WrapResult r = calcWrap(s, p1, p2);
      if (r.code == WrapCode::InsideRadius) continue;
      const double d = calcWrapPenetration(s, p1, p2);
      // the penetration's sign is the library's decision (a quadrant cylinder may also force a wrap)
      if (s.quadrant_sign == 0) {
        ASSERT_EQ(d > 0.0, r.wraps()) << "d = " << d;
      }
      if (d > 0.0 && d < opt.width) continue;  // inside the band
      (r.wraps() ? wrapped : straight)++;
      const Vec3 exact = calcWrappedPathPoint(s, r, p1, p2, alpha);
      const Vec3 smooth = calcSmoothWrapPoint(s, p1, p2, alpha, opt);
      EXPECT_LE((smooth - exact).norm(), 1e-12 * (1.0 + p1.norm() + p2.norm()))
          << "type " << int(s.type) << " d " << d << " alpha " << alpha;
      // the derivative pass gives the same position
      const SmoothWrapPoint sd = calcSmoothWrapPointDerivatives(s, p1, p2, alpha, Vec3::Zero(), Vec3::Zero(), opt);
      EXPECT_LE((sd.x - smooth).norm(), 1e-13 * (1.0 + smooth.norm()));
    }
    EXPECT_GT(wrapped, 300) << "type " << int(s.type);
    EXPECT_GT(straight, 300);
  }
}

double clearance(const WrapSurface& s, const Vec3& p) {
  return (s.type == WrapType::Cylinder ? p.head<2>().norm() : p.norm()) - s.radius;
}

TEST(WrapSmooth, JacobianAndJdotMatchCentralDifferences) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-2.5, 2.5), ua(0.05, 0.95), uv(-1.0, 1.0);
  const SmoothWrapOptions opt{0.3};  // a wide band so that many samples land inside it
  for (const WrapSurface& s : surfaces()) {
    int in_band = 0, tested = 0;
    for (int k = 0; k < 3000 && tested < 200; ++k) {
      const Vec3 p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
      const Vec3 v1(uv(rng), uv(rng), uv(rng)), v2(uv(rng), uv(rng), uv(rng));
      const double alpha = ua(rng);
      // end points at least 0.1 R off the surface: the tangent construction's derivatives grow
      // without bound as an end point approaches the surface, and so does the differences' error
      if (clearance(s, p1) < 0.1 * s.radius || clearance(s, p2) < 0.1 * s.radius) continue;
      const double d = calcWrapPenetration(s, p1, p2);
      if (d < -0.1) continue;  // mostly wrapped and band cases
      const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, p1, p2, alpha, v1, v2, opt);
      // a stencil that straddles a piece boundary of the path (the mass point crossing a tangent
      // point) is not a test of the derivatives: skip the rare sample whose FD is not smooth there
      const test::SmoothWrapFd fd = test::calcSmoothWrapFd(s, p1, p2, alpha, v1, v2, opt, 1e-5, 1e-4);
      if (!fd.converged) continue;
      ++tested;
      if (sp.weight > 0.0 && sp.weight < 1.0) ++in_band;
      EXPECT_TRUE(nearRel(sp.J, fd.J, 1e-6)) << "type " << int(s.type) << " w " << sp.weight << "\n" << sp.J << "\n" << fd.J;
      EXPECT_TRUE(nearRel(sp.Jdot, fd.Jdot, 1e-6)) << "type " << int(s.type) << " w " << sp.weight << "\n" << sp.Jdot << "\n" << fd.Jdot;
    }
    EXPECT_GE(tested, 150) << "type " << int(s.type);
    EXPECT_GE(in_band, 20) << "type " << int(s.type);
  }
}

// a sweep of the insertion along `dir`: the point sits on the first straight piece (alpha small,
// origin far), so the only event is the contact change
struct Sweep {
  WrapSurface s;
  Vec3 p1, p2_0, dir;
  double alpha;
  Vec3 p2(double t) const { return p2_0 + t * dir; }
  double pen(double t) const { return calcWrapPenetration(s, p1, p2(t)); }
  // t where the penetration equals target (bisection; pen increases with t on [0, 1])
  double where(double target) const {
    double lo = 0.0, hi = 1.0;
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      (pen(mid) < target ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  // first and second derivatives of x along the sweep, from the model's J and Jdot
  void derivs(double t, double width, Vec3& x1, Vec3& x2) const {
    const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, p1, p2(t), alpha, Vec3::Zero(), dir, SmoothWrapOptions{width});
    x1 = sp.J.rightCols<3>() * dir;
    x2 = sp.Jdot.rightCols<3>() * dir;
  }
};

std::vector<Sweep> sweeps() {
  // cylinder: the line p1 p2 moves toward the axis as p2 goes down in y; sphere: toward the centre
  return {Sweep{WrapSurface::makeCylinder(1.0, 100.0), Vec3(-4.0, 1.1, 0.2), Vec3(1.5, 1.6, 0.7), Vec3(0, -1.0, 0), 0.15},
          Sweep{WrapSurface::makeSphere(1.0), Vec3(-4.0, 1.1, 0.2), Vec3(1.5, 1.6, 0.7), Vec3(0, -1.0, -0.3), 0.15},
          // the pendulum's quadrant -x cylinder (osim_models/double_pendulum_wrap.osim, scaled by
          // 10): the insertion swings toward +x until the muscle wraps round the -x side
          Sweep{WrapSurface::makeCylinder(0.8, 100.0, 0, -1), Vec3(-1.0, 4.0, 0.1), Vec3(-3.0, -4.0, 0.3), Vec3(3.5, 0, 0), 0.15}};
}

TEST(WrapSmooth, C2AcrossBothEdgesOfTheBandWhereTheExactLibraryJumps) {
  const double width = 0.05;
  for (const Sweep& sw : sweeps()) {
    ASSERT_LT(sw.pen(0.0), 0.0);
    ASSERT_GT(sw.pen(1.0), width);
    for (double edge : {0.0, width}) {
      const double t0 = sw.where(edge);
      // first and second derivatives along the sweep just before and after the edge: the gaps
      // shrink in proportion to the distance e from the edge (no jump; measured: x' gap 2e-1 e,
      // x'' gap up to 4e4 e at the inner edge, O(e^2) at the outer one)
      double gap1[2], gap2[2], x2 = 0.0;
      for (int k = 0; k < 2; ++k) {
        const double e = k == 0 ? 1e-6 : 1e-7;
        Vec3 a1, a2, b1, b2;
        sw.derivs(t0 - e, width, a1, a2);
        sw.derivs(t0 + e, width, b1, b2);
        ASSERT_TRUE(a1.allFinite() && a2.allFinite() && b1.allFinite() && b2.allFinite());
        gap1[k] = (a1 - b1).norm();
        gap2[k] = (a2 - b2).norm();
        x2 = std::max(a2.norm(), b2.norm());
      }
      EXPECT_LT(gap1[1], 1e-6) << "type " << int(sw.s.type) << " edge " << edge;
      EXPECT_LT(gap2[1], 1e-2 * (1.0 + x2)) << "type " << int(sw.s.type) << " edge " << edge;
      EXPECT_LE(gap1[1], 0.15 * gap1[0] + 1e-15);
      EXPECT_LE(gap2[1], 0.15 * gap2[0] + 1e-12);
      // positions equal the exact library on the outer sides
      const double t_out = edge == 0.0 ? t0 - 1e-7 : t0 + 1e-7;
      const WrapResult r = calcWrap(sw.s, sw.p1, sw.p2(t_out));
      EXPECT_LE((calcSmoothWrapPoint(sw.s, sw.p1, sw.p2(t_out), sw.alpha, SmoothWrapOptions{width}) -
                 calcWrappedPathPoint(sw.s, r, sw.p1, sw.p2(t_out), sw.alpha)).norm(), 1e-12);
    }
    // the exact library's derivative along the sweep jumps at the contact change: one-sided
    // differences on either side differ by O(1), which the smooth model removes
    const double t0 = sw.where(0.0), h = 1e-6;
    auto exact = [&](double t) {
      return calcWrappedPathPoint(sw.s, calcWrap(sw.s, sw.p1, sw.p2(t)), sw.p1, sw.p2(t), sw.alpha);
    };
    const Vec3 left = (exact(t0 - 1e-7) - exact(t0 - 1e-7 - h)) / h;
    const Vec3 right = (exact(t0 + 1e-7 + h) - exact(t0 + 1e-7)) / h;
    EXPECT_GT((left - right).norm(), 1e-2) << "type " << int(sw.s.type);
  }
}

TEST(WrapSmooth, BandErrorIsBoundedByTheWidth) {
  // inside the band the model departs from the exact path by at most |x_wrapped - x_straight|,
  // which shrinks with the width
  for (const Sweep& sw : sweeps()) {
    double worst_wide = 0.0, worst_narrow = 0.0;
    for (double width : {0.1, 0.01}) {
      const double ta = sw.where(0.0), tb = sw.where(width);
      for (int k = 1; k < 50; ++k) {
        const double t = ta + (tb - ta) * k / 50.0;
        const Vec3 exact = calcWrappedPathPoint(sw.s, calcWrap(sw.s, sw.p1, sw.p2(t)), sw.p1, sw.p2(t), sw.alpha);
        const double err = (calcSmoothWrapPoint(sw.s, sw.p1, sw.p2(t), sw.alpha, SmoothWrapOptions{width}) - exact).norm();
        (width == 0.1 ? worst_wide : worst_narrow) = std::max(width == 0.1 ? worst_wide : worst_narrow, err);
      }
    }
    EXPECT_LT(worst_narrow, 0.01);
    EXPECT_LT(worst_narrow, 0.2 * worst_wide);
  }
}

TEST(WrapSmooth, UnsupportedSurfacesAreRefusedWithAReason) {
  EXPECT_EQ(smoothWrapUnsupportedReason(WrapSurface::makeEllipsoid(Vec3(1, 2, 3), 2, -1)), "");
  EXPECT_NE(smoothWrapUnsupportedReason(WrapSurface::makeSphere(1.0, 0, 1)), "");
  EXPECT_EQ(smoothWrapUnsupportedReason(WrapSurface::makeCylinder(1.0, 1.0, 0, 1)), "");
  EXPECT_THROW(calcSmoothWrapPoint(WrapSurface::makeSphere(1.0, 0, 1), Vec3(2, 0, 0), Vec3(-2, 0, 0), 0.5),
               std::invalid_argument);
  // an end point inside the surface
  EXPECT_THROW(calcSmoothWrapPoint(WrapSurface::makeSphere(1.0), Vec3(0.5, 0, 0), Vec3(-2, 0, 0), 0.5),
               std::invalid_argument);
}

}  // namespace
}  // namespace redmax
