// `redmax bench`: core vs Simbody speed on built-in scenes, as a table of ratios
// (plugin/simbody/speed_comparison.hpp does the work; this file parses flags and prints).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "converter/error.hpp"
#include "plugin/simbody/speed_comparison.hpp"
#include "validation/id_speed.hpp"
#include "validation/scenes/humanoid.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax::cli {
namespace {

const char* kScenes = "chain5, chain10, chain20, chain40, chain<N> (1 <= N <= 200), humanoid, all";

// scene by name; UsageError for anything else
Model makeScene(const std::string& name) {
  if (name == "humanoid") return scenes::humanoid();
  if (name.rfind("chain", 0) == 0 && name.size() > 5) {
    const std::string digits = name.substr(5);
    if (digits.find_first_not_of("0123456789") == std::string::npos && digits.size() <= 3) {
      const int n = std::stoi(digits);
      if (n >= 1 && n <= 200) return scenes::limbChain(n);
    }
  }
  throw UsageError{"unknown scene '" + name + "' (expected " + kScenes + ")"};
}


int runBench(const std::vector<std::string>& argv) {
  Args a(argv, {"scene", "repeats", "batches", "json", "integrators", "spherical", "dt", "id-setup", "id-model"}, {});
  if (!a.positionals().empty()) throw UsageError{"unexpected argument '" + a.positionals()[0] + "'"};
  const long repeats = a.getInt("repeats", 200);
  const long batches = a.getInt("batches", 5);
  if (repeats < 1 || repeats > 100000000) throw UsageError{"--repeats must be between 1 and 1e8"};
  if (batches < 1 || batches > 1000) throw UsageError{"--batches must be between 1 and 1000"};

  // inverse dynamics on a real trial, both engines (validation/id_speed.hpp)
  if (a.has("id-model") && !a.has("id-setup")) throw UsageError{"--id-model needs --id-setup"};
  if (auto setup = a.get("id-setup")) {
    validation::IdSpeedOptions o;
    o.settings.setup_file = *setup;
    if (auto m = a.get("id-model")) o.settings.model_file = *m;
    o.batches = static_cast<int>(batches);
    try {
      std::cout << validation::formatIdSpeed(validation::timeIdEngines(o));
    } catch (const osim::ConvertError& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
    if (!a.has("scene")) return 0;
  }

  simbody::SpeedOptions opt;
  opt.dt = a.getDouble("dt", 1e-3);
  if (!(opt.dt > 0.0)) throw UsageError{"--dt must be positive"};
  const std::string sph = a.get("spherical", "gimbal");
  if (sph == "gimbal") opt.spherical = simbody::SphericalAs::Gimbal;
  else if (sph == "ball") opt.spherical = simbody::SphericalAs::Ball;
  else throw UsageError{"--spherical expects gimbal or ball, got '" + sph + "'"};
  if (auto list = a.get("integrators")) {
    opt.integrators = splitList(*list);
    if (*list == "none") opt.integrators.clear();
    for (const auto& name : opt.integrators)
      if (name != "euler" && name != "bdf1" && name != "sdirk2" && name != "rk45" && name != "cvode")
        throw UsageError{"unknown integrator '" + name + "' in --integrators (expected euler, bdf1, sdirk2, rk45, cvode or none)"};
  }

  // scenes first, so that bad names fail before any timing
  const std::string scene_arg = a.get("scene", "all");
  std::vector<std::string> names = scene_arg == "all"
      ? std::vector<std::string>{"chain5", "chain10", "chain20", "chain40", "humanoid"}
      : splitList(scene_arg);
  if (names.empty()) throw UsageError{"--scene is empty (expected " + std::string(kScenes) + ")"};
  std::vector<std::pair<std::string, Model>> models;
  for (const auto& n : names) models.emplace_back(n, makeScene(n));

  // the output folder must exist before minutes of timing are spent
  const auto json = a.get("json");
  if (json) {
    const auto parent = std::filesystem::path(*json).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent))
      throw UsageError{*json + ": folder '" + parent.string() + "' does not exist"};
  }

