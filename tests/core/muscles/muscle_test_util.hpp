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

/// skeleton kinematics + one muscle's kinematics at s
inline MuscleKinematics evalMuscle(const Model& model, const Muscle& muscle, const State& s,
                                   bool velocity = true) {
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  MuscleWorkspace ws(model, {muscle});
  calcMuscleKinematics(model, s, sk, muscle, ws.muscles[0], velocity);
  return ws.muscles[0];
}

/// state moved by t along its own velocity (q + t qdot, same qdot): every joint uses qdot = dq/dt
inline State along(const State& s, double t) {
  State r = s;
  r.q += t * s.qdot;
  return r;
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
