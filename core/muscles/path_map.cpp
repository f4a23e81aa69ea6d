#include "core/muscles/path_map.hpp"

#include <algorithm>
#include <stdexcept>

#include "core/muscles/muscle_kinematics.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

void calcPathMap(const std::vector<Vec3>& x, const std::vector<Vec3>* xdot, const MassPoints& mp,
                 PathMap& pm, const std::string& muscle_name) {
  const int P = static_cast<int>(x.size());
  if (P < 2) throw std::invalid_argument("calcPathMap: muscle '" + muscle_name + "' needs at least two path points");
  if (xdot && static_cast<int>(xdot->size()) != P)
    throw std::invalid_argument("calcPathMap: muscle '" + muscle_name + "': " + std::to_string(P) +
                                " points but " + std::to_string(xdot->size()) + " velocities");
  if (mp.size() == 0) throw std::invalid_argument("calcPathMap: muscle '" + muscle_name + "' has no mass points");
  const bool velocity = xdot != nullptr;

  // path stage in point coordinates: x_w = x, J_xr = I, Jdot_xr = 0 (the points are the coordinates)
  MuscleKinematics& mk = pm.mk;
  if (static_cast<int>(mk.active.size()) != P) {
    mk.active.resize(P);
    for (int i = 0; i < P; ++i) mk.active[i] = i;
    mk.J_xr.setIdentity(3 * P, 3 * P);
    mk.Jdot_xr.setZero(3 * P, 3 * P);
  }
  mk.x_w = x;
  if (velocity) mk.xdot_w = *xdot;
  mk.velocity = velocity;
  calcPathSegments(mk, velocity);

  // mass points: J_ar of this mk is J_ax, its Jdot_ar is Jdot_ax (Jdot_xr = 0) [D Eq. 5.5]
  calcMassPointStage(mp, mk, muscle_name);
  pm.x_a = mk.x_a;
  pm.J_ax = mk.J_ar;
  pm.velocity = velocity;
  if (!velocity) return;
  pm.Jdot_ax = mk.Jdot_ar;
  pm.Jdot_ax_xdot.noalias() = pm.Jdot_ax * stackPoints(*xdot);
}

VecX calcMassPointAccelerations(const PathMap& pm, const VecX& xddot) {
  if (!pm.velocity) throw std::logic_error("calcMassPointAccelerations: the path map has no velocity stage");
  if (xddot.size() != pm.J_ax.cols())
    throw std::invalid_argument("calcMassPointAccelerations: " + std::to_string(xddot.size()) +
                                " entries for " + std::to_string(pm.J_ax.cols()) + " point coordinates");
  return pm.J_ax * xddot + pm.Jdot_ax_xdot;
}

VecX stackPoints(const std::vector<Vec3>& x) {
  VecX v(3 * static_cast<int>(x.size()));
  for (size_t i = 0; i < x.size(); ++i) v.segment<3>(3 * static_cast<int>(i)) = x[i];
  return v;
}

