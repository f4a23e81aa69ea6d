#pragma once
// Extension points of the equations of motion. Later layers (muscle mass points, external loads,
// deformables) add to the reduced mass matrix and force without touching joint code [D Eq. 4.76,
// 4.82, 5.7]: each ForceTerm adds its share of
//   M_r qddot = f_r,    and for linearly implicit integrators K_r = -df_r/dq, D_r = -df_r/dqdot.
//
// Terms are immutable once built and may be shared by any number of threads: everything a term
// computes at a state lives in its scratch (TermScratch, made by makeScratch()), which each
// DynamicsWorkspace owns one of per term (MuJoCo's mjData, Pinocchio's Data). A term sees its
// scratch and the evaluation counter through TermContext; the counter tells it whether the scratch
// already holds this state's results, so that addMass, addForce and the energies of one state
// share one evaluation without comparing states.
//
// Auxiliary states and controls (docs/forward.md): a term may own first-order states (a muscle's
// activation and fibre length) and read controls (its actuators' excitations). The System gives
// each term an offset into State::z and into the workspace's controls (TermContext::z_offset,
// u_offset) in the order the terms were added; a term reads its states as
// s.z.segment(ctx.z_offset, numStates()) and its controls from ctx.controls. Terms without
// states or controls see nothing of either.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/SparseCore>

#include "core/skeleton/kinematics.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// Per-workspace scratch of one ForceTerm (or of an integrator, DynamicsWorkspace::integrator).
/// `evaluation` is the TermContext::evaluation its cached results belong to (0: none).
struct TermScratch {
  virtual ~TermScratch() = default;
  std::uint64_t evaluation = 0;
};

/// What a term sees of one evaluation: the skeleton kinematics at the state (Stage::Velocity),
/// its own scratch slot, and the evaluation counter of the workspace (equal for every call at the
/// same kinematics, different after the kinematics were recomputed; 0: unknown, do not reuse).
/// Built implicitly from a SkeletonWorkspace for direct calls outside a System: no scratch, no
/// reuse (a term then evaluates into temporaries).
struct TermContext {
  TermContext(const SkeletonWorkspace& sk) : sk(sk) {}  // NOLINT: implicit on purpose (see above)
  TermContext(const SkeletonWorkspace& sk, TermScratch* scratch, std::uint64_t evaluation)
      : sk(sk), scratch(scratch), evaluation(evaluation) {}
  const SkeletonWorkspace& sk;
  TermScratch* scratch = nullptr;
  std::uint64_t evaluation = 0;
  /// where this term's states start in State::z, and its controls in *controls
  int z_offset = 0;
  int u_offset = 0;
  /// the controls of this evaluation (System::numControls(); null: none, every control is 0)
  const VecX* controls = nullptr;
  /// control k of this term (0 without controls)
  double control(int k) const {
    return controls && u_offset + k < controls->size() ? (*controls)[u_offset + k] : 0.0;
  }
  /// the same kinematics without the scratch (e.g. for evaluations at other states); offsets and
  /// controls are kept
  TermContext withoutScratch() const {
    TermContext c(sk);
    c.z_offset = z_offset;
    c.u_offset = u_offset;
    c.controls = controls;
    return c;
  }
};

