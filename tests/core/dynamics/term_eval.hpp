// One force term evaluated alone at a state (its own kinematics), for the force-element and
// contact tests: the generalized force, the potential, and the potential's central-difference
// gradient that conservative forces must equal with the opposite sign.
#pragma once

#include "core/dynamics/force_term.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax::test {

inline VecX termForce(const Model& m, const ForceTerm& t, const State& s, const VecX& controls = VecX()) {
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  TermContext ctx(sk);
  ctx.controls = &controls;
  VecX f = VecX::Zero(m.nr());
  t.addForce(m, s, ctx, f);
  return f;
}

inline double termPotential(const Model& m, const ForceTerm& t, const State& s) {
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  return t.potentialEnergy(m, s, TermContext(sk));
}

/// dV/dq by central differences of step h in each coordinate
inline VecX potentialGradient(const Model& m, const ForceTerm& t, const State& s, double h = 1e-6) {
  VecX grad(m.nr());
  for (int i = 0; i < m.nr(); ++i) {
    State sp = s, sm = s;
    sp.q[i] += h;
    sm.q[i] -= h;
    grad[i] = (termPotential(m, t, sp) - termPotential(m, t, sm)) / (2 * h);
  }
  return grad;
}

}  // namespace redmax::test
