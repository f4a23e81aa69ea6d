// `redmax simulate`: forward simulation of an OpenSim model in the REDMAX core (docs/commands.md §1).
// The driver is validation/simulate (a library, so that studies call the same code); this file
// parses flags, prints the summary and writes the states atomically. Exit codes: 0 success,
// 1 the run diverged (nothing written), 2 bad input or usage.
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli/muscle_mass_flags.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "validation/forward/forward_tool.hpp"
#include "validation/report/progress.hpp"
#include "converter/trc_file.hpp"
#include "validation/simulate/prescribe_markers.hpp"
#include "validation/simulate/prescribe_motion.hpp"
#include "validation/simulate/simulate.hpp"
#include "validation/simulate/simulate_simbody.hpp"

namespace redmax::cli {
namespace {


const std::vector<std::string> kIntegrators = {"euler", "symplectic", "bdf1", "sdirk2", "rk45", "cvode"};

struct SimulateFlags {
  std::string model, out, initial, muscle_mass_kg, impulse, engine = "core", controls;
  std::string prescribe, prescribe_coordinates, prescribed_forces, prescribe_markers, prescribe_marker_names;
  double prescribe_lowpass = -1.0;
  validation::SimulateOptions so;
  double initial_time = 0.0;
  bool no_qvv = false, progress = false, quiet = false, full_precision = false, strict = false;
  MuscleMassFlags mm;
  std::string simbody_method, simbody_norm = "rms";
  std::string joint_limits, contact = "compliant";
  validation::HardConstraintOptions hard;
};

int runSimulate(SimulateFlags& f, const CLI::App& app) {
  if (!given(app, "--model")) throw UsageError{"simulate needs --model M.osim"};
  if (!given(app, "--duration")) throw UsageError{"simulate needs --duration S"};
  if (!given(app, "--out")) throw UsageError{"simulate needs --out STATES.sto"};
  const std::string &model_path = f.model, &out_path = f.out, &engine = f.engine;
  for (const char* n : {"--simbody-method", "--simbody-norm"})
    if (given(app, n) && engine != "simbody") throw UsageError{std::string(n) + " needs --engine simbody"};
  if (given(app, "--controls") && engine != "core") throw UsageError{"--controls needs --engine core"};
  const bool prescribing = given(app, "--prescribe");
  const bool markers = given(app, "--prescribe-markers");
  if (prescribing && engine != "core") throw UsageError{"--prescribe needs --engine core"};
  if (markers && engine != "core") throw UsageError{"--prescribe-markers needs --engine core"};
  if (prescribing && markers)
    throw UsageError{"--prescribe and --prescribe-markers cannot be combined yet (docs/deformable.md §7)"};
  if (given(app, "--prescribe-coordinates") && !prescribing)
    throw UsageError{"--prescribe-coordinates needs --prescribe MOTION"};
  if (given(app, "--prescribe-marker-names") && !markers)
    throw UsageError{"--prescribe-marker-names needs --prescribe-markers TRIAL.trc"};
  for (const char* n : {"--prescribe-lowpass", "--prescribed-forces"})
    if (given(app, n) && !prescribing && !markers)
      throw UsageError{std::string(n) + " needs --prescribe MOTION or --prescribe-markers TRIAL.trc"};
  // hard unilateral constraints: bdf1 solves the contact QP in its step, rk45 and cvode locate the
  // events (docs/contact.md §6)
  const bool hard = given(app, "--joint-limits") || f.contact == "hard";
  if (given(app, "--limit-restitution") && !given(app, "--joint-limits"))
    throw UsageError{"--limit-restitution needs --joint-limits hard|clamped"};
  for (const char* n : {"--contact-restitution", "--contact-friction"})
    if (given(app, n) && f.contact != "hard") throw UsageError{std::string(n) + " needs --contact hard"};
  if (hard && engine != "core") throw UsageError{"--joint-limits and --contact hard need --engine core"};
  const bool adaptive = f.so.integrator == "rk45" || f.so.integrator == "cvode";
  if (hard && f.so.integrator != "bdf1" && !adaptive)
    throw UsageError{std::string(f.contact == "hard" ? "--contact hard" : "--joint-limits") +
                     " needs --integrator bdf1, rk45 or cvode (" + f.so.integrator +
                     " cannot enforce hard constraints, docs/contact.md §6)"};
  f.hard.joint_limits = f.joint_limits;
  f.hard.contact = f.contact == "hard";
  validation::SimbodyEngineOptions simbody_flags;
  simbody_flags.method = f.simbody_method;
  simbody_flags.infinity_norm = f.simbody_norm == "inf";

  validation::SimulateOptions& so = f.so;
  IntegratorOptions& io = so.integrator_options;
  validation::SimulationModelOptions mo;
  mo.quadratic_velocity = !f.no_qvv;
  applyMuscleMassOptions(app, f.mm, f.muscle_mass_kg, mo);
  if (given(app, "--impulse"))
    for (const std::string& item : splitList(f.impulse, ";")) mo.impulses.push_back(validation::parseImpulse(item));
  const bool quiet = f.quiet;
  // --wrap neural: the run's workspaces count the fallbacks, summed into this (muscle_mass_flags.hpp)
  const std::shared_ptr<WrapFallbackMonitor> monitor = makeWrapFallbackMonitor(f.mm.wrap);
  so.wrap_fallbacks = monitor.get();

  // model and initial state: every problem here is the user's input (exit 2)
  validation::SimulationModel model;
  validation::MotionPrescription prescription;
  validation::MarkerPrescription marker_prescription;
  validation::MarkerStart marker_start;
  State initial;
  std::vector<std::string> control_warnings, not_applied;
  validation::HardConstraintSummary hard_made;
  try {
    model = validation::loadSimulationModel(model_path, mo);
    if (given(app, "--controls")) {
      // the muscles and actuators as forces, driven by the file (validation/forward/forward_tool.hpp)
      validation::addActuatorTerms(model, control_warnings, true, &not_applied, f.hard.contact);
      validation::addControlsFile(*model.system, f.controls, control_warnings);
    } else {
      // the passive forces and contacts; the Simbody engine takes the contact forces only, as
      // Simbody's own force elements (docs/contact.md)
      validation::addPassiveTerms(model, control_warnings, not_applied,
                                  engine == "core" ? validation::PassiveForces::All : validation::PassiveForces::ContactOnly,
                                  f.hard.contact);
    }
    if (prescribing) {
      // hybrid dynamics: the chosen coordinates follow the motion (validation/simulate/prescribe_motion.hpp)
      validation::MotionPrescriptionOptions po;
      if (given(app, "--prescribe-coordinates")) po.coordinates = splitList(f.prescribe_coordinates, ",");
      po.lowpass_cutoff_hz = f.prescribe_lowpass;
      prescription = validation::prescribeMotion(model, osim::readStorage(f.prescribe), f.prescribe, po);
      for (const auto& w : prescription.warnings) control_warnings.push_back(w);
    }
    if (hard) hard_made = validation::addHardConstraints(model, f.hard, not_applied);
    if (given(app, "--initial")) {
      const osim::Storage table = osim::readStorage(f.initial);
      initial = validation::initialStateFromStorage(
          model, table, f.initial,
          given(app, "--initial-time") ? f.initial_time : std::numeric_limits<double>::quiet_NaN());
      if (model.system->numStates() > 0) {
        int row = 0;
        for (int r = 0; r < table.numRows(); ++r)
          if (std::abs(table.time[r] - initial.t) <= 1e-9) row = r;
        validation::readAuxiliaryStates(*model.system, table, row, f.initial, initial);
      }
    } else {
      if (given(app, "--initial-time")) throw UsageError{"--initial-time needs --initial STATE.sto"};
      initial = validation::defaultInitialState(model);
      initial.z = model.system->defaultState().z;
      if (prescribing) initial.t = prescription.t_first;  // the run starts where the motion does
    }
    if (prescribing) {
      const double t_end = initial.t + so.duration;
      if (initial.t < prescription.t_first - 1e-9 || t_end > prescription.t_last + 1e-9) {
        std::ostringstream os;
        os << "the run spans [" << initial.t << ", " << t_end << "] s, outside the motion's ["
           << prescription.t_first << ", " << prescription.t_last << "] s (the splines would extrapolate)";
        throw osim::ConvertError(f.prescribe, 0, os.str());
      }
      validation::applyPrescription(model, prescription, initial);
    }
    if (markers) {
      // markers follow the file (validation/simulate/prescribe_markers.hpp): the window is known now
      const osim::MarkerTable trc = osim::readTrc(f.prescribe_markers);
      if (!given(app, "--initial") && !trc.time.empty()) initial.t = trc.time.front();
      validation::MarkerPrescriptionOptions po;
      if (given(app, "--prescribe-marker-names")) po.markers = splitList(f.prescribe_marker_names, ",");
      po.lowpass_cutoff_hz = f.prescribe_lowpass;
      po.t_begin = initial.t;
      po.t_end = initial.t + so.duration;
      marker_prescription = validation::prescribeMarkers(model, trc, f.prescribe_markers, po);
      for (const auto& w : marker_prescription.warnings) control_warnings.push_back(w);
      marker_start = validation::applyMarkerPrescription(model, marker_prescription, f.prescribe_markers, initial);
      const validation::MarkerPrescription& mp = marker_prescription;
      if (mp.rows > marker_start.independent_rows || mp.rows > mp.free_coordinates) {
        std::ostringstream os;
        os << f.prescribe_markers << ": " << mp.rows << " marker rows on " << mp.free_coordinates
           << " free coordinates, " << marker_start.independent_rows
           << " of the rows independent at the start: the others are met with the minimum-norm forces (only the "
              "components the coordinates feel) and a path the model cannot follow in the least-squares sense "
              "(the summary gives the largest distance)";
        control_warnings.push_back(os.str());
      }
    }
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const ModelError& e) {
    std::cerr << "error: " << model_path << ": " << e.what() << "\n";
    return 2;
  }
  for (const auto& w : model.build.warnings) std::cerr << "warning: " << w << "\n";
  if (f.strict && !not_applied.empty()) {
    std::cerr << "error: " << model_path << ": " << validation::strictRefusal(not_applied) << "\n";
    return 2;
  }
  if (!quiet) {
    for (const auto& w : control_warnings) std::cerr << "warning: " << w << "\n";
    for (const auto& w : not_applied) std::cerr << "warning: not applied: " << w << "\n";
  }
  if (!quiet) {
    const Model& core = model.system->model();
    std::printf("simulate: %s, %d coordinates, %d constraint rows, %zu muscles (%.4g kg in mass points)\n",
                model.description.name.c_str(), core.nr(), model.system->numConstraintRows(),
                model.build.model.muscles().size(), model.muscle_mass);
    // where the mass went, on stderr as the other commands print it (muscle_mass_flags.hpp)
    if (!model.mass_summary.empty()) std::fprintf(stderr, "%s", model.mass_summary.c_str());
    if (model.added_mass > 0.0)
      for (const Muscle& mu : model.build.model.muscles())
        if (pathType(mu.path) == PathType::III && mu.mass_points.size() == 0)
          std::fprintf(stderr, "  muscle %s: lumped (Type III path, no mass given)\n", mu.name.c_str());
  }

  // progress: always with --progress, otherwise once a run has taken more than 2 s
  std::unique_ptr<validation::Progress> progress;
  const auto t_start = std::chrono::steady_clock::now();
  const long total_ms = std::lround(so.duration * 1000.0);
  so.on_row = [&](double t) {
    if (quiet && !f.progress) return;
    if (!progress) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
      if (!f.progress && wall < 2.0) return;
      validation::ProgressOptions po;
      po.log_interval_s = 5.0;
      progress = std::make_unique<validation::Progress>("simulate (ms simulated)", total_ms, po);
    }
    progress->set(std::lround((t - initial.t) * 1000.0));
  };

