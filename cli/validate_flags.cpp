#include "cli/validate_flags.hpp"

namespace redmax::cli {
namespace {

// --reference and --published in the order given (they may be repeated and mixed)
std::vector<validation::IdReference> takeReferences(const ValidateFlags& f, const CLI::App& app) {
  std::vector<validation::IdReference> refs;
  size_t next_ref = 0, next_pub = 0;
  for (const CLI::Option* o : app.parse_order()) {
    const bool ref = o->check_name("--reference");
    if (!ref && !o->check_name("--published")) continue;
    const std::vector<std::string>& values = ref ? f.references : f.published;
    size_t& next = ref ? next_ref : next_pub;
    if (next >= values.size()) continue;
    const std::string& value = values[next++];
    if (value.empty()) throw UsageError{std::string(ref ? "--reference" : "--published") + " needs a file name"};
    refs.push_back({value, ref ? "reference" : "published"});
  }
  return refs;
}

}  // namespace

void addValidateFlags(CLI::App& app, ValidateFlags& f) {
  addIdInputFlags(app, f.in);
  const std::string g = "Comparisons";
  app.add_option("--reference", f.references,
                 "an OpenSim ID result (label 'reference'); may be repeated")
      ->type_name("OPENSIM_ID.sto")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->group(g);
  app.add_option("--published", f.published, "a published ID result (label 'published'); may be repeated")
      ->type_name("ID.sto")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->group(g);
  app.add_option("--tolerance", f.tolerance, "RMS <= REL * peak against references (default 1e-6)")
      ->type_name("REL")
      ->check(nonNegative())
      ->group(g);
  app.add_option("--max-tolerance", f.max_tolerance, "also max |diff| <= REL * peak against references")
      ->type_name("REL")
      ->check(nonNegative())
      ->group(g);
  app.add_option("--engine-tolerance", f.engine_tolerance,
                 "|core - simbody| <= REL * column peak (default 1e-9)")
      ->type_name("REL")
      ->check(nonNegative())
      ->group(g);
  app.add_option("--interpolation", f.interpolation, "the core on the reference's rows (default linear)")
      ->type_name("linear|cubic")
      ->check(oneOf({"linear", "cubic"}))
      ->group(g);
  app.add_flag("--no-simbody", f.no_simbody, "skip the Simbody engine")->group(g);
  app.add_option("--mass-sweep", f.mass_sweep,
                 "solve once per value on the same processed inputs: transfer fractions\n"
                 "in [0, 1) with --muscle-mass transfer --transfer-body BODY (e.g.\n"
                 "0,0.2,0.4,0.6,0.8), or scales >= 0 of the physiological mass with\n"
                 "--muscle-mass physiological (e.g. 0,0.25,0.5,1); 0 is added if absent")
      ->type_name("V1,V2,...")
      ->group("Muscle mass");
  app.add_option("--sweep-columns", f.sweep_columns,
                 "the mass_sweep_torques plot's columns (default ankle, knee and hip of\n"
                 "the transfer side)")
      ->type_name("LIST")
      ->group("Muscle mass");
  app.add_option("--report", f.report, "the report folder (required)")->type_name("DIR");
  app.add_flag("--no-plots", f.no_plots, "no gnuplot plots");
  app.add_flag("--view", f.view,
               "also write the trial's `redmax view` into DIR/view (the model along the\n"
               "coordinates file with the run's muscle mass, a sweep's largest value), linked\n"
               "from report.md (docs/view.md)");
  app.add_option("--gnuplot", f.gnuplot, "the gnuplot executable (default: found on PATH)")->type_name("PATH");
  app.add_flag("--quiet", f.quiet, "no progress, summary or warnings");
}

validation::IdValidationOptions parseValidateFlags(const ValidateFlags& f, const CLI::App& app) {
  validation::IdValidationOptions opt;
  opt.references = takeReferences(f, app);

  // the same inputs as `redmax id`
  opt.settings = parseIdInputFlags(f.in, app, "validate");
  // muscle mass: one extra core run ("inertial effect") or, with --mass-sweep, a sweep
  if (given(app, "--mass-sweep")) {
    if (f.in.muscle_mass.source == "none")
      throw UsageError{"--mass-sweep needs --muscle-mass transfer (fractions) or physiological (scales)"};
    if (given(app, "--transfer-fraction"))
      throw UsageError{"--mass-sweep gives the transfer fractions; leave out --transfer-fraction"};
    opt.mass_sweep = validation::parseMassSweepValues(f.mass_sweep);
  } else if (given(app, "--sweep-columns")) {
    throw UsageError{"--sweep-columns needs --mass-sweep"};
  }
  // the sweep gives the transfer fractions
  opt.muscle_mass = parseMuscleMassFlags(f.in.muscle_mass, !opt.mass_sweep.empty());
  if (!opt.mass_sweep.empty())
    opt.mass_sweep = validation::checkMassSweepValues(opt.muscle_mass, opt.mass_sweep);
  if (given(app, "--sweep-columns")) opt.sweep_columns = splitList(f.sweep_columns, ", \t");

  // the report and the comparisons
  opt.report_dir = f.report;
  if (opt.report_dir.empty()) throw UsageError{"validate needs --report DIR"};
  opt.reference_rms_rel = f.tolerance;
  if (given(app, "--max-tolerance")) opt.reference_max_rel = f.max_tolerance;
  opt.engine_rel = f.engine_tolerance;
  opt.run_simbody = !f.no_simbody;
  if (given(app, "--interpolation")) opt.interpolation = validation::parseInterpolation(f.interpolation);
  opt.gnuplot = f.no_plots ? "none" : f.gnuplot;
  opt.progress = !f.quiet;
  if (f.view) {
    try {
      opt.view = view::findViewAssets(viewAssetFolders());
    } catch (const std::runtime_error& e) {
      throw UsageError{std::string("--view: ") + e.what()};
    }
  }
  return opt;
}

}  // namespace redmax::cli
