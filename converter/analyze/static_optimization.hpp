#pragma once
// One frame of OpenSim's static optimization (StaticOptimization / StaticOptimizationTarget) as a
// convex program over the actuators' controls x (muscle activations, reserve controls):
//
//   minimize   sum_i |x_i|^p                     (p = activation_exponent, OpenSim's objective)
//   subject to A x = b,   lower <= x <= upper     (min/max control of each actuator)
//
// A's column i is actuator i's generalized force per unit control: for a muscle F_i * (-dl_i/dq)
// (F_i = max isometric force, or with use_muscle_physiology the active fibre force along the tendon
// at activation 1 and rigid tendon, OpenSim's calcInextensibleTendonActiveFiberForce), for a
// CoordinateActuator its optimal force on its coordinate. b is what the actuators must supply:
// the inverse-dynamics forces of the frame (with the muscles' mass points when they carry mass).
// OpenSim states the same equalities as accelerations, M^-1 (A x - b) = 0, which has the same
// feasible set and so the same optimum (the objective is strictly convex for p > 1).
//
// Solved by IPOPT (Debian coinor-libipopt-dev; OpenSim's optimizer wraps the same library): exact
// gradient and Hessian, constant linear constraints. checkOptimality re-derives the KKT conditions
// from the returned point alone, so a result is checked independently of the solver.
#include <string>

#include "core/spatial/types.hpp"

namespace redmax::osim {

struct StaticOptimizationProblem {
  MatX A;          ///< generalized force per unit control      (ndof x n)
  VecX b;          ///< generalized force to supply             (ndof)
  VecX lower, upper;  ///< control bounds                       (n)
  double exponent = 2.0;  ///< activation_exponent, > 1
  VecX x0;         ///< starting point (n), e.g. the previous frame's optimum; empty = bounds' middle
};

struct StaticOptimizationOptions {
  double convergence_tolerance = 1e-10;  ///< IPOPT tol (OpenSim's optimizer_convergence_criterion)
  int max_iterations = 1000;             ///< optimizer_max_iterations
};

struct StaticOptimizationResult {
  VecX x;                  ///< the controls at the returned point                     (n)
  VecX lambda;             ///< equality multipliers, grad f + A^T lambda - z = 0       (ndof)
  int iterations = 0;
  double constraint_violation = 0.0;  ///< max |A x - b|
  bool converged = false;
  std::string status;      ///< IPOPT's status in words ("solved", "infeasible", ...)
};

/// Throws std::invalid_argument for inconsistent sizes, lower > upper, exponent <= 1 or
/// non-finite data. A frame that does not converge (e.g. bounds that cannot supply b) returns
/// converged = false with IPOPT's status; it is never reported as a solution.
StaticOptimizationResult solveStaticOptimization(const StaticOptimizationProblem& problem,
                                                 const StaticOptimizationOptions& options = {});

/// The first-order optimality conditions at x, computed from the problem alone: the equality
/// multipliers by least squares on the controls strictly inside their bounds, then
///   stationarity   max over inner i of |p |x_i|^(p-1) sign(x_i) + (A^T lambda)_i|
///   bound signs    max over i at a bound of the wrong-signed part of the bound multiplier
///   feasibility    max |A x - b| and the largest bound violation
/// `active_tol` decides which controls are at a bound.
struct OptimalityReport {
  double stationarity = 0.0;
  double bound_sign = 0.0;
  double equality = 0.0;
  double bound_violation = 0.0;
  int at_bounds = 0;
};
OptimalityReport checkOptimality(const StaticOptimizationProblem& problem, const VecX& x,
                                 double active_tol = 1e-7);

}  // namespace redmax::osim
