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

#include "cli/id_flags.hpp"
#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "plugin/simbody/id_engine.hpp"
#include "converter/build/inertia_fallback.hpp"
#include "plugin/simbody/simbody_options.hpp"
#include "validation/simbody_cross_check.hpp"

namespace redmax::cli {
namespace {


struct IdFlags {
  IdInputFlags in;
  std::string engine = "core", out;
  bool quiet = false, full_precision = false, inertia_fallback = false;
};

int runId(const IdFlags& f, const CLI::App& app) {
  osim::IdToolSettings settings = parseIdInputFlags(f.in, app, "id");
  if (given(app, "--out")) settings.output_file = f.out;
  settings.muscle_mass = parseMuscleMassFlags(f.in.muscle_mass);
  const std::string& engine_name = f.engine;
  const bool with_mass = settings.muscle_mass.source != osim::MuscleMassOptions::Source::None;
  const bool quiet = f.quiet;

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
      if (f.inertia_fallback) {
        // the model --engine simbody solves where Debian's Simbody rejects an inertia (an edit
        // through the model's builder)
        MusculoskeletalModel model = tool->musculoskeletalModel();
        for (const auto& b : osim::applyOpenSimInertiaFallback(model))
          std::cerr << "warning: body '" << b << "': inertia replaced by OpenSim's isotropic fallback (--inertia-fallback)\n";
        engine = std::make_unique<osim::CoreIdEngine>(model, tool->engineOptions());
      } else {
        engine = std::make_unique<osim::CoreIdEngine>(tool->musculoskeletalModel(), tool->engineOptions());
      }
    } else {
      try {
        // muscles with mass points: their inertia through plugin/simbody/muscle_inertia.hpp; an
        // inertia Debian's Simbody (a checking build) rejects gets OpenSim's isotropic fallback, as
        // OpenSim does when its Simbody checks
        validation::SimbodyCrossCheckEngine built =
            validation::makeSimbodyCrossCheckEngine(tool->musculoskeletalModel(), tool->engineOptions());
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
    // --wrap neural: the core's fallbacks, counted in its workspace; the monitor warns once per muscle
    if (auto* core = dynamic_cast<osim::CoreIdEngine*>(engine.get()))
      if (const auto monitor = makeWrapFallbackMonitor(f.in.muscle_mass.wrap)) core->takeWrapFallbackCounts(*monitor);
  } catch (const osim::IdEngineError& e) {
    std::cerr << "error: " << tool->config().coordinates_file << ": " << e.what() << "\n";
    return 1;
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();

  // written atomically; OpenSim creates the results directory, so do we
  try {
    osim::writeResultStorage(out_path, result, f.full_precision);
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
    {"id", "inverse dynamics as OpenSim's InverseDynamicsTool computes it", [](CLI::App& app) {
       auto f = std::make_shared<IdFlags>();
       addIdInputFlags(app, f->in);
       app.add_option("--engine", f->engine,
                      "the REDMAX core (default) or the Simbody system built from the same\n"
                      "core model; both get identical inputs. A body inertia Debian's Simbody\n"
                      "rejects (e.g. gait2392's toes) gets OpenSim's isotropic fallback in\n"
                      "Simbody, with a warning naming the bodies")
           ->type_name("core|simbody")
           ->check(oneOf({"core", "simbody"}));
       app.add_flag("--inertia-fallback", f->inertia_fallback,
                    "core: apply that same fallback (to compare the engines on one model)");
       app.add_option("--out", f->out, "output .sto (default: the setup's results_directory/output_gen_force_file)")
           ->type_name("OUT.sto");
       app.add_flag("--full-precision", f->full_precision, "write %.16e instead of OpenSim's %16.8lf");
       app.add_flag("--quiet", f->quiet, "no progress and no summary line");
       app.footer(std::string(
           "usage: redmax id (--setup ID_SETUP.xml | --model M.osim --coordinates Q.mot)\n"
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
           "Output: 'Inverse Dynamics Generalized Forces', version=1, inDegrees=no; time, then\n"
           "<coord>_moment (Rotational) or <coord>_force columns in OpenSim's q order; written atomically.\n"
           "Prints a summary line (frames, wall time, frames per second) and, for long trials, progress on\n"
           "stderr. Exit codes: 0 success, 1 a frame could not be solved, 2 bad input or usage.\n") +
           muscleMassFooter());
       return [f, &app] { return runId(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
