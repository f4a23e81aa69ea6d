#include "validation/work_precision/work_precision.hpp"
#include "validation/work_precision/hard_cases.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "converter/build/build_core_model.hpp"
#include "converter/build/muscle_mass.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/integrators/integrator.hpp"

namespace redmax::validation {

namespace {

const std::vector<std::string> kIntegrators = {"euler", "symplectic", "bdf1", "sdirk2", "rk45", "cvode"};
constexpr int kEnergySamples = 20;  // energy is sampled at this many equal intervals of a run

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

bool isAdaptive(const std::string& integrator) { return integrator == "rk45" || integrator == "cvode"; }

IntegratorOptions optionsFor(const std::string& integrator, double value) {
  IntegratorOptions o;
  if (isAdaptive(integrator)) {
    o.rtol = value;
    o.atol = 1e-2 * value;  // q, qdot are O(1) in every scene (rad, m, rad/s)
  } else {
    o.dt = value;
  }
  return o;
}

std::string fmt(double x, const char* f = "%.3g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

VecX stacked(const State& s) {
  VecX x(s.q.size() + s.qdot.size());
  x << s.q, s.qdot;
  return x;
}

double totalEnergy(const System& sys, const State& s, DynamicsWorkspace& ws) {
  return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
}

// the built converter model of one osim_models file, without constraints' surprises
osim::BuildResult loadModel(const std::string& models_dir, const std::string& file) {
  const std::string path = (std::filesystem::path(models_dir) / file).string();
  return osim::buildCoreModel(osim::readOsimModel(path));
}

// a System with the built constraints and the given muscle masses (name -> kg; others lumped)
System makeSystem(const osim::BuildResult& b, const std::vector<std::pair<std::string, double>>& masses) {
  std::vector<double> m(b.model.muscles().size(), 0.0);
  for (const auto& [name, kg] : masses) {
    bool found = false;
    for (std::size_t k = 0; k < b.model.muscles().size(); ++k)
      if (b.model.muscles()[k].name == name) m[k] = kg, found = true;
    if (!found) throw std::invalid_argument("work-precision scene: model has no muscle '" + name + "'");
  }
  System sys = b.makeSystem();
  sys.addTerm(std::make_shared<MuscleTerm>(b.model, osim::addMusclePointMasses(b.model.muscles(), m)));
  return sys;
}

int coordinate(const Model& m, const std::string& name) {
  const int k = m.findCoordinate(name);
  if (k < 0) throw std::invalid_argument("work-precision scene: model has no coordinate '" + name + "'");
  return k;
}

std::string markdownTable(const WorkPrecisionSceneResult& r) {
  std::ostringstream os;
  os << "| integrator | setting | status | state error | CPU s | rhs evals | steps | energy drift J/s |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  for (const auto& run : r.runs) {
    os << "| " << run.integrator << " | " << run.knob << " " << fmt(run.value) << " | "
       << (run.ok ? "ok" : "DIVERGED") << " | " << (run.ok ? fmt(run.error, "%.2e") : "-") << " | "
       << fmt(run.cpu_s, "%.3g") << " | " << run.rhs_evals << " | " << run.steps << " | "
       << (run.ok ? fmt(run.energy_drift, "%.2e") : "-") << " |\n";
  }
  return os.str();
}

std::string describeRun(const WorkPrecisionRun& run) {
  std::ostringstream os;
  os << "`" << run.integrator << "` " << run.knob << " = " << fmt(run.value) << ": error " << fmt(run.error, "%.2e")
     << ", " << fmt(run.cpu_s, "%.3g") << " s CPU, " << run.rhs_evals << " rhs evaluations, energy drift "
     << fmt(run.energy_drift, "%.2e") << " J/s";
  return os.str();
}

// the cross-scene summary: the cheapest setting per target, and each integrator's energy drift at
// one comparable setting (dt 1 ms, rtol 1e-6: on both the full and the quick ladders)
std::string summaryMarkdown(const std::vector<WorkPrecisionSceneResult>& scenes, const std::vector<double>& targets) {
  std::ostringstream md;
  md << "Cheapest run (CPU time) whose end-state error (max over q, qdot against the rk45 rtol 1e-12 reference) "
        "reaches each target; the default to use for a scene is the column of the accuracy needed.\n\n| scene |";
  for (double t : targets) md << " error <= " << fmt(t) << " |";
  md << "\n|---|";
  for (std::size_t k = 0; k < targets.size(); ++k) md << "---|";
  md << "\n";
  for (const auto& sr : scenes) {
    md << "| " << sr.name << " (" << sr.ndof << " DoF, " << fmt(sr.duration) << " s) |";
    for (std::size_t k = 0; k < targets.size(); ++k) {
      if (sr.recommended[k] < 0) {
        md << " none |";
        continue;
      }
      const auto& r = sr.runs[sr.recommended[k]];
      md << " `" << r.integrator << "` " << r.knob << " " << fmt(r.value) << ": error " << fmt(r.error, "%.2e") << ", "
         << fmt(1e3 * r.cpu_s, "%.3g") << " ms CPU, " << r.rhs_evals << " rhs |";
    }
    md << "\n";
  }
  std::vector<std::string> integrators;
  for (const auto& sr : scenes)
    for (const auto& r : sr.runs)
      if (std::find(integrators.begin(), integrators.end(), r.integrator) == integrators.end())
        integrators.push_back(r.integrator);
  md << "\nEnergy drift per simulated second, max |E(t) - E(0)| / T in J/s, at dt = 1 ms (fixed-step methods) "
        "and rtol = 1e-6 (adaptive), with the reference's own drift (a scene whose reference drifts is not "
        "conservative for the ODE solvers: Type II via points):\n\n| scene | reference |";
  for (const auto& n : integrators) md << " " << n << " |";
  md << "\n|---|---|";
  for (std::size_t k = 0; k < integrators.size(); ++k) md << "---|";
  md << "\n";
  for (const auto& sr : scenes) {
    md << "| " << sr.name << " | " << fmt(sr.reference_energy_drift, "%.2e") << " |";
    for (const auto& n : integrators) {
      const double v = isAdaptive(n) ? 1e-6 : 1e-3;
      std::string cell = " - |";
      for (const auto& r : sr.runs)
        if (r.integrator == n && std::abs(r.value / v - 1.0) < 1e-9)
          cell = r.ok ? std::string(" ").append(fmt(r.energy_drift, "%.2e")).append(" |") : " diverged |";
      md << cell;
    }
    md << "\n";
  }
  return md.str();
}

}  // namespace

std::vector<std::string> workPrecisionStudyNames() { return {"integrators", "masspoints", "reduction", "hard"}; }

std::vector<std::string> workPrecisionSceneNames() {
  return {"pendulum_straight", "pendulum_via", "pendulum_wrap", "finger", "running_leg"};
}

WrapPendulum makeWrapPendulum(const std::string& models_dir, WrapModel model, double muscle_kg) {
  const auto b = loadModel(models_dir, "double_pendulum_wrap.osim");
  std::vector<Muscle> muscles = b.model.muscles();
  int k = -1;
  for (std::size_t i = 0; i < muscles.size(); ++i)
    if (muscles[i].name == "wrap_muscle") k = static_cast<int>(i);
  if (k < 0) throw std::invalid_argument("work-precision scene: model has no muscle 'wrap_muscle'");
  // Type III: addMusclePointMasses refuses wrapping muscles, so the points are set here as
  // converter/build/muscle_mass.cpp does, then checked against the supported shape
  Muscle& mu = muscles[k];
  mu.mass_points = makeMassPoints(muscle_kg, mu.optimal_fiber_length, mu.tendon_slack_length);
  mu.wrap.model = model;
  validateMuscle(b.model, mu);
  WrapPendulum p{b.makeSystem(), State{}, mu};
  p.system.addTerm(std::make_shared<MuscleTerm>(b.model, muscles));
  p.initial = p.system.defaultState();
  p.initial.q(coordinate(b.model, "q1")) = 0.3;
  p.initial.q(coordinate(b.model, "q2")) = 0.35;
  p.initial.qdot.setZero();
  return p;
}

WorkPrecisionScene makeWorkPrecisionScene(const std::string& name, const std::string& models_dir) {
  if (name == "pendulum_straight") {
    const auto b = loadModel(models_dir, "double_pendulum_straight.osim");
    WorkPrecisionScene s{name, "double pendulum (1 m, 1 kg links), Type I straight_muscle with 1 kg on 20 points",
                         makeSystem(b, {{"straight_muscle", 1.0}}), State{}, 2.0, 1.0};
    s.initial = s.system.defaultState();
    s.initial.q(coordinate(b.model, "q1")) = 0.8;
    s.initial.q(coordinate(b.model, "q2")) = -0.4;
    return s;
  }
  if (name == "pendulum_via") {
    const auto b = loadModel(models_dir, "double_pendulum_via.osim");
    WorkPrecisionScene s{name, "double pendulum (1 m, 1 kg links), Type II via_muscle with 1 kg on 20 points",
                         makeSystem(b, {{"via_muscle", 1.0}}), State{}, 2.0, 1.0};
    s.initial = s.system.defaultState();
    s.initial.q(coordinate(b.model, "q1")) = 0.8;
    s.initial.q(coordinate(b.model, "q2")) = -0.4;
    return s;
  }
  if (name == "pendulum_wrap") {
    WrapPendulum p = makeWrapPendulum(models_dir, WrapModel::Smooth, 1.0);
    return {name,
            "wrapping double pendulum (1 m, 1 kg links), Type III wrap_muscle round a 0.08 m cylinder at the "
            "middle joint, 1 kg on 20 points, smooth wrap model",
            std::move(p.system), p.initial, 2.0, 1.0};
  }
  if (name == "finger") {
    const auto b = loadModel(models_dir, "finger.osim");
    WorkPrecisionScene s{name, "index finger (3 hinges), FDP and FDS Type II with 0.2 kg each, released under gravity",
                         makeSystem(b, {{"FDP", 0.2}, {"FDS", 0.2}}), State{}, 0.3, 1.0};
    s.initial = s.system.defaultState();
    return s;
  }
  if (name == "running_leg") {
    // physiological mass (60 N/cm^2, 1059.7 kg/m^3), taken from the bones it was lumped into
    osim::MuscleMassOptions mo;
    mo.source = osim::MuscleMassOptions::Source::Physiological;
    const std::string path = (std::filesystem::path(models_dir) / "running_leg.osim").string();
    const osim::MuscleMassModel mm = osim::applyMuscleMass(osim::readOsimModel(path), {}, mo);
    System sys = mm.build.makeSystem();
    sys.addTerm(std::make_shared<MuscleTerm>(mm.build.model, mm.build.model.muscles()));
    std::string masses;
    for (const auto& m : mm.plan.muscles)
      if (m.points > 0) masses += (masses.empty() ? "" : ", ") + m.name + " " + fmt(m.mass, "%.3f") + " kg";
    WorkPrecisionScene s{name,
                         "running leg (11 DoF, free pelvis) falling under gravity; physiological muscle mass taken "
                         "from the bones (" + masses + "), gastrocnemii lumped (Type III)",
                         std::move(sys), State{}, 1.0, 1.0};
    s.initial = s.system.defaultState();
    s.initial.qdot(coordinate(mm.build.model, "hip_flexion_r")) = 3.0;
    s.initial.qdot(coordinate(mm.build.model, "knee_angle_r")) = -4.0;
    s.initial.qdot(coordinate(mm.build.model, "ankle_angle_r")) = 2.0;
    return s;
  }
  throw std::invalid_argument("unknown work-precision scene '" + name +
                              "' (expected pendulum_straight, pendulum_via, pendulum_wrap, finger, running_leg)");
}

std::vector<double> workPrecisionLadder(const std::string& integrator, bool quick) {
  if (isAdaptive(integrator)) {
    if (quick) return {1e-4, 1e-6, 1e-8};
    return {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  }
  if (std::find(kIntegrators.begin(), kIntegrators.end(), integrator) == kIntegrators.end())
    throw std::invalid_argument("unknown integrator '" + integrator +
                                "' (expected euler, symplectic, bdf1, sdirk2, rk45, cvode)");
  if (quick) return {4e-3, 2e-3, 1e-3};
  return {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5};
}

WorkPrecisionRun runWorkPrecisionCase(const WorkPrecisionScene& scene, const std::string& integrator, double value,
                                      double t_end, const VecX& x_ref) {
  WorkPrecisionRun r;
  r.integrator = integrator;
  r.knob = isAdaptive(integrator) ? "rtol" : "dt";
  r.value = value;
  auto integ = makeIntegrator(integrator, optionsFor(integrator, value));
  DynamicsWorkspace ws(scene.system.model());
  State s = scene.initial;
  const double E0 = totalEnergy(scene.system, s, ws);
  double dE = 0.0, cpu = 0.0;
  try {
    for (int k = 1; k <= kEnergySamples; ++k) {
      // energy evaluation is not part of the integrator's cost
      const double c0 = threadCpuSeconds();
      integ->advance(scene.system, s, t_end * k / kEnergySamples);
      cpu += threadCpuSeconds() - c0;
      dE = std::max(dE, std::abs(totalEnergy(scene.system, s, ws) - E0));
    }
    r.ok = std::isfinite(dE);
    if (!r.ok) r.failure = "energy not finite";
  } catch (const SimulationError& e) {
    r.failure = std::string(e.what()) + " (t = " + fmt(e.time) + " s, h = " + fmt(e.step) + " s)";
  } catch (const std::exception& e) {
    r.failure = e.what();
  }
  r.cpu_s = cpu;
  r.rhs_evals = integ->stats().rhs_evals;
  r.steps = integ->stats().steps;
  r.failed_steps = integ->stats().failed_steps;
  if (r.ok) {
    r.error = (stacked(s) - x_ref).cwiseAbs().maxCoeff();
    if (!std::isfinite(r.error)) r.ok = false, r.failure = "state not finite";
    r.energy_drift = dE / t_end;
    r.energy_drift_rel = r.energy_drift / scene.energy_scale;
  }
  return r;
}

WorkPrecisionResult runWorkPrecision(const std::string& report_dir, const WorkPrecisionOptions& options,
                                     std::ostream* progress) {
  for (const auto& n : options.studies) {
    const auto all = workPrecisionStudyNames();
    if (std::find(all.begin(), all.end(), n) == all.end())
      throw std::invalid_argument("unknown work-precision study '" + n + "' (expected integrators, masspoints, reduction)");
  }
  auto wants = [&](const std::string& study) {
    return options.studies.empty() ||
           std::find(options.studies.begin(), options.studies.end(), study) != options.studies.end();
  };
  // without the integrators study no scene runs
  const std::vector<std::string> scene_names =
      !wants("integrators") ? std::vector<std::string>{}
                            : options.scenes.empty() ? workPrecisionSceneNames() : options.scenes;
  const std::vector<std::string> integrators = options.integrators.empty() ? kIntegrators : options.integrators;
  for (const auto& n : integrators) workPrecisionLadder(n, options.quick);  // validates the names
  for (const auto& n : scene_names) {
    const auto all = workPrecisionSceneNames();
    if (std::find(all.begin(), all.end(), n) == all.end())
      throw std::invalid_argument("unknown work-precision scene '" + n +
                                  "' (expected pendulum_straight, pendulum_via, pendulum_wrap, finger, running_leg)");
  }

  ReportOptions ropt;
  ropt.title = "redmax work-precision report";
  ropt.gnuplot = options.gnuplot;
  Report report(report_dir, ropt);
  report.setInput("mode", JsonValue(options.quick ? "quick" : "full"));
  report.setInput("models_dir", JsonValue(options.models_dir));
  report.setInput("reference", JsonValue("rk45 rtol 1e-12 atol 1e-14"));
  report.setInput("error", JsonValue("max |x - x_ref| over q and qdot at the end"));
  JsonValue& section = report.section("work_precision");

  using Clock = std::chrono::steady_clock;
  const auto wall0 = Clock::now();
  auto wallSince = [](Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  WorkPrecisionResult result;
  // per-scene sections go after the summary, which needs every scene
  std::vector<std::pair<std::string, std::string>> scene_md;
  for (const auto& name : scene_names) {
    WorkPrecisionScene scene = makeWorkPrecisionScene(name, options.models_dir);
    const double t_end = options.quick ? std::min(0.5, scene.duration) : scene.duration;
    WorkPrecisionSceneResult sr;
    sr.name = name;
    sr.description = scene.description;
    sr.ndof = scene.system.ndof();
    sr.duration = t_end;

    // reference: tight rk45; its kinetic energy range sets the scale of the relative drift
    {
      IntegratorOptions o;
      o.rtol = 1e-12;
      o.atol = 1e-14;
      auto ref = makeIntegrator("rk45", o);
      DynamicsWorkspace ws(scene.system.model());
      State s = scene.initial;
      const double E0 = totalEnergy(scene.system, s, ws);
      double ke = scene.system.kineticEnergy(s, ws), dE = 0.0;
      const double c0 = threadCpuSeconds();
      for (int k = 1; k <= kEnergySamples; ++k) {
        ref->advance(scene.system, s, t_end * k / kEnergySamples);
        ke = std::max(ke, scene.system.kineticEnergy(s, ws));
        dE = std::max(dE, std::abs(totalEnergy(scene.system, s, ws) - E0));
      }
      sr.reference_cpu_s = threadCpuSeconds() - c0;
      sr.reference_energy_drift = dE / t_end;
      scene.energy_scale = std::max(ke, 1e-12);
      sr.energy_scale = scene.energy_scale;
      const VecX x_ref = stacked(s);
      if (progress)
        *progress << "work-precision: " << name << " (" << sr.ndof << " DoF, " << t_end << " s): reference "
                  << fmt(sr.reference_cpu_s) << " s CPU" << std::endl;

      for (const auto& integrator : integrators) {
        for (double v : workPrecisionLadder(integrator, options.quick))
          sr.runs.push_back(runWorkPrecisionCase(scene, integrator, v, t_end, x_ref));
        if (progress) {
          int bad = 0;
          for (const auto& r : sr.runs) bad += (r.integrator == integrator && !r.ok);
          *progress << "  " << integrator << " done" << (bad ? " (" + std::to_string(bad) + " diverged)" : "")
                    << std::endl;
        }
      }
    }

    // recommendations: the cheapest ok run under each target
    for (double target : options.targets) {
      int best = -1;
      for (std::size_t i = 0; i < sr.runs.size(); ++i) {
        const auto& r = sr.runs[i];
        if (r.ok && r.error <= target && (best < 0 || r.cpu_s < sr.runs[best].cpu_s)) best = static_cast<int>(i);
      }
      sr.recommended.push_back(best);
    }

    // CSV
    CsvTable t;
    t.header = {"integrator", "knob", "value", "status", "error", "cpu_s", "rhs_evals", "steps", "failed_steps",
                "energy_drift_J_per_s", "energy_drift_rel_per_s", "failure"};
    for (const auto& r : sr.runs)
      t.addRow({r.integrator, r.knob, formatNumber(r.value), r.ok ? "ok" : "diverged",
                r.ok ? formatNumber(r.error) : "nan", formatNumber(r.cpu_s), std::to_string(r.rhs_evals),
                std::to_string(r.steps), std::to_string(r.failed_steps),
                r.ok ? formatNumber(r.energy_drift) : "nan", r.ok ? formatNumber(r.energy_drift_rel) : "nan", r.failure});
    report.addTable(name, t, sr.description + ": one row per run");

    // log-log error against CPU time, one line per integrator (diverged runs leave gaps)
    std::vector<PlotLine> lines;
    for (const auto& integrator : integrators) {
      std::vector<double> x, y;
      for (const auto& r : sr.runs)
        if (r.integrator == integrator && r.ok) x.push_back(std::max(r.cpu_s, 1e-7)), y.push_back(std::max(r.error, 1e-16));
      lines.push_back(makePlotLine(integrator, x, y, "linespoints"));
    }
    PlotFigure fig;
    fig.title = name;
    fig.panel_width = 640;
    fig.panel_height = 440;
    fig.panels.push_back(makeLogLogPanel(name + ": state error at " + fmt(t_end) + " s vs CPU time", "CPU time (s)",
                                         "max |x - x_ref|", lines));
    report.addPlot(name, fig, "error against CPU time, one line per integrator");

    // report.md and summary.json
    std::ostringstream md;
    md << sr.description << "; " << sr.ndof << " DoF, " << fmt(t_end) << " s simulated; reference rk45 rtol 1e-12 ("
       << fmt(sr.reference_cpu_s) << " s CPU, energy drift " << fmt(sr.reference_energy_drift, "%.2e")
       << " J/s); energy scale (max kinetic energy) " << fmt(sr.energy_scale) << " J.";
    if (sr.reference_energy_drift > 1e-6 * std::max(1.0, sr.energy_scale))
      md << " The reference itself does not conserve energy: mass points of a Type II muscle slide past via "
            "points on moving bodies, where the mass matrix jumps (docs/notes.md, conditional path points), so the "
            "motion is only piecewise smooth, orders degrade, and the variational `symplectic` method (which "
            "keeps momentum continuous across a jump while the others keep velocity continuous) converges to "
            "a different solution.";
    md << "\n\n";
    for (std::size_t k = 0; k < options.targets.size(); ++k) {
      md << "- **Recommended for error <= " << fmt(options.targets[k]) << "**: ";
      if (sr.recommended[k] < 0) md << "no run reached it.\n";
      else md << describeRun(sr.runs[sr.recommended[k]]) << ".\n";
    }
    int diverged = 0;
    for (const auto& r : sr.runs) diverged += !r.ok;
    md << "- Diverged or failed runs: " << diverged << ".\n";
    // the symplectic rows of a non-smooth scene measure a different limit, not an inaccuracy
    // (tests/core/integrators/variational_muscle_test.cpp)
    bool has_symplectic = false;
    for (const auto& r : sr.runs) has_symplectic = has_symplectic || r.integrator == "symplectic";
    if (has_symplectic && sr.reference_energy_drift > 1e-6 * std::max(1.0, sr.energy_scale))
      md << "- `symplectic` rows: their error against the rk45 reference need not go to zero here. Where a "
            "mass point crosses a via point, M(q) jumps; the ODE solvers keep qdot continuous, the variational "
            "step keeps p = M qdot continuous (v+ = M+^-1 M- v-), and it converges at order 1 to that other "
            "solution (event-located references for both rules in "
            "tests/core/integrators/variational_muscle_test.cpp; docs/notes.md).\n";
    md << "\n" << markdownTable(sr);
    scene_md.emplace_back("Scene " + name, md.str());

    JsonValue js = JsonValue::object();
    js["description"] = JsonValue(sr.description);
    js["ndof"] = JsonValue(sr.ndof);
    js["duration_s"] = JsonValue(t_end);
    js["reference_cpu_s"] = JsonValue(sr.reference_cpu_s);
    js["reference_energy_drift_J_per_s"] = JsonValue(sr.reference_energy_drift);
    JsonValue runs = JsonValue::array();
    for (const auto& r : sr.runs) {
      JsonValue o = JsonValue::object();
      o["integrator"] = JsonValue(r.integrator);
      o[r.knob] = JsonValue(r.value);
      o["ok"] = JsonValue(r.ok);
      if (r.ok) {
        o["error"] = JsonValue(r.error);
        o["energy_drift_J_per_s"] = JsonValue(r.energy_drift);
      } else {
        o["failure"] = JsonValue(r.failure);
      }
      o["cpu_s"] = JsonValue(r.cpu_s);
      o["rhs_evals"] = JsonValue(r.rhs_evals);
      runs.push(std::move(o));
    }
    js["runs"] = std::move(runs);
    JsonValue rec = JsonValue::array();
    for (std::size_t k = 0; k < options.targets.size(); ++k) {
      JsonValue o = JsonValue::object();
      o["target"] = JsonValue(options.targets[k]);
      if (sr.recommended[k] >= 0) {
        const auto& r = sr.runs[sr.recommended[k]];
        o["integrator"] = JsonValue(r.integrator);
        o[r.knob] = JsonValue(r.value);
        o["error"] = JsonValue(r.error);
        o["cpu_s"] = JsonValue(r.cpu_s);
      }
      rec.push(std::move(o));
    }
    js["recommended"] = std::move(rec);
    section[name] = std::move(js);
    result.scenes.push_back(std::move(sr));
  }
  if (!scene_names.empty()) report.addWallTime("integrators study", wallSince(wall0));
  if (!result.scenes.empty()) report.addMarkdown("Recommended defaults", summaryMarkdown(result.scenes, options.targets));
  for (const auto& [heading, text] : scene_md) report.addMarkdown(heading, text);
  // the inverse-dynamics studies (id_studies.hpp) on a gait trial
  std::vector<std::string> id_studies;
  for (const char* st : {"masspoints", "reduction"})
    if (wants(st)) id_studies.push_back(st);
  if (!id_studies.empty()) {
    IdStudyOptions io;
    io.models_dir = options.models_dir;
    io.shared_dir = options.shared_dir;
    io.quick = options.quick;
    const auto t0 = Clock::now();
    result.id_studies = runIdStudies(io, id_studies, progress);
    report.addWallTime("id studies", wallSince(t0));
    report.setInput("id_studies_trial", JsonValue(result.id_studies.trial.name));
    addIdStudiesToReport(result.id_studies, report);
  }
  // the hard cases (hard_cases.hpp): scenes built in code, under 1 s
  if (wants("hard")) {
    const auto t0 = Clock::now();
    addHardCasesToReport(runHardCases(options.models_dir, options.quick, progress), report);
    report.addWallTime("hard cases", wallSince(t0));
  }
  report.addWallTime("total (before writing)", wallSince(wall0));
  result.files = report.write();
  return result;
}

}  // namespace redmax::validation
