#include "core/muscles/muscle_inverse_dynamics.hpp"

#include <algorithm>

#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/via_point.hpp"

namespace redmax {

namespace {

// resize (no-op at the same size) and zero a few entries in place: Eigen's setZero calls memset,
// whose call costs more than these handful of stores
void zeroed(VecX& v, int n) {
  v.resize(n);
  for (int i = 0; i < n; ++i) v[i] = 0.0;
}

// The equal-strain matrix L (n x n, tridiagonal: sub(r) = L(r, r-1), diag(r), super(r) = L(r, r+1))
// factored once as L = B U, B lower bidiagonal (diagonal piv_r, sub-diagonal sub(r)), U unit upper
// (super-diagonal c_r), by elimination without pivoting: L is diagonally dominant by rows
// (|sub| + |super| = diag, strictly in the end rows) and so L^T by columns, where elimination
// without pivoting is stable. The three solves of a muscle (L twice, L^T once) share it.
template <class Sub, class Diag, class Super>
void factorTridiagonal(int n, Sub sub, Diag diag, Super super, VecX& c, VecX& inv_piv) {
  c.resize(n);
  inv_piv.resize(n);
  for (int r = 0; r < n; ++r) {
    inv_piv[r] = 1.0 / (r == 0 ? diag(0) : diag(r) - sub(r) * c[r - 1]);
    c[r] = r + 1 < n ? super(r) * inv_piv[r] : 0.0;
  }
}
// L x = b in place: B y = b forward, U x = y backward
template <class Sub>
void solveFactored(int n, Sub sub, const VecX& c, const VecX& inv_piv, VecX& b) {
  b[0] *= inv_piv[0];
  for (int r = 1; r < n; ++r) b[r] = (b[r] - sub(r) * b[r - 1]) * inv_piv[r];
  for (int r = n - 2; r >= 0; --r) b[r] -= c[r] * b[r + 1];
}
// L^T x = b in place: U^T y = b forward, B^T x = y backward
template <class Sub>
void solveFactoredTransposed(int n, Sub sub, const VecX& c, const VecX& inv_piv, VecX& b) {
  for (int r = 1; r < n; ++r) b[r] -= c[r - 1] * b[r - 1];
  b[n - 1] *= inv_piv[n - 1];
  for (int r = n - 2; r >= 0; --r) b[r] = (b[r] - sub(r + 1) * b[r + 1]) * inv_piv[r];
}

}  // namespace

const char* pathwiseInverseDynamicsRefusal(const Muscle& m) {
  if (pathType(m.path) == PathType::III) return "wraps (Type III)";
  if (hasNodePoints(m.path)) return "runs through a deformable node";
  if (m.fibre.enabled()) return "has fibre-following mass points";
  return nullptr;
}

void addCompactMuscleIdShare(const MassPoints& mp, const MuscleKinematics& mk, const VecX& qdot_c, const VecX& qddot_c,
                             const Vec3& gravity, bool quadratic_velocity, bool fibre_bias, VecX& fc) {
  for (int a = 0; a < mp.size(); ++a) {
    Vec3 acc = mk.J_ar.middleRows<3>(3 * a) * qddot_c - gravity;
    if (quadratic_velocity) acc.noalias() += mk.Jdot_ar.middleRows<3>(3 * a) * qdot_c;
    if (fibre_bias) acc.noalias() += mk.a_z.segment<3>(3 * a);  // as addForce: the fibre's own motion
    fc.noalias() += mk.J_ar.middleRows<3>(3 * a).transpose() * (mp.mass[a] * acc);
  }
}

void calcBodyWorldMotion(const BodyMotion& motion, std::vector<BodyWorldMotion>& out) {
  const size_t nb = motion.E_wi.size();
  out.resize(nb);
  for (size_t b = 0; b < nb; ++b) {
    BodyWorldMotion& o = out[b];
    o.R = motion.E_wi[b].topLeftCorner<3, 3>();
    o.p = motion.E_wi[b].topRightCorner<3, 1>();
    o.omega = o.R * motion.phi[b].head<3>();
    o.nu = o.R * motion.phi[b].tail<3>();
    o.alpha = o.R * motion.phidot[b].head<3>();
    o.bias = o.R * motion.phidot[b].tail<3>() + o.omega.cross(o.nu);
  }
}

void addWorldWrenches(const std::vector<BodyWorldMotion>& bodies, const std::vector<Vec6>& w_world,
                      std::vector<Vec6>& wrench) {
  for (size_t b = 0; b < w_world.size(); ++b) {
    const Vec6& w = w_world[b];
    if (w.isZero(0.0)) continue;
    wrench[b].head<3>().noalias() += bodies[b].R.transpose() * w.head<3>();
    wrench[b].tail<3>().noalias() += bodies[b].R.transpose() * w.tail<3>();
  }
}

void addMuscleInverseDynamics(const Model& model, const State& state, const VecX& qddot,
                              const std::vector<BodyWorldMotion>& bodies, const Vec3& gravity,
                              const Muscle& muscle, MuscleKinematics& mk, MuscleIdScratch& sc,
                              std::vector<Vec6>& w_world, VecX& tau) {
  const MusclePath& path = muscle.path;
  const MassPoints& mp = muscle.mass_points;

  // 1. active path points: positions, velocities, accelerations [D Eq. 5.8, 5.11], in world
  //    axes from the body's world motion (BodyWorldMotion); a moving point adds its motion on
  //    the body, rd = R x_b' qdot_k and rdd = R (x_b'' qdot_k^2 + x_b' qddot_k):
  //    xdot = omega x r + nu + rd,  xddot = alpha x r + omega x (omega x r + 2 rd) + bias + rdd
  activePathPoints(path, state.q, mk.active);
  const int P = static_cast<int>(mk.active.size());
  for (std::vector<Vec3>* v : {&mk.x_b, &mk.x_w, &mk.xdot_w, &sc.dx_b, &sc.ddx_b, &sc.r_w, &sc.xddot_w})
    if (static_cast<int>(v->size()) != P) v->resize(P);  // the call costs even at the same size
  for (int a = 0; a < P; ++a) {
    const PathPoint& pt = path.points[mk.active[a]];
    const int b = pt.body;
    if (pt.kind != PathPointKind::Moving) {  // (x_b, dx_b, ddx_b are read for moving points only)
      if (pt.kind == PathPointKind::Node)
        throw std::logic_error("addMuscleInverseDynamics: muscle '" + muscle.name +
                               "' has a deformable node point (MuscleTerm takes its compact J_ar route)");
      if (b < 0) {
        mk.x_w[a] = pt.location;
        mk.xdot_w[a].setZero();
        sc.xddot_w[a].setZero();
        continue;
      }
      const BodyWorldMotion& o = bodies[b];
      const Vec3 r = o.R * pt.location;
      const Vec3 wr = o.omega.cross(r);
      sc.r_w[a] = r;
      mk.x_w[a] = r + o.p;
      mk.xdot_w[a] = wr + o.nu;
      sc.xddot_w[a] = o.alpha.cross(r) + o.omega.cross(wr) + o.bias;
      continue;
    }
    calcPointLocation(pt, state.q, mk.x_b[a], sc.dx_b[a], sc.ddx_b[a]);
    const Vec3& x_b = mk.x_b[a];
    const int c = pt.coordinate;  // none connected: the point is fixed at the functions' values at 0
    const double qd_c = c >= 0 ? state.qdot[c] : 0.0, qdd_c = c >= 0 ? qddot[c] : 0.0;
    const Vec3 xdot_b = sc.dx_b[a] * qd_c;                                // relative to the body
    const Vec3 xddot_b = sc.ddx_b[a] * (qd_c * qd_c) + sc.dx_b[a] * qdd_c;
    if (b < 0) {
      mk.x_w[a] = x_b;
      mk.xdot_w[a] = xdot_b;
      sc.xddot_w[a] = xddot_b;
      continue;
    }
    const BodyWorldMotion& o = bodies[b];
    const Vec3 r = o.R * x_b, rd = o.R * xdot_b;
    const Vec3 v = o.omega.cross(r) + o.nu;
    sc.r_w[a] = r;
    mk.x_w[a] = r + o.p;
    mk.xdot_w[a] = v + rd;
    sc.xddot_w[a] = o.alpha.cross(r) + o.omega.cross(v - o.nu + 2.0 * rd) + o.bias + o.R * xddot_b;
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
  const double inv_length = 1.0 / mk.length;  // divisions are the slow operations here: one each
  for (int i = 1; i < P; ++i) mk.s[i] = mk.s[i - 1] + mk.l[i - 1] * inv_length;
  mk.s[P - 1] = 1.0;
  zeroed(mk.sdot, P);
  zeroed(sc.sddot, P);
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
    factorTridiagonal(n, Lsub, Ldiag, Lsuper, sc.tri_c, sc.tri_d);
    solveFactored(n, Lsub, sc.tri_c, sc.tri_d, sc.rhs);
    mk.sdot.segment(1, n) = sc.rhs;
    // segment length accelerations lddot = dxbar . Delta xddot + dxbardot . Delta xdot [D Eq. 5.28]
    sc.lddot.resize(ns);
    for (int i = 0; i < ns; ++i) {
      const Vec3& u = mk.dxbar[i];
      const Vec3 dxd = mk.xdot_w[i + 1] - mk.xdot_w[i];
      const Vec3 ud = (dxd - u * u.dot(dxd)) * (1.0 / l[i]);
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
    solveFactored(n, Lsub, sc.tri_c, sc.tri_d, sc.rhs);
    sc.sddot.segment(1, n) = sc.rhs;
  }

  // 2. the mass points by segment: three moments each (the rule of calcViaPointMassPoints)
  zeroed(sc.m0, ns);
  zeroed(sc.m1, ns);
  zeroed(sc.m2, ns);
  const int N = mp.size();
  if (sc.alpha_sorted < 0) sc.alpha_sorted = std::is_sorted(mp.alpha.begin(), mp.alpha.end()) ? 1 : 0;
  if (sc.alpha_sorted == 1) {
    // points in increasing alpha (as makeMassPoints places them): each segment's points are one
    // run [lo, hi), whose moments come from the run's centred sums (MuscleIdScratch::Run), formed
    // again only when the run changes (a point crossing a path point)
    if (sc.runs_of != mp.mass.data()) {
      sc.runs.clear();
      sc.runs_of = mp.mass.data();
    }
    if (static_cast<int>(sc.runs.size()) < ns) sc.runs.resize(ns);
    int lo = 0;
    for (int i = 0; i < ns && lo < N; ++i) {
      MuscleIdScratch::Run& run = sc.runs[i];
      int hi = lo;
      if (i + 1 == ns) hi = N;
      else if (run.lo == lo && (run.hi == N || mp.alpha[run.hi] >= s[i + 1]) && (run.hi == lo || mp.alpha[run.hi - 1] < s[i + 1]))
        hi = run.hi;  // the run is unchanged (alpha increasing: the end test suffices)
      else
        while (hi < N && mp.alpha[hi] < s[i + 1]) ++hi;
      if (hi == lo) continue;
      if (run.lo != lo || run.hi != hi) {
        run.lo = lo;
        run.hi = hi;
        run.m = 0.0;
        double ma = 0.0;
        for (int a = lo; a < hi; ++a) run.m += mp.mass[a], ma += mp.mass[a] * mp.alpha[a];
        run.c = run.m > 0.0 ? ma / run.m : mp.alpha[lo];
        run.c2 = 0.0;
        for (int a = lo; a < hi; ++a) run.c2 += mp.mass[a] * (mp.alpha[a] - run.c) * (mp.alpha[a] - run.c);
      }
      const double inv_ds = 1.0 / (s[i + 1] - s[i]), d = (run.c - s[i]) * inv_ds;
      sc.m0[i] = run.m;
      sc.m1[i] = run.m * d;
      sc.m2[i] = run.c2 * (inv_ds * inv_ds) + run.m * d * d;
      lo = hi;
    }
  } else {
    for (int a = 0; a < N; ++a) {
      const double s_a = mp.alpha[a];
      int i = 0;
      while (i < P - 2 && s[i + 1] <= s_a) ++i;
      const double beta = (s_a - s[i]) / (s[i + 1] - s[i]), m = mp.mass[a];
      sc.m0[i] += m;
      sc.m1[i] += m * beta;
      sc.m2[i] += m * beta * beta;
    }
  }
  sc.force_x.resize(P);
  for (Vec3& f : sc.force_x) f.setZero();
  zeroed(sc.force_s, P);
  const VecX& sd = mk.sdot;
  const VecX& sdd = sc.sddot;
  for (int i = 0; i < ns; ++i) {
    if (sc.m0[i] == 0.0 && sc.m1[i] == 0.0) continue;
    const double inv_ds = 1.0 / (s[i + 1] - s[i]);
    const Vec3 dx = mk.x_w[i + 1] - mk.x_w[i], dxd = mk.xdot_w[i + 1] - mk.xdot_w[i];
    const Vec3 dxdd = sc.xddot_w[i + 1] - sc.xddot_w[i];
    // betadot = b0 + b1 beta, betaddot = e0 + e1 beta (from beta Delta s = s_a - s_i)
    const double b0 = -sd[i] * inv_ds, b1 = -(sd[i + 1] - sd[i]) * inv_ds;
    const double e0 = -sdd[i] * inv_ds + 2.0 * b0 * b1, e1 = 2.0 * b1 * b1 - (sdd[i + 1] - sdd[i]) * inv_ds;
    // xddot_a = xddot_i + betaddot Delta x + 2 betadot Delta xdot + beta Delta xddot = c0 + c1 beta
    const Vec3 c0g = sc.xddot_w[i] + e0 * dx + 2.0 * b0 * dxd - gravity;
    const Vec3 c1 = e1 * dx + 2.0 * b1 * dxd + dxdd;
    const Vec3 Fs0 = sc.m0[i] * c0g + sc.m1[i] * c1, Fs1 = sc.m1[i] * c0g + sc.m2[i] * c1;
    const Vec3 F = dx * inv_ds;
    sc.force_x[i] += Fs0 - Fs1;
    sc.force_x[i + 1] += Fs1;
    sc.force_s[i] -= F.dot(Fs0 - Fs1);
    sc.force_s[i + 1] -= F.dot(Fs1);
  }

  // 3. Eulerian forces onto the path points: J_sx^T g = -DeltaXbar^T DeltaS^T L^-T g
  if (n > 0) {
    sc.rhs = sc.force_s.segment(1, n);
    solveFactoredTransposed(n, Lsub, sc.tri_c, sc.tri_d, sc.rhs);
    for (int i = 0; i < ns; ++i) {
      double k = 0.0;  // (DeltaS^T h)_i
      if (i < n) k -= (s[i + 2] - s[i + 1]) * sc.rhs[i];
      if (i > 0) k += (s[i] - s[i - 1]) * sc.rhs[i - 1];
      sc.force_x[i] += k * mk.dxbar[i];
      sc.force_x[i + 1] -= k * mk.dxbar[i];
    }
  }
  // path point forces onto the bodies, in world axes (r x G; G) about the body origin (the body
  // wrench Gamma(x_b)^T R^T G once rotated back, addWorldWrenches), and onto the moving points'
  // coordinates (R x_b') . G
  for (int a = 0; a < P; ++a) {
    const PathPoint& pt = path.points[mk.active[a]];
    const Vec3& G = sc.force_x[a];
    const int c = pt.kind == PathPointKind::Moving ? pt.coordinate : -1;
    const int b = pt.body;
    if (b < 0) {
      if (c >= 0) tau[c] += sc.dx_b[a].dot(G);
      continue;
    }
    w_world[b].head<3>() += sc.r_w[a].cross(G);
    w_world[b].tail<3>() += G;
    if (c >= 0) tau[c] += (bodies[b].R * sc.dx_b[a]).dot(G);
  }
}

}  // namespace redmax
