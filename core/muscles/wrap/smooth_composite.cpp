#include "core/muscles/wrap/smooth_composite.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "core/muscles/wrap/smooth.hpp"
#include "core/muscles/wrap/smooth_jet.hpp"

namespace redmax {
namespace {

using namespace detail;

// a surface's pose over jets: x_common = R x_s + p
template <int M>
struct PoseJ {
  std::array<std::array<Jet<M>, 3>, 3> R{};
  V3<Jet<M>> p{};
};

template <int M>
V3<Jet<M>> toLocal(const PoseJ<M>& f, const V3<Jet<M>>& x) {
  const V3<Jet<M>> d = x - f.p;
  V3<Jet<M>> out;
  for (int b = 0; b < 3; ++b) out[b] = f.R[0][b] * d[0] + f.R[1][b] * d[1] + f.R[2][b] * d[2];
  return out;
}

template <int M>
V3<Jet<M>> toCommon(const PoseJ<M>& f, const V3<Jet<M>>& y) {
  V3<Jet<M>> out;
  for (int a = 0; a < 3; ++a) out[a] = f.p[a] + (f.R[a][0] * y[0] + f.R[a][1] * y[1] + f.R[a][2] * y[2]);
  return out;
}

template <int M>
PoseJ<M> constantPose(const CompositeWrapSurface& s) {
  PoseJ<M> f;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) f.R[a][b] = Jet<M>(s.R(a, b));
    f.p[a] = Jet<M>(s.p[a]);
  }
  return f;
}

template <int M>
V3<Jet<M>> constantV(const Vec3& v) {
  return {Jet<M>(v[0]), Jet<M>(v[1]), Jet<M>(v[2])};
}

// where along the straight line p1 -> p2 it comes closest to the surface (the cylinder's axis,
// the other shapes' centres): the order of the surfaces along the segment (header)
double closestApproach(const CompositeWrapSurface& s, const Vec3& p1, const Vec3& p2) {
  const Vec3 q1 = s.R.transpose() * (p1 - s.p), q2 = s.R.transpose() * (p2 - s.p);
  const Vec3 u = q2 - q1;
  if (s.surface->type == WrapType::Cylinder) {
    const double uu = u[0] * u[0] + u[1] * u[1];
    if (uu > 1e-300) return -(q1[0] * u[0] + q1[1] * u[1]) / uu;
  }
  const double uu = u.squaredNorm();
  return uu > 0.0 ? -q1.dot(u) / uu : 0.5;
}

// the surfaces' maps for given inner points (header): e[m] (m < K - 1) where the path leaves
// surface m, s[m] (m >= 1) where it reaches it, all in path order
template <int M, int K>
struct Chain {
  std::vector<SmoothWrapJetSegment<M>> seg;
  std::array<V3<Jet<M>>, K> e_new{}, s_new{};
};

template <int M, int K>
void evalChain(const std::vector<const WrapSurface*>& surf, const std::vector<PoseJ<M>>& pose, const V3<Jet<M>>& P1,
               const V3<Jet<M>>& P2, const std::array<V3<Jet<M>>, K>& e, const std::array<V3<Jet<M>>, K>& s,
               double width, Chain<M, K>& out) {
  out.seg.clear();
  out.seg.reserve(K);
  for (int m = 0; m < K; ++m) {
    const V3<Jet<M>>& a = m == 0 ? P1 : e[m - 1];
    const V3<Jet<M>>& b = m == K - 1 ? P2 : s[m + 1];
    out.seg.emplace_back(*surf[m], toLocal(pose[m], a), toLocal(pose[m], b), width);
    const SmoothWrapJetSegment<M>& sg = out.seg.back();
    out.e_new[m] = a + sg.weight * (toCommon(pose[m], sg.r2) - a);
    out.s_new[m] = b + sg.weight * (toCommon(pose[m], sg.r1) - b);
  }
}

