#pragma once
// A System is a skeleton Model plus the ForceTerms and Constraints that act on it: what the
// integrators and inverse dynamics see. It assembles
//   M qddot = f                                      (ndof = nr unless terms add coordinates)
// and, with constraints, the KKT system of [D Eq. 4.101-4.109]
//   [ M  G^T ] [qddot ]   [ f   ]
//   [ G   0  ] [lambda] = [ rhs ]
// i.e. M qddot = f - G^T lambda: -G^T lambda is the generalized constraint force. (Prescribed
// coordinates choose the sign of their row so that their multiplier is the actuating force; see
// core/dynamics/constraints/prescribed_coordinate.hpp.)
//
// Hyper-reduced coordinates [D Sec. 4.6.2]: with a CoordinateMap q_r = g(q_R) the system's
// coordinates are q_R (ndof = map->nR()); the skeleton, the ForceTerms and the Constraints still
// see the expanded q_r, and the System maps everything to q_R:
//   M = J_rR^T M_r J_rR,  f = J_rR^T (f_r - M_r Jdot_rR qdot_R),  G = G_r J_rR,
//   rhs = rhs_r - G_r Jdot_rR qdot_R                                 [D Eq. 4.84-4.86, 4.105]
// Without a map (the default) nothing changes: q = q_r and ndof = nr.
//
// Auxiliary first-order states and controls (docs/forward.md): the terms' states (ForceTerm::
// numStates) are stacked in State::z in term order (nz = numStates(), each term at its offset),
// their derivatives zdot go to ws.zdot (forwardDynamics, calcStateDerivatives); the controllers
// (core/dynamics/controller.hpp) write the terms' controls into ws.controls at every evaluation,
// before the terms. With nz = 0 and no controls every path is the one without them.
#include <cstdint>
#include <memory>
#include <vector>

#include "core/dynamics/body_loads.hpp"
#include "core/dynamics/constraint.hpp"
#include "core/dynamics/controller.hpp"
#include "core/dynamics/coordinate_map.hpp"
#include "core/dynamics/force_term.hpp"
#include "core/dynamics/unilateral/unilateral.hpp"
#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/dynamics/structured_forward.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax {

class System;

/// Everything one evaluation of a System writes, and the inputs that change per evaluation; one
/// per thread (MuJoCo's mjData, Pinocchio's Data). A System is immutable while it is evaluated
/// and may be shared by threads that each own a DynamicsWorkspace. Stages are computed in order
/// and only as far as the caller asks:
///   position   ws.sk (poses, J_mr): calcKinematics
///   velocity   ws.sk (twists, Jdot_mr), the terms' scratch (e.g. the muscles' J_ar, Jdot_ar)
///   dynamics   M, f (calcMassAndForce), then K, D, G, rhs, lambda as asked
/// Energies stop at the velocity stage (no M); ID of a term without mass adds none of its work.
struct DynamicsWorkspace {
  /// sized for the model's nr; the term slots are made on the first evaluation by a System
  explicit DynamicsWorkspace(const Model& model);
  /// sized for the system (ndof) with its term slots made now
  explicit DynamicsWorkspace(const System& system);
  DynamicsWorkspace(DynamicsWorkspace&&) = default;
  DynamicsWorkspace& operator=(DynamicsWorkspace&&) = default;

  // inputs of the next evaluation (set by the caller with the State; never written by the System)
  ExternalLoads loads;       // external point forces and torques (measured GRF)  (any count)
  VecX controls;             // actuator controls (excitations): written by the System's
                             // controllers at every evaluation; without controllers the caller's
                             // (zero when not of size System::numControls())     (nu)

  // position and velocity stage
  SkeletonWorkspace sk;
  std::uint64_t evaluation = 0;  // bumped whenever sk is recomputed (TermContext::evaluation)

