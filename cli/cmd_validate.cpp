// `redmax validate`: the inputs of `redmax id`, solved by the core and by Simbody, compared with
// each other and with reference results, written as a report directory (docs/commands.md §1). The work
// is validation/id_validation.hpp; this file parses flags and maps errors to exit codes:
// 0 every comparison passed, 1 one failed (or a frame could not be solved, or the report could
// not be written), 2 bad input or usage.
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "validation/id_validation.hpp"

namespace redmax::cli {
namespace {

// --reference and --published may be repeated; Args keeps only the last value of a flag, so
// they are taken out of argv first
std::vector<std::string> takeReferences(const std::vector<std::string>& argv,
                                        std::vector<validation::IdReference>& refs) {
  std::vector<std::string> rest;
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    bool matched = false;
    for (const std::string flag : {"reference", "published"}) {
      const std::string f = "--" + flag;
      std::string value;
      if (a == f) {
        if (i + 1 >= argv.size()) throw UsageError{f + " needs a value"};
        value = argv[++i];
      } else if (a.rfind(f + "=", 0) == 0) {
        value = a.substr(f.size() + 1);
      } else {
        continue;
      }
      if (value.empty()) throw UsageError{f + " needs a file name"};
      refs.push_back({value, flag});
      matched = true;
      break;
    }
    if (!matched) rest.push_back(a);
  }
  return rest;
}

// "a,b c" -> {"a", "b", "c"}

double nonNegative(const Args& a, const std::string& name, double fallback) {
  const double x = a.getDouble(name, fallback);
  if (x < 0) throw UsageError{"--" + name + " must be >= 0"};
  return x;
}

int runValidate(const std::vector<std::string>& argv_in) {
  validation::IdValidationOptions opt;
  const std::vector<std::string> argv = takeReferences(argv_in, opt.references);
  const std::set<std::string> value_flags =
      withMuscleMassFlags({"setup", "model", "coordinates", "external-loads", "lowpass", "t0", "t1", "report",
                           "forces-to-exclude", "mass-sweep", "sweep-columns", "tolerance", "max-tolerance",
                           "engine-tolerance", "interpolation", "gnuplot"});
  const std::set<std::string> bool_flags = {"exact", "opensim-compat", "quiet", "no-simbody", "no-plots"};
  const Args a(argv, value_flags, bool_flags);
  if (!a.positionals().empty())
    throw UsageError{"validate takes no positional arguments (got '" + a.positionals().front() + "')"};

  // the same inputs as `redmax id`
  osim::IdToolSettings& s = opt.settings;
  s.setup_file = a.get("setup", "");
  if (s.setup_file.empty() && (!a.has("model") || !a.has("coordinates")))
    throw UsageError{"validate needs --setup ID_SETUP.xml, or --model M.osim and --coordinates Q.mot"};
  if (auto v = a.get("model")) s.model_file = *v;
  if (auto v = a.get("coordinates")) s.coordinates_file = *v;
  if (auto v = a.get("external-loads")) s.external_loads_file = *v;
  if (a.has("lowpass")) s.lowpass_cutoff_hz = a.getDouble("lowpass", -1.0);
  if (a.has("t0")) s.t0 = a.getDouble("t0", 0.0);
  if (a.has("t1")) s.t1 = a.getDouble("t1", 0.0);
  if (s.t0 && s.t1 && *s.t0 > *s.t1) throw UsageError{"--t0 is after --t1"};
  if (auto v = a.get("forces-to-exclude")) {
    s.forces_to_exclude = splitList(*v, ", \t");
  }
  if (a.has("exact") && a.has("opensim-compat"))
    throw UsageError{"--exact and --opensim-compat exclude each other"};
  s.opensim_compat = !a.has("exact");
  // muscle mass: one extra core run ("inertial effect") or, with --mass-sweep, a sweep
  if (a.has("mass-sweep")) {
    if (!a.has("muscle-mass") || a.get("muscle-mass", "none") == "none")
      throw UsageError{"--mass-sweep needs --muscle-mass transfer (fractions) or physiological (scales)"};
    if (a.has("transfer-fraction"))
      throw UsageError{"--mass-sweep gives the transfer fractions; leave out --transfer-fraction"};
    opt.mass_sweep = validation::parseMassSweepValues(*a.get("mass-sweep"));
  } else if (a.has("sweep-columns")) {
    throw UsageError{"--sweep-columns needs --mass-sweep"};
  }
  if (!opt.mass_sweep.empty() && a.get("muscle-mass", "") == "transfer") {
    // the sweep gives the fractions: the shared parser still wants one, any valid value does
    std::vector<std::string> with_fraction = argv;
    with_fraction.push_back("--transfer-fraction=0");
    opt.muscle_mass = parseMuscleMassFlags(Args(with_fraction, value_flags, bool_flags));
  } else {
    opt.muscle_mass = parseMuscleMassFlags(a);
  }
  if (!opt.mass_sweep.empty())
    opt.mass_sweep = validation::checkMassSweepValues(opt.muscle_mass, opt.mass_sweep);
  if (auto v = a.get("sweep-columns")) opt.sweep_columns = splitList(*v, ", \t");

  // the report and the comparisons
  opt.report_dir = a.get("report", "");
  if (opt.report_dir.empty()) throw UsageError{"validate needs --report DIR"};
  opt.reference_rms_rel = nonNegative(a, "tolerance", opt.reference_rms_rel);
  if (a.has("max-tolerance")) opt.reference_max_rel = nonNegative(a, "max-tolerance", 0);
  opt.engine_rel = nonNegative(a, "engine-tolerance", opt.engine_rel);
  opt.run_simbody = !a.has("no-simbody");
  if (auto v = a.get("interpolation")) {
    try {
      opt.interpolation = validation::parseInterpolation(*v);
    } catch (const validation::CompareError&) {
      throw UsageError{"--interpolation must be linear or cubic, got '" + *v + "'"};
    }
  }
  opt.gnuplot = a.has("no-plots") ? "none" : a.get("gnuplot", "");
  const bool quiet = a.has("quiet");
  opt.progress = !quiet;

  validation::IdValidationResult r;
  try {
    r = validation::runIdValidation(opt);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const validation::CompareError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    // bad muscle-mass options the model rejects (an unknown body, a regular expression)
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const osim::IdEngineError& e) {
    std::cerr << "error: " << s.coordinates_file.value_or(s.setup_file) << ": " << e.what() << "\n";
    return 1;
  } catch (const validation::ReportError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  if (!quiet) {
    // what the muscle-mass step did (the largest mass of a sweep): bodies before and after, muscles
    if (r.has_inertial_effect) std::cerr << r.inertial_effect.description;
    if (r.has_mass_sweep && !r.mass_sweep.points.empty()) std::cerr << r.mass_sweep.points.back().description;
    for (const auto& w : r.warnings) std::cerr << "warning: " << w << "\n";
    for (const auto& e : r.files.plot_errors) std::cerr << "warning: plot: " << e << "\n";
    std::cout << validation::formatIdValidationSummary(r);
    std::cout << "report: " << opt.report_dir << "/report.md, summary.json"
              << (r.files.plots_skipped ? " (plots skipped: " + r.files.plots_note + ")" : "") << "\n";
  }
  return r.passed ? 0 : 1;
}

CommandRegistration reg(
    {"validate", "inverse dynamics by core and Simbody, compared with each other and with references",
     std::string("usage: redmax validate (--setup ID_SETUP.xml | --model M.osim --coordinates Q.mot)\n"
     "                 [--external-loads LOADS.xml] [--lowpass HZ] [--t0 S] [--t1 S]\n"
     "                 [--forces-to-exclude LIST] [--exact]\n"
     "                 [--reference OPENSIM_ID.sto]... [--published ID.sto]...\n"
     "                 [--tolerance REL] [--max-tolerance REL] [--engine-tolerance REL]\n"
     "                 [--interpolation linear|cubic] [--no-simbody] [--no-plots] [--gnuplot PATH]\n"
     "                 [MUSCLE-MASS OPTIONS] [--mass-sweep V1,V2,... [--sweep-columns LIST]]\n"
     "                 [--quiet] --report DIR\n"
     "Processes the inputs once, as `redmax id` does (see `redmax id --help` for the input flags),\n"
     "solves every frame with the core engine and with the Simbody engine, and compares:\n"
     "  core_vs_simbody      every column and frame: |core - simbody| <= REL * column peak\n"
     "                       (--engine-tolerance, default 1e-9; absolute floor 1e-10)\n"
     "  core_vs_<label>      each --reference (label 'reference') or --published (label\n"
     "                       'published') result: columns matched by name over the overlapping\n"
     "                       time range, the reference's rows as the grid and the core interpolated\n"
     "                       (--interpolation, default linear); passes when RMS <= REL * peak\n"
     "                       (--tolerance, default 1e-6; absolute floor 1e-9) and, with\n"
     "                       --max-tolerance REL, max |diff| <= REL * peak\n"
     "If the Simbody engine cannot build the model, the reason goes into the report and the run\n"
     "continues with the core only (--no-simbody skips it on purpose).\n"
     "DIR receives: summary.json (inputs, per-comparison per-column metrics, PASS/FAIL, the speed\n"
     "of each engine: frames, seconds, frames per second), <cmp>_metrics.csv, <cmp>_series.csv,\n"
     "overlay and difference plots (gnuplot; skipped with a note when absent or --no-plots),\n"
     "overlay_all (every series), core_id.sto and simbody_id.sto (full precision), report.md.\n"
     "MUSCLE-MASS OPTIONS (below). The comparisons above always use the zero-mass core and\n"
     "Simbody (OpenSim's results have no muscle inertia). With muscle mass the core solves the\n"
     "trial again and the per-column difference from the zero-mass core is reported as the\n"
     "inertial effect (inertial_effect.csv, an overlay, core_mass_id.sto, summary.inertial_effect),\n"
     "never a failure; Simbody with muscle inertia solves it too, and the two engines must agree\n"
     "(core_mass_vs_simbody_mass_metrics.csv, summary.simbody_mass_check; a disagreement fails the\n"
     "run, except with --wrap exact, whose finite-difference Jacobians the engines take in different\n"
     "variables: then it is recorded).\n"
     "--mass-sweep V1,V2,...  solve once per value on the same processed inputs: transfer fractions\n"
     "                       in [0, 1) with --muscle-mass transfer --transfer-body BODY (e.g.\n"
     "                       0,0.2,0.4,0.6,0.8), or scales >= 0 of the physiological mass with\n"
     "                       --muscle-mass physiological (e.g. 0,0.25,0.5,1); 0 is added if absent.\n"
     "                       Writes mass_sweep_tau_<v>.csv per value, mass_sweep_peaks.csv (peak\n"
     "                       |tau| and its change), mass_sweep_fit.csv (R^2 of tau(s) - tau(0)\n"
     "                       against s), plots mass_sweep_torques (--sweep-columns, default ankle,\n"
     "                       knee and hip of the transfer side) and mass_sweep_peak_change, and\n"
     "                       summary.mass_sweep. Only its zero check (the value 0 reproduces the\n"
     "                       zero-mass result to 1e-12 of each column's peak) can fail the run.\n"
     "Prints one line per engine and per comparison (worst column, PASS/FAIL).\n"
     "Exit codes: 0 every comparison passed, 1 a comparison failed (or a frame could not be solved,\n"
     "or the report could not be written), 2 bad input or usage.\n") +
         muscleMassUsage(),
     runValidate});

}  // namespace
}  // namespace redmax::cli
