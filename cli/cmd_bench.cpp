// `redmax bench`: core vs Simbody speed on built-in scenes, as a table of ratios
// (plugin/simbody/speed_comparison.hpp does the work; this file parses flags and prints).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli/flags.hpp"
#include "converter/error.hpp"
#include "plugin/simbody/speed_comparison.hpp"
#include "validation/analyze_speed.hpp"
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


struct BenchFlags {
  std::string scene = "all", json, integrators, spherical = "gimbal", id_setup, id_model, analyze_setup;
  long repeats = 200, batches = 5;
  double dt = 1e-3;
};

int runBench(const BenchFlags& f, const CLI::App& app) {
  const long repeats = f.repeats, batches = f.batches;

  // inverse dynamics on a real trial, both engines (validation/id_speed.hpp)
  if (given(app, "--id-model") && !given(app, "--id-setup")) throw UsageError{"--id-model needs --id-setup"};
  if (given(app, "--id-setup")) {
    validation::IdSpeedOptions o;
    o.settings.setup_file = f.id_setup;
    if (given(app, "--id-model")) o.settings.model_file = f.id_model;
    o.batches = static_cast<int>(batches);
    try {
      std::cout << validation::formatIdSpeed(validation::timeIdEngines(o));
    } catch (const osim::ConvertError& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
    if (!given(app, "--scene")) return 0;
  }

  // the AnalyzeTool's analyses on a setup (validation/analyze_speed.hpp)
  if (given(app, "--analyze-setup")) {
    validation::AnalyzeSpeedOptions o;
    o.settings.setup_file = f.analyze_setup;
    o.batches = static_cast<int>(batches);
    try {
      std::cout << validation::formatAnalyzeSpeed(validation::timeAnalyze(o));
    } catch (const osim::ConvertError& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
    if (!given(app, "--scene")) return 0;
  }

  simbody::SpeedOptions opt;
  opt.dt = f.dt;
  opt.spherical = f.spherical == "ball" ? simbody::SphericalAs::Ball : simbody::SphericalAs::Gimbal;
  if (given(app, "--integrators")) {
    opt.integrators = splitList(f.integrators);
    if (f.integrators == "none") opt.integrators.clear();
    for (const auto& name : opt.integrators)
      if (name != "euler" && name != "bdf1" && name != "sdirk2" && name != "rk45" && name != "cvode")
        throw UsageError{"unknown integrator '" + name + "' in --integrators (expected euler, bdf1, sdirk2, rk45, cvode or none)"};
  }

  // scenes first, so that bad names fail before any timing
  const std::string& scene_arg = f.scene;
  std::vector<std::string> names = scene_arg == "all"
      ? std::vector<std::string>{"chain5", "chain10", "chain20", "chain40", "humanoid"}
      : splitList(scene_arg);
  if (names.empty()) throw UsageError{"--scene is empty (expected " + std::string(kScenes) + ")"};
  std::vector<std::pair<std::string, Model>> models;
  for (const auto& n : names) models.emplace_back(n, makeScene(n));

  // the output folder must exist before minutes of timing are spent
  const std::string* json = given(app, "--json") ? &f.json : nullptr;
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
    {"bench", "time the core against Simbody on built-in scenes (ratios)", [](CLI::App& app) {
       auto f = std::make_shared<BenchFlags>();
       app.add_option("--scene", f->scene,
                      "chain<N>: serial chain of N hinges (scenes::limbChain), e.g. chain5, chain40;\n"
                      "humanoid (37 DoF tree); all (default) = chain5,chain10,chain20,chain40,humanoid;\n"
                      "or a comma-separated list")
           ->type_name("NAME[,NAME...]|all");
       app.add_option("--repeats", f->repeats, "calls per timed batch (default 200)")
           ->type_name("N")
           ->check(between(1, 1e8, true, "1", "1e8"));
       app.add_option("--batches", f->batches, "timed batches; the fastest is kept (default 5)")
           ->type_name("B")
           ->check(between(1, 1000, true));
       app.add_option("--json", f->json, "also write the rows as JSON (atomically: temporary file, then rename)")
           ->type_name("OUT");
       app.add_option("--integrators", f->integrators,
                      "comma-separated subset of euler,bdf1,sdirk2,rk45,cvode (default all), or none")
           ->type_name("LIST|none");
       app.add_option("--spherical", f->spherical,
                      "map spherical joints to Simbody Gimbal (u = qdot, default) or Ball (Euler angles)")
           ->type_name("gimbal|ball")
           ->check(oneOf({"gimbal", "ball"}));
       app.add_option("--dt", f->dt, "integrator step / reporting interval in seconds (default 0.001)")
           ->type_name("S")
           ->check(positive());
       app.add_option("--id-setup", f->id_setup,
                      "time inverse dynamics on a real trial instead (an InverseDynamicsTool setup):\n"
                      "microseconds per frame of each engine on the same processed inputs (fastest\n"
                      "of --batches passes over all frames), the ratio, and the wall time of a whole\n"
                      "`redmax id` run against its frame count. Where Debian's Simbody rejects an\n"
                      "inertia (gait2392's toes) both engines are timed with OpenSim's isotropic\n"
                      "fallback for it. Scenes run too only if --scene is given")
           ->type_name("ID_SETUP.xml");
       app.add_option("--id-model", f->id_model, "with --id-setup: overrides its model")->type_name("M.osim");
       app.add_option("--analyze-setup", f->analyze_setup,
                      "time `redmax analyze` on an AnalyzeTool setup instead: frames per second of its\n"
                      "StaticOptimization (without and with physiological muscle mass) and of its\n"
                      "MuscleAnalysis + Actuation, the fastest of --batches passes, the tool's setup\n"
                      "timed apart. Scenes run too only if --scene is given")
           ->type_name("ANALYZE_SETUP.xml");
       app.footer(
           "usage: redmax bench [--scene NAME[,NAME...]|all] [--repeats N] [--batches B] [--json OUT]\n"
           "                    [--integrators LIST|none] [--spherical gimbal|ball] [--dt S]\n"
           "       redmax bench --id-setup ID_SETUP.xml [--id-model M.osim] [--batches B] [--scene ...]\n"
           "       redmax bench --analyze-setup ANALYZE_SETUP.xml [--batches B] [--scene ...]\n"
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
     "Timing only: nothing here is checked for correctness (see plugin_tests for the cross-checks).");
       return [f, &app] { return runBench(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
