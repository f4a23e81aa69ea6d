#include "core/muscles/wrap_composite.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/muscles/via_point.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/muscles/wrap/smooth_composite.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {
namespace {

CompositeWrapSurface compositeSurface(const PathWrap& w, const WrapSurfaceMotion& m) {
  CompositeWrapSurface c;
  c.surface = &w.surface;
  c.R = m.R;
  c.p = m.p;
  c.Rdot = skew(m.omega) * m.R;
  c.pdot = m.pdot;
  return c;
}

// rows of du/dq and d/dt du/dq for a wrapped segment (header of wrap_composite.hpp): the ends,
// each surface's rotation entries and origin; the fraction's row is the caller's
void segmentInputRows(const std::vector<int>& set, const std::vector<WrapSurfaceMotion>& surfaces,
                      const MuscleKinematics& mk, int i, bool vel, MatX& U, MatX& Udot) {
  const int k = static_cast<int>(mk.cols.size());
  const int K = static_cast<int>(set.size());
  const int N = 7 + 12 * K;
  U.setZero(N, k);
  U.middleRows<3>(0) = mk.J_xr.middleRows<3>(3 * i);
  U.middleRows<3>(3) = mk.J_xr.middleRows<3>(3 * (i + 1));
  if (vel) {
    Udot.setZero(N, k);
    Udot.middleRows<3>(0) = mk.Jdot_xr.middleRows<3>(3 * i);
    Udot.middleRows<3>(3) = mk.Jdot_xr.middleRows<3>(3 * (i + 1));
  }
  // rows of skew(v) for v the columns of W: skew(v)(a, c) as a row over the columns
  auto skewRow = [](const MatX& W, int a, int c) -> Eigen::RowVectorXd {
    const int n = static_cast<int>(W.cols());
    if (a == c) return Eigen::RowVectorXd::Zero(n);
    static const int idx[3][3] = {{-1, 2, 1}, {2, -1, 0}, {1, 0, -1}};
    static const double sgn[3][3] = {{0, -1, 1}, {1, 0, -1}, {-1, 1, 0}};
    return sgn[a][c] * W.row(idx[a][c]);
  };
  for (int kk = 0; kk < K; ++kk) {
    const WrapSurfaceMotion& m = surfaces[set[kk]];
    const int r0 = 6 + 12 * kk;
    const Mat3 Rdot = skew(m.omega) * m.R;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        // d R(a, b) / dq_j = sum_c skew(J_om e_j)(a, c) R(c, b), and its rate
        for (int c = 0; c < 3; ++c) {
          if (a == c) continue;
          U.row(r0 + 3 * a + b) += m.R(c, b) * skewRow(m.J_om, a, c);
          if (vel) {
            Udot.row(r0 + 3 * a + b) += m.R(c, b) * skewRow(m.Jdot_om, a, c);
            Udot.row(r0 + 3 * a + b) += Rdot(c, b) * skewRow(m.J_om, a, c);
          }
        }
      }
    U.middleRows<3>(r0 + 9) = m.J_p;
    if (vel) Udot.middleRows<3>(r0 + 9) = m.Jdot_p;
  }
}

std::vector<CompositeWrapSurface> compositeSurfaces(const Muscle& muscle, const std::vector<int>& set,
                                                    const std::vector<WrapSurfaceMotion>& surfaces, bool vel) {
  std::vector<CompositeWrapSurface> cs;
  for (int w : set) {
    cs.push_back(compositeSurface(muscle.path.wraps[w], surfaces[w]));
    if (!vel) cs.back().Rdot.setZero(), cs.back().pdot.setZero();
  }
  return cs;
}

}  // namespace

bool hasSharedWrapSegments(const Muscle& muscle) {
  const MusclePath& path = muscle.path;
  const int np = static_cast<int>(path.points.size());
  for (size_t k = 0; k < path.wraps.size(); ++k) {
    if (!path.wraps[k].surface.active) continue;
    int lo = 0, hi = 0;
    wrapRange(path.wraps[k], np, lo, hi);
    for (size_t j = 0; j < k; ++j) {
      if (!path.wraps[j].surface.active) continue;
      int lo2 = 0, hi2 = 0;
      wrapRange(path.wraps[j], np, lo2, hi2);
      if (std::min(hi, hi2) > std::max(lo, lo2)) return true;
    }
  }
  return false;
}