// the fixed point on values: one sweep of the passes, then Newton with the exact Jacobian
// (jets seeded by the unknowns); Gx = dG/dx at the solution, G(x) = x - F(x)
template <int K>
int solveValues(const std::vector<const WrapSurface*>& surf, const std::vector<CompositeWrapSurface>& ordered,
                const Vec3& p1, const Vec3& p2, double width, std::array<Vec3, K>& e, std::array<Vec3, K>& s,
                MatX& Gx) {
  constexpr int M = 6 * (K - 1);
  using JM = Jet<M>;
  std::vector<PoseJ<M>> pose;
  for (const auto& o : ordered) pose.push_back(constantPose<M>(o));
  const V3<JM> P1 = constantV<M>(p1), P2 = constantV<M>(p2);
  // one sweep: leaving points forward with the far ends at p2, then reaching points backward
  {
    std::array<V3<JM>, K> ej{}, sj{};
    for (int m = 0; m < K; ++m) sj[m] = P2;
    for (int m = 0; m + 1 < K; ++m) {
      const V3<JM>& a = m == 0 ? P1 : ej[m - 1];
      SmoothWrapJetSegment<M> sg(*surf[m], toLocal(pose[m], a), toLocal(pose[m], P2), width);
      ej[m] = a + sg.weight * (toCommon(pose[m], sg.r2) - a);
    }
    for (int m = K - 1; m >= 1; --m) {
      const V3<JM>& a = ej[m - 1];
      const V3<JM>& b = m == K - 1 ? P2 : sj[m + 1];
      SmoothWrapJetSegment<M> sg(*surf[m], toLocal(pose[m], a), toLocal(pose[m], b), width);
      sj[m] = b + sg.weight * (toCommon(pose[m], sg.r1) - b);
    }
    for (int m = 0; m < K; ++m) e[m] = values(ej[m]), s[m] = values(sj[m]);
  }
  auto residual = [&](bool seeded, VecX& G, MatX* J) {
    std::array<V3<JM>, K> ej{}, sj{};
    for (int m = 0; m + 1 < K; ++m)
      for (int c = 0; c < 3; ++c) {
        ej[m][c] = JM(e[m][c]);
        sj[m + 1][c] = JM(s[m + 1][c]);
        if (seeded) ej[m][c].g[6 * m + c] = 1.0, sj[m + 1][c].g[6 * m + 3 + c] = 1.0;
      }
    Chain<M, K> ch;
    evalChain<M, K>(surf, pose, P1, P2, ej, sj, width, ch);
    G.resize(M);
    if (J) J->setIdentity(M, M);
    for (int m = 0; m + 1 < K; ++m)
      for (int c = 0; c < 3; ++c) {
        G[6 * m + c] = e[m][c] - ch.e_new[m][c].v;
        G[6 * m + 3 + c] = s[m + 1][c] - ch.s_new[m + 1][c].v;
        if (J)
          for (int i = 0; i < M; ++i) {
            (*J)(6 * m + c, i) -= ch.e_new[m][c].g[i];
            (*J)(6 * m + 3 + c, i) -= ch.s_new[m + 1][c].g[i];
          }
      }
  };
  auto step = [&](const VecX& dx, double lambda) {
    for (int m = 0; m + 1 < K; ++m) {
      e[m] -= lambda * dx.segment<3>(6 * m);
      s[m + 1] -= lambda * dx.segment<3>(6 * m + 3);
    }
  };
  double scale = 1.0;
  for (const Vec3& v : {p1, p2}) scale = std::max(scale, v.cwiseAbs().maxCoeff());
  const double tol = 1e-14 * scale;
  VecX G, Gt;
  // the passes themselves (x <- F(x)) first: within a band the maps are steep (the weight's slope
  // over a band of a few mm times a lever of tens of cm), where Newton from the sweep can stall far
  // from the root, while the passes contract toward it; Newton then finishes quadratically
  auto passes = [&](int n) {
    double best = std::numeric_limits<double>::infinity();
    int stalled = 0;
    for (int it = 0; it < n; ++it) {
      residual(false, G, nullptr);
      const double g = G.cwiseAbs().maxCoeff();
      if (!std::isfinite(g) || g <= tol) return;
      stalled = g < 0.5 * best ? 0 : stalled + 1;
      best = std::min(best, g);
      if (stalled > 10) return;
      step(G, 1.0);
    }
  };
  passes(60);
  residual(true, G, &Gx);
  bool retried = false;
  for (int it = 1; it <= 80; ++it) {
    const double g0 = G.cwiseAbs().maxCoeff();
    if (!std::isfinite(g0)) break;
    if (g0 <= tol) return it;
    const VecX dx = Gx.partialPivLu().solve(G);
    if (!dx.allFinite()) break;
    // halve the step while the residual grows (rarely needed: the maps are contractions away
    // from degenerate configurations)
    double lambda = 1.0;
    bool ok = false;
    for (int h = 0; h < 12; ++h) {
      step(dx, lambda);
      residual(false, Gt, nullptr);
      const double g1 = Gt.cwiseAbs().maxCoeff();
      if (std::isfinite(g1) && (g1 < g0 || g1 <= tol)) {
        ok = true;
        break;
      }
      step(dx, -lambda);
      lambda *= 0.5;
    }
    if (!ok) {
      // round-off floor: accept a residual near the tolerance
      if (g0 <= 1e3 * tol) return it;
      if (retried) break;
      // Newton stalled: more passes, then Newton again
      retried = true;
      passes(500);
    }
    residual(true, G, &Gx);
  }
  throw std::invalid_argument(
      "the smooth composition of wrap objects on one segment found no fixed point (degenerate: surfaces touching, or "
      "a path that bends back through the next surface)");
}

