// `redmax simulate`: forward simulation of an OpenSim model in the REDMAX core (docs/commands.md §1).
// The driver is validation/simulate (a library, so that studies call the same code); this file
// parses flags, prints the summary and writes the states atomically. Exit codes: 0 success,
// 1 the run diverged (nothing written), 2 bad input or usage.
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "cli/simulate_simbody.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "validation/report/progress.hpp"
#include "validation/simulate/simulate.hpp"

namespace redmax::cli {
namespace {


// --muscle-mass-kg NAME=KG,NAME=KG
std::vector<std::pair<std::string, double>> parseMassList(const std::string& text) {
  std::vector<std::pair<std::string, double>> out;
  for (const std::string& item : splitList(text, ",")) {
    const auto eq = item.find('=');
    double kg = 0.0;
    bool ok = eq != std::string::npos && eq > 0;
    if (ok) {
      try {
        size_t used = 0;
        kg = std::stod(item.substr(eq + 1), &used);
        ok = used == item.size() - eq - 1 && std::isfinite(kg) && kg >= 0.0;
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok) throw UsageError{"--muscle-mass-kg expects NAME=KG[,NAME=KG...] with KG >= 0, got '" + item + "'"};
    out.push_back({item.substr(0, eq), kg});
  }
  if (out.empty()) throw UsageError{"--muscle-mass-kg expects NAME=KG[,NAME=KG...]"};
  return out;
}

// the value flags: simulate's own, the muscle-mass ones and the Simbody engine's (simulate_simbody.hpp)
std::set<std::string> simulateFlags() {
  std::set<std::string> names = withMuscleMassFlags({"model", "duration", "integrator", "dt", "rtol", "atol",
                                                     "max-step", "initial", "initial-time", "wrap", "output-dt", "out",
                                                     "muscle-mass-kg", "impulse", "engine"});
  for (const std::string& n : simbodyEngineFlagNames()) names.insert(n);
  return names;
}

int runSimulate(const std::vector<std::string>& argv) {
  const Args a(argv, simulateFlags(), {"no-qvv", "progress", "quiet", "full-precision"});
  if (!a.positionals().empty())
    throw UsageError{"simulate takes no positional arguments (got '" + a.positionals().front() + "')"};
  if (!a.has("model")) throw UsageError{"simulate needs --model M.osim"};
  if (!a.has("duration")) throw UsageError{"simulate needs --duration S"};
  if (!a.has("out")) throw UsageError{"simulate needs --out STATES.sto"};
  const std::string model_path = *a.get("model"), out_path = *a.get("out");
  const std::string engine = a.get("engine", "core");
  if (engine != "core" && engine != "simbody") throw UsageError{"--engine must be core or simbody, got '" + engine + "'"};
  const SimbodyEngineFlags simbody_flags = parseSimbodyEngineFlags(a, engine);

  validation::SimulateOptions so;
  so.duration = a.getDouble("duration", 0.0);
  if (!(so.duration > 0.0)) throw UsageError{"--duration must be positive"};
  so.integrator = a.get("integrator", "rk45");
  IntegratorOptions& io = so.integrator_options;
  io.dt = a.getDouble("dt", 1e-3);
  io.rtol = a.getDouble("rtol", 1e-6);
  io.atol = a.getDouble("atol", 1e-8);
  io.max_step = a.getDouble("max-step", 0.0);
  if (!(io.dt > 0.0)) throw UsageError{"--dt must be positive"};
  if (!(io.rtol > 0.0) || !(io.atol > 0.0)) throw UsageError{"--rtol and --atol must be positive"};
  if (io.max_step < 0.0) throw UsageError{"--max-step must not be negative"};
  so.output_dt = a.getDouble("output-dt", 0.0);
  if (a.has("output-dt") && !(so.output_dt > 0.0)) throw UsageError{"--output-dt must be positive"};
  {
    const auto names = {"euler", "symplectic", "bdf1", "sdirk2", "rk45", "cvode"};
    bool known = false;
    for (const char* n : names) known = known || so.integrator == n;
    if (!known)
      throw UsageError{"--integrator must be euler, symplectic, bdf1, sdirk2, rk45 or cvode, got '" +
                       so.integrator + "'"};
  }
  // --wrap and friends (muscle_mass_flags.hpp) choose how wrapping muscles with mass move; with no
  // mass at all they would do nothing
  if (hasWrapFlags(a) && !a.has("muscle-mass-kg") && a.get("muscle-mass", "none") == "none")
    throw UsageError{std::string("--") + (a.has("wrap") ? "wrap" : a.has("wrap-width") ? "wrap-width" : "wrap-network") +
                     " needs muscle mass (--muscle-mass physiological|transfer or --muscle-mass-kg)"};

  validation::SimulationModelOptions mo;
  mo.quadratic_velocity = !a.has("no-qvv");
  if (auto v = a.get("muscle-mass-kg")) {
    // explicit masses take the point count and region from --mass-points / --mass-region; the
    // flags that choose or size a mass source do not apply
    if (a.get("muscle-mass", "none") != "none")
      throw UsageError{"--muscle-mass-kg excludes --muscle-mass " + a.get("muscle-mass", "")};
    for (const char* f : {"muscles", "specific-tension", "muscle-density", "transfer-body", "transfer-fraction"})
      if (a.has(f)) throw UsageError{std::string("--") + f + " needs --muscle-mass physiological or transfer"};
    mo.explicit_masses = parseMassList(*v);
    parseWrapFlags(a, mo.muscle_mass);
    const long n = a.getInt("mass-points", 20);
    if (n < 1 || n > 100000) throw UsageError{"--mass-points must be between 1 and 100000"};
    mo.muscle_mass.mass_points = static_cast<int>(n);
    const std::string region = a.get("mass-region", "fibre");
    if (region == "whole") mo.muscle_mass.region = MassPointOptions::Region::WholePath;
    else if (region != "fibre" && region != "fiber") throw UsageError{"--mass-region must be fibre or whole"};
  } else {
    mo.muscle_mass = parseMuscleMassFlags(a);
  }
  if (auto v = a.get("impulse"))
    for (const std::string& item : splitList(*v, ";")) mo.impulses.push_back(validation::parseImpulse(item));
  const bool quiet = a.has("quiet");

  // model and initial state: every problem here is the user's input (exit 2)
  validation::SimulationModel model;
  State initial;
  try {
    model = validation::loadSimulationModel(model_path, mo);
    if (auto init = a.get("initial")) {
      const osim::Storage table = osim::readStorage(*init);
      initial = validation::initialStateFromStorage(model, table, *init,
                                                    a.has("initial-time") ? a.getDouble("initial-time", 0.0)
                                                                          : std::numeric_limits<double>::quiet_NaN());
    } else {
      if (a.has("initial-time")) throw UsageError{"--initial-time needs --initial STATE.sto"};
      initial = validation::defaultInitialState(model);
    }
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const ModelError& e) {
    std::cerr << "error: " << model_path << ": " << e.what() << "\n";
    return 2;
  }
  for (const auto& w : model.build.warnings) std::cerr << "warning: " << w << "\n";
  if (!quiet) {
    const Model& core = model.system->model();
    std::printf("simulate: %s, %d coordinates, %d constraint rows, %zu muscles (%.4g kg in mass points)\n",
                model.description.name.c_str(), core.nr(), model.system->numConstraintRows(),
                model.build.model.muscles().size(), model.muscle_mass);
    // where the mass went, on stderr as the other commands print it (muscle_mass_flags.hpp)
    if (!model.mass_summary.empty()) std::fprintf(stderr, "%s", model.mass_summary.c_str());
    if (model.added_mass > 0.0)
      for (const Muscle& mu : model.build.model.muscles())
        if (pathType(mu.path) == PathType::III && mu.mass_points.size() == 0)
          std::fprintf(stderr, "  muscle %s: lumped (Type III path, no mass given)\n", mu.name.c_str());
  }

  // progress: always with --progress, otherwise once a run has taken more than 2 s
  std::unique_ptr<validation::Progress> progress;
  const auto t_start = std::chrono::steady_clock::now();
  const long total_ms = std::lround(so.duration * 1000.0);
  so.on_row = [&](double t) {
    if (quiet && !a.has("progress")) return;
    if (!progress) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
      if (!a.has("progress") && wall < 2.0) return;
      validation::ProgressOptions po;
      po.log_interval_s = 5.0;
      progress = std::make_unique<validation::Progress>("simulate (ms simulated)", total_ms, po);
    }
    progress->set(std::lround((t - initial.t) * 1000.0));
  };

  // the engine: the core, or Simbody with one particle per mass point (cli/simulate_simbody.hpp)
  if (engine == "simbody") {
    const std::string why = simbodyEngineUnsupportedReason(model, so, mo.quadratic_velocity);
    if (!why.empty()) throw UsageError{why};
  }
  const std::clock_t cpu_start = std::clock();
  validation::SimulationResult res;
  if (engine == "simbody") {
    try {
      res = simulateSimbody(model, initial, so, simbody_flags);
    } catch (const std::invalid_argument& e) {
      std::cerr << "error: " << model_path << ": --engine simbody: " << e.what() << "\n";
      return 2;
    } catch (const ModelError& e) {
      std::cerr << "error: " << model_path << ": --engine simbody: " << e.what() << "\n";
      return 2;
    } catch (const std::runtime_error& e) {  // simbody::SimbodyBuildError: a model Simbody cannot take
      std::cerr << "error: " << model_path << ": --engine simbody cannot build this model: " << e.what() << "\n";
      return 2;
    }
  } else {
    res = validation::simulate(model, initial, so);
  }
  const double cpu_s = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  if (progress) progress->finish();
  if (res.failed) {
    std::cerr << "error: " << model_path << ": simulation failed: " << res.failure << "\n"
              << "(the run reached t = " << (res.states.numRows() > 0 ? res.states.time.back() : initial.t)
              << " s of " << initial.t + so.duration << " s; nothing written to " << out_path << ")\n";
    return 1;
  }

  try {
    const std::filesystem::path parent = std::filesystem::path(out_path).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    osim::StorageWriteOptions wo;
    if (a.has("full-precision")) {
      wo.scientific = true;
      wo.decimals = 16;
    }
    std::ostringstream desc;
    desc << "redmax simulate: model " << model_path << ", engine " << engine << ", integrator " << so.integrator;
    if (!simbody_flags.method.empty() || simbody_flags.infinity_norm)
      desc << " (Simbody " << (simbody_flags.method.empty() ? "default" : simbody_flags.method) << ", "
           << (simbody_flags.infinity_norm ? "inf" : "rms") << " norm)";
    if (so.integrator == "rk45" || so.integrator == "cvode")
      desc << " (rtol " << io.rtol << ", atol " << io.atol << ")";
    else
      desc << " (dt " << io.dt << " s)";
    desc << ", muscle mass " << model.muscle_mass << " kg" << (mo.quadratic_velocity ? "" : ", no muscle QVV")
         << "\n";
    wo.description = desc.str();
    osim::writeStorage(out_path, res.states, wo);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (!quiet) {
    std::printf("simulate: %g s with %s (engine %s): %ld steps, %ld rhs evaluations, %ld failed steps, %.3f s wall, "
                "%.3f s CPU; energy %.10g -> %.10g J, drift %.3e relative (%.3e J) -> %s\n",
                so.duration, (simbody_flags.method.empty() ? so.integrator : simbody_flags.method).c_str(), engine.c_str(), res.stats.steps, res.stats.rhs_evals,
                res.stats.failed_steps, res.wall_s, cpu_s, res.energy_initial, res.energy_final, res.energy_drift_rel, res.energy_drift_abs,
                out_path.c_str());
  }
  // --wrap neural: how often the smooth model stood in for the network (muscle_mass_flags.hpp)
  if (const auto& monitor = mo.muscle_mass.wrap.monitor; monitor && !quiet) {
    const std::string counts = monitor->summary();
    if (!counts.empty()) std::fprintf(stderr, "wrap network fallbacks:\n%s", counts.c_str());
  }
  return 0;
}

CommandRegistration reg(
    {"simulate", "forward simulation of an OpenSim model (states, energies)",
     "usage: redmax simulate --model M.osim --duration S --out STATES.sto\n"
     "                       [--integrator euler|symplectic|bdf1|sdirk2|rk45|cvode] [--dt S]\n"
     "                       [--rtol R] [--atol A] [--max-step S] [--output-dt S]\n"
     "                       [--initial STATE.sto [--initial-time T]]\n"
     "                       [MUSCLE-MASS OPTIONS] [--muscle-mass-kg NAME=KG,...] [--no-qvv]\n"
     "                       [--impulse TARGET:FX,FY,FZ:DURATION]\n"
     "                       [--engine core|simbody [--simbody-method M] [--simbody-norm rms|inf]]\n"
     "                       [--progress] [--quiet] [--full-precision]\n"
     "Integrates the model under gravity from its default pose (each coordinate's default_value and\n"
     "default_speed_value) with its constraints (locked, coupled and prescribed coordinates, welds).\n"
     "  --integrator NAME    euler (semi-implicit, fixed step), symplectic (variational Euler), bdf1\n"
     "                       (linearly implicit), sdirk2, rk45 (Dormand-Prince, adaptive, default), cvode\n"
     "  --dt S               fixed step (default 0.001); --rtol, --atol for rk45/cvode (1e-6, 1e-8)\n"
     "  --output-dt S        time between output rows (default 0.01, or dt if larger; fixed-step\n"
     "                       methods round it to whole steps)\n"
     "  --initial FILE       start from a states or motion file: the row at t = 0 (or the first row;\n"
     "                       --initial-time T picks another and starts there); columns named by\n"
     "                       coordinate, /jointset/J/C/value and /speed, or C_u; degrees if the header\n"
     "                       says inDegrees=yes; absent coordinates keep their defaults\n"
     "  --muscle-mass-kg NAME=KG,...  give these muscles KG each in mass points, ADDED to the model\n"
     "                       (no body gives mass; e.g. the finger's 0.2 kg flexors of [D 6.2.5]);\n"
     "                       --mass-points, --mass-region and --wrap apply; excludes --muscle-mass\n"
     "  --no-qvv             drop the muscles' quadratic velocity vector (energy experiment [D 6.2.4])\n"
     "  --impulse TARGET:FX,FY,FZ:DURATION  a force (N, ground frame) while t < DURATION (s) on a\n"
     "                       body's origin, a marker, or BODY@X,Y,Z (m, body frame); ';' separates several\n"
     "  --engine core|simbody  the REDMAX core (default) or Simbody: the skeleton rebuilt as a Simbody\n"
     "                       system, each muscle mass point a particle held on its path (a Constraint::Custom\n"
     "                       per muscle); --integrator rk45 (RungeKuttaMerson) or cvode (CPodes), --rtol is\n"
     "                       Simbody's accuracy, --atol its constraint tolerance; no core constraints,\n"
     "                       --impulse or --no-qvv; same output columns (Simbody's energies)\n"
     + std::string(simbodyEngineFlagsUsage()) +
     "  --progress           progress on stderr (otherwise shown once a run takes over 2 s)\n"
     "  --full-precision     write %.16e instead of %16.8lf (restarts from the file are then exact)\n"
     "Output: time, /jointset/<joint>/<coord>/value and .../speed for every coordinate (radians, SI),\n"
     "kinetic_energy, potential_energy, total_energy (J; gravity potential relative to the origin).\n"
     "A NaN or divergence stops the run: exit 1, the time, coordinate and step are named, and nothing\n"
     "is written. The summary gives steps, rhs evaluations, wall time and the energy drift\n"
     "max|E(t) - E(0)| relative to max(|E(0)|, max kinetic energy).\n"
     "\n" + std::string(muscleMassUsage()),
     runSimulate});

}  // namespace
}  // namespace redmax::cli
