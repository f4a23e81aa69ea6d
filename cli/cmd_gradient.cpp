// `redmax gradient`: the objective of a simulation and its adjoint gradient (docs/gradients.md).
// The problem is validation/gradient (SPEC parsing), the adjoint core/adjoint; this file parses
// flags and prints. Exit codes: 0 success, 1 the run failed or --check exceeded its tolerance,
// 2 bad input or usage.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/muscle_mass_flags.hpp"
#include "converter/osim_reader.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "validation/gradient/gradient.hpp"

namespace redmax::cli {
namespace {

struct GradientFlags {
  std::string model, integrator = "euler", params, objective, muscle_mass_kg, step_jacobians = "auto";
  double duration = 0.0, dt = 1e-3, check_tolerance = 1e-6, jacobian_step = 0.0;
  bool check = false;
  MuscleMassFlags mm;
};

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int runGradient(GradientFlags& f, const CLI::App& app) {
  for (const char* n : {"--model", "--duration", "--params", "--objective"})
    if (!given(app, n)) throw UsageError{std::string("gradient needs ") + n};
  validation::SimulationModelOptions mo;
  applyMuscleMassOptions(app, f.mm, f.muscle_mass_kg, mo);

  validation::GradientSetup g;
  if (const int rc = loadOrExit2(f.model, [&] {
        g = validation::makeGradientSetup(f.model, mo, f.integrator, f.duration, f.dt, f.params, f.objective);
      }))
    return rc;
  for (const auto& w : g.model.build.warnings) std::cerr << "warning: " << w << "\n";
  for (const auto& w : g.warnings) std::cerr << "warning: " << w << "\n";
  for (const auto& w : g.not_applied) std::cerr << "warning: not applied: " << w << "\n";
  if (given(app, "--jacobian-step")) g.problem.jacobian_step = f.jacobian_step;
  g.problem.step_jacobians = f.step_jacobians;

  adjoint::Result res;
  double adjoint_s = 0.0;
  try {
    const auto t0 = std::chrono::steady_clock::now();
    res = adjoint::evaluate(g.problem, g.objective, g.p0, true);
    adjoint_s = secondsSince(t0);
  } catch (const adjoint::AdjointError& e) {
    std::cerr << "error: " << f.model << ": " << e.what() << "\n";
    return 2;
  } catch (const SimulationError& e) {
    std::cerr << "error: " << f.model << ": simulation failed: " << e.what() << "\n";
    return 1;
  } catch (const hill::MuscleModelError& e) {
    std::cerr << "error: " << f.model << ": simulation failed: " << e.what() << "\n";
    return 1;
  }
  std::printf("gradient: %s, integrator %s, %ld steps of %.6g s, %d parameters, muscle mass %.4g kg\n",
              g.model.description.name.c_str(), f.integrator.c_str(), res.steps, f.duration / res.steps,
              static_cast<int>(g.p0.size()), g.model.muscle_mass);
  std::printf("step Jacobians: %s\n", adjoint::stepJacobiansText(res).c_str());
  std::printf("objective %.12e\n", res.objective);
  std::printf("%-36s %20s %20s\n", "parameter", "value", "dJ/dp");
  for (Eigen::Index i = 0; i < g.p0.size(); ++i)
    std::printf("%-36s %20.12e %20.12e\n", g.param_names[i].c_str(), g.p0[i], res.gradient[i]);
  std::printf("time: forward %.4f s, forward + adjoint %.4f s (%.1f x forward, %ld step evaluations)\n",
              res.forward_seconds,
              adjoint_s, adjoint_s / res.forward_seconds, res.step_evaluations);
  if (!f.check) return 0;

  VecX fd;
  double fd_s = 0.0;
  try {
    const auto t0 = std::chrono::steady_clock::now();
    fd = adjoint::finiteDifferenceGradient(g.problem, g.objective, g.p0);
    fd_s = secondsSince(t0);
  } catch (const SimulationError& e) {
    std::cerr << "error: " << f.model << ": simulation failed in the finite-difference check: " << e.what() << "\n";
    return 1;
  } catch (const hill::MuscleModelError& e) {
    std::cerr << "error: " << f.model << ": simulation failed in the finite-difference check: " << e.what() << "\n";
    return 1;
  }
  const double err = adjoint::worstRelativeError(res.gradient, fd);
  std::printf("%-36s %20s %20s\n", "parameter", "central difference", "adjoint - difference");
  for (Eigen::Index i = 0; i < g.p0.size(); ++i)
    std::printf("%-36s %20.12e %20.3e\n", g.param_names[i].c_str(), fd[i], res.gradient[i] - fd[i]);
  const bool ok = err <= f.check_tolerance;
  std::printf("check: %ld runs of central differences, %.4f s (%.1f x forward + adjoint); worst relative error "
              "%.3e (tolerance %.3g) -> %s\n",
              static_cast<long>(adjoint::kDifferenceRunsPerParameter) * g.p0.size(), fd_s, fd_s / adjoint_s, err, f.check_tolerance, ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}

CommandRegistration reg(
    {"gradient", "objective of a simulation and its adjoint gradient (parameters, objectives: SPEC)",
     [](CLI::App& app) {
       auto f = std::make_shared<GradientFlags>();
       app.add_option("--model", f->model, "the OpenSim model (.osim); required")
           ->type_name("M.osim")
           ->check(existingFile());
       app.add_option("--duration", f->duration, "simulated seconds; required")->type_name("S")->check(positive());
       app.add_option("--dt", f->dt, "fixed step (default 0.001); the run is ceil(S / dt) equal steps")
           ->type_name("H")
           ->check(positive());
       app.add_option("--integrator", f->integrator,
                      "euler (semi-implicit, default), bdf1 (linearly implicit) or sdirk2")
           ->type_name("euler|bdf1|sdirk2")
           ->check(oneOf({"euler", "bdf1", "sdirk2"}));
       app.add_option("--params", f->params,
                      "the parameters, groups separated by ';':\n"
                      "torques:C[@K][=V],...  constant generalized force on coordinate C in K\n"
                      "                       equal time pieces (default 1), value V (default 0)\n"
                      "excitations:M[@K][=V],... excitation of muscle M as K nodes of a piecewise-\n"
                      "                       linear function of time (default 1), value V (default\n"
                      "                       0.1) within its [min_control, max_control]; the muscles\n"
                      "                       then pull (Hill-type, activation and fibre states), the\n"
                      "                       others at their min_control\n"
                      "q0:C[=V],...           initial value of C (default the model's)\n"
                      "qdot0:C[=V],...        initial speed of C\n"
                      "masses:M,...           mass of muscle M (from --muscle-mass-kg M=KG); required")
           ->type_name("SPEC");
       app.add_option("--objective", f->objective,
                      "the objective, terms [W*]TERM separated by ';' (weight W, default 1):\n"
                      "point:BODY@x,y,z=X,Y,Z W/2 |p - target|^2 at the end, p the point x,y,z of\n"
                      "                       BODY (body frame), target X,Y,Z in ground (m)\n"
                      "marker:NAME=X,Y,Z      the same for a marker of the model's MarkerSet\n"
                      "track:MARKER=FILE.trc  W/2 times the integral over the run of |p(t) - target(t)|^2,\n"
                      "                       p the marker, target the file's marker of the same name\n"
                      "                       (linear between its rows, which must cover the run)\n"
                      "coords:FILE.mot[@C,...] W/2 times the integral over the run of the squared\n"
                      "                       error of the model's coordinates that the motion (.mot/.sto)\n"
                      "                       has, or of the named ones C,...; Rotational ones converted\n"
                      "                       from degrees when the file's inDegrees says so; linear\n"
                      "                       between its rows, which must cover the run\n"
                      "speed                  W/2 |qdot|^2 at the end (come to rest)\n"
                      "effort                 W times the integral of the squared generalized forces\n"
                      "excitation             W times the integral of the squared excitations;\n"
                      "required")
           ->type_name("SPEC");
       app.add_flag("--check", f->check,
                    "also compute central differences of whole simulations (fourth order at four\n"
                    "steps, 16 runs per parameter) and print the worst relative error\n"
                    "max|adjoint - difference| / max|difference|; exit 1 when it is above\n"
                    "--check-tolerance");
       app.add_option("--jacobian-step", f->jacobian_step,
                      "relative step of the step Jacobians' central differences (default 6e-6; 2e-7\n"
                      "with excited muscles none of which wraps; docs/gradients.md §2)")
           ->type_name("REL")
           ->check(between(1e-12, 0.1, false));
       app.add_option("--step-jacobians", f->step_jacobians,
                      "how the step Jacobians are formed: analytic (derivatives of inverse dynamics;\n"
                      "exit 2 where a part of the system has none), differences (central differences\n"
                      "of the step), auto (default: analytic where they apply; docs/gradients.md §2.1)")
           ->type_name("auto|analytic|differences")
           ->check(oneOf({"auto", "analytic", "differences"}));
       app.add_option("--check-tolerance", f->check_tolerance, "the --check bound (default 1e-6)")
           ->type_name("T")
           ->check(positive());
       app.add_option("--muscle-mass-kg", f->muscle_mass_kg,
                      "give these muscles KG each in mass points, ADDED to the model; their masses\n"
                      "may then be parameters (masses:NAME); --mass-points, --mass-region and --wrap\n"
                      "apply; excludes --muscle-mass")
           ->type_name("NAME=KG,...")
           ->group("Muscle mass");
       addMuscleMassFlags(app, f->mm);
       app.footer(std::string(
           "usage: redmax gradient --model M.osim --duration S --params SPEC --objective SPEC\n"
           "                       [--dt H] [--integrator euler|bdf1|sdirk2]\n"
           "                       [MUSCLE-MASS OPTIONS] [--muscle-mass-kg NAME=KG,...]\n"
           "                       [--check [--check-tolerance T]] [--jacobian-step REL]\n"
           "                       [--step-jacobians auto|analytic|differences]\n"
           "Simulates the model from its default pose with the given parameters (gravity, joint springs\n"
           "and dampers, constraints, muscle inertia; the muscles pull only when --params has an\n"
           "excitations: group) and prints the objective and its gradient by the discrete adjoint of\n"
           "the fixed-step integrator (docs/gradients.md).\n"
           "e.g. --params 'torques:r_shoulder_elev,r_elbow_flex' --objective 'point:r_ulna_radius_hand@0,-0.2,0=0.3,0.1,0.4'\n"
           "     --params 'excitations:BIClong@10,TRIlong@10' --objective 'point:r_ulna_radius_hand@0,-0.2,0=0.3,0.1,0.4;1e-3*excitation'\n") +
           muscleMassFooter());
       return [f, &app] { return runGradient(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