  // dynamics stage
  MatX M;          // mass matrix                      (ndof x ndof)
  VecX f;          // generalized force                (ndof)
  MatX K, D;       // -df/dq, -df/dqdot (implicit use) (ndof x ndof)
  MatX G;          // stacked constraint Jacobian      (nc x ndof)
  VecX rhs;        // acceleration-level rhs           (nc)
  VecX lambda;     // constraint multipliers           (nc)
  VecX pos_err, vel_err;                            // (nc)
  VecX zdot;       // auxiliary state derivatives (forwardDynamics, calcStateDerivatives) (nz)
  /// true when M and f hold the last evaluated state's (calcMassAndForce, forwardDynamics on the
  /// Dense or TreeSparse route); false after forwardDynamics on the Articulated route, which
  /// forms neither: whoever reads M or f after forwardDynamics calls calcMassAndForce first then
  bool has_mass = false;
  /// the route the last forwardDynamics took, after fall-backs (System::forward_route)
  ForwardRoute last_route = ForwardRoute::Dense;
  StructuredForwardWorkspace fd;  // scratch of the CRBA, LTDL and ABA routes

  // recursive inverse dynamics (System::inverseDynamicsRecursive): poses, twists, rates, wrenches
  RecursiveIdWorkspace rid;
  VecX tau_direct;  // the terms' generalized forces that act on no body              (nr)

  // hyper-reduced coordinates only (System with a CoordinateMap); skeleton-side quantities,
  // sized on first use
  State s_r;                 // expanded state: q_r = g(q_R), qdot_r = J_rR qdot_R   (nr)
  MatX J_rR, Jdot_rR;        // (nr x ndof)
  MatX M_r;                  // skeleton + terms mass matrix in q_r              (nr x nr)
  VecX f_r;                  // skeleton + terms force in q_r                    (nr)
  MatX K_r, D_r;             // (nr x nr)
  MatX G_r;                  // constraint Jacobian in q_r                       (nc x nr)
  VecX rhs_r;                // (nc)

  // scratch owned for others (System::bind): one slot per ForceTerm of the bound system, in
  // System::terms() order (null where the term needs none), and one for an integrator that keeps
  // state per workspace (the built-in ones need none: VariationalEulerWorkspace is the
  // integrator's). All are dropped when the workspace is bound to another system (or it changed).
  std::vector<std::unique_ptr<TermScratch>> term_scratch;  // (number of terms)
  std::unique_ptr<TermScratch> integrator;
  std::uint64_t system_id = 0;  // System::id() the slots belong to; 0 = none
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
  /// Identity of this system and its terms, constraints and map: unique in the process, new for
  /// a copy and after every change (addTerm, addConstraint, setCoordinateMap,
  /// addExtraCoordinates); workspaces key their scratch on it.
  std::uint64_t id() const { return id_.value; }
  /// Make ws's scratch slots for this system unless they are already (a no-op then). Every
  /// evaluation below does it; integrators call it before using ws.integrator.
  void bind(DynamicsWorkspace& ws) const;
  /// number of system coordinates: nr, or the map's nR with hyper-reduced coordinates
  int ndof() const { return ndof_; }
  /// Append n coordinates that the skeleton does not own (e.g. free nodes of a deformable body
  /// [D Sec. 4.6.3]): they follow q_r in the state, start at zero, and only ForceTerms give them
  /// mass and force (the skeleton's blocks of M and f are zero there; constraints act on q_r).
  /// Returns the index of the first one. Not combinable with a coordinate map.
  int addExtraCoordinates(int n);
  int numExtraCoordinates() const { return n_extra_; }
  int numConstraintRows() const { return nc_; }

  /// add a term; its states and controls (if any) follow those of the terms before it
  void addTerm(std::shared_ptr<const ForceTerm> term);
  /// replace term i by one with the same numbers of states and controls (ModelError otherwise)
  void replaceTerm(size_t i, std::shared_ptr<const ForceTerm> term);
  void addConstraint(std::shared_ptr<const Constraint> c);
  const std::vector<std::shared_ptr<const ForceTerm>>& terms() const { return terms_; }
  const std::vector<std::shared_ptr<const Constraint>>& constraints() const { return constraints_; }
  StabilizationOptions stabilization;
  /// how forwardDynamics solves for qddot (core/dynamics/structured_forward.hpp, docs/forward.md):
  /// Auto picks by structure; every route gives the same qddot to round-off. With any route
  /// other than Dense, calcMassAndForce forms the skeleton's M by CRBA and its f by Newton-Euler
  /// at qddot = 0 (Dense: J_mr^T M_m J_mr and J_mr^T (f_m - M_m Jdot_mr qdot), the reference).
  ForwardRoute forward_route = ForwardRoute::Auto;
  /// the route forwardDynamics will try for this system (Auto resolved; before the run-time
  /// fall-backs that ws.last_route records): Dense with constraints, a coordinate map or extra
  /// coordinates, Articulated only when no term adds mass (ForceTerm::addsMass)
  ForwardRoute plannedForwardRoute() const;
  /// Hard unilateral constraints (joint limits, collisions; core/dynamics/unilateral/unilateral.hpp),
  /// enforced by the integrators that can (bdf1); the others refuse the system. nullptr removes
  /// them. Throws ModelError with a coordinate map (their rows are built in q_r).
  void setUnilateral(std::shared_ptr<const UnilateralConstraints> u);
  const std::shared_ptr<const UnilateralConstraints>& unilateral() const { return unilateral_; }

