// Several smooth wrap surfaces on one segment (issue 22, core/muscles/wrap/smooth_composite.hpp):
// equal to the exact library's converged path where every surface is outside its band, J and Jdot
// against central differences in all inputs (ends, surface poses, fraction), C2 across each
// surface's contact change, and one surface equal to the single-surface smooth model.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/muscles/path.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/muscles/wrap/smooth_composite.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/spatial/se3.hpp"
#include "tests/core/muscles/wrap_composite_reference.hpp"
#include "tests/core/muscles/wrap_smooth_fd.hpp"

namespace redmax {
namespace {

// K cylinders (the last one a sphere when asked; radius 0.05-0.09 m, length 1 m, axes tilted up to 0.3 rad) 0.3 m apart along x, a
// segment from x = -0.25 to 0.25 + 0.3 (K - 1) passing above them at heights 0.02-0.14 m: each
// surface wrapped, in its band or clear, at random; velocities of the ends and the surfaces random
struct Scene {
  std::vector<WrapSurface> surf;
  std::vector<CompositeWrapSurface> s;
  Vec3 p1, p2, v1, v2;
};

Scene randomScene(std::mt19937& rng, int K, bool sphere_last = false) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto in = [&](double lo, double hi) { return lo + (hi - lo) * 0.5 * (u(rng) + 1.0); };
  Scene sc;
  sc.surf.resize(K);
  sc.s.resize(K);
  for (int k = 0; k < K; ++k) {
    sc.surf[k] = sphere_last && k == K - 1 ? WrapSurface::makeSphere(in(0.05, 0.09))
                                           : WrapSurface::makeCylinder(in(0.05, 0.09), 1.0);
    const Mat3 R = (Eigen::AngleAxisd(0.3 * u(rng), Vec3::UnitX()) * Eigen::AngleAxisd(0.3 * u(rng), Vec3::UnitY()))
                       .toRotationMatrix();
    sc.s[k].R = R;
    sc.s[k].p = Vec3(0.3 * k, 0.03 * u(rng), 0.0);
    sc.s[k].Rdot = skew(Vec3(0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng))) * R;
    sc.s[k].pdot = Vec3(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
  }
  for (int k = 0; k < K; ++k) sc.s[k].surface = &sc.surf[k];
  sc.p1 = Vec3(-0.25, in(0.02, 0.14), 0.05 * u(rng));
  sc.p2 = Vec3(0.25 + 0.3 * (K - 1), in(0.02, 0.14), 0.05 * u(rng));
  sc.v1 = Vec3(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
  sc.v2 = Vec3(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
  return sc;
}

// the inputs u = (p1, p2, R_k row-major, p_k, ..., alpha) as a vector, and back
VecX packInputs(const Scene& sc) {
  const int K = static_cast<int>(sc.s.size());
  VecX u(6 + 12 * K);
  u << sc.p1, sc.p2, VecX::Zero(12 * K);
  for (int k = 0; k < K; ++k) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) u[6 + 12 * k + 3 * a + b] = sc.s[k].R(a, b);
    u.segment<3>(6 + 12 * k + 9) = sc.s[k].p;
  }
  return u;
}
VecX packRates(const Scene& sc) {
  const int K = static_cast<int>(sc.s.size());
  VecX u(6 + 12 * K);
  u << sc.v1, sc.v2, VecX::Zero(12 * K);
  for (int k = 0; k < K; ++k) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) u[6 + 12 * k + 3 * a + b] = sc.s[k].Rdot(a, b);
    u.segment<3>(6 + 12 * k + 9) = sc.s[k].pdot;
  }
  return u;
}
Scene unpack(const Scene& base, const VecX& u) {
  Scene sc = base;
  const int K = static_cast<int>(sc.s.size());
  sc.p1 = u.segment<3>(0);
  sc.p2 = u.segment<3>(3);
  for (int k = 0; k < K; ++k) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) sc.s[k].R(a, b) = u[6 + 12 * k + 3 * a + b];
    sc.s[k].p = u.segment<3>(6 + 12 * k + 9);
    sc.s[k].surface = &sc.surf[k];
  }
  return sc;
}

