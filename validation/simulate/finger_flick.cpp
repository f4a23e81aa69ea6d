#include "validation/simulate/finger_flick.hpp"

#include <algorithm>

#include <cmath>
#include <limits>
#include <sstream>

#include "validation/forward/forward_tool.hpp"

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
  if (!options.gravity) mo.gravity = Vec3::Zero();
  SimulationModel m = loadSimulationModel(options.model_path, mo);
  if (!options.joint_limits.empty()) {
    HardConstraintOptions ho;
    ho.joint_limits = options.joint_limits;
    ho.limit_restitution = options.limit_restitution;
    std::vector<std::string> not_applied;  // (the finger's coordinates all have their own columns)
    addHardConstraints(m, ho, not_applied);
  }
  const State s0 = defaultInitialState(m);
  // the coordinates' ranges, to measure excursions through the bone
  std::vector<std::pair<int, std::pair<double, double>>> ranges;
  for (const osim::CoordinateDesc& c : m.description.coordinates) {
    const int k = m.system->model().findCoordinate(c.name);
    if (k >= 0 && !c.locked && !c.prescribed && c.range_min < c.range_max) ranges.push_back({k, {c.range_min, c.range_max}});
  }
  double excursion = 0.0;

  SimulateOptions so;
  so.integrator = options.integrator;
  so.integrator_options.dt = options.dt;
  so.duration = options.duration;
  so.output_dt = options.dt;  // check every step
  double E_flick = std::numeric_limits<double>::quiet_NaN(), K_max = 0.0;
  so.check = [&](const State& s, double K, double V) -> std::string {
    K_max = std::max(K_max, K);
    for (const auto& [k, r] : ranges) excursion = std::max({excursion, r.first - s.q[k], s.q[k] - r.second});
    if (s.t < options.impulse_time - 1e-12) return "";
    if (std::isnan(E_flick)) E_flick = K + V;  // the first row after the flick
    if (K + V - E_flick > options.energy_growth * K_max) {
      std::ostringstream os;
      os << "energy grew from " << E_flick << " to " << K + V << " J at t = " << s.t << " s";
      return os.str();
    }
    return "";
  };
  const SimulationResult r = simulate(m, s0, so);
  return {force, !r.failed, r.failure, excursion};
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
    out.excursion = r.max_excursion;
  }
  if (pass > 0.0 && std::isfinite(fail)) {
    while (fail / pass > 1.0 + rel_tol) {
      const double mid = std::sqrt(pass * fail);
      const FlickRun r = runFlick(options, mid);
      out.runs.push_back(r);
      if (r.survived) {
        pass = mid;
        out.excursion = r.max_excursion;
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

std::vector<FlickStudyRow> runFlickStudy(const FlickOptions& base, const std::vector<std::string>& integrators,
                                         const std::vector<bool>& gravity, double inertial_kg,
                                         const std::vector<double>& dts) {
  std::vector<FlickStudyRow> rows;
  const std::vector<double> steps = dts.empty() ? std::vector<double>{base.dt} : dts;
  for (bool g : gravity) {
   for (double dt : steps) {
    for (const std::string& integ : integrators) {
      for (int inertial = 0; inertial < 2; ++inertial) {
        FlickOptions o = base;
        o.integrator = integ;
        o.dt = dt;
        o.gravity = g;
        o.muscle_masses.clear();
        if (inertial) o.muscle_masses = {{"FDP", inertial_kg}, {"FDS", inertial_kg}};
        FlickStudyRow row;
        row.integrator = integ;
        row.dt = dt;
        row.variant = inertial ? "inertial" : "lumped";
        row.gravity = g;
        row.artifact = findLargestSurvivedFlick(o);
        o.energy_growth = std::numeric_limits<double>::infinity();
        row.divergence = findLargestSurvivedFlick(o);
        rows.push_back(std::move(row));
      }
    }
   }
  }
  return rows;
}

namespace {
std::string fmt(double x) {
  std::ostringstream os;
  os.precision(3);
  if (std::isinf(x))
    os << "none";
  else
    os << x;
  return os.str();
}
}  // namespace

std::string formatFlickTable(const std::vector<FlickStudyRow>& rows) {
  std::ostringstream os;
  os << "| integrator | dt (ms) | gravity | variant | largest force, no energy artifact (first failing) | "
        "largest force, no divergence (first failing) | excursion beyond a range there (rad) |\n"
        "|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows)
    os << "| " << r.integrator << " | " << r.dt * 1e3 << " | " << (r.gravity ? "on" : "off") << " | " << r.variant
       << " | "
       << fmt(r.artifact.largest_survived) << " N (" << fmt(r.artifact.smallest_failed) << ") | "
       << fmt(r.divergence.largest_survived) << " N (" << fmt(r.divergence.smallest_failed) << ") | "
       << fmt(r.divergence.excursion) << " |\n";
  return os.str();
}

std::string formatFlickCsv(const std::vector<FlickStudyRow>& rows) {
  std::ostringstream os;
  os.precision(10);
  os << "integrator,dt_s,gravity,variant,artifact_survived_N,artifact_failed_N,divergence_survived_N,"
        "divergence_failed_N,artifact_runs,divergence_runs,artifact_excursion,divergence_excursion\n";
  for (const auto& r : rows)
    os << r.integrator << "," << r.dt << "," << (r.gravity ? 1 : 0) << "," << r.variant << "," << r.artifact.largest_survived << ","
       << r.artifact.smallest_failed << "," << r.divergence.largest_survived << "," << r.divergence.smallest_failed
       << "," << r.artifact.runs.size() << "," << r.divergence.runs.size() << "," << r.artifact.excursion << ","
       << r.divergence.excursion << "\n";
  return os.str();
}

}  // namespace redmax::validation