  // auxiliary states and controls
  /// nz: the terms' states, stacked in State::z
  int numStates() const { return nz_; }
  /// every state's name (nz), in State::z order
  std::vector<std::string> stateNames() const;
  /// offset of term i's states in State::z, and of its controls in ws.controls
  int stateOffset(size_t i) const { return z_offset_[i]; }
  int controlOffset(size_t i) const { return u_offset_[i]; }
  /// nu: the terms' controls
  int numControls() const { return nu_; }
  /// every control's name (nu): the actuators' names
  std::vector<std::string> controlNames() const;
  /// add a controller (they add up, OpenSim's ControllerSet)
  void addController(std::shared_ptr<const Controller> c);
  const std::vector<std::shared_ptr<const Controller>>& controllers() const { return controllers_; }
  /// kinematics, controls and zdot (ws.zdot) at s; no M, f
  void calcStateDerivatives(const State& s, DynamicsWorkspace& ws) const;
  /// the terms' equilibrium of the auxiliary states at s (ForceTerm::equilibrateStates), in term
  /// order, into s.z
  void equilibrateStates(State& s, DynamicsWorkspace& ws) const;

  /// default q, qdot = 0 and the terms' default states z
  State defaultState() const;

  /// Use hyper-reduced coordinates q_r = g(q_R) [D Sec. 4.6.2]; nullptr goes back to q_r.
  /// States passed to the System afterwards have ndof() = map->nR() entries. Throws ModelError
  /// if the map was built for a model with a different number of coordinates.
  void setCoordinateMap(std::shared_ptr<const CoordinateMap> map);
  const std::shared_ptr<const CoordinateMap>& coordinateMap() const { return map_; }
  /// the skeleton state (q_r, qdot_r) of a system state, for output and for skeleton-level
  /// algorithms (identity without a map)
  State expandState(const State& s) const;
  /// the system state of a skeleton state: the independent entries (identity without a map)
  State reduceState(const State& s_r) const;
  /// Joint chart switches [D Sec. 4.5.8] on a system state. Without a map this is
  /// reparameterizeJoints(model(), s). With a map, only joints whose coordinates are all
  /// independent and none of which drives a dependent coordinate may switch (a switch would
  /// otherwise jump the dependents). Returns the number of joints switched.
  int reparameterize(State& s) const;

  /// The implicit step's matrices without forming dense ndof x ndof ones (bdf1's sparse route,
  /// for many extra coordinates): ws.f as calcMassAndForce gives it, and M, K = -df/dq, D = -df/dqdot
  /// (K and D only with `stiffness`) as sparse matrices over all coordinates: the skeleton's and the
  /// q_r-only terms' blocks dense inside, the terms with extra coordinates by their
  /// addSparseMatrices. Equal to calcMassAndForce + calcStiffnessDamping to round-off. Throws
  /// ModelError with a coordinate map, std::logic_error for a term that reaches extra coordinates
  /// without a sparse form.
  void calcSparseMatrices(const State& s, DynamicsWorkspace& ws, bool stiffness, Eigen::SparseMatrix<double>& M,
                          Eigen::SparseMatrix<double>& K, Eigen::SparseMatrix<double>& D) const;

