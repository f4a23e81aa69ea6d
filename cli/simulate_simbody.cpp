#include "cli/simulate_simbody.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "plugin/simbody/particle_simulation.hpp"

namespace redmax::cli {

std::string simbodyEngineUnsupportedReason(const validation::SimulationModel& m, const validation::SimulateOptions& so,
                                           bool quadratic_velocity) {
  if (so.integrator != "rk45" && so.integrator != "cvode")
    return "--engine simbody takes --integrator rk45 (Simbody's RungeKuttaMersonIntegrator) or cvode (Simbody's "
           "CPodesIntegrator), got '" + so.integrator + "'";
  if (m.system->numConstraintRows() > 0)
    return "--engine simbody does not carry the model's constraints (" +
           std::to_string(m.system->numConstraintRows()) +
           " rows: locked, coupled or prescribed coordinates, welds); use --engine core";
  if (m.impulses) return "--engine simbody does not apply --impulse loads; use --engine core";
  // particles always carry their full inertia: there is no quadratic velocity term to drop
  if (!quadratic_velocity) return "--no-qvv has no Simbody counterpart (particles carry their full inertia)";
  return "";
}

validation::SimulationResult simulateSimbody(const validation::SimulationModel& m, const State& initial,
                                             const validation::SimulateOptions& so) {
  if (!(so.duration > 0.0) || !std::isfinite(so.duration))
    throw std::invalid_argument("the duration must be a positive number of seconds");
  if (!(so.output_dt >= 0.0) || !std::isfinite(so.output_dt))
    throw std::invalid_argument("the output interval must be a positive number of seconds");
  const Model& model = m.system->model();
  simbody::ParticleSimulationOptions po;
  po.integrator = so.integrator == "cvode" ? "cpodes" : "merson";
  po.accuracy = so.integrator_options.rtol;
  po.constraint_tolerance = so.integrator_options.atol;
  po.max_step = so.integrator_options.max_step;

  // the core driver's output times (adaptive methods): t0 + k h_out, the last one t0 + duration
  const double h_out = so.output_dt > 0.0 ? so.output_dt : 0.01;
  const double t0 = initial.t, t1 = t0 + so.duration;
  const long n_rows = std::max(1L, static_cast<long>(std::ceil(so.duration / h_out - 1e-9)));
  if (n_rows > 50'000'000) throw std::invalid_argument("more than 5e7 output rows: raise the output interval");

  validation::SimulationResult res;
  res.states.name = "redmax simulate states";
  res.states.version = 1;
  res.states.in_degrees = false;
  res.states.labels = m.q_labels;
  res.states.labels.insert(res.states.labels.end(), m.u_labels.begin(), m.u_labels.end());
  for (const char* e : {"kinetic_energy", "potential_energy", "total_energy"}) res.states.labels.push_back(e);
  const int nr = model.nr();
  std::vector<VecX> rows;
  double max_ke = 0.0;

  const auto start = std::chrono::steady_clock::now();
  simbody::ParticleSimulation sim(model, m.muscles, initial, po);
  auto record = [&](const State& s) -> bool {
    const double K = sim.kineticEnergy(), V = sim.potentialEnergy();
    VecX row(2 * nr + 3);
    row << s.q, s.qdot, K, V, K + V;
    if (!row.allFinite()) {
      std::ostringstream os;
      os << "non-finite state or energy at t = " << s.t << " s (Simbody)";
      res.failed = true;
      res.failure = os.str();
      res.failure_time = s.t;
      return false;
    }
    if (rows.empty()) res.energy_initial = K + V;
    res.energy_final = K + V;
    max_ke = std::max(max_ke, K);
    res.energy_drift_abs = std::max(res.energy_drift_abs, std::abs(K + V - res.energy_initial));
    res.states.time.push_back(s.t);
    rows.push_back(row);
    return true;
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
      for (const Muscle& mu : m.muscles) via = via || (mu.mass_points.size() > 0 && mu.path.points.size() > 2);
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
  const double scale = std::max(std::abs(res.energy_initial), max_ke);
  res.energy_drift_rel = scale > 0.0 ? res.energy_drift_abs / scale : 0.0;
  res.states.data.resize(static_cast<Eigen::Index>(rows.size()), 2 * nr + 3);
  for (size_t r = 0; r < rows.size(); ++r) res.states.data.row(static_cast<Eigen::Index>(r)) = rows[r].transpose();
  return res;
}

}  // namespace redmax::cli
