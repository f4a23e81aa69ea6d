#pragma once
// The core (REDMAX) engine of the inverse-dynamics tool: tau = M qddot - f [D Eq. 4.18] with
// gravity and the external loads as an input of the evaluation (DynamicsWorkspace::loads),
// constraints ignored (OpenSim's
// calcResidualForceIgnoringConstraints).
//
// OpenSim compatibility for Ball/Free/Ellipsoid joints (IdEngineOptions::rates_as_u). OpenSim puts
// the data's Euler-angle rates into Simbody's u, which Simbody reads as the angular velocity of M
// in F (expressed in F). The core keeps qdot = dq/dt and reproduces this by a change of velocity
// variables per marked joint (block-diagonal, so it is exact for the whole tree):
//   u = T(q) qdot,  T = blockdiag(R, R) S  (free: [w_F; v_F])   or  T = R S_w  (ball, ellipsoid: w_F)
//   udot = T qddot + Tdot qdot,  Tdot = blockdiag(R[w], R[w]) S + blockdiag(R, R) Sdot
// with R = R_FM(q), S and Sdot the joint's twist map in M [D Eq. 4.29] and w = S_w qdot.
// Given OpenSim's u and udot the engine solves qdot = T^-1 u, qddot = T^-1 (udot - Tdot qdot),
// runs the core inverse dynamics, and returns tau_u = T^-T tau_qdot (power balance
// tau_u . u = tau_qdot . qdot). The result is the generalized force OpenSim writes, computed from
// the core's exact dynamics.
#include <memory>
#include <vector>

#include "converter/id/id_engine.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/speed_map.hpp"
#include "core/dynamics/system.hpp"
#include "core/joints/joint.hpp"
#include "core/model/musculoskeletal_model.hpp"

namespace redmax::osim {

using redmax::calcOpenSimSpeedMap;
using redmax::hasOpenSimSpeedMap;

/// Everything one frame of a CoreIdEngine writes; one per thread. The engine itself is not
/// changed by solving with a workspace, so threads that share one engine (and its System) each
/// solve their frames with their own CoreIdWorkspace, bit-identically to a serial run.
struct CoreIdWorkspace {
  explicit CoreIdWorkspace(const System& system);
  // inputs of the frame in the core's convention (equal to (v, vdot) without marked joints)
  State state;               // t, q, qdot                                      (nr)
  VecX qddot;                //                                                 (nr)
  // position stage: poses for the loads (MassMatrix route), speed maps of the marked joints
  std::vector<Mat4> E_wi;    // body poses                                      (nb)
  std::vector<MatJ> T;       // u = T qdot per marked joint (mapping tau back)  (marked)
  // the System's evaluation; dyn.loads holds the frame's resolved external loads
  DynamicsWorkspace dyn;
};

class CoreIdEngine final : public IdEngine {
 public:
  /// Throws IdEngineError if a marked joint has no OpenSim speed map, or the options do not
  /// match the model's joints.
  /// The skeleton alone (no muscle inertia).
  explicit CoreIdEngine(Model model, IdEngineOptions options = {});
  /// The model's skeleton; when any muscle carries mass points, a MuscleTerm over the model's
  /// muscles (settings().muscle_term, core/dynamics/muscle_term.hpp) joins the System, so tau
  /// gains the muscles' inertia, quadratic velocity and gravity terms [D Eq. 5.7]. The term works
  /// in the core's qdot = dq/dt convention like the rest of the system, so the rates_as_u change
  /// of variables applies unchanged. Constraints and force elements are not solved (OpenSim's ID).
  explicit CoreIdEngine(const MusculoskeletalModel& model, IdEngineOptions options = {});
  std::string name() const override { return "core"; }
  /// How tau is computed: Recursive (default; System::beginInverseDynamics / finishInverseDynamics:
  /// Newton-Euler, the GRFs and the muscles' mass points as body wrenches, docs/performance.md §6)
  /// or MassMatrix (System::inverseDynamics, tau = M qddot - f [D Eq. 4.18]: the reference, equal
  /// to round-off, tests/validation/id_routes_test.cpp).
  enum class Route { Recursive, MassMatrix };
  void setRoute(Route route) { route_ = route; }
  Route route() const { return route_; }
  /// one frame with the engine's own workspace (lastState(), lastQddot())
  void calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                             const std::vector<IdLoadSample>& loads, VecX& tau) override;
  /// one frame with the caller's workspace (made as CoreIdWorkspace(system())); const, so any
  /// number of threads may share the engine, each with its own workspace
  void calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                             const std::vector<IdLoadSample>& loads, VecX& tau, CoreIdWorkspace& ws) const;

  const Model& model() const { return system_.model(); }
  const System& system() const { return system_; }
  /// sum of the muscles' mass points (kg); 0 without muscle mass
  double muscleMass() const { return muscle_mass_; }
  /// (qdot, qddot) in the core's own convention for the last frame solved with the engine's own
  /// workspace (equal to (v, vdot) without marked joints)
  const State& lastState() const { return ws_.state; }
  const VecX& lastQddot() const { return ws_.qddot; }
  /// the network wrap-model counts of the frames solved with the engine's own workspace, added to
  /// `monitor` and zeroed (a caller's own CoreIdWorkspace: takeWrapFallbackCounts(system(), ws.dyn, ...))
  void takeWrapFallbackCounts(WrapFallbackMonitor& monitor) {
    redmax::takeWrapFallbackCounts(system_, ws_.dyn, monitor);
  }

 private:
  System system_;
  IdEngineOptions options_;
  std::vector<int> marked_;  // marked joint slots
  double muscle_mass_ = 0.0;
  Route route_ = Route::Recursive;
  CoreIdWorkspace ws_;       // for the IdEngine interface (one caller at a time)
};

}  // namespace redmax::osim
