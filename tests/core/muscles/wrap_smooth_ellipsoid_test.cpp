// The smooth model on ellipsoids: the exact library's hybrid construction with its iterative
// pieces made differentiable (closest points refined by Newton steps over dual numbers, tangent
// points in closed form, the polyline replaced by its limit curve); equal to the library outside
// the band to the library's own accuracy, J and Jdot against central differences, C1/C2 across
// the band.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/muscles/wrap/smooth.hpp"
#include "tests/core/muscles/wrap_smooth_fd.hpp"

namespace redmax {
namespace {

bool nearRel(const MatX& a, const MatX& b, double tol) { return (a - b).norm() <= tol * (1.0 + b.norm()); }

bool insideEllipsoid(const WrapSurface& s, const Vec3& p, double margin) {
  return p.cwiseQuotient(s.dimensions).norm() < 1.0 + margin;
}

// The library's path is not a path where its construction breaks: the point where the wrapping
// plane meets the coordinate axis most normal to it (the rays' origin) lies outside the ellipsoid,
// so its rays after the first tangent point hit the far side (the polyline jumps), or the tangent
// search does not converge (NaN). Seen only with a quadrant (c1 mirrored onto the other side).
bool brokenPolyline(const WrapResult& r) {
  if (!r.r1.allFinite() || !r.r2.allFinite() || !std::isfinite(r.length)) return true;
  double longest = 0.0, total = 0.0;
  for (size_t i = 0; i + 1 < r.polyline.size(); ++i) {
    const double seg = (r.polyline[i + 1] - r.polyline[i]).norm();
    longest = std::max(longest, seg);
    total += seg;
  }
  const size_t n = r.polyline.size() > 1 ? r.polyline.size() - 1 : 1;
  return n > 2 && longest > 10.0 * total / n;
}

// quadrant 0: none; otherwise a random axis and sign per sample (OpenSim's wrap on the active side,
// the far-side wrap where the near one would bend back)
class WrapSmoothEllipsoidQ : public ::testing::TestWithParam<bool> {};

WrapSurface randomEllipsoid(std::mt19937& rng, bool quadrant) {
  std::uniform_real_distribution<double> ud(0.5, 1.5);
  std::uniform_int_distribution<int> axis(0, 2), sign(0, 1);
  const Vec3 d(ud(rng), ud(rng), ud(rng));
  if (!quadrant) return WrapSurface::makeEllipsoid(d);
  const int ax = axis(rng);
  return WrapSurface::makeEllipsoid(d, ax, sign(rng) ? 1 : -1);
}

TEST_P(WrapSmoothEllipsoidQ, EqualsExactLibraryAwayFromTheTransition) {
  // the default training box: semi-axes in [0.5, 1.5], end points in [-3, 3]^3
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 3.0), ua(0.0, 1.0);
  std::vector<double> errs;
  int straight = 0, broken = 0;
  for (int k = 0; k < 3000; ++k) {
    const WrapSurface s = randomEllipsoid(rng, GetParam());
    const Vec3 p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
    const double alpha = ua(rng);
    if (insideEllipsoid(s, p1, 0.0) || insideEllipsoid(s, p2, 0.0)) continue;
    const WrapResult r = calcWrap(s, p1, p2);
    const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, p1, p2, alpha, Vec3::Zero(), Vec3::Zero());
    if (sp.weight != 0.0 && sp.weight != 1.0) continue;  // inside the band
    ASSERT_EQ(sp.weight == 1.0, r.wraps()) << "d " << sp.penetration;
    const Vec3 exact = calcWrappedPathPoint(s, r, p1, p2, alpha);
    EXPECT_LE((calcSmoothWrapPoint(s, p1, p2, alpha) - sp.x).norm(), 1e-12);
    if (!r.wraps()) {
      ++straight;
      EXPECT_LE((sp.x - exact).norm(), 1e-14);
      continue;
    }
    if (brokenPolyline(r)) {
      ++broken;
      continue;
    }
    // the library's path and length against the model's, relative to the smallest semi-axis
    errs.push_back((sp.x - exact).norm() / s.dimensions.minCoeff());
  }
  ASSERT_GT(errs.size(), 300u);
  EXPECT_GT(straight, 1000);
  // measured: none without a quadrant, 6 of 409 wrapped samples with one
  std::printf("ellipsoid%s: %d wrapped samples where the library's own path is broken\n",
              GetParam() ? " with a quadrant" : "", broken);
  EXPECT_LE(broken, GetParam() ? 12 : 0);
  std::sort(errs.begin(), errs.end());
  const double median = errs[errs.size() / 2], p99 = errs[errs.size() * 99 / 100], worst = errs.back();
  std::printf("ellipsoid%s: %zu wrapped samples, |smooth - exact| / min semi-axis: median %.1e, 99%% %.1e, max %.1e\n",
              GetParam() ? " with a quadrant" : "", errs.size(), median, p99, worst);
  // the library's tangent points stop at a residual of 1e-4 and its arc is a polyline (measured:
  // median 5.7e-6, 99th percentile 9.6e-5, max 1.5e-3)
  EXPECT_LT(median, 2e-5);
  EXPECT_LT(p99, 3e-4);
  EXPECT_LT(worst, 5e-3);
}

