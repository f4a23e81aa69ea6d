#pragma once
// Shared helpers of the muscle tests: random states and paths on small models, and one-call
// evaluation of the muscle pipeline at a state.
#include <random>
#include <vector>

#include "core/muscles/muscle_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::test {

inline State randomState(int nr, std::mt19937& rng, double qscale = 1.0, double vscale = 2.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.q = VecX::NullaryExpr(nr, [&] { return qscale * u(rng); });
  s.qdot = VecX::NullaryExpr(nr, [&] { return vscale * u(rng); });
  return s;
}

inline Vec3 randomVec(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return Vec3(u(rng), u(rng), u(rng)) * scale;
}

/// the same kinematics with every Jacobian in nr columns (cols becomes 0..nr-1)
inline void expandAll(MuscleKinematics& mk, int nr) {
  const int k = static_cast<int>(mk.cols.size());
  for (MatX* J : {&mk.J_xr, &mk.Jdot_xr, &mk.J_sr, &mk.Jdot_sr, &mk.J_ar, &mk.Jdot_ar})
    if (J->cols() == k && J->size() > 0) *J = expandColumns(*J, mk, nr);
  mk.cols.resize(nr);
  mk.col_of.resize(nr);
  for (int c = 0; c < nr; ++c) mk.cols[c] = mk.col_of[c] = c;
}

/// skeleton kinematics + one muscle's kinematics at s, Jacobians expanded to nr columns
inline MuscleKinematics evalMuscle(const Model& model, const Muscle& muscle, const State& s,
                                   bool velocity = true) {
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  MuscleWorkspace ws(model, {muscle});
  calcMuscleKinematics(model, s, sk, muscle, ws.muscles[0], velocity);
  MuscleKinematics mk = ws.muscles[0];
  expandAll(mk, model.nr());
  return mk;
}

/// the largest distance of a mass point from the straight origin-insertion line (m): above round-off
/// when a Type III path wraps
inline double offStraightLine(const MuscleKinematics& mk) {
  const Vec3 a = mk.x_w.front(), b = mk.x_w.back();
  double off = 0.0;
  for (const Vec3& x : mk.x_a) off = std::max(off, ((x - a).cross(b - a)).norm() / (b - a).norm());
  return off;
}

/// state moved by t along its own velocity (q + t qdot, same qdot): every joint uses qdot = dq/dt
inline State along(const State& s, double t) {
  State r = s;
  r.q += t * s.qdot;
  return r;
}

/// J_ar by central differences (step h) of the mass points x_a in each coordinate, 3 N x nr
inline MatX calcJarFd(const Model& model, const Muscle& muscle, const State& s, double h) {
  const int N = muscle.mass_points.size(), nr = model.nr();
  MatX J(3 * N, nr);
  for (int j = 0; j < nr; ++j) {
    State sp = s, sm = s;
    sp.q[j] += h;
    sm.q[j] -= h;
    const MuscleKinematics kp = evalMuscle(model, muscle, sp, false), km = evalMuscle(model, muscle, sm, false);
    for (int a = 0; a < N; ++a) J.block<3, 1>(3 * a, j) = (kp.x_a[a] - km.x_a[a]) / (2 * h);
  }
  return J;
}

/// Jdot_ar by central differences (step h) of J_ar along the state's own velocity (along())
inline MatX calcJdotArFd(const Model& model, const Muscle& muscle, const State& s, double h) {
  return (evalMuscle(model, muscle, along(s, h)).J_ar - evalMuscle(model, muscle, along(s, -h)).J_ar) / (2 * h);
}

/// point at arc fraction alpha of the polyline through pts (independent of the library's code)
inline Vec3 pointAtArcFraction(const std::vector<Vec3>& pts, double alpha) {
  double total = 0.0;
  for (size_t i = 0; i + 1 < pts.size(); ++i) total += (pts[i + 1] - pts[i]).norm();
  double target = alpha * total;
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    const double li = (pts[i + 1] - pts[i]).norm();
    if (target <= li || i + 2 == pts.size()) return pts[i] + (target / li) * (pts[i + 1] - pts[i]);
    target -= li;
  }
  return pts.back();
}

}  // namespace redmax::test
