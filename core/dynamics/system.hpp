#pragma once
// A System is a skeleton Model plus the ForceTerms and Constraints that act on it: what the
// integrators and inverse dynamics see. It assembles
//   M qddot = f                                      (ndof = nr unless terms add coordinates)
// and, with constraints, the KKT system of [D Eq. 4.101-4.109]
//   [ M  G^T ] [qddot ]   [ f   ]
//   [ G   0  ] [lambda] = [ rhs ]
#include <memory>
#include <vector>

#include "core/dynamics/constraint.hpp"
#include "core/dynamics/force_term.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax {

/// Scratch for one evaluation of the dynamics; one per thread.
struct DynamicsWorkspace {
  explicit DynamicsWorkspace(const Model& model);
  SkeletonWorkspace sk;
  MatX M;          // mass matrix                      (ndof x ndof)
  VecX f;          // generalized force                (ndof)
  MatX K, D;       // -df/dq, -df/dqdot (implicit use) (ndof x ndof)
  MatX G;          // stacked constraint Jacobian      (nc x ndof)
  VecX rhs;        // acceleration-level rhs           (nc)
  VecX lambda;     // constraint multipliers           (nc)
  VecX pos_err, vel_err;                            // (nc)
};

/// Baumgarte stabilisation for acceleration-level constraints: rhs -= 2 alpha verr + beta^2 perr.
struct StabilizationOptions {
  double alpha = 0.0;
  double beta = 0.0;
};

class System {
 public:
  explicit System(Model model);

  const Model& model() const { return model_; }
  int ndof() const { return model_.nr(); }
  int numConstraintRows() const { return nc_; }

  void addTerm(std::shared_ptr<const ForceTerm> term) { terms_.push_back(std::move(term)); }
  void addConstraint(std::shared_ptr<const Constraint> c);
  const std::vector<std::shared_ptr<const ForceTerm>>& terms() const { return terms_; }
  const std::vector<std::shared_ptr<const Constraint>>& constraints() const { return constraints_; }
  StabilizationOptions stabilization;

  State defaultState() const;

  /// kinematics, M and f (skeleton + terms) [D Eq. 4.76]
  void calcMassAndForce(const State& s, DynamicsWorkspace& ws) const;
  /// K and D (joint springs/dampers + terms), after calcMassAndForce [D Eq. 4.82]
  void calcStiffnessDamping(const State& s, DynamicsWorkspace& ws) const;
  /// constraint G, rhs (stabilised) and errors, after calcMassAndForce
  void calcConstraints(const State& s, DynamicsWorkspace& ws) const;

  /// accelerations; solves the KKT system when there are constraints. Multipliers in ws.lambda.
  VecX forwardDynamics(const State& s, DynamicsWorkspace& ws) const;
  /// generalized forces tau with M qddot = f + tau (REDMAX route, unconstrained) [D Eq. 4.18]
  VecX inverseDynamics(const State& s, const VecX& qddot, DynamicsWorkspace& ws) const;

  double kineticEnergy(const State& s, DynamicsWorkspace& ws) const;
  double potentialEnergy(const State& s, DynamicsWorkspace& ws) const;

  /// solve [M G^T; G 0] [x; lambda] = [a; b] (dense; G may be empty)
  static VecX solveKKT(const MatX& M, const MatX& G, const VecX& a, const VecX& b, VecX* lambda);

 private:
  Model model_;
  std::vector<std::shared_ptr<const ForceTerm>> terms_;
  std::vector<std::shared_ptr<const Constraint>> constraints_;
  int nc_ = 0;
};

}  // namespace redmax