TEST_P(WrapSmoothEllipsoidQ, JacobianAndJdotMatchCentralDifferences) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-3.0, 3.0), ua(0.05, 0.95), uv(-1.0, 1.0);
  int in_band = 0, wrapped = 0, tested = 0;
  for (int k = 0; k < 3000 && tested < 120; ++k) {
    const WrapSurface s = randomEllipsoid(rng, GetParam());
    const SmoothWrapOptions opt{0.3 * s.dimensions.minCoeff()};  // a wide band so that many samples land inside it
    const Vec3 p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
    const Vec3 v1(uv(rng), uv(rng), uv(rng)), v2(uv(rng), uv(rng), uv(rng));
    const double alpha = ua(rng);
    // end points off the surface (the tangent construction's derivatives grow without bound as an
    // end point nears it)
    if (insideEllipsoid(s, p1, 0.2) || insideEllipsoid(s, p2, 0.2)) continue;
    const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, p1, p2, alpha, v1, v2, opt);
    if (sp.weight == 0.0) continue;
    // skip the stencil that straddles a piece boundary of the library's construction (a mass point
    // crossing a tangent point, the hybrid method's linear blends and fades, a fan sample
    // switching roots)
    const test::SmoothWrapFd fd = test::calcSmoothWrapFd(s, p1, p2, alpha, v1, v2, opt, 1e-6, 3e-7);
    if (!fd.converged) continue;
    ++tested;
    if (sp.weight > 0.0 && sp.weight < 1.0) ++in_band;
    if (sp.weight == 1.0) ++wrapped;
    EXPECT_TRUE(nearRel(sp.J, fd.J, 1e-6)) << "w " << sp.weight << "\n" << sp.J << "\n" << fd.J;
    EXPECT_TRUE(nearRel(sp.Jdot, fd.Jdot, 1e-6)) << "w " << sp.weight << "\n" << sp.Jdot << "\n" << fd.Jdot;
  }
  EXPECT_GE(tested, 100);
  EXPECT_GE(in_band, 10);
  EXPECT_GE(wrapped, 30);
}

INSTANTIATE_TEST_SUITE_P(Quadrant, WrapSmoothEllipsoidQ, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& i) { return i.param ? "WithQuadrant" : "None"; });

// the insertion moves so that the line approaches the ellipsoid and wraps on it; the first and
// second derivatives along the sweep are continuous at both edges of the band, where the exact
// library's derivative jumps
TEST(WrapSmoothEllipsoid, C2AcrossBothEdgesOfTheBand) {
  const WrapSurface s = WrapSurface::makeEllipsoid(Vec3(0.8, 1.2, 0.6));
  const double width = 0.03, alpha = 0.3;
  const Vec3 p1(-2.5, 1.6, 0.3), p2_0(2.0, 1.7, -0.2), dir(0.0, -1.6, 0.1);
  auto p2 = [&](double t) { return Vec3(p2_0 + t * dir); };
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
    EXPECT_LT(gap1[1], 1e-6) << "edge " << edge;
    EXPECT_LT(gap2[1], 1e-2 * (1.0 + x2)) << "edge " << edge;
    EXPECT_LE(gap1[1], 0.15 * gap1[0] + 1e-15);
    EXPECT_LE(gap2[1], 0.15 * gap2[0] + 1e-12);
  }
  const double t0 = where(0.0), h = 1e-6;
  auto exact = [&](double t) { return calcWrappedPathPoint(s, calcWrap(s, p1, p2(t)), p1, p2(t), alpha); };
  const Vec3 left = (exact(t0 - 1e-7) - exact(t0 - 1e-7 - h)) / h;
  const Vec3 right = (exact(t0 + 1e-7 + h) - exact(t0 + 1e-7)) / h;
  EXPECT_GT((left - right).norm(), 1e-2);
}

TEST(WrapSmoothEllipsoid, ArcLengthQuadratureConverged) {
  // the model's wrapped length against the library's polyline of up to 499 segments: they agree
  // to the polyline's own error, far below the position tolerance above
  const WrapSurface s = WrapSurface::makeEllipsoid(Vec3(0.05, 0.03, 0.02));  // muscle-sized, metres
  const Vec3 p1(-0.08, 0.01, 0.004), p2(0.07, -0.005, 0.006);
  const WrapResult r = calcWrap(s, p1, p2);
  ASSERT_TRUE(r.wraps());
  const SmoothWrapLength L = calcSmoothWrapLength(s, p1, p2, Vec3::Zero(), Vec3::Zero());
  EXPECT_NEAR(L.length, calcWrappedPathLength(r, p1, p2), 1e-6);
  EXPECT_EQ(smoothWrapUnsupportedReason(s), "");
  EXPECT_EQ(smoothWrapUnsupportedReason(WrapSurface::makeEllipsoid(Vec3(1, 2, 3), 0, 1)), "");
  EXPECT_THROW(calcSmoothWrapPoint(s, Vec3(0.01, 0, 0), p2, 0.5), std::invalid_argument);
}

}  // namespace
}  // namespace redmax
