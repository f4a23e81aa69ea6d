#include "core/integrators/symplectic_euler.hpp"

#include <cmath>

#include "core/skeleton/kinematics.hpp"

namespace redmax {

void SymplecticEuler::step(const System& sys, State& s, double h, DynamicsWorkspace& ws) {
  sys.calcMassAndForce(s, ws);
  ++stats_.rhs_evals;
  const VecX a = ws.M * s.qdot + h * ws.f;
  if (sys.numConstraintRows() == 0) {
    s.qdot = ws.M.ldlt().solve(a);
  } else {
    sys.calcConstraints(s, ws);
    const VecX b = ws.G * s.qdot + h * ws.rhs - ws.vel_err;
    s.qdot = System::solveKKT(ws.M, ws.G, a, b, &ws.lambda);
  }
  s.q += h * s.qdot;
  s.t += h;
  ++stats_.steps;
  stats_.reparameterizations += reparameterizeJoints(sys.model(), s);
  checkFinite(s, h, "euler");
}

void SymplecticEuler::advance(const System& sys, State& s, double t_out) {
  // equal steps no longer than dt that land on t_out exactly (no round-off sliver steps)
  const double span = t_out - s.t;
  if (span <= 0.0) return;
  const long n = std::max(1L, static_cast<long>(std::ceil(span / opt_.dt - 1e-9)));
  if (n > opt_.max_steps) throw SimulationError("euler: more than max_steps steps requested", s.t, opt_.dt);
  const double h = span / static_cast<double>(n);
  const double t0 = s.t;
  DynamicsWorkspace ws(sys.model());
  for (long k = 0; k < n; ++k) step(sys, s, h, ws);
  s.t = t0 + span;
}

}  // namespace redmax