void calcWrapPathMap(const WrapSurface& surface, const WrapMassOptions& wrap, const MassPoints& mp, const Vec3& x1,
                     const Vec3& x2, const Mat3& R, const Vec3& p, const WrapSegmentVelocity* v, WrapPathMap& out,
                     const std::string& muscle_name) {
  const int N = mp.size();
  if (N == 0) throw std::invalid_argument("calcWrapPathMap: muscle '" + muscle_name + "' has no mass points");
  const bool vel = v != nullptr;
  // end points in the surface frame and their rates [D Eq. 5.39-5.41]
  const Vec3 r1 = x1 - p, r2 = x2 - p;
  const Vec3 p1 = R.transpose() * r1, p2 = R.transpose() * r2;
  Vec3 p1dot = Vec3::Zero(), p2dot = Vec3::Zero(), p1ddot = Vec3::Zero(), p2ddot = Vec3::Zero();
  Vec3 omega = Vec3::Zero();
  if (vel) {
    omega = v->omega;
    const Vec3 r1dot = v->xdot1 - v->pdot, r2dot = v->xdot2 - v->pdot;
    const Vec3 s1 = r1dot - omega.cross(r1), s2 = r2dot - omega.cross(r2);
    p1dot = R.transpose() * s1;
    p2dot = R.transpose() * s2;
    // the part of p_i's acceleration that does not come from vdot (d/dt R^T = -R^T [omega])
    p1ddot = -(R.transpose() * (omega.cross(s1) + omega.cross(r1dot)));
    p2ddot = -(R.transpose() * (omega.cross(s2) + omega.cross(r2dot)));
  }

  // the core's wrap model in s (its one dispatch point: smooth, exact or neural) [D Eq. 5.38, 5.44]
  // (Neural: not counted here; this map serves the Simbody plugins, which do not report fallbacks)
  WrapModelPoints wp;
  NetworkWrapWorkspace network;
  try {
    calcWrapModelPoints(wrap, surface, p1, p2, p1dot, p2dot, mp.alpha, {}, false, vel, wp, network);
  } catch (const std::invalid_argument& e) {
    throw MuscleError("muscle '" + muscle_name + "', wrap surface: " + e.what());
  }

  out.x_a.resize(N);
  out.J.resize(3 * N, 12);
  out.velocity = vel;
  if (vel) out.bias.resize(3 * N);
  const Mat3 Rt = R.transpose();
  for (int a = 0; a < N; ++a) {
    const Vec3 Rw = R * wp.x[a];
    out.x_a[a] = Rw + p;
    const Mat3 B1 = R * wp.J[a].leftCols<3>() * Rt, B2 = R * wp.J[a].rightCols<3>() * Rt;
    auto Ja = out.J.middleRows<3>(3 * a);
    Ja.leftCols<3>() = B1;
    Ja.middleCols<3>(3) = B2;
    Ja.middleCols<3>(6) = -skew(Rw) + B1 * skew(r1) + B2 * skew(r2);
    Ja.rightCols<3>() = Mat3::Identity() - B1 - B2;
    if (!vel) continue;
    const Vec3 RJp = R * (wp.J[a].leftCols<3>() * p1dot + wp.J[a].rightCols<3>() * p2dot);
    const Vec3 RJdp = R * (wp.Jdot[a].leftCols<3>() * p1dot + wp.Jdot[a].rightCols<3>() * p2dot);
    const Vec3 RJpp = R * (wp.J[a].leftCols<3>() * p1ddot + wp.J[a].rightCols<3>() * p2ddot);
    out.bias.segment<3>(3 * a) = omega.cross(omega.cross(Rw)) + 2.0 * omega.cross(RJp) + RJdp + RJpp;
  }
}

