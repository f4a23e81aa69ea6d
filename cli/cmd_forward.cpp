// `redmax forward`: OpenSim's ForwardTool on a setup file (docs/forward.md, docs/commands.md).
// The tool is validation/forward/forward_tool.hpp; this file parses flags, prints warnings and the
// summary. Exit codes: 0 success, 1 the run failed (nothing written), 2 bad input or usage.
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/muscle_mass_flags.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "validation/forward/forward_tool.hpp"

namespace redmax::cli {
namespace {

struct ForwardFlags {
  std::string setup, out_dir, muscle_class, integrator = "rk45";
  double report_interval = 0.01, tolerance = 0.0;
  bool quiet = false;
  MuscleMassFlags mm;
};

int runForward(const ForwardFlags& f, const CLI::App& app) {
  if (!given(app, "--setup")) throw UsageError{"forward needs --setup FORWARD_SETUP.xml"};
  validation::ForwardToolSettings s;
  s.setup_file = f.setup;
  if (given(app, "--out-dir")) s.out_dir = f.out_dir;
  s.muscle_class = f.muscle_class;
  s.muscle_mass = parseMuscleMassFlags(f.mm);
  s.integrator = f.integrator;
  s.report_interval = f.report_interval;
  if (given(app, "--tolerance")) s.tolerance = f.tolerance;
  std::unique_ptr<validation::ForwardTool> tool;
  try {
    tool = std::make_unique<validation::ForwardTool>(s);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const ModelError& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 2;
  } catch (const hill::MuscleModelError& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 2;
  }
  if (!f.quiet)
    for (const std::string& w : tool->warnings()) std::cerr << "warning: " << w << "\n";
  validation::ForwardResult r;
  try {
    r = tool->run();
  } catch (const std::exception& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 1;
  }
  if (r.failed) {
    std::cerr << "error: " << f.setup << ": " << r.failure << "\n";
    return 1;
  }
  try {
    tool->write(r);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (!f.quiet) {
    const auto& st = tool->setup();
    std::printf("forward: %s, t %.6g to %.6g s, %d states, %d controls, %s: %ld steps, %ld rhs, %.3f s wall\n",
                st.name.c_str(), st.initial_time, st.final_time, r.states.numColumns(), r.controls.numColumns(),
                s.integrator.c_str(), r.stats.steps, r.stats.rhs_evals, r.wall_s);
    std::printf("  -> %s\n  -> %s\n", tool->statesPath().c_str(), tool->controlsPath().c_str());
  }
  return 0;
}

CommandRegistration reg(
    {"forward", "OpenSim's ForwardTool: muscle-driven forward simulation from a setup file", [](CLI::App& app) {
       auto f = std::make_shared<ForwardFlags>();
       app.add_option("--setup", f->setup,
                      "ForwardTool setup (.xml): model_file, ControllerSet / controls_file,\n"
                      "states_file, initial/final_time, integrator settings; required")
           ->type_name("FORWARD_SETUP.xml");
       app.add_option("--out-dir", f->out_dir,
                      "results folder (default: the setup's results_directory): DIR/<name>_states.sto\n"
                      "and DIR/<name>_controls.sto")
           ->type_name("DIR");
       app.add_option("--muscle-class", f->muscle_class,
                      "read every muscle as this OpenSim class (Object::renameType), e.g.\n"
                      "Thelen2003Muscle_Deprecated")
           ->type_name("CLASS");
       app.add_option("--integrator", f->integrator, "rk45 (default), cvode, or a fixed-step method")
           ->type_name("euler|symplectic|bdf1|sdirk2|rk45|cvode")
           ->check(oneOf({"euler", "symplectic", "bdf1", "sdirk2", "rk45", "cvode"}));
       app.add_option("--report-interval", f->report_interval, "s between output rows (default 0.01)")
           ->type_name("S")
           ->check(positive());
       app.add_option("--tolerance", f->tolerance,
                      "rtol = atol of the adaptive integrator (default: integrator_error_tolerance)")
           ->type_name("T")
           ->check(positive());
       app.add_flag("--quiet", f->quiet, "no summary and no warnings");
       addMuscleMassFlags(app, f->mm);
       app.footer(
           "usage: redmax forward --setup FORWARD_SETUP.xml [--out-dir DIR] [--muscle-class CLASS]\n"
           "                      [--integrator NAME] [--report-interval S] [--tolerance T]\n"
           "                      [MUSCLE-MASS OPTIONS]\n"
           "States are written under OpenSim 4 names: /jointset/J/C/value, /jointset/J/C/speed,\n"
           "/forceset/M/activation, /forceset/M/fiber_length.\n"
           "Exit codes: 0 success, 1 the run failed (nothing written), 2 bad input or usage.");
       return [f, &app] { return runForward(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
