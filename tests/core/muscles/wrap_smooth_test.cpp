// The analytic smooth wrap model: equal to the exact library away from the transition band, C1
// and C2 across both edges of the band (where the exact library's Jacobian jumps), and its
// Jacobian and Jdot against central differences.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
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

double clearance(const WrapSurface& s, const Vec3& p) {
  return (s.type == WrapType::Cylinder ? p.head<2>().norm() : p.norm()) - s.radius;
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
      // an end within the band of the surface: the end-point fade (next tests)
      if (clearance(s, p1) < opt.width || clearance(s, p2) < opt.width) continue;
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
    return test::whereAlong([this](double t) { return pen(t); }, target);
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

// A shallow penetration with the muscle line passing 2.5e-7 m from the apex of OpenSim's slide
// plane (the running leg's medial gastrocnemius over its quadrant condyle cylinder during a free
// swing, in the surface frame): the plane, once formed from p1 - apex and p2 - apex, made J and
// Jdot jump by 7e-8 and 7e-2 (|Jdot| 314) for any input change down to 1e-16 m, which stalled rk45
// at 1e-11. Formed as the plane through the ends and the axis point, J and Jdot move with the
// inputs as derivatives do (measured for 1e-15 m: 1.7e-12 and 1.1e-9).
TEST(WrapSmooth, AShallowWrapNearTheSlidePlanesApexIsWellConditioned) {
  const WrapSurface surf = WrapSurface::makeCylinder(0.022, 0.12, 0, -1);
  const Vec3 p1(-0.010000000000000018, 0.03500000000000001, -0.023999999999999987);
  const Vec3 p2(-0.18045697891038742, -0.44693587719737154, -0.0040000000000000018);
  const Vec3 v1 = Vec3::Zero(), v2(-2.0173994652044711, 0.88090418241295787, 0.0);
  const std::vector<double> alphas{0.025, 0.275, 0.525, 0.775, 0.975};
  const SmoothWrapOptions so;
  ASSERT_GT(calcWrapPenetration(surf, p1, p2), 0.0);
  WrapMassPoints base;
  calcSmoothWrapPoints(surf, p1, p2, v1, v2, alphas, {}, so, base);
  double worst_j = 0.0, worst_jdot = 0.0;
  for (int k = 0; k < 6; ++k) {
    Vec3 q1 = p1, q2 = p2;
    (k < 3 ? q1[k] : q2[k - 3]) += 1e-15;
    WrapMassPoints w;
    calcSmoothWrapPoints(surf, q1, q2, v1, v2, alphas, {}, so, w);
    for (size_t a = 0; a < alphas.size(); ++a) {
      worst_j = std::max(worst_j, (w.J[a] - base.J[a]).cwiseAbs().maxCoeff());
      worst_jdot = std::max(worst_jdot, (w.Jdot[a] - base.Jdot[a]).cwiseAbs().maxCoeff());
    }
  }
  std::cout << "[ measured ] inputs moved by 1e-15 m: J moves " << worst_j << ", Jdot " << worst_jdot << "\n";
  EXPECT_LT(worst_j, 1e-11);
  EXPECT_LT(worst_jdot, 1e-8);
}

TEST(WrapSmooth, UnsupportedSurfacesAreRefusedWithAReason) {
  EXPECT_EQ(smoothWrapUnsupportedReason(WrapSurface::makeEllipsoid(Vec3(1, 2, 3), 2, -1)), "");
  EXPECT_EQ(smoothWrapUnsupportedReason(WrapSurface::makeSphere(1.0, 0, 1)), "");  // since issue 22
  EXPECT_EQ(smoothWrapUnsupportedReason(WrapSurface::makeCylinder(1.0, 1.0, 0, 1)), "");
  EXPECT_EQ(smoothWrapUnsupportedReason(WrapSurface::makeSphere(0.0, 0, 1)), "the radius must be positive");
  WrapSurface off = WrapSurface::makeSphere(1.0, 0, 1);
  off.active = false;
  EXPECT_EQ(smoothWrapUnsupportedReason(off), "the surface is inactive");
  try {
    calcSmoothWrapPoint(WrapSurface::makeSphere(0.0, 0, 1), Vec3(2, 0, 0), Vec3(-2, 0, 0), 0.5);
    ADD_FAILURE() << "accepted a sphere of radius 0";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "smooth wrap: the radius must be positive");
  }
  // an end point inside the surface
  EXPECT_THROW(calcSmoothWrapPoint(WrapSurface::makeSphere(1.0), Vec3(0.5, 0, 0), Vec3(-2, 0, 0), 0.5),
               std::invalid_argument);
}