namespace {

// the exact model on a path other than origin -> one surface -> insertion: OpenSim's whole wrapped
// path (core/muscles/wrap/wrap_path.hpp) on the map's inputs, x_a at fractions alpha of its
// geometric length (what the core's calcExactPathMassPointsFd evaluates at each q)
void exactPathPoints(const Muscle& mu, const std::vector<int>& active, const std::vector<Vec3>& x,
                     const std::vector<Mat4>& E_ws, std::vector<Vec3>& x_a) {
  const WrappedPath wp = calcWrappedPathAt(mu.path, active, x, E_ws);
  const MassPoints& mp = mu.mass_points;
  x_a.resize(mp.size());
  for (int a = 0; a < mp.size(); ++a) x_a[a] = calcWrappedPathPointAt(wp, E_ws, mp.alpha[a]);
}

Mat4 framePose(const Mat3& R, const Vec3& p) {
  Mat4 E = Mat4::Identity();
  E.topLeftCorner<3, 3>() = R;
  E.topRightCorner<3, 1>() = p;
  return E;
}

// the inputs moved along v for time t with vdot = 0: x_i + t xdot_i, R_w -> exp(t [omega_w]) R_w,
// p_w + t pdot_w (v's columns: a frame's angular velocity is a left, world-axis rotation)
void moveInputs(const std::vector<Vec3>& x, const std::vector<SurfaceFrameState>& f, const VecX& v, double t,
                std::vector<Vec3>& xt, std::vector<Mat4>& Et) {
  const int P = static_cast<int>(x.size());
  xt.resize(P);
  for (int i = 0; i < P; ++i) xt[i] = x[i] + t * v.segment<3>(3 * i);
  Et.resize(f.size());
  for (size_t w = 0; w < f.size(); ++w) {
    const int c = 3 * P + 6 * static_cast<int>(w);
    Et[w] = framePose(expSO3(Vec3(t * v.segment<3>(c))) * f[w].R, f[w].p + t * v.segment<3>(c + 3));
  }
}

// J by central differences in v's coordinates (step h: m for the points and the frames' origins,
// rad for the frames' rotations; the core's step in q) and, with velocities, the bias b = xddot_a at
// vdot = 0 = d^2/dt^2 x_a(inputs moved along v) by the fourth-order central second difference over
// displacements of 1e-4 (m or rad) per unit |v| (1e-5 where that stencil straddles a kink). The core differentiates the same points in q (J:
// central, step 1e-6; Jdot: a mixed stencil of 1e-5): the two agree to those differences' error.
void calcExactGeneralPathMapFd(const Muscle& mu, const std::vector<int>& active, const std::vector<Vec3>& x,
                               const std::vector<Vec3>* xdot, const std::vector<SurfaceFrameState>& surfaces,
                               GeneralPathMap& out) {
  const int P = static_cast<int>(x.size()), W = static_cast<int>(surfaces.size());
  const int N = mu.mass_points.size(), k = 3 * P + 6 * W;
  std::vector<Mat4> E_ws(W);
  for (int w = 0; w < W; ++w) E_ws[w] = framePose(surfaces[w].R, surfaces[w].p);
  exactPathPoints(mu, active, x, E_ws, out.x_a);
  out.J.resize(3 * N, k);
  const double h = 1e-6;
  std::vector<Vec3> xs = x, xp, xm;
  std::vector<Mat4> Es = E_ws;
  auto column = [&](int c) {
    for (int a = 0; a < N; ++a) out.J.block<3, 1>(3 * a, c) = (xp[a] - xm[a]) / (2.0 * h);
  };
  for (int i = 0; i < P; ++i)
    for (int d = 0; d < 3; ++d) {
      xs[i][d] = x[i][d] + h;
      exactPathPoints(mu, active, xs, E_ws, xp);
      xs[i][d] = x[i][d] - h;
      exactPathPoints(mu, active, xs, E_ws, xm);
      xs[i][d] = x[i][d];
      column(3 * i + d);
    }
  for (int w = 0; w < W; ++w)
    for (int d = 0; d < 3; ++d) {
      const Vec3 e = Vec3::Unit(d) * h;
      Es[w].topLeftCorner<3, 3>() = expSO3(e) * surfaces[w].R;
      exactPathPoints(mu, active, x, Es, xp);
      Es[w].topLeftCorner<3, 3>() = expSO3(Vec3(-e)) * surfaces[w].R;
      exactPathPoints(mu, active, x, Es, xm);
      Es[w] = E_ws[w];
      column(3 * P + 6 * w + d);
      Es[w].topRightCorner<3, 1>() = surfaces[w].p + e;
      exactPathPoints(mu, active, x, Es, xp);
      Es[w].topRightCorner<3, 1>() = surfaces[w].p - e;
      exactPathPoints(mu, active, x, Es, xm);
      Es[w] = E_ws[w];
      column(3 * P + 6 * w + 3 + d);
    }
  if (!xdot) return;
  out.bias.setZero(3 * N);
  const VecX v = stackGeneralVelocities(*xdot, surfaces);
  const double speed = v.norm();
  if (!(speed > 0.0)) return;
  // second differences along v over displacements s per unit |v|: the fourth-order estimate, and
  // whether its two second-order parts (steps tau and 2 tau) agree. With several surfaces on one
  // segment OpenSim's passes make the path only piecewise smooth at a fine scale; a stencil that
  // straddles such a kink shows as disagreeing parts, and the step shrinks (noisier, but on one
  // side of the kink)
  std::vector<std::vector<Vec3>> xa(5);
  auto secondDifference = [&](double s) {
    const double tau = s / speed;
    for (int j = -2; j <= 2; ++j) {
      moveInputs(x, surfaces, v, j * tau, xs, Es);
      exactPathPoints(mu, active, xs, Es, xa[j + 2]);
    }
    double gap = 0.0, size = 0.0;
    for (int a = 0; a < N; ++a) {
      const Vec3 d1 = (xa[1][a] - 2.0 * xa[2][a] + xa[3][a]) / (tau * tau);
      const Vec3 d2 = (xa[0][a] - 2.0 * xa[2][a] + xa[4][a]) / (4.0 * tau * tau);
      out.bias.segment<3>(3 * a) = (4.0 * d1 - d2) / 3.0;  // = (-x_-2 + 16 x_-1 - 30 x_0 + 16 x_1 - x_2) / 12 tau^2
      gap = std::max(gap, (d1 - d2).cwiseAbs().maxCoeff());
      size = std::max(size, d1.cwiseAbs().maxCoeff());
    }
    return gap <= 1e-3 * size;
  };
  // 1e-4: the best agreement with the smooth model's analytic bias where both apply
  // (tests/plugin/general_path_map_test.cpp); 1e-5 where a kink is seen
  if (!secondDifference(1e-4)) secondDifference(1e-5);
}

}  // namespace

