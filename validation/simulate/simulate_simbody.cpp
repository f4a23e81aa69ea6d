#include "validation/simulate/simulate_simbody.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "plugin/simbody/particle_simulation.hpp"

namespace redmax::validation {

std::string simbodyEngineUnsupportedReason(const SimulationModel& m, const SimulateOptions& so,
                                           bool quadratic_velocity) {
  if (so.integrator != "rk45" && so.integrator != "cvode")
    return "--engine simbody takes --integrator rk45 (Simbody's RungeKuttaMersonIntegrator) or cvode (Simbody's "
           "CPodesIntegrator), got '" + so.integrator + "'";
  if (m.system->numConstraintRows() > 0)
    return "--engine simbody does not carry the model's constraints (" +
           std::to_string(m.system->numConstraintRows()) +
           " rows: locked, coupled or prescribed coordinates, welds); use --engine core";
  if (m.impulses) return "--engine simbody does not apply --impulse loads; use --engine core";
  if (m.system->unilateral())
    return "--engine simbody has no hard unilateral constraints (--joint-limits, --contact hard); use --engine core";
  for (const Muscle& mu : m.build.model.muscles())
    if (mu.fibre.enabled() && mu.mass_points.size() > 0)
      return "--engine simbody moves mass points at fixed arc fractions only; --mass-placement fibre needs --engine core";
  // particles always carry their full inertia: there is no quadratic velocity term to drop
  if (!quadratic_velocity) return "--no-qvv has no Simbody counterpart (particles carry their full inertia)";
  return "";
}

const std::vector<std::string>& simbodyMethodNames() {
  static const std::vector<std::string> names = {"merson", "feldberg", "rk3", "verlet", "cpodes"};
  return names;
}

SimulationResult simulateSimbody(const SimulationModel& m, const State& initial,
                                             const SimulateOptions& so, const SimbodyEngineOptions& engine) {
  if (!(so.duration > 0.0) || !std::isfinite(so.duration))
    throw std::invalid_argument("the duration must be a positive number of seconds");
  if (!(so.output_dt >= 0.0) || !std::isfinite(so.output_dt))
    throw std::invalid_argument("the output interval must be a positive number of seconds");
  simbody::ParticleSimulationOptions po;
  po.integrator = so.integrator == "cvode" ? "cpodes" : "merson";
  po.accuracy = so.integrator_options.rtol;
  po.constraint_tolerance = so.integrator_options.atol;
  po.max_step = so.integrator_options.max_step;
  if (!engine.method.empty()) po.integrator = engine.method;
  po.infinity_norm = engine.infinity_norm;
  // the model's compliant contact, as Simbody's own force elements (plugin/simbody/contact_forces.hpp)
  for (const auto& t : m.system->terms()) {
    if (const auto* hc = dynamic_cast<const HuntCrossleyForceTerm*>(t.get()))
      po.hunt_crossley.insert(po.hunt_crossley.end(), hc->forces().begin(), hc->forces().end());
    if (const auto* ss = dynamic_cast<const SmoothSphereHalfSpaceForceTerm*>(t.get()))
      po.smooth_contacts.insert(po.smooth_contacts.end(), ss->contactList().begin(), ss->contactList().end());
  }

  // the core driver's output times (adaptive methods): t0 + k h_out, the last one t0 + duration
  const double h_out = so.output_dt > 0.0 ? so.output_dt : 0.01;
  const double t0 = initial.t, t1 = t0 + so.duration;
  const long n_rows = std::max(1L, static_cast<long>(std::ceil(so.duration / h_out - 1e-9)));
  if (n_rows > 50'000'000) throw std::invalid_argument("more than 5e7 output rows: raise the output interval");

  SimulationResult res = makeStatesResult(m);

  const auto start = std::chrono::steady_clock::now();
  simbody::ParticleSimulation sim(m.build.model, initial, po);
  StateRecorder recorder(res);
  auto record = [&](const State& s) -> bool {
    return recorder.add(s.t, s.q, s.qdot, sim.kineticEnergy(), sim.potentialEnergy(), " (Simbody)");
  };

  bool ok = record(sim.state());
  for (long k = 1; ok && k <= n_rows; ++k) {
    const double t = k == n_rows ? t1 : t0 + k * h_out;
    try {
      ok = record(sim.advance(t));
    } catch (const std::runtime_error& e) {
      res.failed = true;
      res.failure = e.what();
      // the usual cause with via points: a particle cannot jump in velocity [particle_muscles.hpp]
      bool via = false;
      for (const Muscle& mu : m.build.model.muscles()) via = via || (mu.mass_points.size() > 0 && mu.path.points.size() > 2);
      if (via)
        res.failure += "\n(a mass point sliding past a via point needs a velocity jump that a Simbody particle "
                       "cannot follow: fewer --mass-points, --mass-region fibre, or --engine core)";
      res.failure_time = t;
      break;
    }
    if (ok && so.on_row) so.on_row(t);
  }
  const simbody::ParticleSimulationCounts c = sim.counts();
  res.stats.steps = c.steps;
  res.stats.rhs_evals = c.realizations;
  res.stats.failed_steps = c.failed_steps;
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  res.final_state = sim.state();
  recorder.finish();
  return res;
}

}  // namespace redmax::validation
