#include "validation/simulate/finger_flick.hpp"

#include <cmath>
#include <limits>
#include <sstream>

namespace redmax::validation {

FlickRun runFlick(const FlickOptions& options, double force) {
  SimulationModelOptions mo;
  mo.explicit_masses = options.muscle_masses;
  mo.muscle_mass.mass_points = options.mass_points;
  ImpulseSpec imp;
  imp.target = options.target;
  imp.force_w = force * options.direction.normalized();
  imp.duration = options.impulse_time;
  mo.impulses = {imp};
  const SimulationModel m = loadSimulationModel(options.model_path, mo);
  const State s0 = defaultInitialState(m);
  const auto [K0, V0] = calcEnergies(m, s0);

  SimulateOptions so;
  so.integrator = options.integrator;
  so.integrator_options.dt = options.dt;
  so.duration = options.duration;
  so.output_dt = options.dt;  // check every step
  double E_flick = std::numeric_limits<double>::quiet_NaN(), K_flick = 0.0;
  so.check = [&](const State& s, double K, double V) -> std::string {
    for (int i = 0; i < s.q.size(); ++i) {
      if (std::abs(s.q[i] - s0.q[i]) > options.max_excursion) {
        std::ostringstream os;
        os << "coordinate '" << m.coordinate_names[i] << "' turned " << s.q[i] - s0.q[i] << " rad at t = " << s.t
           << " s";
        return os.str();
      }
    }
    if (s.t < options.impulse_time - 1e-12) return "";
    if (std::isnan(E_flick)) {  // first row after the flick: the energy it gave
      E_flick = K + V;
      K_flick = std::max(K + V - (K0 + V0), K);
      return "";
    }
    if (K + V - E_flick > options.energy_growth * K_flick) {
      std::ostringstream os;
      os << "energy grew from " << E_flick << " to " << K + V << " J at t = " << s.t << " s";
      return os.str();
    }
    return "";
  };
  const SimulationResult r = simulate(m, s0, so);
  return {force, !r.failed, r.failure};
}

FlickSearch findLargestSurvivedFlick(const FlickOptions& options, double lo, double hi, double step,
                                     double rel_tol) {
  FlickSearch out;
  out.smallest_failed = std::numeric_limits<double>::infinity();
  double pass = 0.0, fail = std::numeric_limits<double>::infinity();
  for (double f = lo; f <= hi * (1 + 1e-12); f *= step) {
    const FlickRun r = runFlick(options, f);
    out.runs.push_back(r);
    if (!r.survived) {
      fail = f;
      out.first_failure = r.why;
      break;
    }
    pass = f;
  }
  if (pass > 0.0 && std::isfinite(fail)) {
    while (fail / pass > 1.0 + rel_tol) {
      const double mid = std::sqrt(pass * fail);
      const FlickRun r = runFlick(options, mid);
      out.runs.push_back(r);
      if (r.survived) {
        pass = mid;
      } else {
        fail = mid;
        out.first_failure = r.why;
      }
    }
  }
  out.largest_survived = pass;
  out.smallest_failed = fail;
  return out;
}

}  // namespace redmax::validation