  /// Position projection onto the constraint manifold: mass-weighted Newton steps
  ///   [M G^T; G 0] [dq; mu] = [0; -C]
  /// until max |C| <= tol or max_iter steps; redundant rows are handled as in solveKKT.
  /// Returns the final max |C| (0 without constraints). Uses s.t for prescribed motion.
  double projectPositions(State& s, DynamicsWorkspace& ws, double tol = 1e-12, int max_iter = 20) const;
  /// Velocity projection: qdot += dqdot with [M G^T; G 0] [dqdot; mu] = [0; -Cdot]; returns the
  /// remaining max |Cdot| predicted by the linear step.
  double projectVelocities(State& s, DynamicsWorkspace& ws) const;

  /// kinematics, M and f (skeleton + ws.loads + terms) [D Eq. 4.76]
  void calcMassAndForce(const State& s, DynamicsWorkspace& ws) const;
  /// K and D (joint springs/dampers + terms), after calcMassAndForce [D Eq. 4.82]
  void calcStiffnessDamping(const State& s, DynamicsWorkspace& ws) const;
  /// constraint G, rhs (stabilised) and errors, after calcMassAndForce
  void calcConstraints(const State& s, DynamicsWorkspace& ws) const;
  /// Mdot(q, qdot) qdot (ndof), Mdot = sum_j dM/dq_j qdot_j, after calcMassAndForce at the same
  /// s (reads its kinematics). With it the Lagrangian's dL/dq plus the non-conservative forces is
  ///   dL/dq + f_nc = f + Mdot qdot        (from d/dt(M qdot) = dL/dq + f_nc and M qddot = f),
  /// which the variational integrator needs. Skeleton: M_r = J_mr^T M_m J_mr with M_m constant, so
  /// Mdot_r qdot = Jdot_mr^T M_m phi + J_mr^T M_m Jdot_mr qdot (analytic); ForceTerms add theirs
  /// (ForceTerm::addMassDotTimesVelocity). With a CoordinateMap, M = J_rR^T M_r J_rR gives
  ///   Mdot qdot = Jdot_rR^T M_r qdot_r + J_rR^T (Mdot_r qdot_r + M_r Jdot_rR qdot).
  void calcMassDotTimesVelocity(const State& s, DynamicsWorkspace& ws, VecX& Mdot_v) const;

  /// accelerations; solves the KKT system when there are constraints. Multipliers in ws.lambda.
  VecX forwardDynamics(const State& s, DynamicsWorkspace& ws) const;
  /// generalized forces tau with M qddot = f + tau (REDMAX route, unconstrained) [D Eq. 4.18]
  VecX inverseDynamics(const State& s, const VecX& qddot, DynamicsWorkspace& ws) const;
  /// The same tau by recursive Newton-Euler, without M, J_mr or the terms' Jacobians where the
  /// terms allow (docs/performance.md §6): the skeleton's forward pass (poses, twists, their rates),
  /// ws.loads and every term's share as body wrenches (ForceTerm::idRoute, addInverseDynamics;
  /// terms of route MassMatrix add M_t qddot - f_t), then the backward pass. Equal to
  /// inverseDynamics to round-off. With a coordinate map or extra coordinates it is
  /// inverseDynamics.
  void inverseDynamicsRecursive(const State& s, const VecX& qddot, DynamicsWorkspace& ws, VecX& tau) const;
  /// inverseDynamicsRecursive in two steps, so that loads that depend on the poses can be set in
  /// ws.loads in between: begin runs the forward pass (poses in ws.rid.E_wi), finish adds ws.loads
  /// and the terms and runs the backward pass. Throws ModelError with a map or extra coordinates.
  void beginInverseDynamics(const State& s, const VecX& qddot, DynamicsWorkspace& ws) const;
  void finishInverseDynamics(const State& s, const VecX& qddot, DynamicsWorkspace& ws, VecX& tau) const;
  /// generalized forces (ndof) of the prescribed constraints' rows, -G_p^T lambda_p, after
  /// forwardDynamics: the actuation that realises the prescribed motion [D Eq. 4.109]
  VecX prescribedForces(const DynamicsWorkspace& ws) const;

  /// kinematics and energies only (no M); the potential includes ws.loads' (BodyLoads' rule)
  double kineticEnergy(const State& s, DynamicsWorkspace& ws) const;
  double potentialEnergy(const State& s, DynamicsWorkspace& ws) const;

