#include "core/muscles/path_kinematics.hpp"

#include <algorithm>

namespace redmax {

MuscleWorkspace::MuscleWorkspace(const Model& model, const std::vector<Muscle>& list) {
  muscles.resize(list.size());
  for (size_t m = 0; m < list.size(); ++m) {
    // size for every point active; conditional switches only shrink the used part
    MuscleKinematics& mk = muscles[m];
    const int P = static_cast<int>(list[m].path.points.size());
    const int N = list[m].mass_points.size();
    mk.active.reserve(P);
    mk.x_b.reserve(P);
    mk.x_w.reserve(P);
    mk.J_xm.reserve(P);
    mk.xdot_w.reserve(P);
    mk.Jdot_xm.reserve(P);
    mk.dxbar.reserve(P);
    mk.J_xr.setZero(3 * P, model.nr());
    mk.Jdot_xr.setZero(3 * P, model.nr());
    mk.x_a.assign(N, Vec3::Zero());
    mk.segment.assign(N, 0);
    mk.beta.assign(N, 0.0);
    mk.J_ar.setZero(3 * N, model.nr());
    mk.Jdot_ar.setZero(3 * N, model.nr());
  }
}

void calcPointLocation(const PathPoint& p, const VecX& q, Vec3& x_b, Vec3& dx_b, Vec3& ddx_b) {
  x_b = p.location;
  dx_b.setZero();
  ddx_b.setZero();
  if (p.kind != PathPointKind::Moving) return;
  // OpenSim evaluates the functions at 0 when no coordinate is connected
  double arg = p.coordinate >= 0 ? q[p.coordinate] : 0.0;
  bool inside = p.coordinate >= 0;
  if (p.clamp && (arg < p.clamp_lo || arg > p.clamp_hi)) {
    // the clamped map is constant outside the range, so its derivatives vanish there
    arg = std::clamp(arg, p.clamp_lo, p.clamp_hi);
    inside = false;
  }
  FunctionValue fv;
  for (int k = 0; k < 3; ++k) {
    const AxisFunctionPtr& f = p.functions[k];
    if (!f) continue;
    // one argument (q), or none for a constant (validatePath rejects more)
    const int na = f->numArgs();
    VecJ x = VecJ::Constant(na, arg);
    const bool derivs = inside && na == 1;
    f->evaluate(x, derivs ? 2 : 0, fv);
    x_b[k] = fv.value;
    if (derivs) {
      dx_b[k] = fv.gradient[0];
      ddx_b[k] = fv.hessian(0, 0);
    }
  }
}

void calcPathPoints(const Model& model, const State& state, const SkeletonWorkspace& sk,
                    const MusclePath& path, MuscleKinematics& mk, bool velocity) {
  const int nr = model.nr();
  const int need = velocity ? static_cast<int>(Stage::Velocity) : static_cast<int>(Stage::Position);
  if (static_cast<int>(sk.stage) < need)
    throw std::logic_error("calcPathPoints: skeleton workspace is not at the required stage (call calcKinematics)");

  // active set: conditional points by OpenSim's inclusive rule (path.hpp)
  mk.active.clear();
  for (int k = 0; k < static_cast<int>(path.points.size()); ++k)
    if (isPathPointActive(path.points[k], state.q)) mk.active.push_back(k);
  const int P = static_cast<int>(mk.active.size());

  mk.x_b.resize(P);
  mk.x_w.resize(P);
  mk.J_xm.resize(P);
  if (mk.J_xr.rows() != 3 * P || mk.J_xr.cols() != nr) mk.J_xr.resize(3 * P, nr);
  mk.J_xr.setZero();
  if (velocity) {
    mk.xdot_w.resize(P);
    mk.Jdot_xm.resize(P);
    if (mk.Jdot_xr.rows() != 3 * P || mk.Jdot_xr.cols() != nr) mk.Jdot_xr.resize(3 * P, nr);
    mk.Jdot_xr.setZero();
  }

  for (int a = 0; a < P; ++a) {
    const PathPoint& pt = path.points[mk.active[a]];
    Vec3 dx_b, ddx_b;
    calcPointLocation(pt, state.q, mk.x_b[a], dx_b, ddx_b);
    const Vec3& x_b = mk.x_b[a];
    const int b = pt.body;
    const int c = pt.kind == PathPointKind::Moving ? pt.coordinate : -1;
    const double qdot_c = c >= 0 ? state.qdot[c] : 0.0;
    auto J = mk.J_xr.middleRows<3>(3 * a);

    if (b < 0) {
      // world point: only a moving point's own coordinate moves it
      mk.x_w[a] = x_b;
      mk.J_xm[a].setZero();
      if (c >= 0) J.col(c) += dx_b;
      if (velocity) {
        mk.xdot_w[a] = dx_b * qdot_c;
        mk.Jdot_xm[a].setZero();
        if (c >= 0) mk.Jdot_xr.middleRows<3>(3 * a).col(c) += ddx_b * qdot_c;
      }
      continue;
    }

    // body point: x_w = R x_b + p, J_xm block R Gamma(x_b) [D Eq. 5.8-5.9]
    const Mat3 R = sk.E_wi[b].topLeftCorner<3, 3>();
    mk.x_w[a] = R * x_b + sk.E_wi[b].topRightCorner<3, 1>();
    mk.J_xm[a].noalias() = R * Gamma(x_b);
    // J_xr = J_xm J_mr over the columns of b's ancestor joints (others are zero in J_mr)
    for (int j : model.ancestors(b)) {
      const JointSlot& sj = model.joints[j];
      if (sj.nq == 0) continue;
      J.middleCols(sj.q_index, sj.nq).noalias() = mk.J_xm[a] * sk.J_mr.block(6 * b, sj.q_index, 6, sj.nq);
    }
    // moving point: direct dependence on its coordinate, not through the body twist
    if (c >= 0) J.col(c) += R * dx_b;

    if (!velocity) continue;
    const Vec6& phi = sk.phi[b];
    const Vec3 omega = phi.head<3>();
    const Vec3 xdot_b = dx_b * qdot_c;
    mk.xdot_w[a] = R * (Gamma(x_b) * phi + xdot_b);
    // Jdot_xm = R [omega] Gamma(x_b) + R Gamma(xdot_b), Gamma(xdot_b) = ([xdot_b]^T 0) [D Eq. 5.11]
    Mat3x6 Gdot = Mat3x6::Zero();
    Gdot.leftCols<3>() = skew(xdot_b).transpose();
    mk.Jdot_xm[a].noalias() = R * (skew(omega) * Gamma(x_b) + Gdot);
    auto Jd = mk.Jdot_xr.middleRows<3>(3 * a);
    // product rule on J_xm J_mr [D Eq. 5.5]
    for (int j : model.ancestors(b)) {
      const JointSlot& sj = model.joints[j];
      if (sj.nq == 0) continue;
      Jd.middleCols(sj.q_index, sj.nq).noalias() =
          mk.Jdot_xm[a] * sk.J_mr.block(6 * b, sj.q_index, 6, sj.nq) +
          mk.J_xm[a] * sk.Jdot_mr.block(6 * b, sj.q_index, 6, sj.nq);
    }
    // d/dt (R x_b') = R ([omega] x_b' + x_b'' qdot_c)
    if (c >= 0) Jd.col(c) += R * (omega.cross(dx_b) + ddx_b * qdot_c);
  }

  // segments [D Eq. 5.17-5.19, 5.27]
  const int ns = std::max(P - 1, 0);
  mk.l.resize(ns);
  mk.dxbar.resize(ns);
  mk.length = 0.0;
  if (velocity) mk.ldot.resize(ns);
  mk.lengthening_speed = 0.0;
  for (int i = 0; i < ns; ++i) {
    const Vec3 dx = mk.x_w[i + 1] - mk.x_w[i];
    mk.l[i] = dx.norm();
    mk.dxbar[i] = mk.l[i] > 0.0 ? Vec3(dx / mk.l[i]) : Vec3::Zero();
    mk.length += mk.l[i];
    if (velocity) {
      mk.ldot[i] = mk.dxbar[i].dot(mk.xdot_w[i + 1] - mk.xdot_w[i]);
      mk.lengthening_speed += mk.ldot[i];
    }
  }
  mk.velocity = velocity;
}

double calcPathLength(const Model& model, const MusclePath& path, const VecX& q,
                      const std::vector<Mat4>& E_wi) {
  (void)model;
  double length = 0.0;
  Vec3 prev = Vec3::Zero();
  bool first = true;
  for (const PathPoint& pt : path.points) {
    if (!isPathPointActive(pt, q)) continue;
    Vec3 x_b, dx, ddx;
    calcPointLocation(pt, q, x_b, dx, ddx);
    const Vec3 x_w = pt.body >= 0 ? transformPoint(E_wi[pt.body], x_b) : x_b;
    if (!first) length += (x_w - prev).norm();
    prev = x_w;
    first = false;
  }
  return length;
}

}  // namespace redmax
