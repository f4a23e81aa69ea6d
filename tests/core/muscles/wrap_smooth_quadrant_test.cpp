// The smooth model on quadrant cylinders: continuous wherever the exact library is, in particular
// where the straight line passes on the inactive side of the quadrant plane inside the transition
// band (the library wraps round the active side there whatever the penetration's sign), and equal
// to the library wherever the blend weight is 0 or 1.
#include <gtest/gtest.h>

#include <functional>

#include "core/muscles/wrap/smooth.hpp"

namespace redmax {
namespace {

struct ScanResult {
  double smooth_rate = 0.0;  ///< max |x(t + dt) - x(t)| / dt of the smooth model
  double exact_rate = 0.0;   ///< the same for the exact library
  double excess_rate = 0.0;  ///< max (|dx_smooth| - |dx_exact|) / dt: jumps of the model's own
  double off_band_err = 0.0;  ///< max |smooth - exact| where the weight is 0 or 1
  int off_band = 0, in_band = 0;
};

// scan t in [0, 1] in n steps; end points p1(t), p2(t); a few arc fractions
ScanResult scan(const WrapSurface& s, const std::function<Vec3(double)>& p1, const std::function<Vec3(double)>& p2,
                double width, int n) {
  ScanResult r;
  const SmoothWrapOptions opt{width};
  for (double alpha : {0.15, 0.5, 0.85}) {
    Vec3 xs_prev = Vec3::Zero(), xe_prev = Vec3::Zero();
    for (int i = 0; i <= n; ++i) {
      const double t = static_cast<double>(i) / n;
      const Vec3 a = p1(t), b = p2(t);
      const Vec3 xs = calcSmoothWrapPoint(s, a, b, alpha, opt);
      const Vec3 xe = calcWrappedPathPoint(s, calcWrap(s, a, b), a, b, alpha);
      const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, a, b, alpha, Vec3::Zero(), Vec3::Zero(), opt);
      if (sp.weight == 0.0 || sp.weight == 1.0) {
        r.off_band_err = std::max(r.off_band_err, (xs - xe).norm());
        ++r.off_band;
      } else {
        ++r.in_band;
      }
      if (i > 0) {
        r.smooth_rate = std::max(r.smooth_rate, (xs - xs_prev).norm() * n);
        r.exact_rate = std::max(r.exact_rate, (xe - xe_prev).norm() * n);
        r.excess_rate = std::max(r.excess_rate, ((xs - xs_prev).norm() - (xe - xe_prev).norm()) * n);
      }
      xs_prev = xs;
      xe_prev = xe;
    }
  }
  return r;
}

// the quadrant plane's side of the point of the line p1 p2 nearest the axis (x coordinate)
double footX(const Vec3& p1, const Vec3& p2) {
  const Vec3 u = p2 - p1;
  const double t = -p1.head<2>().dot(u.head<2>()) / u.head<2>().squaredNorm();
  return p1[0] + t * u[0];
}

TEST(WrapSmoothQuadrant, ContinuousWhereTheLinePassesOnTheInactiveSideInTheBand) {
  // the pendulum's quadrant -x cylinder; the insertion swings to +x so that the line moves from
  // just right of the axis to well right of it (inactive side): the library wraps round the -x
  // side all along (MandatoryWrap, then Wrapped), continuously
  const WrapSurface s = WrapSurface::makeCylinder(0.8, 100.0, 0, -1);
  const double width = 0.04;
  auto p1 = [](double) { return Vec3(-1.0, 4.0, 0.1); };
  auto p2 = [](double t) { return Vec3(1.07 + 3.43 * t, -4.0, 0.3); };
  ASSERT_GT(calcWrapPenetration(s, p1(0.0), p2(0.0)), width);
  ASSERT_LT(calcWrapPenetration(s, p1(1.0), p2(1.0)), 0.0);
  for (double t : {0.0, 0.5, 1.0}) ASSERT_GT(footX(p1(t), p2(t)), 0.0);
  const int n = 4000;
  const ScanResult r = scan(s, p1, p2, width, n);
  // the library is continuous here: its difference quotient stays O(1)
  EXPECT_LT(r.exact_rate, 20.0);
  // so must the smooth model be (a jump of size J shows as J * n = J * 4000)
  EXPECT_LT(r.smooth_rate, 1.5 * r.exact_rate + 1.0) << "exact rate " << r.exact_rate;
  EXPECT_LT(r.excess_rate, 1.0);
  EXPECT_LE(r.off_band_err, 1e-12);
  EXPECT_GT(r.off_band, n);
}

TEST(WrapSmoothQuadrant, NoJumpOfItsOwnWhereTheFootCrossesTheQuadrantPlaneInTheBand) {
  // a nearly horizontal line just inside the top of the cylinder, turning so that its point
  // nearest the axis crosses x = 0 while the penetration stays inside the band. The library jumps
  // here by itself (its candidate table flips from the short wrap over the top to the wrap under
  // the bottom, 5 mm before the plane): the model, whose band narrows to nothing at the plane,
  // follows the library there and adds no jump of its own
  const WrapSurface s = WrapSurface::makeCylinder(0.8, 100.0, 0, -1);
  const double width = 0.04;
  auto p1 = [](double t) { return Vec3(-3.0, 0.78 + 0.1 * (2 * t - 1), 0.1); };
  auto p2 = [](double t) { return Vec3(3.0, 0.78 - 0.1 * (2 * t - 1), 0.2); };
  ASSERT_LT(footX(p1(0.0), p2(0.0)) * footX(p1(1.0), p2(1.0)), 0.0);
  const double d_mid = calcWrapPenetration(s, p1(0.5), p2(0.5));
  ASSERT_GT(d_mid, 0.0);
  ASSERT_LT(d_mid, width);
  const int n = 4000;
  const ScanResult r = scan(s, p1, p2, width, n);
  EXPECT_GT(r.exact_rate, 1000.0);  // the library's own jump
  EXPECT_LT(r.excess_rate, 1.0);
  EXPECT_LE(r.off_band_err, 1e-12);
}

TEST(WrapSmoothQuadrant, BlendedOnTheActiveSideExactOnTheInactiveSide) {
  // inside the band: a line passing on the active side is blended (contact-driven wrap); one on
  // the inactive side with the ends on opposite sides is the library's wrap (weight 1)
  const WrapSurface s = WrapSurface::makeCylinder(0.8, 100.0, 0, -1);
  const SmoothWrapOptions opt{0.04};
  // slanted lines 0.788 from the axis (d = 0.012), left and right of it, ends on opposite sides of
  // x = 0
  const Vec3 a1(0.188, 4.0, 0.0), a2(-1.812, -4.0, 0.0);
  const Vec3 b1(-0.188, 4.0, 0.0), b2(1.812, -4.0, 0.0);
  ASSERT_NEAR(calcWrapPenetration(s, a1, a2), 0.012, 1e-3);
  ASSERT_NEAR(calcWrapPenetration(s, b1, b2), 0.012, 1e-3);
  ASSERT_LT(footX(a1, a2), 0.0);
  ASSERT_GT(footX(b1, b2), 0.0);
  const SmoothWrapPoint pa = calcSmoothWrapPointDerivatives(s, a1, a2, 0.5, Vec3::Zero(), Vec3::Zero(), opt);
  const SmoothWrapPoint pb = calcSmoothWrapPointDerivatives(s, b1, b2, 0.5, Vec3::Zero(), Vec3::Zero(), opt);
  EXPECT_GT(pa.weight, 0.0);
  EXPECT_LT(pa.weight, 1.0);
  EXPECT_EQ(pb.weight, 1.0);
  const Vec3 exact = calcWrappedPathPoint(s, calcWrap(s, b1, b2), b1, b2, 0.5);
  EXPECT_LE((pb.x - exact).norm(), 1e-12);
}

}  // namespace
}  // namespace redmax
