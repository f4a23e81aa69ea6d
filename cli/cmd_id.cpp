// `redmax id`: inverse dynamics as OpenSim's InverseDynamicsTool computes it (docs/commands.md §1,
// docs/opensim_compatibility.md §7). converter/id/ does the input processing; the engine is the core or
// Simbody (plugin/simbody/id_engine.hpp). Errors are `error: FILE[:LINE]: what` with exit code 2
// for bad input, 1 for a frame that cannot be solved.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "plugin/simbody/id_engine.hpp"
#include "converter/build/inertia_fallback.hpp"
#include "plugin/simbody/simbody_options.hpp"
#include "validation/simbody_cross_check.hpp"

namespace redmax::cli {
namespace {


osim::IdToolSettings parseSettings(const Args& a) {
  if (!a.positionals().empty())
    throw UsageError{"id takes no positional arguments (got '" + a.positionals().front() + "')"};
  osim::IdToolSettings s;
  s.setup_file = a.get("setup", "");
  if (s.setup_file.empty() && (!a.has("model") || !a.has("coordinates")))
    throw UsageError{"id needs --setup ID_SETUP.xml, or --model M.osim and --coordinates Q.mot"};
  if (auto v = a.get("model")) s.model_file = *v;
  if (auto v = a.get("coordinates")) s.coordinates_file = *v;
  if (auto v = a.get("external-loads")) s.external_loads_file = *v;
  if (auto v = a.get("out")) s.output_file = *v;
  if (a.has("lowpass")) s.lowpass_cutoff_hz = a.getDouble("lowpass", -1.0);
  if (a.has("t0")) s.t0 = a.getDouble("t0", 0.0);
  if (a.has("t1")) s.t1 = a.getDouble("t1", 0.0);
  if (s.t0 && s.t1 && *s.t0 > *s.t1) throw UsageError{"--t0 is after --t1"};
  if (auto v = a.get("forces-to-exclude")) s.forces_to_exclude = splitList(*v, ", \t");
  if (a.has("exact") && a.has("opensim-compat"))
    throw UsageError{"--exact and --opensim-compat exclude each other"};
  s.opensim_compat = !a.has("exact");
  s.muscle_mass = parseMuscleMassFlags(a);
  return s;
}

int runId(const std::vector<std::string>& argv) {
  const Args a(argv,
               withMuscleMassFlags({"setup", "model", "coordinates", "external-loads", "lowpass", "t0",
                                    "t1", "engine", "out", "forces-to-exclude"}),
               {"exact", "opensim-compat", "quiet", "full-precision", "inertia-fallback"});
  const osim::IdToolSettings settings = parseSettings(a);
  const std::string engine_name = a.get("engine", "core");
  if (engine_name != "core" && engine_name != "simbody")
    throw UsageError{"--engine must be core or simbody, got '" + engine_name + "'"};
  const bool with_mass = settings.muscle_mass.source != osim::MuscleMassOptions::Source::None;
  const bool quiet = a.has("quiet");

  std::unique_ptr<osim::InverseDynamicsTool> tool;
  std::unique_ptr<osim::IdEngine> engine;
  std::string out_path;
  try {
    const osim::IdToolConfig config = osim::resolveIdSettings(settings);
    if (config.output_file.empty())
      throw UsageError{"no output file: give --out OUT.sto (or a setup with output_gen_force_file)"};
    out_path = config.output_file;
    tool = std::make_unique<osim::InverseDynamicsTool>(config);
    for (const auto& w : tool->warnings()) std::cerr << "warning: " << w << "\n";
    if (with_mass && !quiet) std::cerr << osim::describeMuscleMass(tool->muscleMassPlan());
    if (engine_name == "core") {
      if (a.has("inertia-fallback")) {
        // the model --engine simbody solves where Debian's Simbody rejects an inertia
        Model model = tool->model();
        for (const auto& b : osim::applyOpenSimInertiaFallback(model))
          std::cerr << "warning: body '" << b << "': inertia replaced by OpenSim's isotropic fallback (--inertia-fallback)\n";
        engine = std::make_unique<osim::CoreIdEngine>(model, tool->muscles(), tool->engineOptions());
      } else {
        engine = std::make_unique<osim::CoreIdEngine>(tool->model(), tool->muscles(), tool->engineOptions());
      }
    } else {
      try {
        // muscles with mass points: their inertia through plugin/simbody/muscle_inertia.hpp; an
        // inertia Debian's Simbody (a checking build) rejects gets OpenSim's isotropic fallback, as
        // OpenSim does when its Simbody checks
        validation::SimbodyCrossCheckEngine built =
            validation::makeSimbodyCrossCheckEngine(tool->model(), tool->muscles(), tool->engineOptions());
        if (built.usedFallback())
          std::cerr << "warning: Simbody rejects the inertia of " << built.replacedBodies() << " (" << built.rejection
                    << "): --engine simbody uses OpenSim's isotropic fallback for them (--engine core "
                       "--inertia-fallback solves the same model)\n";
        engine = std::move(built.engine);
      } catch (const simbody::SimbodyBuildError& e) {
        throw osim::ConvertError(config.model_file, 0,
                                 std::string("--engine simbody cannot build this model: ") + e.what());
      } catch (const ModelError& e) {
        // e.g. a wrapping muscle shape Simbody's muscle inertia does not take (muscle_mass_flags.hpp)
        throw osim::ConvertError(config.model_file, 0,
                                 std::string("--engine simbody: ") + e.what() +
                                     (with_mass ? " (--wrap lumped keeps wrapping muscles massless)" : ""));
      }
    }
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const osim::IdEngineError& e) {
    std::cerr << "error: " << settings.model_file.value_or(settings.setup_file) << ": " << e.what() << "\n";
    return 2;
  }

  // solve, with progress on stderr for long trials (at most once a second)
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto last = start;
  bool printed = false;
  auto progress = [&](int done, int total) {
    if (quiet) return;
    const auto now = Clock::now();
    if (now - last < std::chrono::seconds(1) && done < total) return;
    if (done == total && !printed) return;
    last = now;
    printed = true;
    std::fprintf(stderr, "id: frame %d/%d (%.0f%%)\n", done, total, 100.0 * done / total);
  };
  osim::Storage result;
  try {
    result = tool->run(*engine, progress);
  } catch (const osim::IdEngineError& e) {
    std::cerr << "error: " << tool->config().coordinates_file << ": " << e.what() << "\n";
    return 1;
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();

  // written atomically; OpenSim creates the results directory, so do we
  try {
    const std::filesystem::path parent = std::filesystem::path(out_path).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    osim::StorageWriteOptions wo;
    if (a.has("full-precision")) {
      wo.scientific = true;
      wo.decimals = 16;
    }
    osim::writeStorage(out_path, result, wo);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (!quiet) {
    const int n = result.numRows();
    std::printf("id: %d frames, %d coordinates, %.4f s wall, %.0f frames/s (engine %s, %s) -> %s\n", n,
                result.numColumns(), wall, wall > 0 ? n / wall : 0.0, engine->name().c_str(),
                tool->config().opensim_compat ? "opensim-compat" : "exact", out_path.c_str());
  }
  return 0;
}

CommandRegistration reg(
    {"id", "inverse dynamics as OpenSim's InverseDynamicsTool computes it",
     std::string("usage: redmax id (--setup ID_SETUP.xml | --model M.osim --coordinates Q.mot)\n"
     "                 [--external-loads LOADS.xml] [--lowpass HZ] [--t0 S] [--t1 S]\n"
     "                 [--forces-to-exclude LIST] [--engine core|simbody] [--exact]\n"
     "                 [--inertia-fallback] [--full-precision] [--quiet] [MUSCLE-MASS OPTIONS]\n"
     "                 --out OUT.sto\n"
     "Computes the generalized forces of a motion, processing the inputs as OpenSim 4.x's\n"
     "InverseDynamicsTool does: coordinates in degrees converted for Rotational coordinates only;\n"
     "with a cutoff >= 0, padding, resampling to the smallest time step and the zero-phase\n"
     "Butterworth low-pass; quintic natural splines giving q, qdot and qddot; coordinates absent\n"
     "from the file held at their defaults; external loads interpolated (natural cubic) and applied\n"
     "at the current poses; gravity from the model; constraints ignored; muscle forces excluded\n"
     "(with muscle mass, the muscles' inertia is included, by either engine).\n"
     "  --setup FILE         an InverseDynamicsTool setup (paths relative to it); flags override it\n"
     "  --model, --coordinates, --external-loads FILE\n"
     "  --lowpass HZ         cutoff for the coordinates (< 0: no filtering; setup default -1)\n"
     "  --t0 S, --t1 S       time range; output rows are the processed samples from the last at or\n"
     "                       before t0 to the last at or before t1 (as OpenSim)\n"
     "  --forces-to-exclude LIST  comma-separated: All, Actuators, Muscles, group or force names\n"
     "                       (default without a setup: Muscles). Forces OpenSim would still apply\n"
     "                       and redmax does not model are listed as warnings\n"
     "  --engine core|simbody  the REDMAX core (default) or the Simbody system built from the same\n"
     "                       core model; both get identical inputs. A body inertia Debian's Simbody\n"
     "                       rejects (e.g. gait2392's toes) gets OpenSim's isotropic fallback in\n"
     "                       Simbody, with a warning naming the bodies\n"
     "  --inertia-fallback   core: apply that same fallback (to compare the engines on one model)\n"
     "  --exact              exact kinematics instead of OpenSim compatibility (the default,\n"
     "                       --opensim-compat): by default CustomJoints use Simbody's approximate\n"
     "                       velocity terms and Ball/Free/Ellipsoid joints read the data's Euler-angle\n"
     "                       rates as angular velocity in the parent frame, as OpenSim does; with\n"
     "                       --exact every column is the force conjugate to its coordinate's rate\n"
     "  --out FILE           output .sto (default: the setup's results_directory/output_gen_force_file)\n"
     "  --full-precision     write %.16e instead of OpenSim's %16.8lf\n"
     "  --quiet              no progress and no summary line\n"
     "Output: 'Inverse Dynamics Generalized Forces', version=1, inDegrees=no; time, then\n"
     "<coord>_moment (Rotational) or <coord>_force columns in OpenSim's q order; written atomically.\n"
     "Prints a summary line (frames, wall time, frames per second) and, for long trials, progress on\n"
     "stderr. Exit codes: 0 success, 1 a frame could not be solved, 2 bad input or usage.\n") +
         muscleMassUsage(),
     runId});

}  // namespace
}  // namespace redmax::cli
