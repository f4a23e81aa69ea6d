#pragma once
// A core redmax::Model rebuilt as a Simbody system, for cross-checks and speed comparisons.
//
// Notation (Simbody's, see MobilizedBody.h): P parent body, F joint frame on the parent, M joint
// frame on the child, B child body. X_PF = JointSlot::E_pf and X_BM = inverse of JointSlot::E_mi.
// One MobilizedBody per JointSlot, in core body order (parents first):
//   Fixed -> Weld, Revolute(axis) -> Pin, Prismatic(axis) -> Slider (F and M are rotated by the
//   same rotation so that Simbody's z (Pin) or x (Slider) axis lies along the core axis),
//   SphericalEuler XYZ -> Gimbal or Ball, Universal -> Universal, Free3D (OpenSim layout) -> Free,
//   FunctionBased -> FunctionBased (six AxisFunctionAdapters, coordinate lists and axes, as OpenSim's
//   CustomJoint; Simbody's approximate Hdot, so compare with a simbody_compat core joint),
//   Ellipsoid -> Ellipsoid (u = angular velocity in F, as Ball), Reversed(inner) -> inner's
//   mobilizer with Direction::Reverse (only inner joints with u = qdot).
// Ball and Free always run with Euler angles (SimbodyMatterSubsystem::setUseEulerAngles), so
// Simbody's q equals the core q for every joint. Simbody's generalized speeds u equal qdot except
// for Ball and Ellipsoid (u = w_FM expressed in F) and Free (u = [w_FM; v_FM], both in F). The velocity map
//   u = T(q) qdot,   udot = T qddot + Tdot qdot        (T block diagonal, nu x nr)
// converts between the two spaces: M_core = T^T M_u T, tau_core = T^T f_u. Its blocks for Ball,
// Free and Ellipsoid are the core's speed map (core/dynamics/speed_map.hpp).
//
// Only TUs that need Simbody include this header (BUILD_NOTES: ~15 s and 700 MB per TU; every such
// TU must be compiled with -UNDEBUG, which the SimTKcommon target propagates).
#include <memory>
#include <string>
#include <vector>

#include "plugin/simbody/simbody_include.hpp"

#include "core/skeleton/model.hpp"
#include "core/skeleton/state.hpp"
#include "plugin/simbody/simbody_options.hpp"
#include "plugin/simbody/simtk_convert.hpp"

namespace redmax::simbody {

/// The Simbody system built from a core model. Not copyable (Simbody handles point into it).
struct SimbodyModel {
  SimbodyModel() : matter(system), forces(system) {}
  SimbodyModel(const SimbodyModel&) = delete;
  SimbodyModel& operator=(const SimbodyModel&) = delete;

  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter;
  SimTK::GeneralForceSubsystem forces;
  std::vector<SimTK::MobilizedBody> mobods;  // per core body                       (nb)
  std::vector<MobilizerMap> map;             // per core joint slot                  (nb)
  int nq = 0;                                // Simbody q count (>= core nr: see map)
  int nu = 0;                                // Simbody u count (== core nr)
  /// default state: Euler angles on, realized to Stage::Model, q = core defaults, u = 0
  SimTK::State default_state;
};

/// Build the Simbody system. Throws SimbodyBuildError naming the offending body or joint.
std::unique_ptr<SimbodyModel> makeSimbodyModel(const Model& model, const SimbodyBuildOptions& opt = {});

/// T (nu x nr) and, if Tdot is given, its time derivative, with u = T qdot; core state needed
/// (q and qdot). Identity blocks for mobilizers with u = qdot; rows in Simbody u order.
void calcVelocityMap(const SimbodyModel& sm, const Model& model, const State& s, MatX& T,
                     MatX* Tdot = nullptr);

/// Write the core state (t, q, qdot) into a Simbody state made from sm.default_state: q copied,
/// u = T qdot. Invalidates Stage::Position and above.
void setSimbodyState(const SimbodyModel& sm, const Model& model, const State& s, SimTK::State& sb);

/// Read a Simbody state back: q copied, qdot = T^-1 u.
void getCoreState(const SimbodyModel& sm, const Model& model, const SimTK::State& sb, State& s);

/// Simbody's mass matrix (calcM, u space) mapped to core velocities: T^T M_u T (nr x nr).
MatX calcSimbodyMassCore(const SimbodyModel& sm, const Model& model, const State& s);

/// Simbody inverse dynamics (calcResidualForceIgnoringConstraints with the force subsystem's body
/// and mobility forces at Stage::Dynamics as the applied forces) mapped to core generalized forces:
/// tau with M qddot = f + tau in core terms.
VecX calcSimbodyInverseDynamicsCore(const SimbodyModel& sm, const Model& model, const State& s,
                                    const VecX& qddot);

/// Simbody forward dynamics (realize(Acceleration)) mapped to core accelerations:
/// qddot = T^-1 (udot - Tdot qdot).
VecX calcSimbodyForwardDynamicsCore(const SimbodyModel& sm, const Model& model, const State& s);

/// conversions between Eigen and SimTK containers (vectors and transforms: simtk_convert.hpp)
SimTK::Vector toSimTK(const VecX& v);
VecX fromSimTK(const SimTK::Vector& v);
MatX fromSimTK(const SimTK::Matrix& m);

}  // namespace redmax::simbody