/// How a term takes part in recursive inverse dynamics (System::inverseDynamicsRecursive).
enum class TermIdRoute {
  MassMatrix,             ///< through addMass and addForce: the System adds M_t qddot - f_t
  Wrenches,               ///< addInverseDynamics from the body motion alone (no J_mr)
  WrenchesWithKinematics  ///< addInverseDynamics, which also reads ctx.sk (Stage::Velocity)
};

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  virtual std::string name() const = 0;
  /// this term's per-workspace scratch (null: the term needs none); called once per workspace
  virtual std::unique_ptr<TermScratch> makeScratch(const Model&) const { return nullptr; }
  /// add this term's inertia to M (ndof x ndof); needs Stage::Velocity
  virtual void addMass(const Model&, const State&, const TermContext&, MatX& M) const {}
  /// whether addMass may add anything. False lets System::forwardDynamics solve a system whose
  /// terms all add no mass by the articulated-body algorithm, without forming M (ForwardRoute).
  /// Default true, so that a term overriding addMass is never left out; massless terms say false.
  virtual bool addsMass() const { return true; }
  /// add this term's generalized force (including its quadratic-velocity part) to f (ndof)
  virtual void addForce(const Model&, const State&, const TermContext&, VecX& f) const = 0;
  /// add K = -df/dq and D = -df/dqdot (ndof x ndof); default: explicit term (adds nothing)
  virtual void addStiffnessDamping(const Model&, const State&, const TermContext&, MatX& K, MatX& D) const {}
  /// add Mdot(q, qdot) qdot of this term's inertia to Mdot_v (ndof), where Mdot = sum_j dM/dq_j
  /// qdot_j; needs Stage::Velocity at s. Used by the variational (symplectic) integrator, whose
  /// momentum equation needs dL/dq = f + Mdot qdot. Default: a central difference of addMass along
  /// qdot, (M(q + e qdot) - M(q - e qdot)) qdot / (2 e) with |e qdot|_inf = 6e-6 (about
  /// cbrt(machine epsilon): relative error ~1e-10), evaluated in a scratch SkeletonWorkspace; a
  /// term whose addMass adds nothing at s costs one addMass call. Override it analytically where
  /// the mass matrix is known in closed form.
  virtual void addMassDotTimesVelocity(const Model& model, const State& s, const TermContext& ctx,
                                       VecX& Mdot_v) const {
    const int n = static_cast<int>(Mdot_v.size());
    MatX M = MatX::Zero(n, n);
    addMass(model, s, ctx, M);
    const double vmax = s.qdot.size() > 0 ? s.qdot.lpNorm<Eigen::Infinity>() : 0.0;
    if (M.isZero(0.0) || !(vmax > 0.0)) return;
    const double e = 6e-6 / vmax;
    SkeletonWorkspace scratch(model);
    State sp = s, sm = s;
    sp.q += e * s.qdot;
    sm.q -= e * s.qdot;
    MatX Mp = MatX::Zero(n, n), Mm = MatX::Zero(n, n);
    // other states: no reuse of the scratch's results for s
    calcKinematics(model, sp, scratch);
    addMass(model, sp, TermContext(scratch), Mp);
    calcKinematics(model, sm, scratch);
    addMass(model, sm, TermContext(scratch), Mm);
    Mdot_v.noalias() += ((Mp - Mm) * s.qdot) / (2.0 * e);
  }
  virtual double kineticEnergy(const Model&, const State&, const TermContext&) const { return 0.0; }

  // recursive inverse dynamics; default: the System forms this term's M_t qddot - f_t
  virtual TermIdRoute idRoute() const { return TermIdRoute::MassMatrix; }
  /// this term's share of M qddot - f at (s, qddot) [D Eq. 4.18] (idRoute() other than
  /// MassMatrix): wrenches the bodies must supply for it added to wrench[b] (body coordinates;
  /// the skeleton's backward pass maps them through J_mr^T) and generalized forces that act on no
  /// body added to tau (nr). `motion`: poses, twists and their rates at (s, qddot).
  virtual void addInverseDynamics(const Model&, const State&, const VecX& qddot, const TermContext&,
                                  const BodyMotion& motion, std::vector<Vec6>& wrench, VecX& tau) const {}

  // auxiliary first-order states (State::z) and controls; defaults: none
  /// number of states this term owns in State::z
  virtual int numStates() const { return 0; }
  /// their full names (numStates), OpenSim 4 style, e.g. "/forceset/BIClong/activation"
  virtual std::vector<std::string> stateNames() const { return {}; }
  /// their default values (numStates)
  virtual void defaultStates(const Model&, Eigen::Ref<VecX> z) const {}
  /// their time derivatives at s (numStates); needs Stage::Velocity and ctx.controls of s
  virtual void calcStateDerivatives(const Model&, const State&, const TermContext&, Eigen::Ref<VecX> zdot) const {}
  /// OpenSim's equilibrium of the auxiliary states at s (e.g. fibre lengths balancing the tendon):
  /// writes into z (numStates, initially s's); needs Stage::Velocity. Default: leaves z.
  virtual void equilibrateStates(const Model&, const State&, const TermContext&, Eigen::Ref<VecX> z) const {}
  /// number of controls (excitations) this term reads through TermContext::control
  virtual int numControls() const { return 0; }
  /// their names (numControls): the actuator names, as OpenSim's controls files name them
  virtual std::vector<std::string> controlNames() const { return {}; }
  virtual double potentialEnergy(const Model&, const State&, const TermContext&) const { return 0.0; }

  // Sparse assembly, for systems with many extra coordinates (System::calcSparseMatrices, the
  // sparse route of bdf1, docs/deformable.md §5). A term whose M, K or D reach extra coordinates
  // says so (matricesOnSkeletonOnly() false) and adds them as triplets over all coordinates in
  // addSparseMatrices; every other term keeps its dense addMass / addStiffnessDamping, which the
  // System then calls on matrices of the q_r block only (nr x nr).
  using Triplets = std::vector<Eigen::Triplet<double>>;
  /// false when addMass or addStiffnessDamping may write outside the q_r block
  virtual bool matricesOnSkeletonOnly() const { return true; }
  /// add M, and with `stiffness` also K and D, as (row, column, value) triplets over all
  /// coordinates (duplicates are summed); false: no sparse form (the System uses the dense one)
  virtual bool addSparseMatrices(const Model&, const State&, const TermContext&, bool /*stiffness*/,
                                 Triplets& /*M*/, Triplets& /*K*/, Triplets& /*D*/) const {
    return false;
  }
};

}  // namespace redmax
