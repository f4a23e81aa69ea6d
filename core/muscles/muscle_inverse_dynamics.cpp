#include "core/muscles/muscle_inverse_dynamics.hpp"

#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/via_point.hpp"

namespace redmax {

namespace {

// Solves T x = b in place (b becomes x) for the tridiagonal T of size n with sub(r) = T(r, r-1),
// diag(r) = T(r, r), super(r) = T(r, r+1), by elimination without pivoting: the equal-strain
// matrix L is diagonally dominant by rows (|sub| + |super| = diag, strictly in the end rows) and
// so L^T by columns, where elimination without pivoting is stable.
template <class Sub, class Diag, class Super>
void solveTridiagonal(int n, Sub sub, Diag diag, Super super, VecX& b, VecX& c) {
  c.resize(n);
  double m = diag(0);
  c[0] = n > 1 ? super(0) / m : 0.0;
  b[0] /= m;
  for (int r = 1; r < n; ++r) {
    m = diag(r) - sub(r) * c[r - 1];
    c[r] = r + 1 < n ? super(r) / m : 0.0;
    b[r] = (b[r] - sub(r) * b[r - 1]) / m;
  }
  for (int r = n - 2; r >= 0; --r) b[r] -= c[r] * b[r + 1];
}

}  // namespace

void addMuscleInverseDynamics(const Model& model, const State& state, const VecX& qddot,
                              const BodyMotion& motion, const Vec3& gravity, const Muscle& muscle,
                              MuscleKinematics& mk, MuscleIdScratch& sc, std::vector<Vec6>& wrench, VecX& tau) {
  const MusclePath& path = muscle.path;
  const MassPoints& mp = muscle.mass_points;

  // 1. active path points: positions, velocities, accelerations [D Eq. 5.8, 5.11]
  activePathPoints(path, state.q, mk.active);
  const int P = static_cast<int>(mk.active.size());
  mk.x_b.resize(P);
  mk.x_w.resize(P);
  mk.xdot_w.resize(P);
  sc.dx_b.resize(P);
  sc.ddx_b.resize(P);
  sc.xddot_w.resize(P);
  for (int a = 0; a < P; ++a) {
    const PathPoint& pt = path.points[mk.active[a]];
    calcPointLocation(pt, state.q, mk.x_b[a], sc.dx_b[a], sc.ddx_b[a]);
    const Vec3& x_b = mk.x_b[a];
    const int c = pt.kind == PathPointKind::Moving ? pt.coordinate : -1;
    const double qd_c = c >= 0 ? state.qdot[c] : 0.0, qdd_c = c >= 0 ? qddot[c] : 0.0;
    const Vec3 xdot_b = sc.dx_b[a] * qd_c;                                // relative to the body
    const Vec3 xddot_b = sc.ddx_b[a] * (qd_c * qd_c) + sc.dx_b[a] * qdd_c;
    const int b = pt.body;
    if (b < 0) {
      mk.x_w[a] = x_b;
      mk.xdot_w[a] = xdot_b;
      sc.xddot_w[a] = xddot_b;
      continue;
    }
    const Mat3 R = motion.E_wi[b].topLeftCorner<3, 3>();
    const Vec6& phi = motion.phi[b];
    const Vec6& phidot = motion.phidot[b];
    const Vec3 omega = phi.head<3>();
    const Vec3 v = omega.cross(x_b) + phi.tail<3>();  // Gamma(x_b) phi
    mk.x_w[a] = R * x_b + motion.E_wi[b].topRightCorner<3, 1>();
    mk.xdot_w[a] = R * (v + xdot_b);
    sc.xddot_w[a] = R * (phidot.head<3>().cross(x_b) + phidot.tail<3>() + omega.cross(v + 2.0 * xdot_b) + xddot_b);
  }
  calcPathSegments(mk, true);
  if (P < 2) throw std::logic_error("addMuscleInverseDynamics: fewer than two active path points");
  if (P == 2 && !(mk.length > 0.0))
    throw MuscleError("muscle '" + muscle.name + "': origin and insertion coincide here; mass points need a path of positive length");
  if (P > 2) checkEulerianSegments(mk, muscle.name);

  // Eulerian coordinates s (arc fractions), sdot, sddot [D Eq. 5.20-5.24]; ends fixed at 0 and 1
  const int ns = P - 1, n = P - 2;
  mk.s.resize(P);
  mk.s[0] = 0.0;
  for (int i = 1; i < P; ++i) mk.s[i] = mk.s[i - 1] + mk.l[i - 1] / mk.length;
  mk.s[P - 1] = 1.0;
  mk.sdot.setZero(P);
  sc.sddot.setZero(P);
  const VecX& l = mk.l;
  const VecX& ld = mk.ldot;
  const VecX& s = mk.s;
  // L (n x n, row r: internal point r + 1): sub(r) = -l[r+1], diag(r) = l[r] + l[r+1], super(r) = -l[r]
  auto Lsub = [&](int r) { return -l[r + 1]; };
  auto Ldiag = [&](int r) { return l[r] + l[r + 1]; };
  auto Lsuper = [&](int r) { return -l[r]; };
  if (n > 0) {
    // (DeltaS v)_r = -Delta s_{r+1} v_r + Delta s_r v_{r+1}   (row r: internal point r + 1)
    auto dS = [&](const auto& v, int r) { return -(s[r + 2] - s[r + 1]) * v[r] + (s[r + 1] - s[r]) * v[r + 1]; };
    // L sdot = -DeltaS ldot
    sc.rhs.resize(n);
    for (int r = 0; r < n; ++r) sc.rhs[r] = -dS(ld, r);
    solveTridiagonal(n, Lsub, Ldiag, Lsuper, sc.rhs, sc.tri_c);
    mk.sdot.segment(1, n) = sc.rhs;
    // segment length accelerations lddot = dxbar . Delta xddot + dxbardot . Delta xdot [D Eq. 5.28]
    sc.lddot.resize(ns);
    for (int i = 0; i < ns; ++i) {
      const Vec3& u = mk.dxbar[i];
      const Vec3 dxd = mk.xdot_w[i + 1] - mk.xdot_w[i];
      const Vec3 ud = (dxd - u * u.dot(dxd)) / l[i];
      sc.lddot[i] = u.dot(sc.xddot_w[i + 1] - sc.xddot_w[i]) + ud.dot(dxd);
    }
    // L sddot = -(DeltaS lddot + Ldot sdot + DeltaSdot ldot)
    const VecX& sd = mk.sdot;
    for (int r = 0; r < n; ++r) {
      double Ld_sd = (ld[r] + ld[r + 1]) * sd[r + 1];
      if (r > 0) Ld_sd -= ld[r + 1] * sd[r];
      if (r + 1 < n) Ld_sd -= ld[r] * sd[r + 2];
      const double dSd_ld = -(sd[r + 2] - sd[r + 1]) * ld[r] + (sd[r + 1] - sd[r]) * ld[r + 1];
      sc.rhs[r] = -(dS(sc.lddot, r) + Ld_sd + dSd_ld);
    }
    solveTridiagonal(n, Lsub, Ldiag, Lsuper, sc.rhs, sc.tri_c);
    sc.sddot.segment(1, n) = sc.rhs;
  }

  // 2. the mass points by segment: three moments each (the rule of calcViaPointMassPoints)
  sc.m0.setZero(ns);
  sc.m1.setZero(ns);
  sc.m2.setZero(ns);
  for (int a = 0; a < mp.size(); ++a) {
    const double s_a = mp.alpha[a];
    int i = 0;
    while (i < P - 2 && s[i + 1] <= s_a) ++i;
    const double beta = (s_a - s[i]) / (s[i + 1] - s[i]), m = mp.mass[a];
    sc.m0[i] += m;
    sc.m1[i] += m * beta;
    sc.m2[i] += m * beta * beta;
  }
  sc.force_x.assign(P, Vec3::Zero());
  sc.force_s.setZero(P);
  const VecX& sd = mk.sdot;
  const VecX& sdd = sc.sddot;
  for (int i = 0; i < ns; ++i) {
    if (sc.m0[i] == 0.0 && sc.m1[i] == 0.0) continue;
    const double ds = s[i + 1] - s[i];
    const Vec3 dx = mk.x_w[i + 1] - mk.x_w[i], dxd = mk.xdot_w[i + 1] - mk.xdot_w[i];
    const Vec3 dxdd = sc.xddot_w[i + 1] - sc.xddot_w[i];
    // betadot = b0 + b1 beta, betaddot = e0 + e1 beta (from beta Delta s = s_a - s_i)
    const double b0 = -sd[i] / ds, b1 = -(sd[i + 1] - sd[i]) / ds;
    const double e0 = -sdd[i] / ds + 2.0 * b0 * b1, e1 = 2.0 * b1 * b1 - (sdd[i + 1] - sdd[i]) / ds;
    // xddot_a = xddot_i + betaddot Delta x + 2 betadot Delta xdot + beta Delta xddot = c0 + c1 beta
    const Vec3 c0g = sc.xddot_w[i] + e0 * dx + 2.0 * b0 * dxd - gravity;
    const Vec3 c1 = e1 * dx + 2.0 * b1 * dxd + dxdd;
    const Vec3 Fs0 = sc.m0[i] * c0g + sc.m1[i] * c1, Fs1 = sc.m1[i] * c0g + sc.m2[i] * c1;
    const Vec3 F = dx / ds;
    sc.force_x[i] += Fs0 - Fs1;
    sc.force_x[i + 1] += Fs1;
    sc.force_s[i] -= F.dot(Fs0 - Fs1);
    sc.force_s[i + 1] -= F.dot(Fs1);
  }

  // 3. Eulerian forces onto the path points: J_sx^T g = -DeltaXbar^T DeltaS^T L^-T g
  if (n > 0) {
    sc.rhs = sc.force_s.segment(1, n);
    // L^T: sub(r) = L(r-1, r) = -l[r-1], super(r) = L(r+1, r) = -l[r+2]
    solveTridiagonal(n, [&](int r) { return -l[r - 1]; }, Ldiag, [&](int r) { return -l[r + 2]; }, sc.rhs, sc.tri_c);
    for (int i = 0; i < ns; ++i) {
      double k = 0.0;  // (DeltaS^T h)_i
      if (i < n) k -= (s[i + 2] - s[i + 1]) * sc.rhs[i];
      if (i > 0) k += (s[i] - s[i - 1]) * sc.rhs[i - 1];
      sc.force_x[i] += k * mk.dxbar[i];
      sc.force_x[i + 1] -= k * mk.dxbar[i];
    }
  }
  // path point forces onto the bodies (Gamma(x_b)^T R^T G) and the moving points' coordinates
  for (int a = 0; a < P; ++a) {
    const PathPoint& pt = path.points[mk.active[a]];
    const Vec3& G = sc.force_x[a];
    const int c = pt.kind == PathPointKind::Moving ? pt.coordinate : -1;
    const int b = pt.body;
    if (b < 0) {
      if (c >= 0) tau[c] += sc.dx_b[a].dot(G);
      continue;
    }
    const Vec3 g = motion.E_wi[b].topLeftCorner<3, 3>().transpose() * G;
    wrench[b].head<3>() += mk.x_b[a].cross(g);
    wrench[b].tail<3>() += g;
    if (c >= 0) tau[c] += sc.dx_b[a].dot(g);  // (R x_b') . G
  }
}

}  // namespace redmax