std::vector<std::vector<int>> calcSegmentWrapSets(const Muscle& muscle, const std::vector<int>& active,
                                                  const std::vector<Vec3>& x_w, const std::vector<Mat4>& E_ws) {
  const MusclePath& path = muscle.path;
  const int P = static_cast<int>(x_w.size());
  const int nseg = std::max(P - 1, 0);
  const int np = static_cast<int>(path.points.size());
  const bool single_shape = path.points.size() == 2 && path.wraps.size() == 1;
  std::vector<std::vector<int>> sets(nseg);
  for (size_t w = 0; w < path.wraps.size(); ++w) {
    const PathWrap& pw = path.wraps[w];
    if (!pw.surface.active) continue;
    int first = 0, last = 0;
    if (!wrapSegments(pw, active, np, first, last)) continue;
    const Mat3 R = E_ws[w].topLeftCorner<3, 3>();
    const Vec3 p = E_ws[w].topRightCorner<3, 1>();
    int best = -1;
    double best_d = -std::numeric_limits<double>::infinity();
    for (int i = first; i < last; ++i) {
      if (single_shape) {
        best = i;
        break;
      }
      const Vec3 p1 = R.transpose() * (x_w[i] - p), p2 = R.transpose() * (x_w[i + 1] - p);
      if (endInsideSurface(pw.surface, p1, p2)) continue;  // OpenSim's InsideRadius: no wrap on it
      if (last - first == 1) {
        best = i;
        break;
      }
      const double d = calcWrapPenetration(pw.surface, p1, p2);
      if (d > best_d) {
        best_d = d;
        best = i;
      }
    }
    if (best >= 0) sets[best].push_back(static_cast<int>(w));
  }
  return sets;
}

double calcCompositePathLength(const Muscle& muscle, const std::vector<int>& active, const std::vector<Vec3>& x_w,
                               const std::vector<Mat4>& E_ws) {
  const std::vector<std::vector<int>> sets = calcSegmentWrapSets(muscle, active, x_w, E_ws);
  double length = 0.0;
  for (size_t i = 0; i < sets.size(); ++i) {
    if (sets[i].empty()) {
      length += (x_w[i + 1] - x_w[i]).norm();
      continue;
    }
    std::vector<CompositeWrapSurface> cs;
    for (int w : sets[i]) {
      CompositeWrapSurface c;
      c.surface = &muscle.path.wraps[w].surface;
      c.R = E_ws[w].topLeftCorner<3, 3>();
      c.p = E_ws[w].topRightCorner<3, 1>();
      cs.push_back(c);
    }
    std::vector<Vec3> x;
    length += calcSmoothCompositeWrapPoints(cs, x_w[i], x_w[i + 1], {}, muscle.wrap.width, x);
  }
  return length;
}

