#include "core/muscles/muscle_id_tangent.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "core/geometry/dual.hpp"
#include "core/geometry/local_difference.hpp"
#include "core/muscles/path_kinematics.hpp"

namespace redmax {
namespace {

using D = detail::Dual<double>;
using V = detail::V3<D>;
using detail::cross;
using detail::dot;

V dual(const Vec3& value, const Vec3& tangent) {
  return {D(value[0], tangent[0]), D(value[1], tangent[1]), D(value[2], tangent[2])};
}
using detail::values;
Vec3 tangentOf3(const V& v) { return Vec3(v[0].b, v[1].b, v[2].b); }
// R v for a rotation varying as dR = [dtheta] R and a dual v: value R v, tangent dtheta x R v + R dv
V rotate(const Mat3& R, const Vec3& dtheta, const V& v) {
  const Vec3 Rv = R * values(v);
  return dual(Rv, dtheta.cross(Rv) + R * tangentOf3(v));
}
// R^T w likewise: value R^T w, tangent R^T (dw - dtheta x w)
V rotateBack(const Mat3& R, const Vec3& dtheta, const V& w) {
  return dual(R.transpose() * values(w), R.transpose() * (tangentOf3(w) - dtheta.cross(values(w))));
}
V zero() { return detail::constant<D>(Vec3::Zero()); }

// the moving point's functions' third derivative along q_c: the local difference of the second
// (calcPointLocation), zero where the clamp holds the point
Vec3 thirdDerivative(const PathPoint& pt, const VecX& q) {
  if (pt.kind != PathPointKind::Moving || pt.coordinate < 0) return Vec3::Zero();
  const double qc = q[pt.coordinate];
  if (pt.clamp && (qc < pt.clamp_lo || qc > pt.clamp_hi)) return Vec3::Zero();
  Vec3 x, dx, ddx;
  VecX qm = q;
  return localDerivative(
      [&](double v) {
        qm[pt.coordinate] = v;
        calcPointLocation(pt, qm, x, dx, ddx);
        return Vec3(ddx);
      },
      qc);
}

// Thomas solve of L x = b (in place), L tridiagonal (sub, diag, super by row; sub[0], super[n-1]
// unused), without pivoting as muscle_inverse_dynamics.cpp (L is diagonally dominant by rows)
void solveTridiagonal(int n, const std::vector<D>& sub, const std::vector<D>& diag, const std::vector<D>& super,
                      std::vector<D>& b, std::vector<D>& c, std::vector<D>& d) {
  c.resize(n);
  d.resize(n);
  for (int r = 0; r < n; ++r) {
    const D piv = r == 0 ? diag[0] : diag[r] - sub[r] * c[r - 1];
    c[r] = r + 1 < n ? super[r] / piv : D(0.0);
    d[r] = (r == 0 ? b[0] : b[r] - sub[r] * d[r - 1]) / piv;
  }
  for (int r = n - 1; r >= 0; --r) b[r] = r + 1 < n ? d[r] - c[r] * b[r + 1] : d[r];
}

}  // namespace

void addMuscleIdShareTangent(const Muscle& muscle, const State& s, const VecX& qddot, const VecX& dq,
                             const VecX& dqdot, const std::vector<BodyWorldMotion>& bodies,
                             const std::vector<BodyWorldTangent>* tangents, const Vec3& gravity,
                             std::vector<Vec6>& wrench, VecX& tau, std::vector<Vec6>* dwrench, VecX* dtau,
                             MuscleIdTangentScratch& sc) {
  const MusclePath& path = muscle.path;
  const MassPoints& mp = muscle.mass_points;
  if (pathType(path) == PathType::III)
    throw std::logic_error("addMuscleIdShareTangent: muscle '" + muscle.name + "' wraps (Type III)");
  static const BodyWorldTangent kNone;
  auto tangentOf = [&](int b) -> const BodyWorldTangent& { return tangents ? (*tangents)[b] : kNone; };

  // 1. active path points' world position, velocity, acceleration (as addMuscleInverseDynamics)
  std::vector<int>& active = sc.active;
  activePathPoints(path, s.q, active);
  const int P = static_cast<int>(active.size());
  if (P < 2) throw std::logic_error("addMuscleIdShareTangent: fewer than two active path points");
  // dxw: a moving point's R x_b' (for tau)
  std::vector<V>&x = sc.x, &xd = sc.xd, &xdd = sc.xdd, &r = sc.r, &dxw = sc.dxw;
  for (std::vector<V>* v : {&x, &xd, &xdd, &r, &dxw}) v->resize(P);
  for (int a = 0; a < P; ++a) {
    const PathPoint& pt = path.points[active[a]];
    if (pt.kind == PathPointKind::Node)
      throw std::logic_error("addMuscleIdShareTangent: muscle '" + muscle.name + "' has a deformable node point");
    const int b = pt.body;
    V xb, xb1 = zero(), xb2 = zero();  // x_b and its first and second derivative in q_c (moving)
    D qd_c(0.0), qdd_c(0.0);
    if (pt.kind == PathPointKind::Moving) {
      Vec3 v0, v1, v2;
      calcPointLocation(pt, s.q, v0, v1, v2);
      const int c = pt.coordinate;
      const double dqc = c >= 0 ? dq[c] : 0.0;
      xb = dual(v0, v1 * dqc);
      xb1 = dual(v1, v2 * dqc);
      xb2 = dual(v2, thirdDerivative(pt, s.q) * dqc);
      if (c >= 0) {
        qd_c = D(s.qdot[c], dqdot[c]);
        qdd_c = D(qddot[c], 0.0);
      }
    } else {
      xb = dual(pt.location, Vec3::Zero());
    }
    const V xb_d = qd_c * xb1;                          // relative velocity on the body
    const V xb_dd = (qd_c * qd_c) * xb2 + qdd_c * xb1;  // relative acceleration
    if (b < 0) {
      x[a] = xb;
      xd[a] = xb_d;
      xdd[a] = xb_dd;
      r[a] = zero();
      dxw[a] = xb1;
      continue;
    }
    const BodyWorldMotion& o = bodies[b];
    const BodyWorldTangent& t = tangentOf(b);
    const V omega = dual(o.omega, t.domega), nu = dual(o.nu, t.dnu), alpha = dual(o.alpha, t.dalpha);
    const V bias = dual(o.bias, t.dbias), p = dual(o.p, t.dp);
    r[a] = rotate(o.R, t.dtheta, xb);
    const V rd = rotate(o.R, t.dtheta, xb_d);
    const V v = cross(omega, r[a]) + nu;
    x[a] = r[a] + p;
    xd[a] = v + rd;
    xdd[a] = cross(alpha, r[a]) + cross(omega, cross(omega, r[a]) + D(2.0) * rd) + bias +
             rotate(o.R, t.dtheta, xb_dd);
    dxw[a] = rotate(o.R, t.dtheta, xb1);
  }

  // segments [D Eq. 5.17-5.19, 5.27-5.28]
  const int ns = P - 1, n = P - 2;
  std::vector<D>&l = sc.l, &ld = sc.ld, &ldd = sc.ldd;
  for (std::vector<D>* v : {&l, &ld, &ldd}) v->resize(ns);
  std::vector<V>& u = sc.u;
  u.resize(ns);
  D length(0.0);
  for (int i = 0; i < ns; ++i) {
    const V dx = x[i + 1] - x[i], dxd = xd[i + 1] - xd[i];
    l[i] = detail::norm(dx);
    if (!(l[i].a > 0.0)) break;  // reported below
    u[i] = (D(1.0) / l[i]) * dx;
    ld[i] = dot(u[i], dxd);
    const V ud = (D(1.0) / l[i]) * (dxd - ld[i] * u[i]);
    ldd[i] = dot(u[i], xdd[i + 1] - xdd[i]) + dot(ud, dxd);
    length = length + l[i];
  }
  // checkEulerianSegments' rule
  for (int i = 0; i < ns && P > 2; ++i)
    if (!(l[i].a > 1e-12 * (1.0 + length.a)))
      throw MuscleError("muscle '" + muscle.name + "': path segment " + std::to_string(i) +
                        " has zero length here; mass points need distinct consecutive path points");
  if (!(length.a > 0.0))
    throw MuscleError("muscle '" + muscle.name + "': origin and insertion coincide here; mass points need a path of positive length");
  // Eulerian coordinates s (arc fractions), sdot, sddot [D Eq. 5.20-5.24]; ends 0 and 1
  std::vector<D>&sv = sc.sv, &sd = sc.sd, &sdd = sc.sdd;
  for (std::vector<D>* v : {&sv, &sd, &sdd}) v->assign(P, D(0.0));
  for (int i = 1; i < P; ++i) sv[i] = sv[i - 1] + l[i - 1] / length;
  sv[P - 1] = D(1.0);
  if (n > 0) {
    std::vector<D>&sub = sc.sub, &diag = sc.diag, &super = sc.super, &rhs = sc.rhs;
    for (std::vector<D>* v : {&sub, &diag, &super, &rhs}) v->resize(n);
    for (int rr = 0; rr < n; ++rr) {
      sub[rr] = -l[rr + 1];
      diag[rr] = l[rr] + l[rr + 1];
      super[rr] = -l[rr];
    }
    // (DeltaS v)_r = -Delta s_{r+1} v_r + Delta s_r v_{r+1}
    auto dS = [&](const std::vector<D>& vv, int rr) {
      return -(sv[rr + 2] - sv[rr + 1]) * vv[rr] + (sv[rr + 1] - sv[rr]) * vv[rr + 1];
    };
    for (int rr = 0; rr < n; ++rr) rhs[rr] = -dS(ld, rr);
    solveTridiagonal(n, sub, diag, super, rhs, sc.c, sc.d);
    for (int rr = 0; rr < n; ++rr) sd[rr + 1] = rhs[rr];
    // L sddot = -(DeltaS lddot + Ldot sdot + DeltaSdot ldot)
    for (int rr = 0; rr < n; ++rr) {
      D Ld_sd = (ld[rr] + ld[rr + 1]) * sd[rr + 1];
      if (rr > 0) Ld_sd = Ld_sd - ld[rr + 1] * sd[rr];
      if (rr + 1 < n) Ld_sd = Ld_sd - ld[rr] * sd[rr + 2];
      const D dSd_ld = -(sd[rr + 2] - sd[rr + 1]) * ld[rr] + (sd[rr + 1] - sd[rr]) * ld[rr + 1];
      rhs[rr] = -(dS(ldd, rr) + Ld_sd + dSd_ld);
    }
    solveTridiagonal(n, sub, diag, super, rhs, sc.c, sc.d);
    for (int rr = 0; rr < n; ++rr) sdd[rr + 1] = rhs[rr];
  }

  // 2. the mass points by segment (the segment rule of calcViaPointMassPoints), moments, forces
  std::vector<D>&m0 = sc.m0, &m1 = sc.m1, &m2 = sc.m2;
  for (std::vector<D>* v : {&m0, &m1, &m2}) v->assign(ns, D(0.0));
  for (int a = 0; a < mp.size(); ++a) {
    const double s_a = mp.alpha[a];
    int i = 0;
    while (i < P - 2 && sv[i + 1].a <= s_a) ++i;
    const D beta = (D(s_a) - sv[i]) / (sv[i + 1] - sv[i]);
    const double m = mp.mass[a];
    m0[i] = m0[i] + D(m);
    m1[i] = m1[i] + m * beta;
    m2[i] = m2[i] + m * (beta * beta);
  }
  std::vector<V>& fx = sc.fx;
  fx.assign(P, zero());
  std::vector<D>& fs = sc.fs;
  fs.assign(P, D(0.0));
  const V g = dual(gravity, Vec3::Zero());
  for (int i = 0; i < ns; ++i) {
    if (m0[i].a == 0.0 && m1[i].a == 0.0) continue;
    const D inv_ds = D(1.0) / (sv[i + 1] - sv[i]);
    const V dx = x[i + 1] - x[i], dxd = xd[i + 1] - xd[i], dxdd = xdd[i + 1] - xdd[i];
    const D b0 = -(sd[i] * inv_ds), b1 = -((sd[i + 1] - sd[i]) * inv_ds);
    const D e0 = -(sdd[i] * inv_ds) + 2.0 * (b0 * b1), e1 = 2.0 * (b1 * b1) - (sdd[i + 1] - sdd[i]) * inv_ds;
    const V c0g = xdd[i] + e0 * dx + (2.0 * b0) * dxd - g;
    const V c1 = e1 * dx + (2.0 * b1) * dxd + dxdd;
    const V Fs0 = m0[i] * c0g + m1[i] * c1, Fs1 = m1[i] * c0g + m2[i] * c1;
    const V F = inv_ds * dx;
    fx[i] = fx[i] + (Fs0 - Fs1);
    fx[i + 1] = fx[i + 1] + Fs1;
    fs[i] = fs[i] - dot(F, Fs0 - Fs1);
    fs[i + 1] = fs[i + 1] - dot(F, Fs1);
  }
  // 3. Eulerian forces onto the path points: J_sx^T g = -DeltaXbar^T DeltaS^T L^-T g
  if (n > 0) {
    std::vector<D>&sub = sc.sub, &diag = sc.diag, &super = sc.super, &rhs = sc.rhs;
    for (std::vector<D>* v : {&sub, &diag, &super, &rhs}) v->resize(n);
    for (int rr = 0; rr < n; ++rr) {
      sub[rr] = rr > 0 ? -l[rr - 1] : D(0.0);        // L^T(r, r-1) = L(r-1, r) = -l[r-1]
      diag[rr] = l[rr] + l[rr + 1];
      super[rr] = rr + 1 < n ? -l[rr + 2] : D(0.0);  // L^T(r, r+1) = L(r+1, r) = -l[r+2]
      rhs[rr] = fs[rr + 1];
    }
    solveTridiagonal(n, sub, diag, super, rhs, sc.c, sc.d);
    for (int i = 0; i < ns; ++i) {
      D k(0.0);
      if (i < n) k = k - (sv[i + 2] - sv[i + 1]) * rhs[i];
      if (i > 0) k = k + (sv[i] - sv[i - 1]) * rhs[i - 1];
      fx[i] = fx[i] + k * u[i];
      fx[i + 1] = fx[i + 1] - k * u[i];
    }
  }
  // onto the bodies (body coordinates) and the moving points' coordinates
  for (int a = 0; a < P; ++a) {
    const PathPoint& pt = path.points[active[a]];
    const V& G = fx[a];
    const int c = pt.kind == PathPointKind::Moving ? pt.coordinate : -1;
    if (c >= 0) {
      const D t = dot(dxw[a], G);
      tau[c] += t.a;
      if (dtau) (*dtau)[c] += t.b;
    }
    const int b = pt.body;
    if (b < 0) continue;
    const BodyWorldTangent& t = tangentOf(b);
    const V tq = rotateBack(bodies[b].R, t.dtheta, cross(r[a], G));
    const V f = rotateBack(bodies[b].R, t.dtheta, G);
    wrench[b].head<3>() += values(tq);
    wrench[b].tail<3>() += values(f);
    if (dwrench) {
      (*dwrench)[b].head<3>() += tangentOf3(tq);
      (*dwrench)[b].tail<3>() += tangentOf3(f);
    }
  }
}

}  // namespace redmax
