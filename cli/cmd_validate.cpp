// `redmax validate`: the inputs of `redmax id`, solved by the core and by Simbody, compared with
// each other and with reference results, written as a report directory (docs/commands.md §1). The work
// is validation/id_validation.hpp; this file parses flags and maps errors to exit codes:
// 0 every comparison passed, 1 one failed (or a frame could not be solved, or the report could
// not be written), 2 bad input or usage.
#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cli/validate_flags.hpp"
#include "validation/id_validation.hpp"

namespace redmax::cli {
namespace {

int runValidate(const ValidateFlags& f, const CLI::App& app) {
  const validation::IdValidationOptions opt = parseValidateFlags(f, app);
  const osim::IdToolSettings& s = opt.settings;
  const bool quiet = f.quiet;

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
     [](CLI::App& app) {
       auto f = std::make_shared<ValidateFlags>();
       addValidateFlags(app, *f);
       app.footer(std::string(
           "usage: redmax validate (--setup ID_SETUP.xml | --model M.osim --coordinates Q.mot)\n"
           "                 [--external-loads LOADS.xml] [--lowpass HZ] [--t0 S] [--t1 S]\n"
           "                 [--forces-to-exclude LIST] [--exact]\n"
           "                 [--reference OPENSIM_ID.sto]... [--published ID.sto]...\n"
           "                 [--tolerance REL] [--max-tolerance REL] [--engine-tolerance REL]\n"
           "                 [--interpolation linear|cubic] [--no-simbody] [--no-plots] [--gnuplot PATH] [--view]\n"
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
     "With MUSCLE-MASS OPTIONS, the comparisons above always use the zero-mass core and\n"
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
     "                       summary.mass_sweep. Fails the run: the zero check (the value 0\n"
     "                       reproduces the zero-mass result to 1e-12 of each column's peak) and\n"
     "                       core vs Simbody with muscle inertia at every value (mass_sweep_simbody.csv).\n"
     "Prints one line per engine and per comparison (worst column, PASS/FAIL).\n"
     "Exit codes: 0 every comparison passed, 1 a comparison failed (or a frame could not be solved,\n"
     "or the report could not be written), 2 bad input or usage.\n") + muscleMassFooter());
       return [f, &app] { return runValidate(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
