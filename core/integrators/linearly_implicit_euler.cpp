#include "core/integrators/linearly_implicit_euler.hpp"

#include "core/dynamics/unilateral/qp_solver.hpp"
#include "core/integrators/implicit_solve.hpp"

#include <stdexcept>

namespace redmax {

LinearlyImplicitEuler::LinearlyImplicitEuler(const IntegratorOptions& opt) : FixedStepIntegrator(opt) {
  if (opt.linear_solver != "auto" && opt.linear_solver != "dense" && opt.linear_solver != "sparse")
    throw std::invalid_argument("bdf1: linear_solver must be auto, dense or sparse, not '" + opt.linear_solver + "'");
}

bool LinearlyImplicitEuler::sparseRoute(const System& sys) const {
  const std::string& how = options().linear_solver;
  if (how == "dense") return false;
  const bool possible = !sys.coordinateMap() && !sys.unilateral();
  if (how == "sparse") {
    if (!possible)
      throw ModelError("bdf1: the sparse linear solver takes no coordinate map and no hard unilateral constraints");
    return true;
  }
  return possible && sys.numExtraCoordinates() > 0 && sys.ndof() >= kSparseStepFrom;
}

void LinearlyImplicitEuler::step(const System& sys, State& s, double h, DynamicsWorkspace& ws) {
  const bool sparse = sparseRoute(sys);
  // implicit matrix and right-hand side [D Eq. 4.80, 4.82]: (M + h D + h^2 K) qdot+ = M qdot + h (f + D qdot),
  // dense or over sparse matrices (the same step)
  MatX A;
  Eigen::SparseMatrix<double> As;
  VecX a;
  if (sparse) {
    sys.calcSparseMatrices(s, ws, true, M_, K_, D_);
    a = M_ * s.qdot + h * (ws.f + D_ * s.qdot);
    As = M_ + h * D_ + (h * h) * K_;
  } else {
    sys.calcMassAndForce(s, ws);
    sys.calcStiffnessDamping(s, ws);
    A = ws.M + h * ws.D + (h * h) * ws.K;
    a = ws.M * s.qdot + h * (ws.f + ws.D * s.qdot);
  }
  ++stats_.rhs_evals;
  ++stats_.jacobian_evals;
  static const MatX no_rows;
  static const VecX no_rhs;
  const bool bilateral = sys.numConstraintRows() > 0;
  VecX b;
  if (bilateral) {
    // velocity-level constraint rows, drift removed as in symplectic Euler [D Eq. 4.102, 4.110]
    sys.calcConstraints(s, ws);
    b = ws.G * s.qdot + h * ws.rhs - ws.vel_err;
  }
  const MatX& G = bilateral ? ws.G : no_rows;
  const VecX& bb = bilateral ? b : no_rhs;
  bool done = false;
  if (sparse) {
    try {
      s.qdot = detail::solveImplicitSparse(As, G, a, bb, &ws.lambda);
    } catch (const std::runtime_error& e) {
      throw SimulationError(std::string("bdf1: ") + e.what() + " at t = " + std::to_string(s.t), s.t, h);
    }
    done = true;
  } else if (const auto& u = sys.unilateral()) {
    // hard unilateral constraints (dense route only): the contact QP on top of this step
    // (docs/contact.md §6); calcMassAndForce left the kinematics of s at the velocity stage in ws.sk
    u->detect(sys.model(), s, ws.sk, sys.ndof(), h, rows_);
    stats_.max_penetration = std::max(stats_.max_penetration, rows_.max_penetration);
    if (!rows_.c.empty()) {
      UnilateralStepStats st;
      try {
        s.qdot = solveUnilateralStep(A, a, G, bb, rows_, u->options(), &warm_, &ws.lambda, &st);
      } catch (const QpError& e) {
        throw SimulationError(std::string("bdf1: contact QP failed: ") + e.what() + " at t = " +
                                  std::to_string(s.t) + " with step h = " + std::to_string(h),
                              s.t, h);
      }
      stats_.unilateral_steps += st.candidates > 0;
      stats_.qp_iterations += st.qp_iterations;
      stats_.qp_solves += st.friction_iterations;
      stats_.contact_rows += st.contacts;
      stats_.max_contacts = std::max(stats_.max_contacts, st.contacts);
      stats_.friction_unconverged += !st.friction_converged;
      done = true;
    }
  }
  if (!done) s.qdot = detail::solveImplicit(A, G, a, bb, &ws.lambda);
  s.q += h * s.qdot;
  s.t += h;
}

}  // namespace redmax
