#include "cli/forward_flags.hpp"

namespace redmax::cli {

void addForwardFlags(CLI::App& app, ForwardFlags& f) {
  app.add_option("--setup", f.setup,
                 "ForwardTool setup (.xml): model_file, ControllerSet / controls_file,\n"
                 "states_file, initial/final_time, integrator settings; required")
      ->type_name("FORWARD_SETUP.xml");
  app.add_option("--out-dir", f.out_dir,
                 "results folder (default: the setup's results_directory): DIR/<name>_states.sto\n"
                 "and DIR/<name>_controls.sto")
      ->type_name("DIR");
  app.add_option("--muscle-class", f.muscle_class,
                 "read every muscle as this OpenSim class (Object::renameType), e.g.\n"
                 "Thelen2003Muscle_Deprecated")
      ->type_name("CLASS");
  app.add_option("--integrator", f.integrator, "rk45 (default), cvode, or a fixed-step method")
      ->type_name("euler|symplectic|bdf1|sdirk2|rk45|cvode")
      ->check(oneOf({"euler", "symplectic", "bdf1", "sdirk2", "rk45", "cvode"}));
  app.add_option("--report-interval", f.report_interval, "s between output rows (default 0.01)")
      ->type_name("S")
      ->check(positive());
  app.add_option("--tolerance", f.tolerance, "rtol = atol of the adaptive integrator (default: integrator_error_tolerance)")
      ->type_name("T")
      ->check(positive());
  app.add_flag("--quiet", f.quiet, "no summary and no warnings");
  app.add_flag("--strict", f.strict,
               "refuse to run (exit 2) when a force or contact geometry of the model would not\n"
               "be applied (each is named)");
  app.add_flag("--view", f.view,
               "also write the run's `redmax view` into DIR/<name>_view (the model along the\n"
               "states written, with the run's muscle mass; docs/view.md)");
  addMuscleMassFlags(app, f.mm);
}

validation::ForwardToolSettings parseForwardFlags(const ForwardFlags& f, const CLI::App& app) {
  if (!given(app, "--setup")) throw UsageError{"forward needs --setup FORWARD_SETUP.xml"};
  validation::ForwardToolSettings s;
  s.setup_file = f.setup;
  if (given(app, "--out-dir")) s.out_dir = f.out_dir;
  s.muscle_class = f.muscle_class;
  s.muscle_mass = parseMuscleMassFlags(f.mm);
  s.integrator = f.integrator;
  s.report_interval = f.report_interval;
  if (given(app, "--tolerance")) s.tolerance = f.tolerance;
  s.strict = f.strict;
  if (f.view) {
    try {
      s.view = view::findViewAssets(viewAssetFolders());
    } catch (const std::runtime_error& e) {
      throw UsageError{std::string("--view: ") + e.what()};
    }
  }
  return s;
}

}  // namespace redmax::cli
