#include "core/muscles/path_map.hpp"

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
  WrapModelPoints wp;
  try {
    calcWrapModelPoints(wrap, surface, p1, p2, p1dot, p2dot, mp.alpha, {}, false, vel, wp);
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

}  // namespace redmax