CompositeWrapResult compose(const Scene& sc, const std::vector<double>& alphas, const std::vector<double>& alphadots,
                            bool moving, double width = 0.0) {
  CompositeWrapResult r;
  std::vector<CompositeWrapSurface> s = sc.s;
  for (size_t k = 0; k < s.size(); ++k) {
    s[k].surface = &sc.surf[k];
    if (!moving) s[k].Rdot.setZero(), s[k].pdot.setZero();
  }
  calcSmoothCompositeWrap(s, sc.p1, sc.p2, moving ? sc.v1 : Vec3::Zero(), moving ? sc.v2 : Vec3::Zero(), alphas,
                          moving ? alphadots : std::vector<double>{}, width, r);
  return r;
}

bool outsideBands(const CompositeWrapResult& r) {
  for (double w : r.weights)
    if (w != 0.0 && w != 1.0) return false;
  return true;
}

TEST(WrapSmoothComposite, EqualsTheLibrarysConvergedPathOutsideTheBands) {
 for (const bool sphere : {false, true}) {
  std::mt19937 rng(22);
  const std::vector<double> alphas{0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0};
  int clean = 0, both = 0, one = 0, banded = 0, unconverged = 0, mismatch = 0;
  double worst = 0.0, worst_len = 0.0, worst_opensim = 0.0;
  int max_newton = 0;
  for (int n = 0; n < 2000; ++n) {
    const Scene sc = randomScene(rng, 2, sphere);
    const CompositeWrapResult r = compose(sc, alphas, {}, false);
    max_newton = std::max(max_newton, r.newton_iterations);
    if (!outsideBands(r)) {
      ++banded;
      continue;
    }
    const test::ConvergedLibraryPath lib = test::convergeLibraryPath(sc.s, r.order, sc.p1, sc.p2);
    if (!lib.converged) {
      if (unconverged < 4)
        std::printf("unconverged: last move %.3e, wraps %d %d, weights %g %g\n", lib.last_moved, int(lib.wraps[0]),
                    int(lib.wraps[1]), r.weights[0], r.weights[1]);
      ++unconverged;
      continue;
    }
    // the library wraps exactly the surfaces the composition gives weight 1
    bool same = true;
    for (size_t k = 0; k < sc.s.size(); ++k) same = same && lib.wraps[k] == (r.weights[k] == 1.0);
    if (!same) {
      ++mismatch;
      continue;
    }
    ++clean;
    const int nw = (r.weights[0] == 1.0) + (r.weights[1] == 1.0);
    both += nw == 2;
    one += nw == 1;
    worst_len = std::max(worst_len, std::abs(r.length - lib.length));
    for (size_t a = 0; a < alphas.size(); ++a)
      worst = std::max(worst, (r.x[a] - test::convergedLibraryPoint(sc.s, lib, alphas[a])).norm());
    if (nw == 2) {
      // OpenSim's own passes (calcWrappedPathAt: 8 passes at most, stopping at a 0.5 mm length
      // change, its cylinder's 2 mm tangency correction): measured only
      MusclePath path;
      path.points = {makeFixedPoint(-1, sc.p1, "p1"), makeFixedPoint(-1, sc.p2, "p2")};
      std::vector<Mat4> E_ws;
      for (size_t k = 0; k < sc.s.size(); ++k) {
        PathWrap w;
        w.name = "c" + std::to_string(k);
        w.surface = sc.surf[k];
        w.body = -1;
        w.E_bs = makeE(sc.s[k].R, sc.s[k].p);
        path.wraps.push_back(w);
        E_ws.push_back(w.E_bs);
      }
      path.num_wraps = 2;
      const WrappedPath wp = calcWrappedPathAt(path, {0, 1}, {sc.p1, sc.p2}, E_ws);
      for (size_t a = 0; a < alphas.size(); ++a)
        worst_opensim = std::max(worst_opensim, (r.x[a] - calcWrappedPathPointAt(wp, E_ws, alphas[a])).norm());
    }
  }
  std::printf("[ measured ] %s on one segment, 2000 random: %d outside the bands (%d both wrapped, %d one), "
              "%d in a band, %d where the library does not converge, %d where it wraps other surfaces; max |x - "
              "converged library| %.1e m, |L - L_lib| %.1e m; both wrapped, against OpenSim's passes (calcWrappedPathAt) "
              "%.1e m; Newton iterations at most %d\n",
              sphere ? "a cylinder and a sphere" : "two cylinders", clean, both, one, banded, unconverged, mismatch, worst,
              worst_len, worst_opensim, max_newton);
  EXPECT_GT(both, 100);
  EXPECT_GT(one, 100);
  EXPECT_EQ(unconverged, 0);
  EXPECT_EQ(mismatch, 0);
  EXPECT_LE(worst, 1e-12);
  EXPECT_LE(worst_len, 1e-12);
 }
}

