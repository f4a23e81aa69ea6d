#include "core/muscles/path_map.hpp"

#include <algorithm>
#include <stdexcept>

#include "core/muscles/muscle_kinematics.hpp"
#include "core/muscles/path_kinematics.hpp"
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

std::string generalPathMapUnsupportedReason(const Muscle& muscle) {
  const MusclePath& path = muscle.path;
  if (path.wraps.empty() || muscle.wrap.model != WrapModel::Exact) return "";
  if (path.points.size() == 2 && path.wraps.size() == 1) return "";
  return "the exact wrap model on a path other than origin -> one wrap surface -> insertion (this one has " +
         std::to_string(path.points.size()) + " points and " + std::to_string(path.wraps.size()) +
         " wrap objects) differentiates OpenSim's whole wrapped path in the coordinates, which a map over "
         "path points and surface frames cannot do: use the smooth or neural wrap model, or the core";
}

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
  const std::string why = generalPathMapUnsupportedReason(muscle);
  if (!why.empty()) throw std::invalid_argument("calcGeneralPathMap: muscle '" + name + "': " + why);
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