// An end point that reaches the surface while the line penetrates deeply: the exact construction's
// tangent point runs into the end like sqrt(clearance), so its derivatives are unbounded (a free
// swing of subject_walk_armless_18musc with mass on glut_max2 crawled into this and returned NaN,
// docs/notes.md). The model fades to the straight path over a narrow band outside the surface
// (smoothWrapEndFadeWidth: 0.02 of the width): the exact path at clearance >= that band, the
// straight one at the surface, finite and bounded J and Jdot all the way, matching central
// differences inside the fade.
TEST(WrapSmooth, AnEndPointReachingTheSurfaceFadesToTheStraightPath) {
  const double R = 1.0, width = 0.05;
  const SmoothWrapOptions opt{width};
  struct Case {
    WrapSurface s;
    Vec3 p1, dir;  // p2(c) = (R + c) dir, dir a unit radial direction
  };
  const std::vector<Case> cases{
      {WrapSurface::makeCylinder(R, 100.0), Vec3(-3.0, 0.4, 0.3), Vec3(0.6, -0.8, 0.0)},
      {WrapSurface::makeSphere(R), Vec3(-3.0, 0.4, 0.3), Vec3(0.6, -0.8, 0.0)},
      {WrapSurface::makeCylinder(R, 100.0, 1, -1), Vec3(-3.0, 0.4, 0.3), Vec3(0.6, -0.8, 0.0)}};
  const double alpha = 0.6;  // on the far straight piece or the arc near p2
  for (const Case& c : cases) {
    auto p2 = [&](double clear) { Vec3 p = (R + clear) * c.dir; p[2] = c.s.type == WrapType::Cylinder ? 0.5 : p[2]; return p; };
    // the line penetrates by much more than the band, so only the end fade acts
    ASSERT_GT(calcWrapPenetration(c.s, c.p1, p2(width)), 4 * width) << "type " << int(c.s.type);
    const double wf = smoothWrapEndFadeWidth(c.s, opt);
    EXPECT_NEAR(wf, 0.02 * width, 1e-15);
    EXPECT_NEAR(calcWrapEndClearance(c.s, p2(0.3 * wf)), 0.3 * wf, 1e-15);
    // outside the fade: the exact path
    {
      const Vec3 q2 = p2(1.01 * wf);
      const WrapResult r = calcWrap(c.s, c.p1, q2);
      ASSERT_TRUE(r.wraps());
      EXPECT_LE((calcSmoothWrapPoint(c.s, c.p1, q2, alpha, opt) - calcWrappedPathPoint(c.s, r, c.p1, q2, alpha)).norm(), 1e-12);
    }
    // at the surface (and inside the fade's cut-off): the straight path, derivatives finite
    for (double clear : {0.0, 1e-9}) {
      const Vec3 q2 = p2(clear);
      const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(c.s, c.p1, q2, alpha, Vec3(0.1, 0.2, 0.3), c.dir, opt);
      EXPECT_LE((sp.x - (c.p1 + alpha * (q2 - c.p1))).norm(), 1e-12) << "type " << int(c.s.type) << " clearance " << clear;
      EXPECT_TRUE(sp.J.allFinite() && sp.Jdot.allFinite());
    }
    // across the fade: J and Jdot against central differences, and bounded as the end nears the
    // surface (the exact construction's grow like clearance^(-1/2) and clearance^(-3/2))
    double worst_J = 0.0, worst_Jdot = 0.0;
    int tested = 0;
    for (double f : {0.9, 0.5, 0.2, 0.05, 0.01, 1e-3}) {
      const Vec3 q2 = p2(f * wf);
      const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(c.s, c.p1, q2, alpha, Vec3(0.1, 0.2, 0.3), c.dir, opt);
      ASSERT_TRUE(sp.J.allFinite() && sp.Jdot.allFinite());
      worst_J = std::max(worst_J, sp.J.norm());
      worst_Jdot = std::max(worst_Jdot, sp.Jdot.norm());
      const test::SmoothWrapFd fd =
          test::calcSmoothWrapFd(c.s, c.p1, q2, alpha, Vec3(0.1, 0.2, 0.3), c.dir, opt, 1e-4 * f * wf, 1e-4);
      if (!fd.converged) continue;
      ++tested;
      EXPECT_TRUE(nearRel(sp.J, fd.J, 1e-6)) << "type " << int(c.s.type) << " f " << f << "\n" << sp.J << "\n" << fd.J;
      EXPECT_TRUE(nearRel(sp.Jdot, fd.Jdot, 1e-5)) << "type " << int(c.s.type) << " f " << f << "\n" << sp.Jdot << "\n" << fd.Jdot;
    }
    EXPECT_GE(tested, 4) << "type " << int(c.s.type);
    std::printf("[ measured ] type %d: across the end fade max |J| %.3g, max |Jdot| %.3g\n", int(c.s.type), worst_J, worst_Jdot);
    // bounded: the fade's cube kills the construction's growth; what is left is the jump from the
    // wrapped to the straight path (O(R) here) spread over the band: O(1/wf) and O(1/wf^2)
    EXPECT_LT(worst_J, 5.0 / wf);
    EXPECT_LT(worst_Jdot, 5.0 / (wf * wf));
  }
}

}  // namespace
}  // namespace redmax
