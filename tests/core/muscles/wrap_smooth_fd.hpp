#pragma once
// Central differences of the smooth wrap model's point (core/muscles/wrap/smooth.hpp), shared by
// the cylinder/sphere, torus and ellipsoid tests: J = dx/d(p1, p2) from the points, Jdot from J
// along (v1, v2), and whether the differences have converged (their error falls as h^2, so
// FD(2h) - FD(h) is 3 times it): a stencil that straddles a piece boundary of the construction (a
// mass point crossing a tangent point, the library switching roots or cases) is no test of the
// derivatives, and callers skip it.
#include <algorithm>
#include <Eigen/Core>

#include "core/muscles/wrap/smooth.hpp"

namespace redmax::test {

struct SmoothWrapFd {
  Eigen::Matrix<double, 3, 6> J, Jdot;
  bool converged = false;  ///< Jdot by steps 2h and h: |d| <= converge_tol (1 + |Jdot|)
};

inline SmoothWrapFd calcSmoothWrapFd(const WrapSurface& s, const Vec3& p1, const Vec3& p2, double alpha,
                                     const Vec3& v1, const Vec3& v2, const SmoothWrapOptions& opt, double h,
                                     double converge_tol) {
  SmoothWrapFd fd;
  for (int i = 0; i < 6; ++i) {
    Vec3 a1 = p1, a2 = p2, b1 = p1, b2 = p2;
    (i < 3 ? a1 : a2)[i % 3] += h;
    (i < 3 ? b1 : b2)[i % 3] -= h;
    fd.J.col(i) = (calcSmoothWrapPoint(s, a1, a2, alpha, opt) - calcSmoothWrapPoint(s, b1, b2, alpha, opt)) / (2 * h);
  }
  auto J = [&](double t) { return calcSmoothWrapPointDerivatives(s, p1 + t * v1, p2 + t * v2, alpha, v1, v2, opt).J; };
  fd.Jdot = (J(h) - J(-h)) / (2 * h);
  const Eigen::Matrix<double, 3, 6> Jdot2 = (J(2 * h) - J(-2 * h)) / (4 * h);
  fd.converged = (Jdot2 - fd.Jdot).norm() <= converge_tol * (1.0 + fd.Jdot.norm());
  return fd;
}

// t in [0, 1] where an increasing penetration pen(t) equals target (bisection)
template <class Pen>
double whereAlong(Pen&& pen, double target) {
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (pen(mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// C2 check at a band edge t0: the jumps of derivs' first and second derivatives (x1, x2) across t0
// at distances 1e-6 and 1e-7, and the largest |x2| seen at the nearer one
struct EdgeGaps {
  double gap1[2] = {0.0, 0.0}, gap2[2] = {0.0, 0.0};
  double x2 = 0.0;
  bool finite = true;
};
template <class Derivs>
EdgeGaps edgeGaps(Derivs&& derivs, double t0) {
  EdgeGaps g;
  for (int k = 0; k < 2; ++k) {
    const double e = k == 0 ? 1e-6 : 1e-7;
    Vec3 a1, a2, b1, b2;
    derivs(t0 - e, a1, a2);
    derivs(t0 + e, b1, b2);
    g.finite = g.finite && a1.allFinite() && a2.allFinite() && b1.allFinite() && b2.allFinite();
    g.gap1[k] = (a1 - b1).norm();
    g.gap2[k] = (a2 - b2).norm();
    g.x2 = std::max(a2.norm(), b2.norm());
  }
  return g;
}

}  // namespace redmax::test
