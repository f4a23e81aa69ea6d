// `redmax optimize --task reach`: constant shoulder and elbow torques that bring the hand to a
// target, by L-BFGS on adjoint gradients and gradient-free (docs/gradients.md §7); `--task track`:
// torques that make the run follow a motion's coordinates (--motion) and further tracking terms. The task and the
// report are validation/optimize; this file parses flags, prints progress and the summary.
// Exit codes: 0 success (also when a method did not reach the tolerance: the report says so),
// 1 a run diverged or the report could not be written, 2 bad input or usage.
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/muscle_mass_flags.hpp"
#include "converter/osim_reader.hpp"
#include "validation/optimize/reach.hpp"
#include "validation/simulate/spec_parse.hpp"

namespace redmax::cli {
namespace {

struct OptimizeFlags {
  std::string task, model, body = "hand", target, point = "0,0,0", integrator = "euler", method = "lbfgs,bobyqa";
  std::string coordinates, report, muscle_mass_kg, drive = "torques", muscles, torques_in_time, motion, objective;
  double duration = 0.0, dt = 0.01, rest = 0.0, tolerance = 1e-3, max_torque = 100.0, initial_step = 1.0;
  double initial_excitation = 0.1, excitation_weight = 0.0;
  int nodes = 5;
  long max_simulations = 2000;
  bool quiet = false;
  std::string initial_speeds = "default";
  MuscleMassFlags mm;
};

int runOptimize(OptimizeFlags& f, const CLI::App& app) {
  const bool track = f.task == "track";
  for (const char* n : {"--task", "--model", "--duration"})
    if (!given(app, n)) throw UsageError{std::string("optimize needs ") + n};
  if (!track && !given(app, "--target")) throw UsageError{"optimize needs --target (--task reach)"};
  if (track && !given(app, "--motion") && !given(app, "--objective"))
    throw UsageError{"optimize --task track needs --motion and/or --objective"};
  for (const char* n : {"--target", "--body", "--point", "--drive"})
    if (track && given(app, n)) {
      std::cerr << "error: " << n << ": not used by --task track (the objective is --motion and --objective)\n";
      return 2;
    }
  for (const char* n : {"--motion", "--objective", "--initial-speeds"})
    if (!track && given(app, n)) {
      std::cerr << "error: " << n << ": needs --task track\n";
      return 2;
    }
  validation::ReachOptions o;
  o.task = f.task;
  o.motion = f.motion;
  o.objective = f.objective;
  o.initial_speeds = f.initial_speeds;
  o.model_path = f.model;
  o.body = f.body;
  if (!track && !validation::parseVec3(f.target, o.target)) {
    std::cerr << "error: --target '" << f.target << "': must be three numbers X,Y,Z (m, ground)\n";
    return 2;
  }
  if (!validation::parseVec3(f.point, o.point)) {
    std::cerr << "error: --point '" << f.point << "': must be three numbers x,y,z (m, in the body's frame)\n";
    return 2;
  }
  if (!f.coordinates.empty()) o.coordinates = splitList(f.coordinates);
  o.torques_in_time = f.torques_in_time;
  o.duration = f.duration;
  o.dt = f.dt;
  o.integrator = f.integrator;
  o.rest_weight = f.rest;
  o.tolerance = f.tolerance;
  o.max_torque = f.max_torque;
  o.initial_step = f.initial_step;
  o.drive = f.drive;
  if (!f.muscles.empty()) o.muscles = splitList(f.muscles);
  o.nodes = f.nodes;
  o.initial_excitation = f.initial_excitation;
  o.excitation_weight = f.excitation_weight;
  const bool excite = f.drive == "excitations";
  if (excite && !given(app, "--initial-step")) o.initial_step = 0.1;  // an excitation, not rad/s^2
  if (!excite)
    for (const char* n : {"--excite", "--nodes", "--initial-excitation", "--excitation-weight"})
      if (given(app, n)) {
        std::cerr << "error: " << n << ": needs --drive excitations\n";
        return 2;
      }
  if (excite && given(app, "--torques-in-time")) {
    std::cerr << "error: --torques-in-time: the excitation drive has no torques\n";
    return 2;
  }
  o.max_simulations = f.max_simulations;
  const std::vector<std::string> methods = splitList(f.method);
  for (const auto& m : methods) {
    bool known = false;
    for (const auto& k : validation::reachMethods()) known = known || k == m;
    if (!known) {
      std::cerr << "error: --method '" << m << "': unknown (" << joinChoices(validation::reachMethods()) << ")\n";
      return 2;
    }
  }
  if (methods.empty()) throw UsageError{"--method: no method"};
  applyMuscleMassOptions(app, f.mm, f.muscle_mass_kg, o.model_options);

  validation::ReachSetup setup;
  if (const int rc = loadOrExit2(f.model, [&] { setup = validation::makeReachSetup(o); })) return rc;
  for (const auto& w : setup.gradient.model.build.warnings) std::cerr << "warning: " << w << "\n";
  for (const auto& w : setup.gradient.warnings) std::cerr << "warning: " << w << "\n";
  for (const auto& w : setup.gradient.not_applied) std::cerr << "warning: not applied: " << w << "\n";
  if (!f.quiet && track)
    std::fprintf(stderr, "track: %s, %zu torques, %zu tracked coordinates, %zu tracked markers, %.4g kg of muscle mass\n",
                 setup.gradient.model.description.name.c_str(), setup.gradient.param_names.size(),
                 setup.gradient.objective.coordinate_tracks.size(), setup.gradient.objective.tracks.size(),
                 setup.gradient.model.muscle_mass);
  else if (!f.quiet)
    std::fprintf(stderr, "reach: %s, %zu %s, hand at (%.4g, %.4g, %.4g) m, target (%.4g, %.4g, %.4g) m, %.4g kg of muscle mass\n",
                 setup.gradient.model.description.name.c_str(), setup.gradient.param_names.size(),
                 excite ? "excitation nodes" : "torques", setup.start_point[0],
                 setup.start_point[1], setup.start_point[2], o.target[0], o.target[1], o.target[2],
                 setup.gradient.model.muscle_mass);

  std::vector<validation::ReachResult> results;
  const validation::ReachProgress progress = [&f, track](const std::string& m, const validation::ReachEvaluation& e) {
    if (!f.quiet)
      std::fprintf(stderr, "%s: simulation %ld, J = %.6e (best %.6e), error %.4e%s, %.3f s\n", m.c_str(), e.simulations,
                   e.objective, e.best_objective, e.error, track ? " (RMS)" : " m", e.seconds);
  };
  for (const auto& m : methods) {
    try {
      results.push_back(validation::optimizeReach(setup, m, progress));
    } catch (const SimulationError& e) {
      std::cerr << "error: " << f.model << ": " << m << ": simulation failed: " << e.what() << "\n";
      return 1;
    }
  }
  std::printf("%-12s %12s %16s %12s %14s %14s %8s  %s\n", "method", "simulations", "step evaluations", "wall (s)",
              "objective", track ? "RMS error" : "error (m)", "reached", "stop");
  for (const auto& r : results)
    std::printf("%-12s %12ld %16ld %12.4f %14.6e %14.6e %8s  %s\n", r.method.c_str(), r.simulations, r.step_evaluations,
                r.seconds, r.objective, r.error, r.reached ? "yes" : "no", r.stop.c_str());
  for (const auto& r : results)
    if (!r.gradient_route.empty()) std::printf("%s step Jacobians: %s\n", r.method.c_str(), r.gradient_route.c_str());
  for (const auto& r : results) {
    std::printf(excite ? "%s excitations:" : "%s torques (N m):", r.method.c_str());
    for (Eigen::Index i = 0; i < r.torques.size(); ++i) std::printf(" %s=%.8g", setup.gradient.param_names[i].c_str(), r.torques[i]);
    std::printf("\n");
  }
  if (!f.report.empty()) {
    try {
      const std::string plot = validation::writeReachReport(f.report, setup, results, commandLine(app));
      std::printf("report: %s (%s)\n", f.report.c_str(), plot.c_str());
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 1;
    }
  }
  return 0;
}

CommandRegistration reg(
    {"optimize", "optimize a task through the simulation's adjoint gradient (--task reach or track)",
     [](CLI::App& app) {
       auto f = std::make_shared<OptimizeFlags>();
       app.add_option("--task", f->task,
                      "the task: reach (constant torques bring a hand point to a target) or track\n"
                      "(torques that make the run follow --motion and/or --objective); required")
           ->type_name("reach|track")
           ->check(oneOf({"reach", "track"}));
       app.add_option("--motion", f->motion,
                      "--task track: the motion (.mot/.sto) whose coordinates the run tracks, all that the\n"
                      "model has or the named ones C,... (the gradient's coords: term, weight 1); the run\n"
                      "starts from its pose at t = 0 (its speeds: --initial-speeds)")
           ->type_name("FILE.mot[@C,...]");
       app.add_option("--objective", f->objective,
                      "--task track: further terms of `redmax gradient`'s --objective SPEC, e.g.\n"
                      "'track:MARKER=FILE.trc;1e-4*effort' (docs/gradients.md §3)")
           ->type_name("SPEC");
       app.add_option("--initial-speeds", f->initial_speeds,
                      "--task track: the tracked coordinates' speeds at the start: the model's defaults, the\n"
                      "motion's rates there (second-order differences of its first rows), or free (optimized\n"
                      "with the torques, from the motion's rates; reported as 'qdot0 C' parameters)")
           ->type_name("default|motion|free")
           ->check(oneOf({"default", "motion", "free"}));
       app.add_option("--model", f->model, "the OpenSim model (.osim), e.g. osim_models/reach_arm.osim; required")
           ->type_name("M.osim")
           ->check(existingFile());
       app.add_option("--target", f->target, "the target in ground (m); required for --task reach")->type_name("X,Y,Z");
       app.add_option("--body", f->body, "the body that reaches (default hand)")->type_name("BODY");
       app.add_option("--point", f->point, "the point of BODY that reaches, in its frame (m; default 0,0,0)")
           ->type_name("x,y,z");
       app.add_option("--coordinates", f->coordinates,
                      "the coordinates that get a constant torque (default: all of the model's)")
           ->type_name("C,...");
       app.add_option("--torques-in-time", f->torques_in_time,
                      "the torques as functions of time: K constant pieces, K~linear (K nodes, piecewise\n"
                      "linear) or K~cubic (K >= 4 control points of a cubic B-spline); default constant")
           ->type_name("K[~linear|~cubic]");
       app.add_option("--duration", f->duration, "simulated seconds; the hand is judged at the end; required")
           ->type_name("S")
           ->check(positive());
       app.add_option("--dt", f->dt, "fixed step (default 0.01)")->type_name("H")->check(positive());
       app.add_option("--integrator", f->integrator, "euler (default), bdf1 or sdirk2")
           ->type_name("euler|bdf1|sdirk2")
           ->check(oneOf({"euler", "bdf1", "sdirk2"}));
       app.add_option("--method", f->method,
                      "the methods, each from zero torques, comma-separated (default lbfgs,bobyqa):\n"
                      "lbfgs (L-BFGS on the adjoint gradient), nelder-mead or bobyqa (NLopt, gradient-free)")
           ->type_name("M,...");
       app.add_option("--rest", f->rest, "weight W of W/2 |qdot|^2 at the end: the hand also comes to rest (default 0)")
           ->type_name("WEIGHT")
           ->check(nonNegative());
       app.add_option("--tolerance", f->tolerance,
                      "the reach error (m) that counts as reached; the methods stop at the objective\n"
                      "1/2 T^2 (default 0.001); --task track: the RMS error sqrt(2 J / duration), stop\n"
                      "at 1/2 T^2 duration")
           ->type_name("T")
           ->check(positive());
       app.add_option("--max-simulations", f->max_simulations, "per method (default 2000)")
           ->type_name("N")
           ->check(between(1, 1e9, true));
       app.add_option("--max-torque", f->max_torque,
                      "N m: the gradient-free methods' bounds on each torque, +-T (default 100)")
           ->type_name("T")
           ->check(positive());
       app.add_option("--initial-step", f->initial_step, "rad/s^2: the gradient-free methods' first step in joint acceleration (each\n"
                      "torque divided by its coordinate's diagonal mass-matrix entry at the start; default 1)")
           ->type_name("T")
           ->check(positive());
       app.add_option("--drive", f->drive,
                      "what drives the arm: torques (constant generalized forces, default) or\n"
                      "excitations (the muscles' excitations as piecewise-linear nodes; the Hill-type\n"
                      "muscles pull, activation and fibre length are states; needs dt of about 0.5 ms)")
           ->type_name("torques|excitations")
           ->check(oneOf({"torques", "excitations"}));
       app.add_option("--excite", f->muscles,
                      "--drive excitations: the excited muscles (default: all with a Hill-type model;\n"
                      "the others stay at their min_control)")
           ->type_name("M,...");
       app.add_option("--nodes", f->nodes, "--drive excitations: nodes per muscle over the run (default 5)")
           ->type_name("K")
           ->check(between(1, 100000, true));
       app.add_option("--initial-excitation", f->initial_excitation,
                      "--drive excitations: every node's start value (default 0.1)")
           ->type_name("E");
       app.add_option("--excitation-weight", f->excitation_weight,
                      "--drive excitations: weight W of W times the integral of the squared excitations\n"
                      "(default 0)")
           ->type_name("W")
           ->check(nonNegative());
       app.add_option("--report", f->report,
                      "write DIR/report.md, DIR/<method>_iterations.csv, DIR/objective.png (gnuplot);\n"
                      "with --drive excitations also DIR/best_run.csv and DIR/best_run.png (hand path,\n"
                      "excitations, tendon forces; the lumped replay when the muscles carry mass); with\n"
                      "--task track DIR/best_run.csv and DIR/tracking.png (tracked against simulated)")
           ->type_name("DIR");
       app.add_flag("--quiet", f->quiet, "no progress on stderr");
       app.add_option("--muscle-mass-kg", f->muscle_mass_kg,
                      "give these muscles KG each in mass points, ADDED to the model; excludes --muscle-mass")
           ->type_name("NAME=KG,...")
           ->group("Muscle mass");
       addMuscleMassFlags(app, f->mm);
       app.footer(std::string(
           "usage: redmax optimize --task reach --model M.osim --target X,Y,Z --duration S\n"
           "                       [--body BODY] [--point x,y,z] [--dt H] [--integrator euler|bdf1|sdirk2]\n"
           "                       [--method lbfgs,nelder-mead,bobyqa] [--rest WEIGHT] [--tolerance T]\n"
           "                       [--drive excitations [--excite M,...] [--nodes K]]\n"
           "                       [MUSCLE-MASS OPTIONS] [--report DIR]\n"
           "       redmax optimize --task track --model M.osim --duration S --motion FILE.mot[@C,...]\n"
           "                       [--objective SPEC] [--coordinates C,...] [--torques-in-time K[~cubic]]\n"
           "                       [--method ...] [--tolerance T] [--report DIR]\n"
           "Finds constant generalized forces on the model's coordinates that bring the point to the target\n"
           "at the end of a run from the default pose (gravity, muscle inertia; the muscles pull no force),\n"
           "or with --drive excitations the muscles' excitation nodes (the muscles pull),\n"
           "[D Sec. 6.2.11]: minimizes 1/2 |p - target|^2 (+ WEIGHT/2 |qdot|^2) with each method from zero\n"
           "and prints simulations, wall time and final error per method (docs/gradients.md §7).\n"
           "--task track: the torques that make the run follow a motion's coordinates (and TRC markers),\n"
           "from zero; the report adds best_run.csv and tracking.png (tracked against simulated).\n"
           "e.g. redmax optimize --task reach --model osim_models/reach_arm.osim --point 0,-0.08,0\n"
           "       --target 0.25,-0.35,0.1 --duration 0.4 --muscle-mass physiological --report reach\n") +
           muscleMassFooter());
       return [f, &app] { return runOptimize(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
