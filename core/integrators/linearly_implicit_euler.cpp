#include "core/integrators/linearly_implicit_euler.hpp"

#include "core/integrators/implicit_solve.hpp"

namespace redmax {

void LinearlyImplicitEuler::step(const System& sys, State& s, double h, DynamicsWorkspace& ws) {
  sys.calcMassAndForce(s, ws);
  sys.calcStiffnessDamping(s, ws);
  ++stats_.rhs_evals;
  ++stats_.jacobian_evals;
  // implicit matrix and right-hand side [D Eq. 4.80, 4.82]
  const MatX A = ws.M + h * ws.D + (h * h) * ws.K;
  const VecX a = ws.M * s.qdot + h * (ws.f + ws.D * s.qdot);
  static const MatX no_rows;
  if (sys.numConstraintRows() == 0) {
    s.qdot = detail::solveImplicit(A, no_rows, a, VecX(), &ws.lambda);
  } else {
    // velocity-level constraint rows, drift removed as in symplectic Euler [D Eq. 4.102, 4.110]
    sys.calcConstraints(s, ws);
    const VecX b = ws.G * s.qdot + h * ws.rhs - ws.vel_err;
    s.qdot = detail::solveImplicit(A, ws.G, a, b, &ws.lambda);
  }
  s.q += h * s.qdot;
  s.t += h;
}

}  // namespace redmax