// central differences of the composition in all its inputs (u, then alpha) and of J along the rates
void checkAgainstDifferences(int K, bool sphere, int count, unsigned seed, double* worst_J, double* worst_Jdot, int* checked,
                             int* skipped, int* in_band) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(-1.0, 1.0);
  const std::vector<double> alphas{0.05, 0.25, 0.45, 0.65, 0.85};
  const double h = 1e-6;
  for (int n = 0; n < count; ++n) {
    const Scene sc = randomScene(rng, K, sphere);
    std::vector<double> alphadots;
    for (size_t a = 0; a < alphas.size(); ++a) alphadots.push_back(0.2 * u01(rng));
    const CompositeWrapResult r = compose(sc, alphas, alphadots, true);
    if (!outsideBands(r)) ++*in_band;
    const int N = r.inputs;
    const VecX u = packInputs(sc), ud = packRates(sc);
    // J: central differences with steps h and 2h, Richardson-extrapolated (error O(h^4): in bands
    // of 2.5-4.5 mm the third derivatives make the O(h^2) error of one step reach 1e-6 of J)
    std::vector<MatX> J_fd(alphas.size(), MatX::Zero(3, N));
    for (int i = 0; i < N; ++i)
      for (const double step : {h, 2 * h}) {
        const double c = step == h ? 4.0 / 3.0 : -1.0 / 3.0;
        std::vector<Vec3> xp, xm;
        if (i < N - 1) {
          VecX up = u, um = u;
          up[i] += step;
          um[i] -= step;
          xp = compose(unpack(sc, up), alphas, {}, false).x;
          xm = compose(unpack(sc, um), alphas, {}, false).x;
        } else {
          std::vector<double> ap = alphas, am = alphas;
          for (size_t a = 0; a < alphas.size(); ++a) ap[a] += step, am[a] -= step;
          xp = compose(sc, ap, {}, false).x;
          xm = compose(sc, am, {}, false).x;
        }
        for (size_t a = 0; a < alphas.size(); ++a) J_fd[a].col(i) += c * (xp[a] - xm[a]) / (2 * step);
      }
    // Jdot: J along the rates (u + t ud, alpha + t alphadot), steps h and 2h (convergence test)
    auto Jat = [&](double t) {
      std::vector<double> at = alphas;
      for (size_t a = 0; a < alphas.size(); ++a) at[a] += t * alphadots[a];
      return compose(unpack(sc, u + t * ud), at, {}, false).J;
    };
    const std::vector<MatX> Jp = Jat(h), Jm = Jat(-h), Jp2 = Jat(2 * h), Jm2 = Jat(-2 * h);
    for (size_t a = 0; a < alphas.size(); ++a) {
      const MatX Jdot_h = (Jp[a] - Jm[a]) / (2 * h), Jdot_fd2 = (Jp2[a] - Jm2[a]) / (4 * h);
      const MatX Jdot_fd = (4.0 * Jdot_h - Jdot_fd2) / 3.0;
      if ((Jdot_fd2 - Jdot_h).norm() > 1e-5 * (1.0 + Jdot_h.norm())) {
        ++*skipped;  // the stencil straddles a piece boundary (a point crossing a tangent point)
        continue;
      }
      ++*checked;
      *worst_J = std::max(*worst_J, (r.J[a] - J_fd[a]).norm() / (1.0 + J_fd[a].norm()));
      *worst_Jdot = std::max(*worst_Jdot, (r.Jdot[a] - Jdot_fd).norm() / (1.0 + Jdot_fd.norm()));
    }
  }
}