  std::vector<simbody::SpeedRow> rows;
  for (const auto& [name, model] : models) {
    simbody::SpeedComparison cmp(name, model, opt);
    for (const auto& why : cmp.skipped()) std::cerr << "note: " << name << ": integrator skipped: " << why << "\n";
    auto r = simbody::timeSpeedComparison(cmp, static_cast<int>(repeats), static_cast<int>(batches));
    rows.insert(rows.end(), r.begin(), r.end());
  }
  std::cout << "redmax vs Simbody, CPU microseconds per call (fastest of " << batches << " batches of "
            << repeats << "), 1 thread; ratio = redmax / Simbody\n"
            << simbody::formatSpeedTable(rows);
  if (json) {
    simbody::writeSpeedJson(rows, *json);
    std::cout << "wrote " << *json << "\n";
  }
  return 0;
}

CommandRegistration reg(
    {"bench", "time the core against Simbody on built-in scenes (ratios)",
     "usage: redmax bench [--scene NAME[,NAME...]|all] [--repeats N] [--batches B] [--json OUT]\n"
     "                    [--integrators LIST|none] [--spherical gimbal|ball] [--dt S]\n"
     "       redmax bench --id-setup ID_SETUP.xml [--id-model M.osim] [--batches B] [--scene ...]\n"
     "Times, on the same tree and state, each core operation next to Simbody's equivalent:\n"
     "  kinematics        calcKinematics                     vs realize(Velocity)\n"
     "  mass_matrix       calcSkeletonMass                   vs calcM\n"
     "  id_redmax         System::inverseDynamics            vs realize(Dynamics) + calcResidualForceIgnoringConstraints\n"
     "  id_recursive      inverseDynamicsRecursive           vs the same Simbody call\n"
     "  forward_dynamics  System::forwardDynamics            vs realize(Acceleration)\n"
     "  step_<name>       one step of dt with a core integrator vs its closest Simbody integrator\n"
     "                    (euler, bdf1: SemiExplicitEuler; sdirk2: SemiExplicitEuler2; rk45: RungeKuttaMerson;\n"
     "                    cvode: CPodes; adaptive ones at accuracy 1e-6)\n"
     "and prints: scene, DoF, operation, redmax us, Simbody us, ratio (redmax / Simbody).\n"
     "  --scene       chain<N>: serial chain of N hinges (scenes::limbChain), e.g. chain5, chain40;\n"
     "                humanoid (37 DoF tree); all (default) = chain5,chain10,chain20,chain40,humanoid\n"
     "  --repeats     calls per timed batch (default 200); the fastest of --batches (default 5) is kept\n"
     "  --json OUT    also write the rows as JSON (atomically: temporary file, then rename)\n"
     "  --integrators comma-separated subset of euler,bdf1,sdirk2,rk45,cvode (default all), or none\n"
     "  --spherical   map spherical joints to Simbody Gimbal (u = qdot, default) or Ball (Euler angles)\n"
     "  --dt          integrator step / reporting interval in seconds (default 0.001)\n"
     "  --id-setup    time inverse dynamics on a real trial instead (an InverseDynamicsTool setup;\n"
     "                --id-model overrides its model): microseconds per frame of each engine on the\n"
     "                same processed inputs (fastest of --batches passes over all frames), the ratio,\n"
     "                and the wall time of a whole `redmax id` run against its frame count. Where\n"
     "                Debian's Simbody rejects an inertia (gait2392's toes) both engines are timed\n"
     "                with OpenSim's isotropic fallback for it. Scenes run too only if --scene is given.\n"
     "Timing only: nothing here is checked for correctness (see plugin_tests for the cross-checks).\n",
     runBench});

}  // namespace
}  // namespace redmax::cli