  // the engine: the core, or Simbody with one particle per mass point (validation/simulate/simulate_simbody.hpp)
  if (engine == "simbody") {
    const std::string why = validation::simbodyEngineUnsupportedReason(model, so, mo.quadratic_velocity);
    if (!why.empty()) throw UsageError{why};
  }
  std::unique_ptr<validation::PrescribedForceRecorder> prescribed_forces;
  if (prescribing) {
    prescribed_forces = std::make_unique<validation::PrescribedForceRecorder>(model, prescription);
    so.check = prescribed_forces->check(so.check);
  } else if (markers) {
    prescribed_forces = std::make_unique<validation::PrescribedForceRecorder>(model, marker_prescription);
    so.check = prescribed_forces->check(so.check);
  }
  const std::clock_t cpu_start = std::clock();
  validation::SimulationResult res;
  if (engine == "simbody") {
    try {
      res = validation::simulateSimbody(model, initial, so, simbody_flags);
    } catch (const std::invalid_argument& e) {
      std::cerr << "error: " << model_path << ": --engine simbody: " << e.what() << "\n";
      return 2;
    } catch (const ModelError& e) {
      std::cerr << "error: " << model_path << ": --engine simbody: " << e.what() << "\n";
      return 2;
    } catch (const std::runtime_error& e) {  // simbody::SimbodyBuildError: a model Simbody cannot take
      std::cerr << "error: " << model_path << ": --engine simbody cannot build this model: " << e.what() << "\n";
      return 2;
    }
  } else {
    res = validation::simulate(model, initial, so);
  }
  const double cpu_s = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  if (progress) progress->finish();
  if (res.failed) {
    std::cerr << "error: " << model_path << ": simulation failed: " << res.failure << "\n"
              << "(the run reached t = " << (res.states.numRows() > 0 ? res.states.time.back() : initial.t)
              << " s of " << initial.t + so.duration << " s; nothing written to " << out_path << ")\n";
    return 1;
  }