TEST(WrapSmoothComposite, JacobianAndJdotMatchCentralDifferences) {
  for (int K : {2, 3}) for (const bool sphere : {false, true}) {
    double wJ = 0.0, wJd = 0.0;
    int checked = 0, skipped = 0, in_band = 0;
    checkAgainstDifferences(K, sphere, K == 2 ? 60 : 20, 7 + K, &wJ, &wJd, &checked, &skipped, &in_band);
    std::printf("[ measured ] %d surfaces (%s) on one segment: %d points checked (%d scenes with a surface in its band), "
                "%d skipped (stencil across a tangent point); worst relative J error %.1e, Jdot %.1e\n",
                K, sphere ? "the last a sphere" : "cylinders", checked, in_band, skipped, wJ, wJd);
    EXPECT_GE(checked, K == 2 ? 250 : 80);
    EXPECT_GE(in_band, K == 2 ? 2 : 1);  // measured 8, 7 (K = 2), 1, 2 (K = 3)
    EXPECT_LE(wJ, 1e-6);
    EXPECT_LE(wJd, 1e-6);
  }
}

TEST(WrapSmoothComposite, C2AcrossEachSurfacesContactChange) {
  // two cylinders of radius 0.06 m 0.3 m apart; sweep 1 moves p2 down through B's contact with A
  // wrapped, sweep 2 moves p1 down through A's contact with B wrapped
  WrapSurface cyl = WrapSurface::makeCylinder(0.06, 1.0);
  Scene base;
  base.surf = {cyl, cyl};
  base.s.resize(2);
  base.s[0].p = Vec3(0.0, 0.0, 0.0);
  base.s[1].R = Eigen::AngleAxisd(0.2, Vec3::UnitX()).toRotationMatrix();
  base.s[1].p = Vec3(0.3, 0.0, 0.0);
  for (int sweep = 0; sweep < 2; ++sweep) {
    const int moving = sweep == 0 ? 1 : 0;  // the surface whose contact changes
    Scene sc = base;
    const Vec3 a0 = sweep == 0 ? Vec3(-0.25, 0.02, 0.01) : Vec3(-0.25, 0.12, 0.01);
    const Vec3 b0 = sweep == 0 ? Vec3(0.55, 0.12, -0.02) : Vec3(0.55, 0.02, -0.02);
    const Vec3 dir(0.0, -0.1, 0.0);
    auto at = [&](double t) {
      Scene x = sc;
      x.p1 = sweep == 1 ? Vec3(a0 + t * dir) : a0;
      x.p2 = sweep == 0 ? Vec3(b0 + t * dir) : b0;
      x.v1 = sweep == 1 ? dir : Vec3::Zero();
      x.v2 = sweep == 0 ? dir : Vec3::Zero();
      return x;
    };
    const double alpha = 0.7 - 0.4 * sweep;  // a point on the moving surface's side
    auto weight = [&](double t) { return compose(at(t), {alpha}, {0.0}, true).weights[moving]; };
    ASSERT_EQ(weight(0.0), 0.0);
    ASSERT_EQ(weight(1.0), 1.0);
    ASSERT_EQ(compose(at(0.0), {alpha}, {0.0}, true).weights[1 - moving], 1.0);
    auto bisect = [&](auto&& inside) {
      double lo = 0.0, hi = 1.0;
      for (int k = 0; k < 200; ++k) (inside(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
      return 0.5 * (lo + hi);
    };
    const double t_in = bisect([&](double t) { return weight(t) > 0.0; });
    const double t_out = bisect([&](double t) { return weight(t) >= 1.0; });
    ASSERT_LT(t_in, t_out);
    for (double t0 : {t_in, t_out}) {
      auto derivs = [&](double t, Vec3& x1, Vec3& x2) {
        const Scene x = at(t);
        const CompositeWrapResult r = compose(x, {alpha}, {0.0}, true);
        const int c = sweep == 0 ? 3 : 0;
        x1 = r.J[0].middleCols<3>(c) * dir;
        x2 = r.Jdot[0].middleCols<3>(c) * dir;
      };
      const test::EdgeGaps g = test::edgeGaps(derivs, t0);
      ASSERT_TRUE(g.finite);
      std::printf("[ measured ] sweep %d, edge at t = %.6f: x' gaps %.1e, %.1e; x'' gaps %.1e, %.1e (|x''| %.1e)\n",
                  sweep, t0, g.gap1[0], g.gap1[1], g.gap2[0], g.gap2[1], g.x2);
      EXPECT_LT(g.gap1[1], 1e-6);
      EXPECT_LT(g.gap2[1], 1e-2 * (1.0 + g.x2));
      EXPECT_LE(g.gap1[1], 0.15 * g.gap1[0] + 1e-15);
      // measured ratio 0.14 (inner edge) and 0.17 (outer edge; 0.10 between 1e-5 and 1e-6, 0.11
      // between 1e-7 and 1e-8): no jump, the gap shrinks with the distance
      EXPECT_LE(g.gap2[1], 0.2 * g.gap2[0] + 1e-12);
    }
  }
}

TEST(WrapSmoothComposite, OneSurfaceIsTheSmoothModel) {
  std::mt19937 rng(3);
  double worst_x = 0.0, worst_J = 0.0, worst_Jdot = 0.0;
  const std::vector<double> alphas{0.0, 0.2, 0.4, 0.6, 0.8, 1.0};
  for (int n = 0; n < 300; ++n) {
    Scene sc = randomScene(rng, 1);
    sc.s[0].R.setIdentity();
    sc.s[0].p.setZero();
    sc.s[0].Rdot.setZero();  // a still surface: the single model's frame
    sc.s[0].pdot.setZero();
    const CompositeWrapResult r = compose(sc, alphas, {}, true);
    for (size_t a = 0; a < alphas.size(); ++a) {
      const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(sc.surf[0], sc.p1, sc.p2, alphas[a], sc.v1, sc.v2);
      worst_x = std::max(worst_x, (r.x[a] - sp.x).norm());
      worst_J = std::max(worst_J, (r.J[a].leftCols<6>() - sp.J).norm());
      worst_Jdot = std::max(worst_Jdot, (r.Jdot[a].leftCols<6>() - sp.Jdot).norm());
    }
  }
  std::printf("[ measured ] one surface against the single-surface smooth model: x %.1e m, J %.1e, Jdot %.1e\n", worst_x,
              worst_J, worst_Jdot);
  EXPECT_LE(worst_x, 1e-15);
  EXPECT_LE(worst_J, 1e-13);
  EXPECT_LE(worst_Jdot, 1e-12);
}

TEST(WrapSmoothComposite, RefusesWhatItCannotCompose) {
  WrapSurface cyl = WrapSurface::makeCylinder(0.05, 1.0);
  std::vector<CompositeWrapSurface> s(4);
  for (auto& x : s) x.surface = &cyl;
  CompositeWrapResult r;
  EXPECT_THROW(calcSmoothCompositeWrap(s, Vec3(-1, 0.1, 0), Vec3(1, 0.1, 0), Vec3::Zero(), Vec3::Zero(), {}, {}, 0.0, r),
               std::invalid_argument);
  s.resize(2);
  s[1].p = Vec3(0.3, 0, 0);
  // an end inside a surface
  EXPECT_THROW(calcSmoothCompositeWrap(s, Vec3(0.01, 0, 0), Vec3(1, 0.1, 0), Vec3::Zero(), Vec3::Zero(), {}, {}, 0.0, r),
               std::invalid_argument);
  // parallel axes with every point in their common normal plane: I - dF/dx is singular (the path
  // may slide along the axes), an error rather than NaN
  try {
    calcSmoothCompositeWrap(s, Vec3(-1, 0.03, 0), Vec3(1, 0.03, 0), Vec3::Zero(), Vec3::Zero(), {0.5}, {}, 0.0, r);
    ADD_FAILURE() << "a degenerate fixed point was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("degenerate fixed point"), std::string::npos) << e.what();
  }
  // tilt one axis: a fixed point again
  s[1].R = Eigen::AngleAxisd(0.2, Vec3::UnitX()).toRotationMatrix();
  EXPECT_NO_THROW(calcSmoothCompositeWrap(s, Vec3(-1, 0.03, 0), Vec3(1, 0.03, 0), Vec3::Zero(), Vec3::Zero(), {0.5}, {},
                                          0.0, r));
  EXPECT_EQ(r.weights, (std::vector<double>{1.0, 1.0}));
}

}  // namespace
}  // namespace redmax