void calcCompositeWrapMassPointsOnSurfaces(const Muscle& muscle, const std::vector<WrapSurfaceMotion>& surfaces,
                                           MuscleKinematics& mk) {
  const MassPoints& mp = muscle.mass_points;
  const MusclePath& path = muscle.path;
  const int N = mp.size();
  const int k = static_cast<int>(mk.cols.size());
  const int P = static_cast<int>(mk.x_w.size());
  const int nseg = P - 1;
  const bool vel = mk.velocity;
  const std::string who = "muscle '" + muscle.name + "'";
  if (P < 2) throw std::logic_error("calcWrapMassPoints: needs the path stage");
  if (surfaces.size() != path.wraps.size())
    throw std::invalid_argument("calcCompositeWrapMassPointsOnSurfaces: " + who + ": " +
                                std::to_string(surfaces.size()) + " surfaces for " + std::to_string(path.wraps.size()) +
                                " wrap objects");
  std::vector<Mat4> E_ws(path.wraps.size(), Mat4::Identity());
  for (size_t w = 0; w < path.wraps.size(); ++w) {
    E_ws[w].topLeftCorner<3, 3>() = surfaces[w].R;
    E_ws[w].topRightCorner<3, 1>() = surfaces[w].p;
  }
  const std::vector<std::vector<int>> sets = calcSegmentWrapSets(muscle, mk.active, mk.x_w, E_ws);
  auto wrapNames = [&](const std::vector<int>& set) {
    std::string s;
    for (int w : set) s += (s.empty() ? "'" : ", '") + path.wraps[w].name + "'";
    return s;
  };
  auto compose = [&](int i, const std::vector<double>& alphas, const std::vector<double>& alphadots,
                     CompositeWrapResult& r) {
    const std::vector<CompositeWrapSurface> cs = compositeSurfaces(muscle, sets[i], surfaces, vel);
    try {
      calcSmoothCompositeWrap(cs, mk.x_w[i], mk.x_w[i + 1], vel ? mk.xdot_w[i] : Vec3::Zero(),
                              vel ? mk.xdot_w[i + 1] : Vec3::Zero(), alphas, vel ? alphadots : std::vector<double>{},
                              muscle.wrap.width, r);
    } catch (const std::invalid_argument& ex) {
      throw MuscleError(who + ", wrap object" + (sets[i].size() > 1 ? "s " : " ") + wrapNames(sets[i]) + ": " +
                        ex.what());
    }
  };
  std::vector<MatX> U(nseg), Udot(nseg);
  for (int i = 0; i < nseg; ++i)
    if (!sets[i].empty()) segmentInputRows(sets[i], surfaces, mk, i, vel, U[i], Udot[i]);

  // Eulerian coordinates over the segment lengths (wrap_muscle.hpp); one segment: (0, 1)
  mk.s.setZero(P);
  mk.s[P - 1] = 1.0;
  mk.J_sr.setZero(P, k);
  mk.sdot.setZero(P);
  if (vel) mk.Jdot_sr.setZero(P, k);
  if (nseg > 1) {
    VecX L(nseg), Ld = VecX::Zero(nseg);
    MatX J_L(nseg, k), Jdot_L = MatX::Zero(nseg, k);
    for (int i = 0; i < nseg; ++i) {
      if (sets[i].empty()) {
        straightSegmentLengthRow(mk, i, vel, L, Ld, J_L, Jdot_L);
      } else {
        CompositeWrapResult r;
        compose(i, {}, {}, r);
        L[i] = r.length;
        J_L.row(i).noalias() = r.J_L * U[i];
        if (vel) {
          Ld[i] = r.length_rate;
          Jdot_L.row(i).noalias() = r.Jdot_L * U[i] + r.J_L * Udot[i];
        }
      }
    }
    calcEulerianFromSegmentLengths(L, Ld, J_L, Jdot_L, vel, muscle.name, mk);
  }

  // mass points: segment, beta and betadot [D Eq. 5.29, 5.31]
  std::vector<double> betadot;
  locateWrapMassPoints(mp, mk, betadot);
  // straight segments: Type II's EOL construction (via_point.hpp) with these s
  std::vector<int> straight(nseg, -1);
  for (int i = 0; i < nseg; ++i)
    if (!sets[i].empty()) straight[i] = 0;
  MatX J_zr, Jdot_zr;
  calcStraightSegmentMassPoints(straight, betadot, J_zr, Jdot_zr, mk);
  // wrapped segments: the composition at the points' fractions, then du/dq (the fraction's row:
  // J_beta = c_i J_s,i + c_i1 J_s,i+1, c_i = -(1 - beta) / ds, c_i1 = -beta / ds, and its rate)
  const bool moving_beta = nseg > 1;
  for (int i = 0; i < nseg; ++i) {
    if (sets[i].empty()) continue;
    std::vector<int> idx;
    std::vector<double> betas, bds;
    for (int a = 0; a < N; ++a)
      if (mk.segment[a] == i) idx.push_back(a), betas.push_back(mk.beta[a]), bds.push_back(moving_beta ? betadot[a] : 0.0);
    if (idx.empty()) continue;
    CompositeWrapResult r;
    compose(i, betas, bds, r);
    const int Nu = r.inputs;
    const double ds = mk.s[i + 1] - mk.s[i];
    const double dsdot = vel ? mk.sdot[i + 1] - mk.sdot[i] : 0.0;
    MatX& Ui = U[i];
    for (size_t j = 0; j < idx.size(); ++j) {
      const int a = idx[j];
      const double beta = betas[j];
      if (moving_beta) {
        const double ci = -(1.0 - beta) / ds, ci1 = -beta / ds;
        Ui.row(Nu - 1) = ci * mk.J_sr.row(i) + ci1 * mk.J_sr.row(i + 1);
        if (vel) {
          const double bd = bds[j];
          const double cid = (bd - ci * dsdot) / ds, ci1d = (-bd - ci1 * dsdot) / ds;
          Udot[i].row(Nu - 1) =
              cid * mk.J_sr.row(i) + ci1d * mk.J_sr.row(i + 1) + ci * mk.Jdot_sr.row(i) + ci1 * mk.Jdot_sr.row(i + 1);
        }
      }
      mk.x_a[a] = r.x[j];
      mk.J_ar.middleRows(3 * a, 3).noalias() = r.J[j] * Ui;
      if (!vel) continue;
      mk.Jdot_ar.middleRows(3 * a, 3).noalias() = r.Jdot[j] * Ui;
      mk.Jdot_ar.middleRows(3 * a, 3).noalias() += r.J[j] * Udot[i];
    }
  }
}

}  // namespace redmax