void calcGeneralPathMap(const Muscle& muscle, const std::vector<int>& active, const std::vector<Vec3>& x,
                        const std::vector<Vec3>* xdot, const std::vector<SurfaceFrameState>& surfaces,
                        GeneralPathMap& out) {
  const MusclePath& path = muscle.path;
  const int P = static_cast<int>(x.size());
  const int W = static_cast<int>(path.wraps.size());
  const bool vel = xdot != nullptr;
  const std::string& name = muscle.name;
  if (static_cast<int>(active.size()) != P || static_cast<int>(surfaces.size()) != W)
    throw std::invalid_argument("calcGeneralPathMap: muscle '" + name + "': " + std::to_string(P) + " points, " +
                                std::to_string(active.size()) + " active indices, " +
                                std::to_string(surfaces.size()) + " surface frames for " + std::to_string(W) +
                                " wrap objects");
  out.velocity = vel;
  if (W == 0) {
    // Types I and II: the point map itself
    calcPathMap(x, xdot, muscle.mass_points, out.pm, name);
    out.x_a = out.pm.x_a;
    out.J = out.pm.J_ax;
    if (vel) out.bias = out.pm.Jdot_ax_xdot;
    out.seg_wrap.clear();
    return;
  }
  if (P < 2) throw std::invalid_argument("calcGeneralPathMap: muscle '" + name + "' needs at least two path points");
  if (vel && static_cast<int>(xdot->size()) != P)
    throw std::invalid_argument("calcGeneralPathMap: muscle '" + name + "': " + std::to_string(P) + " points but " +
                                std::to_string(xdot->size()) + " velocities");
  if (muscle.mass_points.size() == 0)
    throw std::invalid_argument("calcGeneralPathMap: muscle '" + name + "' has no mass points");

  // origin -> one active surface -> insertion: the dissertation's map, the same numbers (to
  // round-off) at less cost
  if (P == 2 && W == 1 && path.points.size() == 2 && path.wraps[0].surface.active) {
    const SurfaceFrameState& f = surfaces[0];
    WrapSegmentVelocity v;
    if (vel) v = WrapSegmentVelocity{(*xdot)[0], (*xdot)[1], f.omega, f.pdot};
    calcWrapPathMap(path.wraps[0].surface, muscle.wrap, muscle.mass_points, x[0], x[1], f.R, f.p, vel ? &v : nullptr,
                    out.wmap, name);
    out.x_a = out.wmap.x_a;
    out.J = out.wmap.J;
    if (vel) out.bias = out.wmap.bias;
    out.seg_wrap.assign(1, 0);
    return;
  }
  // the exact model on any other path: OpenSim's whole path, differentiated in v (no segment choice)
  if (muscle.wrap.model == WrapModel::Exact && !(path.points.size() == 2 && W == 1)) {
    calcExactGeneralPathMapFd(muscle, active, x, xdot, surfaces, out);
    out.seg_wrap.clear();
    return;
  }

  // the path stage in v's coordinates: J_xr = (I 0), Jdot_xr = 0
  const int k = 3 * P + 6 * W;
  MuscleKinematics& mk = out.mk;
  if (static_cast<int>(mk.cols.size()) != k || mk.J_xr.rows() != 3 * P) {
    mk.cols.resize(k);
    for (int c = 0; c < k; ++c) mk.cols[c] = c;
    mk.col_of = mk.cols;
    mk.J_xr.setZero(3 * P, k);
    mk.J_xr.leftCols(3 * P).setIdentity();
    mk.Jdot_xr.setZero(3 * P, k);
  }
  mk.active = active;
  mk.x_w = x;
  if (vel) mk.xdot_w = *xdot;
  mk.velocity = vel;
  calcPathSegments(mk, vel);

  // the wrap choice needs body poses: a frame's body pose E_wb = E_ws E_bs^-1 (world frames: E_bs)
  int nb = 0;
  for (const PathWrap& w : path.wraps) nb = std::max(nb, w.body + 1);
  std::vector<Mat4> E_wi(nb, Mat4::Identity());
  for (int w = 0; w < W; ++w) {
    const PathWrap& pw = path.wraps[w];
    if (pw.body < 0) continue;
    Mat4 E_ws = Mat4::Identity();
    E_ws.topLeftCorner<3, 3>() = surfaces[w].R;
    E_ws.topRightCorner<3, 1>() = surfaces[w].p;
    E_wi[pw.body] = E_ws * inverseE(pw.E_bs);
  }
  out.seg_wrap = calcSegmentWraps(muscle, active, x, E_wi);

  // each surface's motion: its (omega, pdot) columns of v, constant selectors
  std::vector<WrapSurfaceMotion> sm(W);
  for (int w = 0; w < W; ++w) {
    WrapSurfaceMotion& m = sm[w];
    m.R = surfaces[w].R;
    m.p = surfaces[w].p;
    m.J_om.setZero(3, k);
    m.J_p.setZero(3, k);
    m.J_om.middleCols<3>(3 * P + 6 * w).setIdentity();
    m.J_p.middleCols<3>(3 * P + 6 * w + 3).setIdentity();
    m.Jdot_om.setZero(3, k);
    m.Jdot_p.setZero(3, k);
    if (vel) {
      m.omega = surfaces[w].omega;
      m.pdot = surfaces[w].pdot;
    }
  }
  calcWrapMassPointsOnSurfaces(muscle, out.seg_wrap, sm, mk);
  out.x_a = mk.x_a;
  out.J = mk.J_ar;
  if (!vel) return;
  out.bias.noalias() = mk.Jdot_ar * stackGeneralVelocities(*xdot, surfaces);
}

VecX stackGeneralVelocities(const std::vector<Vec3>& xdot, const std::vector<SurfaceFrameState>& frames) {
  const int P = static_cast<int>(xdot.size()), W = static_cast<int>(frames.size());
  VecX v(3 * P + 6 * W);
  v.head(3 * P) = stackPoints(xdot);
  for (int w = 0; w < W; ++w) v.segment<6>(3 * P + 6 * w) << frames[w].omega, frames[w].pdot;
  return v;
}

}  // namespace redmax
