#include "cli/id_flags.hpp"

namespace redmax::cli {

void addIdInputFlags(CLI::App& app, IdInputFlags& f) {
  const std::string g = "Inputs";
  app.add_option("--setup", f.setup, "an InverseDynamicsTool setup (paths relative to it); flags override it")
      ->type_name("ID_SETUP.xml")
      ->check(existingFile())
      ->group(g);
  app.add_option("--model", f.model, "the OpenSim model (.osim)")->type_name("M.osim")->check(existingFile())->group(g);
  app.add_option("--coordinates", f.coordinates,
                 "the motion (.mot/.sto): columns named as coordinates or as state names\n"
                 "(/jointset/<joint>/<coord>/value); coordinates absent from the file are held at\n"
                 "their defaults; Rotational columns of a degrees file are converted")
      ->type_name("Q.mot")
      ->check(existingFile())
      ->group(g);
  app.add_option("--external-loads", f.external_loads, "an OpenSim ExternalLoads file")
      ->type_name("LOADS.xml")
      ->group(g);
  app.add_option("--lowpass", f.lowpass, "cutoff for the coordinates (< 0: no filtering; setup default -1)")
      ->type_name("HZ")
      ->check(number())
      ->group(g);
  app.add_option("--t0", f.t0,
                 "time range start; output rows are the processed samples from the last at or\n"
                 "before t0 to the last at or before t1 (as OpenSim)")
      ->type_name("S")
      ->check(number())
      ->group(g);
  app.add_option("--t1", f.t1, "time range end")->type_name("S")->check(number())->group(g);
  app.add_option("--forces-to-exclude", f.forces_to_exclude,
                 "comma-separated: All, Actuators, Muscles, group or force names (default\n"
                 "without a setup: Muscles). Forces OpenSim would still apply and redmax does\n"
                 "not model are listed as warnings")
      ->type_name("LIST")
      ->group(g);
  app.add_flag("--exact", f.exact,
               "exact kinematics instead of OpenSim compatibility (the default,\n"
               "--opensim-compat): by default CustomJoints use Simbody's approximate velocity\n"
               "terms and Ball/Free/Ellipsoid joints read the data's Euler-angle rates as\n"
               "angular velocity in the parent frame, as OpenSim does; with --exact every\n"
               "column is the force conjugate to its coordinate's rate")
      ->group(g);
  app.add_flag("--opensim-compat", f.opensim_compat, "OpenSim-compatible kinematics (the default)")->group(g);
  addMuscleMassFlags(app, f.muscle_mass);
}

osim::IdToolSettings parseIdInputFlags(const IdInputFlags& f, const CLI::App& app, const std::string& command) {
  osim::IdToolSettings s;
  s.setup_file = f.setup;
  if (s.setup_file.empty() && (!given(app, "--model") || !given(app, "--coordinates")))
    throw UsageError{command + " needs --setup ID_SETUP.xml, or --model M.osim and --coordinates Q.mot"};
  if (given(app, "--model")) s.model_file = f.model;
  if (given(app, "--coordinates")) s.coordinates_file = f.coordinates;
  if (given(app, "--external-loads")) s.external_loads_file = f.external_loads;
  if (given(app, "--lowpass")) s.lowpass_cutoff_hz = f.lowpass;
  if (given(app, "--t0")) s.t0 = f.t0;
  if (given(app, "--t1")) s.t1 = f.t1;
  if (s.t0 && s.t1 && *s.t0 > *s.t1) throw UsageError{"--t0 is after --t1"};
  if (given(app, "--forces-to-exclude")) s.forces_to_exclude = splitList(f.forces_to_exclude, ", \t");
  if (f.exact && f.opensim_compat) throw UsageError{"--exact and --opensim-compat exclude each other"};
  s.opensim_compat = !f.exact;
  return s;
}

}  // namespace redmax::cli
