#include "converter/id/core_id_engine.hpp"

#include <algorithm>
#include <sstream>

#include <Eigen/Dense>

#include "core/dynamics/muscle_term.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::osim {

CoreIdWorkspace::CoreIdWorkspace(const System& system) : E_wi(system.model().nb()), dyn(system) {}

CoreIdEngine::CoreIdEngine(Model model, IdEngineOptions options)
    : system_(std::move(model)), options_(std::move(options)), ws_(system_) {
  const Model& m = system_.model();
  if (!options_.rates_as_u.empty() && static_cast<int>(options_.rates_as_u.size()) != m.nb())
    throw IdEngineError("engine options name " + std::to_string(options_.rates_as_u.size()) +
                        " joints; the model has " + std::to_string(m.nb()));
  for (int j = 0; j < m.nb(); ++j) {
    if (!options_.marked(j)) continue;
    if (!hasOpenSimSpeedMap(m.joints()[j].joint))
      throw IdEngineError("joint '" + m.joints()[j].name + "' (" + m.joints()[j].joint.typeName() +
                          ") cannot take OpenSim's Euler-rate speeds");
    marked_.push_back(j);
  }
}

CoreIdEngine::CoreIdEngine(const MusculoskeletalModel& model, IdEngineOptions options)
    : CoreIdEngine(model.skeleton(), std::move(options)) {
  const std::vector<Muscle>& muscles = model.muscles();
  const bool any_mass = std::any_of(muscles.begin(), muscles.end(),
                                    [](const Muscle& m) { return m.mass_points.size() > 0; });
  if (!any_mass) return;
  auto term = std::make_shared<MuscleTerm>(system_.model(), muscles, model.settings().muscle_term);
  muscle_mass_ = term->totalMass();
  system_.addTerm(std::move(term));
  system_.bind(ws_.dyn);  // slots for the new term
}

void CoreIdEngine::calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                                         const std::vector<IdLoadSample>& loads, VecX& tau) {
  calcGeneralizedForces(t, q, v, vdot, loads, tau, ws_);
}

void CoreIdEngine::calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                                         const std::vector<IdLoadSample>& loads, VecX& tau,
                                         CoreIdWorkspace& ws) const {
  const Model& m = system_.model();
  const int nr = m.nr();
  if (q.size() != nr || v.size() != nr || vdot.size() != nr)
    throw IdEngineError("inverse dynamics needs " + std::to_string(nr) + " coordinates, speeds and "
                        "accelerations");
  ws.state.t = t;
  ws.state.q = q;
  ws.state.qdot = v;
  ws.qddot = vdot;
  ws.T.resize(marked_.size());

  // OpenSim's u -> the core's qdot for marked joints: qdot = T^-1 u, qddot = T^-1 (udot - Tdot qdot)
  for (size_t k = 0; k < marked_.size(); ++k) {
    const JointSlot& slot = m.joints()[marked_[k]];
    const int i0 = slot.q_index, n = slot.nq;
    const VecJ qj = q.segment(i0, n);
    MatJ T, Tdot;
    calcOpenSimSpeedMap(slot.joint, qj, VecJ::Zero(n), T, nullptr);
    Eigen::JacobiSVD<MatJ> svd(T);
    const auto& sv = svd.singularValues();
    if (!(sv(n - 1) > 1e-12 * sv(0))) {
      std::ostringstream os;
      os << "joint '" << slot.name << "' at t = " << t
         << ": the map from Euler-angle rates to angular velocity is singular (gimbal lock)";
      throw IdEngineError(os.str());
    }
    const Eigen::PartialPivLU<MatJ> lu(T);
    const VecJ qdot_j = lu.solve(VecJ(v.segment(i0, n)));
    calcOpenSimSpeedMap(slot.joint, qj, qdot_j, T, &Tdot);
    ws.state.qdot.segment(i0, n) = qdot_j;
    ws.qddot.segment(i0, n) = lu.solve(VecJ(vdot.segment(i0, n) - Tdot * qdot_j));
    ws.T[k] = T;
  }

  // external loads at the current poses (an input of this evaluation), then tau = M qddot - f
  // [D Eq. 4.18]: recursively (the forward pass gives the poses) or through M
  if (route_ == Route::Recursive) {
    system_.beginInverseDynamics(ws.state, ws.qddot, ws.dyn);
    resolveLoads(loads, ws.dyn.rid.E_wi, ws.dyn.loads);
    system_.finishInverseDynamics(ws.state, ws.qddot, ws.dyn, tau);
  } else {
    calcBodyPoses(m, q, ws.E_wi);
    resolveLoads(loads, ws.E_wi, ws.dyn.loads);
    tau = system_.inverseDynamics(ws.state, ws.qddot, ws.dyn);
  }

  // back to OpenSim's u: tau_u = T^-T tau_qdot
  for (size_t k = 0; k < marked_.size(); ++k) {
    const JointSlot& slot = m.joints()[marked_[k]];
    const MatJ Tt = ws.T[k].transpose();
    tau.segment(slot.q_index, slot.nq) =
        Eigen::PartialPivLU<MatJ>(Tt).solve(VecJ(tau.segment(slot.q_index, slot.nq)));
  }
}

}  // namespace redmax::osim