template <class T>
T smoothstep(const T& v) {
  return v * v * v * (10.0 + v * (-15.0 + 6.0 * v));
}

template <int N>
Jet<N> clamp01(const Jet<N>& v) {
  if (v.v < 0.0) return Jet<N>(0.0);
  if (v.v > 1.0) return Jet<N>(1.0);
  return v;
}

template <int K>
void compose(const std::vector<CompositeWrapSurface>& surfaces, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
             const Vec3& p2dot, const std::vector<double>& alphas, const std::vector<double>& alphadots, double width,
             CompositeWrapResult& out) {
  constexpr int N = 7 + 12 * K;
  using J = Jet<N>;
  using V = V3<J>;
  // order along the segment
  std::vector<double> t(K);
  for (int k = 0; k < K; ++k) t[k] = closestApproach(surfaces[k], p1, p2);
  std::vector<int> order(K);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return t[a] < t[b]; });
  std::vector<const WrapSurface*> surf;
  std::vector<CompositeWrapSurface> ordered;
  for (int k : order) surf.push_back(surfaces[k].surface), ordered.push_back(surfaces[k]);
  // inputs as jets (header: u = (p1, p2, R_1, p_1, ..., alpha), caller's surface indices)
  V P1, P2;
  for (int c = 0; c < 3; ++c) {
    P1[c] = J(p1[c]);
    P1[c].t = p1dot[c];
    P1[c].g[c] = 1.0;
    P2[c] = J(p2[c]);
    P2[c].t = p2dot[c];
    P2[c].g[3 + c] = 1.0;
  }
  std::vector<PoseJ<N>> pose(K);
  for (int m = 0; m < K; ++m) {
    const int k = order[m];
    const CompositeWrapSurface& s = surfaces[k];
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        J& r = pose[m].R[a][b];
        r = J(s.R(a, b));
        r.t = s.Rdot(a, b);
        r.g[6 + 12 * k + 3 * a + b] = 1.0;
      }
      J& q = pose[m].p[a];
      q = J(s.p[a]);
      q.t = s.pdot[a];
      q.g[6 + 12 * k + 9 + a] = 1.0;
    }
  }
  // the fixed point: values, then two Newton steps over the jets with the converged Jacobian
  std::array<V, K> ej{}, sj{};
  out.newton_iterations = 0;
  if constexpr (K > 1) {
    std::array<Vec3, K> e{}, s{};
    MatX Gx;
    out.newton_iterations = solveValues<K>(surf, ordered, p1, p2, width, e, s, Gx);
    // a singular I - dF/dx: the fixed point is not locally unique (e.g. parallel cylinders with
    // every point in their common normal plane: the path may slide along the axes), no derivative
    const Eigen::PartialPivLU<MatX> lu(Gx);
    const MatX Minv = lu.inverse();
    if (!Minv.allFinite() || !(lu.rcond() > 1e-12))
      throw std::invalid_argument(
          "the smooth composition of wrap objects on one segment has a degenerate fixed point here (I - dF/dx "
          "singular: the path is not locally unique)");
    for (int m = 0; m < K; ++m) ej[m] = constantV<N>(e[m]), sj[m] = constantV<N>(s[m]);
    for (int it = 0; it < 2; ++it) {
      Chain<N, K> ch;
      evalChain<N, K>(surf, pose, P1, P2, ej, sj, width, ch);
      std::vector<J> G(6 * (K - 1));
      for (int m = 0; m + 1 < K; ++m)
        for (int c = 0; c < 3; ++c) {
          G[6 * m + c] = ej[m][c] - ch.e_new[m][c];
          G[6 * m + 3 + c] = sj[m + 1][c] - ch.s_new[m + 1][c];
        }
      for (int m = 0; m + 1 < K; ++m)
        for (int c = 0; c < 3; ++c)
          for (int i = 0; i < 6 * (K - 1); ++i) {
            ej[m][c] = ej[m][c] - Minv(6 * m + c, i) * G[i];
            sj[m + 1][c] = sj[m + 1][c] - Minv(6 * m + 3 + c, i) * G[i];
          }
    }
  }
  Chain<N, K> ch;
  evalChain<N, K>(surf, pose, P1, P2, ej, sj, width, ch);
  // the path (header): start of each curve, fades, length
  std::array<J, K> T{}, sig{}, h{};
  sig[0] = J(0.0);
  for (int m = 0; m < K; ++m) {
    T[m] = ch.seg[m].length;
    if (m + 1 < K) sig[m + 1] = sig[m] + ch.seg[m].weight * ch.seg[m].lead;
  }
  const J L = sig[K - 1] + T[K - 1];
  if (!std::isfinite(L.v))
    throw std::invalid_argument("the smooth composition of wrap objects on one segment is not finite here");
  for (int m = 0; m + 1 < K; ++m) {
    const J a = T[m] - (sig[m + 1] - sig[m]), b = T[m + 1];
    h[m] = (a * b) / (a + b);
  }
  auto curve = [&](int m, const J& s) { return toCommon(pose[m], ch.seg[m].point(clamp01((s - sig[m]) / T[m]))); };
  auto pointAt = [&](const J& s) {
    V X = curve(0, s);
    for (int m = 0; m + 1 < K; ++m) {
      if (!(s.v > sig[m + 1].v)) break;
      const V next = curve(m + 1, s);
      if (!(h[m].v > 1e-14 * L.v)) {  // no straight piece between the surfaces (degenerate)
        X = next;
        continue;
      }
      const J v = (s - sig[m + 1]) / h[m];
      if (v.v >= 1.0) {
        X = next;
      } else {
        const J phi = smoothstep(v);
        X = X + phi * (next - X);
      }
    }
    return X;
  };
  out.inputs = N;
  out.order = order;
  out.weights.assign(K, 0.0);
  for (int m = 0; m < K; ++m) out.weights[order[m]] = ch.seg[m].weight.v;
  out.length = L.v;
  out.length_rate = L.t;
  out.J_L.resize(N);
  out.Jdot_L.resize(N);
  for (int i = 0; i < N; ++i) out.J_L[i] = L.g[i], out.Jdot_L[i] = L.gt[i];
  const size_t n = alphas.size();
  out.x.resize(n);
  out.J.resize(n);
  out.Jdot.resize(n);
  for (size_t a = 0; a < n; ++a) {
    J al(std::clamp(alphas[a], 0.0, 1.0));
    al.t = alphadots.empty() ? 0.0 : alphadots[a];
    al.g[N - 1] = 1.0;
    const V x = pointAt(al * L);
    out.J[a].resize(3, N);
    out.Jdot[a].resize(3, N);
    for (int c = 0; c < 3; ++c) {
      out.x[a][c] = x[c].v;
      for (int i = 0; i < N; ++i) out.J[a](c, i) = x[c].g[i], out.Jdot[a](c, i) = x[c].gt[i];
    }
  }
}

}  // namespace

