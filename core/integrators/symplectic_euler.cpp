#include "core/integrators/symplectic_euler.hpp"

namespace redmax {

void SymplecticEuler::step(const System& sys, State& s, double h, DynamicsWorkspace& ws) {
  sys.calcMassAndForce(s, ws);
  ++stats_.rhs_evals;
  // momentum update [D Eq. 4.20]
  const VecX a = ws.M * s.qdot + h * ws.f;
  if (sys.numConstraintRows() == 0) {
    s.qdot = ws.M.ldlt().solve(a);
  } else {
    // velocity-level constraint rows [D Eq. 4.102, 4.110]
    sys.calcConstraints(s, ws);
    const VecX b = ws.G * s.qdot + h * ws.rhs - ws.vel_err;
    s.qdot = System::solveKKT(ws.M, ws.G, a, b, &ws.lambda);
  }
  // positions with the new velocities: this is what makes the scheme symplectic
  s.q += h * s.qdot;
  s.t += h;
}

}  // namespace redmax