  /// solve [M G^T; G 0] [x; lambda] = [a; b] (dense; G may be empty). Redundant rows of G
  /// (rank-deficient G M^-1 G^T, e.g. a 3-row point constraint closing a planar loop) are
  /// handled by a complete orthogonal decomposition: x is the consistent solution and lambda the
  /// minimum-norm multiplier; an inconsistent b is met in the least-squares sense.
  static VecX solveKKT(const MatX& M, const MatX& G, const VecX& a, const VecX& b, VecX* lambda);
  /// the same with the multipliers acting through H: [M H^T; G 0] [x; lambda] = [a; b]
  /// (Constraint::hasForceRows); the Schur complement G M^-1 H^T is not symmetric
  static VecX solveKKT(const MatX& M, const MatX& G, const MatX& H, const VecX& a, const VecX& b, VecX* lambda);

 private:
  // a fresh process-wide serial number on construction, copy and renew()
  struct Id {
    Id() : value(next()) {}
    Id(const Id&) : value(next()) {}
    Id& operator=(const Id&) {
      value = next();
      return *this;
    }
    void renew() { value = next(); }
    static std::uint64_t next();
    std::uint64_t value;
  };
  // kinematics of (skeleton) state s into ws.sk, as a new evaluation
  void calcSkeletonKinematics(const State& s, DynamicsWorkspace& ws) const;
  // what term i sees of the current evaluation of ws
  TermContext context(const DynamicsWorkspace& ws, size_t i) const {
    TermContext c(ws.sk, ws.term_scratch[i].get(), ws.evaluation);
    c.z_offset = z_offset_[i];
    c.u_offset = u_offset_[i];
    if (nu_ > 0) c.controls = &ws.controls;
    return c;
  }
  // ws.controls at skeleton state s_sk (after its kinematics): the controllers', or the caller's
  void calcControls(const State& s_sk, DynamicsWorkspace& ws) const;
  // ws.zdot at skeleton state s_sk of the current evaluation
  void calcStateDerivativesHere(const State& s_sk, DynamicsWorkspace& ws) const;
  // kinematics and controls of s as a new evaluation (expanded first with a coordinate map);
  // returns the skeleton state they are at (s, or ws.s_r)
  const State& kinematicsAndControls(const State& s, DynamicsWorkspace& ws) const;

  Id id_;
  Model model_;
  std::vector<std::shared_ptr<const ForceTerm>> terms_;
  std::vector<std::shared_ptr<const Constraint>> constraints_;
  std::vector<std::shared_ptr<const Controller>> controllers_;
  std::vector<int> z_offset_, u_offset_;  // per term                          (number of terms)
  int nz_ = 0, nu_ = 0;
  bool mass_terms_ = false;  // a term adds mass (ForceTerm::addsMass), kept by addTerm/replaceTerm
  int nc_ = 0;
  bool force_rows_ = false;  // some constraint has force rows other than G (Constraint::hasForceRows)
  std::shared_ptr<const CoordinateMap> map_;
  std::shared_ptr<const UnilateralConstraints> unilateral_;
  int ndof_ = 0;
  int n_extra_ = 0;  // coordinates after q_r that only ForceTerms see
  /// with a map: ws.s_r, ws.J_rR, ws.Jdot_rR from a system state
  void expandInto(const State& s, DynamicsWorkspace& ws) const;
  // the skeleton's M_r into `M` by the route's method (CRBA unless forward_route is Dense)
  void calcSkeletonMassHere(DynamicsWorkspace& ws, MatX& M) const;
  // the skeleton's f_r at s_sk (kinematics in ws.sk) into `f`: Newton-Euler at qddot = 0 unless
  // forward_route is Dense (J_mr^T (f_m - M_m Jdot_mr qdot) + springs and dampers)
  void calcSkeletonForceHere(const State& s_sk, DynamicsWorkspace& ws, VecX& f) const;
  // forwardDynamics by ABA; false (nothing returned) when a pivot fails
  bool forwardArticulated(const State& s, DynamicsWorkspace& ws, VecX& qddot) const;
};

}  // namespace redmax