void calcSmoothCompositeWrap(const std::vector<CompositeWrapSurface>& surfaces, const Vec3& p1, const Vec3& p2,
                             const Vec3& p1dot, const Vec3& p2dot, const std::vector<double>& alphas,
                             const std::vector<double>& alphadots, double width, CompositeWrapResult& out) {
  const int K = static_cast<int>(surfaces.size());
  if (K < 1 || K > 3)
    throw std::invalid_argument("the smooth composition takes 1 to 3 wrap objects on one segment, not " +
                                std::to_string(K));
  if (!alphadots.empty() && alphadots.size() != alphas.size())
    throw std::invalid_argument("smooth composition: alphadots must be empty or one per alpha");
  if (!p1.allFinite() || !p2.allFinite() || p1 == p2)
    throw std::invalid_argument("smooth composition: degenerate end points");
  for (const CompositeWrapSurface& s : surfaces) {
    if (!s.surface) throw std::invalid_argument("smooth composition: no surface");
    const std::string why = smoothWrapUnsupportedReason(*s.surface);
    if (!why.empty()) throw std::invalid_argument("smooth wrap: " + why);
    if (s.surface->contains(s.R.transpose() * (p1 - s.p)) || s.surface->contains(s.R.transpose() * (p2 - s.p)))
      throw std::invalid_argument("smooth wrap: an end point lies inside the surface");
  }
  switch (K) {
    case 1: compose<1>(surfaces, p1, p2, p1dot, p2dot, alphas, alphadots, width, out); break;
    case 2: compose<2>(surfaces, p1, p2, p1dot, p2dot, alphas, alphadots, width, out); break;
    default: compose<3>(surfaces, p1, p2, p1dot, p2dot, alphas, alphadots, width, out); break;
  }
}

double calcSmoothCompositeWrapPoints(const std::vector<CompositeWrapSurface>& surfaces, const Vec3& p1,
                                     const Vec3& p2, const std::vector<double>& alphas, double width,
                                     std::vector<Vec3>& x) {
  CompositeWrapResult r;
  calcSmoothCompositeWrap(surfaces, p1, p2, Vec3::Zero(), Vec3::Zero(), alphas, {}, width, r);
  x = r.x;
  return r.length;
}

}  // namespace redmax