  try {
    std::ostringstream desc;
    desc << "redmax simulate: model " << model_path << ", engine " << engine << ", integrator " << so.integrator;
    if (!simbody_flags.method.empty() || simbody_flags.infinity_norm)
      desc << " (Simbody " << (simbody_flags.method.empty() ? "default" : simbody_flags.method) << ", "
           << (simbody_flags.infinity_norm ? "inf" : "rms") << " norm)";
    if (so.integrator == "rk45" || so.integrator == "cvode")
      desc << " (rtol " << io.rtol << ", atol " << io.atol << ")";
    else
      desc << " (dt " << io.dt << " s)";
    desc << ", muscle mass " << model.muscle_mass << " kg" << (mo.quadratic_velocity ? "" : ", no muscle QVV")
         << "\n";
    if (prescribed_forces && given(app, "--prescribed-forces")) {
      std::ostringstream pd;
      if (markers)
        pd << "redmax simulate: world forces (N) at the markers prescribed by " << f.prescribe_markers
           << ", then the generalized forces they take (" << model_path << ")\n";
      else
        pd << "redmax simulate: generalized forces of the coordinates prescribed by " << f.prescribe << " ("
           << model_path << ")\n";
      osim::writeResultStorage(f.prescribed_forces, prescribed_forces->table(), f.full_precision, pd.str());
    }
    osim::writeResultStorage(out_path, res.states, f.full_precision, desc.str());
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (!quiet) {
    std::printf("simulate: %g s with %s (engine %s): %ld steps, %ld rhs evaluations, %ld failed steps, %.3f s wall, "
                "%.3f s CPU; energy %.10g -> %.10g J, drift %.3e relative (%.3e J) -> %s\n",
                so.duration, (simbody_flags.method.empty() ? so.integrator : simbody_flags.method).c_str(), engine.c_str(), res.stats.steps, res.stats.rhs_evals,
                res.stats.failed_steps, res.wall_s, cpu_s, res.energy_initial, res.energy_final, res.energy_drift_rel, res.energy_drift_abs,
                out_path.c_str());
    if (prescribed_forces && markers) {
      // per marker: the largest force it took and how far it got from its trajectory (output rows)
      const validation::MarkerPrescription& mp = marker_prescription;
      std::printf("prescribed from %s: %zu markers", f.prescribe_markers.c_str(), mp.markers.size());
      for (size_t k = 0; k < mp.markers.size(); ++k)
        std::printf("%s %s max |F| %.4g N, max distance %.3g m", k == 0 ? ";" : ",", mp.markers[k].c_str(),
                    prescribed_forces->markerPeakForce()[k], prescribed_forces->markerPeakDistance()[k]);
      std::printf("%s\n", given(app, "--prescribed-forces") ? (" -> " + f.prescribed_forces).c_str() : "");
    } else if (prescribed_forces) {
      // the largest generalized force each prescription took
      std::printf("prescribed from %s: %zu coordinates", f.prescribe.c_str(), prescription.coordinates.size());
      const osim::Storage& t = prescribed_forces->table();
      for (int c = 0; c < t.numColumns(); ++c)
        std::printf("%s %s max |%.4g|", c == 0 ? ";" : ",", t.labels[c].c_str(),
                    t.numRows() > 0 ? t.data.col(c).cwiseAbs().maxCoeff() : 0.0);
      std::printf("%s\n", given(app, "--prescribed-forces") ? (" -> " + f.prescribed_forces).c_str() : "");
    }
    // contacts, sampled at the output rows (docs/contact.md)
    if (res.contacts.contacts > 0)
      std::printf("contacts: %d pairs, %d active at the end (at most %d at once), largest penetration %.4g m (%s at t = %g), "
                  "largest net contact force %.6g N (y %.6g N) at t = %g\n",
                  res.contacts.contacts, res.contacts.active_final, res.contacts.active_max, res.contacts.max_penetration,
                  res.contacts.deepest.empty() ? "none" : res.contacts.deepest.c_str(), res.contacts.deepest_time,
                  res.contacts.max_force, res.contacts.max_force_up, res.contacts.max_force_time);
  }
  if (hard && !quiet && (f.so.integrator == "rk45" || f.so.integrator == "cvode"))
    std::printf("unilateral: %d joint limits, %d contact pairs by event location; %ld impacts, %ld releases, %ld "
                "slips, %ld sticks, largest penetration %.3g (m or rad; at the checks and events)\n",
                hard_made.limits, hard_made.pairs, res.stats.event_impacts, res.stats.event_releases,
                res.stats.event_slips, res.stats.event_sticks, res.stats.max_penetration);
  else if (hard && !quiet)
    std::printf("unilateral: %d joint limits, %d contact pairs; %ld of %ld steps solved a contact QP, at most %d "
                "contacts at once (%.3g on average), %ld QP iterations in %ld QPs, largest penetration %.3g "
                "(m or rad)%s\n",
                hard_made.limits, hard_made.pairs, res.stats.unilateral_steps, res.stats.steps, res.stats.max_contacts,
                res.stats.unilateral_steps > 0 ? double(res.stats.contact_rows) / double(res.stats.unilateral_steps) : 0.0,
                res.stats.qp_iterations, res.stats.qp_solves, res.stats.max_penetration,
                res.stats.friction_unconverged > 0
                    ? (", friction fixed point unconverged in " + std::to_string(res.stats.friction_unconverged) + " steps").c_str()
                    : "");
  // --wrap neural: how often the smooth model stood in for the network (muscle_mass_flags.hpp)
  if (monitor && !quiet) {
    const std::string counts = monitor->summary();
    if (!counts.empty()) std::fprintf(stderr, "wrap network fallbacks:\n%s", counts.c_str());
  }
  return 0;
}

CommandRegistration reg(
    {"simulate", "forward simulation of an OpenSim model (states, energies)", [](CLI::App& app) {
       auto f = std::make_shared<SimulateFlags>();
       validation::SimulateOptions& so = f->so;
       IntegratorOptions& io = so.integrator_options;
       so.integrator = "rk45";
       io.dt = 1e-3;
       io.rtol = 1e-6;
       io.atol = 1e-8;
       io.max_step = 0.0;
       so.output_dt = 0.0;
       app.add_option("--model", f->model, "the OpenSim model (.osim); required")
           ->type_name("M.osim")
           ->check(existingFile());
       app.add_option("--duration", so.duration, "simulated seconds; required")->type_name("S")->check(positive());
       app.add_option("--out", f->out, "the states file (.sto); required")->type_name("STATES.sto");
       app.add_option("--integrator", so.integrator,
                      "euler (semi-implicit, fixed step), symplectic (variational Euler), bdf1\n"
                      "(linearly implicit), sdirk2, rk45 (Dormand-Prince, adaptive, default), cvode")
           ->type_name("euler|symplectic|bdf1|sdirk2|rk45|cvode")
           ->check(oneOf(kIntegrators));
       app.add_option("--dt", io.dt, "fixed step (default 0.001)")->type_name("S")->check(positive());
       app.add_option("--rtol", io.rtol, "relative tolerance of rk45/cvode (default 1e-6)")
           ->type_name("R")
           ->check(positive());
       app.add_option("--atol", io.atol, "absolute tolerance of rk45/cvode (default 1e-8)")
           ->type_name("A")
           ->check(positive());
       app.add_option("--max-step", io.max_step, "largest adaptive step (default 0: no limit)")
           ->type_name("S")
           ->check(nonNegative());
       app.add_option("--output-dt", so.output_dt,
                      "time between output rows (default 0.01, or dt if larger; fixed-step\n"
                      "methods round it to whole steps)")
           ->type_name("S")
           ->check(positive());
       app.add_option("--initial", f->initial,
                      "start from a states or motion file: the row at t = 0 (or the first row;\n"
                      "--initial-time T picks another and starts there); columns named by\n"
                      "coordinate, /jointset/J/C/value and /speed, or C_u; degrees if the header\n"
                      "says inDegrees=yes; absent coordinates keep their defaults")
           ->type_name("STATE.sto")
           ->check(existingFile());
       app.add_option("--initial-time", f->initial_time, "with --initial: the row to start from")
           ->type_name("T")
           ->check(number());
       app.add_option("--controls", f->controls,
                      "excite the muscles and CoordinateActuators from an OpenSim ControlSet (.xml)\n"
                      "or controls table (.sto), as `redmax forward` does (docs/forward.md): muscles\n"
                      "with a force model then pull and their activation and fibre-length states\n"
                      "are integrated and written after the energies")
           ->type_name("FILE")
           ->check(existingFile());
       app.add_option("--muscle-mass-kg", f->muscle_mass_kg,
                      "give these muscles KG each in mass points, ADDED to the model (no body\n"
                      "gives mass; e.g. the finger's 0.2 kg flexors of [D 6.2.5]); --mass-points,\n"
                      "--mass-region and --wrap apply; excludes --muscle-mass")
           ->type_name("NAME=KG,...")
           ->group("Muscle mass");
       app.add_flag("--no-qvv", f->no_qvv, "drop the muscles' quadratic velocity vector (energy experiment [D 6.2.4])");
       app.add_option("--impulse", f->impulse,
                      "a force (N, ground frame) while t < DURATION (s) on a body's origin, a\n"
                      "marker, or BODY@X,Y,Z (m, body frame); ';' separates several")
           ->type_name("TARGET:FX,FY,FZ:DURATION");
       app.add_option("--engine", f->engine,
                      "the REDMAX core (default) or Simbody: the skeleton rebuilt as a Simbody\n"
                      "system, each muscle mass point a particle held on its path (a\n"
                      "Constraint::Custom per muscle); --integrator rk45 (RungeKuttaMerson) or cvode\n"
                      "(CPodes), --rtol is Simbody's accuracy, --atol its constraint tolerance; no\n"
                      "core constraints, --impulse or --no-qvv; same output columns (Simbody's energies)")
           ->type_name("core|simbody")
           ->check(oneOf({"core", "simbody"}));
       app.add_option("--simbody-method", f->simbody_method,
                      "with --engine simbody: merson (RungeKuttaMerson), feldberg\n"
                      "(RungeKuttaFeldberg), rk3, verlet or cpodes instead of --integrator's")
           ->type_name("merson|feldberg|rk3|verlet|cpodes")
           ->check(oneOf(validation::simbodyMethodNames()));
       app.add_option("--simbody-norm", f->simbody_norm,
                      "Simbody's step error norm: rms over all q and over all u, the particles'\n"
                      "included (default), or the largest component; the finger agrees with the\n"
                      "core to 1e-6 rad over 1 s with --simbody-method feldberg --simbody-norm inf\n"
                      "--rtol 3e-12 --atol 3e-13")
           ->type_name("rms|inf")
           ->check(oneOf({"rms", "inf"}));
       app.add_option("--prescribe", f->prescribe,
                      "hybrid dynamics: coordinates of this motion (.mot/.sto; columns named as\n"
                      "coordinates or /jointset/J/C/value, degrees converted) follow it exactly, the\n"
                      "others move forward; q(t) is the ID tool's spline of each column (natural\n"
                      "quintic), the run starts at the motion's first time (or --initial's) and may\n"
                      "not run past its last")
           ->type_name("MOTION");
       app.add_option("--prescribe-coordinates", f->prescribe_coordinates,
                      "with --prescribe: only these coordinates (default: every free coordinate the\n"
                      "motion has a column for)")
           ->type_name("C1,C2,...");
       app.add_option("--prescribe-markers", f->prescribe_markers,
                      "maximal inverse dynamics: markers of the model's MarkerSet follow this\n"
                      "OpenSim marker file (.trc, mm or m) exactly, each a natural quintic spline of\n"
                      "its samples; the coordinates start solved onto the markers (refused if a\n"
                      "marker stays over 1e-6 m off), then move forward; a gap in the run's window is\n"
                      "refused; the run starts at the file's first time (or --initial's) and may not\n"
                      "run past its last; not with --prescribe")
           ->type_name("TRIAL.trc");
       app.add_option("--prescribe-marker-names", f->prescribe_marker_names,
                      "with --prescribe-markers: only these markers (default: every marker of the\n"
                      "model the file has)")
           ->type_name("A,B,...");
       app.add_option("--prescribe-lowpass", f->prescribe_lowpass,
                      "with --prescribe or --prescribe-markers: low-pass cutoff (Hz) before the\n"
                      "splines, as the ID tool's lowpass_cutoff_frequency_for_coordinates (default:\n"
                      "none)")
           ->type_name("HZ");
       app.add_option("--prescribed-forces", f->prescribed_forces,
                      "with --prescribe: write the generalized force each prescription takes at every\n"
                      "output row (columns <coord>_moment / <coord>_force, as redmax id names them;\n"
                      "with every coordinate prescribed they are the motion's inverse dynamics); with\n"
                      "--prescribe-markers: each marker's world force (<marker>_fx/_fy/_fz, N), then\n"
                      "the generalized force the markers take on every coordinate")
           ->type_name("FORCES.sto");
       app.add_option("--joint-limits", f->joint_limits,
                      "enforce coordinate ranges as hard unilateral constraints: every coordinate's\n"
                      "range (hard) or those OpenSim marks clamped; locked and prescribed coordinates\n"
                      "are left out; needs --integrator bdf1, or rk45 / cvode (event location)\n"
                      "(docs/contact.md §6)")
           ->type_name("hard|clamped")
           ->check(oneOf({"hard", "clamped"}));
       app.add_option("--limit-restitution", f->hard.limit_restitution,
                      "restitution of the joint limits (default 0: a stop without bounce)")
           ->type_name("E")
           ->check(CLI::Range(0.0, 1.0));
       app.add_option("--contact", f->contact,
                      "compliant (default): HuntCrossleyForce and SmoothSphereHalfSpaceForce as\n"
                      "OpenSim computes them; hard: their ContactSphere / ContactHalfSpace pairs as\n"
                      "hard contacts with Coulomb friction (the forces' dynamic_friction), no\n"
                      "penetration; needs --integrator bdf1, or rk45 / cvode (event location)")
           ->type_name("compliant|hard")
           ->check(oneOf({"compliant", "hard"}));
       app.add_option("--contact-restitution", f->hard.contact_restitution,
                      "with --contact hard: restitution of every pair (default 0)")
           ->type_name("E")
           ->check(CLI::Range(0.0, 1.0));
       app.add_option("--contact-friction", f->hard.contact_friction,
                      "with --contact hard: Coulomb mu of every pair instead of the model's")
           ->type_name("MU")
           ->check(nonNegative());
       app.add_flag("--progress", f->progress, "progress on stderr (otherwise shown once a run takes over 2 s)");
       app.add_flag("--quiet", f->quiet, "no summary and no progress");
       app.add_flag("--strict", f->strict,
                    "refuse to run (exit 2) when a force or contact geometry of the model would not\n"
                    "be applied (each is named; without --strict each is a warning)");
       app.add_flag("--full-precision", f->full_precision,
                    "write %.16e instead of %16.8lf (restarts from the file are then exact)");
       addMuscleMassFlags(app, f->mm);
       app.footer(std::string(
           "usage: redmax simulate --model M.osim --duration S --out STATES.sto\n"
           "                       [--integrator euler|symplectic|bdf1|sdirk2|rk45|cvode] [--dt S]\n"
           "                       [--rtol R] [--atol A] [--max-step S] [--output-dt S]\n"
           "                       [--initial STATE.sto [--initial-time T]] [--controls FILE]\n"
           "                       [--prescribe MOTION [--prescribe-coordinates LIST] [--prescribe-lowpass HZ]\n"
           "                        [--prescribed-forces FORCES.sto]]\n"
           "                       [--prescribe-markers TRIAL.trc [--prescribe-marker-names A,B,...]\n"
           "                        [--prescribe-lowpass HZ] [--prescribed-forces FORCES.sto]]\n"
           "                       [MUSCLE-MASS OPTIONS] [--muscle-mass-kg NAME=KG,...] [--no-qvv]\n"
           "                       [--impulse TARGET:FX,FY,FZ:DURATION]\n"
           "                       [--engine core|simbody [--simbody-method M] [--simbody-norm rms|inf]]\n"
           "                       [--joint-limits hard|clamped [--limit-restitution E]]\n"
           "                       [--contact compliant|hard [--contact-restitution E] [--contact-friction MU]]\n"
           "                       [--progress] [--quiet] [--strict] [--full-precision]\n"
           "Integrates the model under gravity from its default pose (each coordinate's default_value and\n"
           "default_speed_value) with its constraints (locked, coupled and prescribed coordinates, welds),\n"
           "its passive forces (CoordinateLimitForce, springs, BushingForce) and contacts (HuntCrossleyForce,\n"
           "SmoothSphereHalfSpaceForce over ContactSphere / ContactHalfSpace; docs/contact.md). Muscles and\n"
           "actuators pull only with --controls. Every force or geometry not applied is named in a warning.\n"
           "Output: time, /jointset/<joint>/<coord>/value and .../speed for every coordinate (radians, SI),\n"
           "kinetic_energy, potential_energy, total_energy (J; gravity potential relative to the origin).\n"
           "A NaN or divergence stops the run: exit 1, the time, coordinate and step are named, and nothing\n"
           "is written. The summary gives steps, rhs evaluations, wall time and the energy drift\n"
           "max|E(t) - E(0)| relative to max(|E(0)|, max kinetic energy). With --joint-limits or --contact\n"
           "hard it adds the contacts, QP iterations and the largest penetration.\n") +
           muscleMassFooter());
       return [f, &app] { return runSimulate(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
