#include "cli/analyze_flags.hpp"

#include "core/muscles/hill/factory.hpp"

namespace redmax::cli {

void addAnalyzeFlags(CLI::App& app, AnalyzeFlags& f) {
  app.add_option("--setup", f.setup, "an AnalyzeTool setup (paths relative to it)")
      ->type_name("ANALYZE_SETUP.xml")
      ->required()
      ->check(existingFile());
  app.add_option("--out-dir", f.out_dir, "where the result files go (default: the setup's results_directory)")
      ->type_name("DIR");
  app.add_option("--muscle-class", f.muscle_class, "read every muscle as CLASS (OpenSim's Object::renameType)")
      ->type_name("CLASS")
      ->check(oneOf(hill::muscleModelClasses()));
  app.add_flag("--quiet", f.quiet, "no summary line");
  addMuscleMassFlags(app, f.muscle_mass);
}

osim::AnalyzeToolSettings parseAnalyzeFlags(const AnalyzeFlags& f, const CLI::App& app) {
  osim::AnalyzeToolSettings settings;
  settings.setup_file = f.setup;
  if (given(app, "--out-dir")) settings.out_dir = f.out_dir;
  if (given(app, "--muscle-class")) settings.muscle_class = f.muscle_class;
  settings.muscle_mass = parseMuscleMassFlags(f.muscle_mass);
  return settings;
}

}  // namespace redmax::cli
