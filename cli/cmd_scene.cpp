// `redmax scene NAME`: the deformable-body and hybrid-dynamics scenes built in code
// (docs/deformable.md §4, §6), the muscle-driven spline-leg scene (docs/forward.md §6) and the
// hard-contact scenes (docs/contact.md §6); this file only parses and calls
// validation/scenes/deformable_scenes, hybrid_scenes, contact_scenes and
// validation/forward/spline_leg_scene.
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/flags.hpp"
#include "validation/forward/spline_leg_scene.hpp"
#include "validation/scenes/contact_scenes.hpp"
#include "validation/scenes/deformable_scenes.hpp"
#include "validation/scenes/hybrid_scenes.hpp"

namespace redmax::cli {
namespace {

constexpr const char* kSplineLeg = "spline-leg";

std::vector<std::string> sceneNames() {
  std::vector<std::string> v = scenes::deformableSceneNames();
  for (const auto& n : scenes::hybridSceneNames()) v.push_back(n);
  v.push_back(kSplineLeg);
  for (const auto& n : scenes::contactSceneNames()) v.push_back(n);
  return v;
}

// the bundled model: ./osim_models (run from the repository) or the source tree's
std::string bundledModel(const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path here = fs::path("osim_models") / file;
  if (fs::is_regular_file(here)) return here.string();
  return (fs::path(REDMAX_SOURCE_DIR) / "osim_models" / file).string();
}

bool isContact(const std::string& name) {
  for (const auto& n : scenes::contactSceneNames())
    if (n == name) return true;
  return false;
}

bool isHybrid(const std::string& name) {
  for (const auto& n : scenes::hybridSceneNames())
    if (n == name) return true;
  return false;
}

struct SceneFlags {
  std::string name;
  std::string out;
  std::string model;
  double duration = 0.0;  // 0: the scene's own
};

constexpr const char* kSummary =
    "run a deformable-body, hybrid-dynamics, muscle-driven or hard-contact scene (cantilever, strand,\n"
    "soft-pendulum, soft-insertion, hand, starfish, spline-leg, ball-drop, block-slide, box-stack,\n"
    "limit-pendulum)";

CommandRegistration reg({"scene", kSummary, [](CLI::App& app) {
                           auto f = std::make_shared<SceneFlags>();
                           app.add_option("name", f->name, "the scene")
                               ->required()
                               ->type_name("cantilever|strand|soft-pendulum|soft-insertion|hand|starfish|spline-leg|ball-drop|\n"
                                          "block-slide|box-stack|limit-pendulum")
                               ->check(oneOf(sceneNames()));
                           app.add_option("--out", f->out, "output folder (default: ./scene-NAME)")->type_name("DIR");
                           app.add_option("--model", f->model,
                                          "spline-leg only: the model (default: osim_models/spline_leg.osim)")
                               ->type_name("FILE");
                           app.add_option("--duration", f->duration, "spline-leg only: simulated seconds (default 1.2)")
                               ->type_name("S")
                               ->check(CLI::PositiveNumber);
                           app.footer(
                               "Runs the scene and prints its summary; writes DIR/states.csv and a VTK series\n"
                               "(DIR/NAME_NNNN.vtk per output frame, DIR/NAME.pvd for ParaView).\n"
                               "  cantilever     FEM beam under its own weight, static; prints\n"
                               "                 `tip deflection D m, beam theory B m` (Euler-Bernoulli)\n"
                               "  strand         mass-spring chain falling from a fixed end, zero damping,\n"
                               "                 symplectic Euler; prints its energy change\n"
                               "  soft-pendulum  soft FEM block on a swinging rigid link (bdf1, fully implicit\n"
                               "                 coupling) against the same block held rigid\n"
                               "  soft-insertion a Thelen muscle with mass points inserting on a free node of a soft\n"
                               "                 block on a hinged link, constant excitation (bdf1), against the\n"
                               "                 same muscle inserting on the link; prints the angle difference,\n"
                               "                 the tendon forces and the insertion's displacement\n"
                               "  hand           arm, elbow and four fingers with DIP = 0.5 PIP (hyper-reduced\n"
                               "                 coordinates), fingertips prescribed on circles (maximal\n"
                               "                 inverse dynamics), elbow angle prescribed; prints the largest\n"
                               "                 prescribed-point and prescribed-angle errors\n"
                               "  starfish       a free disc and five arms of four hinges inside a co-rotated\n"
                               "                 FEM star (243 nodes); the disc's centre and the first joints\n"
                               "                 prescribed, the rest passive (bdf1, fully implicit); prints\n"
                               "                 steps, wall time, the prescribed-joint and -point errors,\n"
                               "                 kinetic energy and the smallest tet volume ratio\n"
                               "  spline-leg     the dissertation's 6.2.10 leg: spline knee, six Hill muscles\n"
                               "                 (gastrocnemii constant, soleus and tibialis anterior on an ankle\n"
                               "                 controller, rectus femoris then semimembranosus by hand), lumped\n"
                               "                 against inertial and spline against revolute knee; writes states,\n"
                               "                 muscle forces, summary.txt and plots (docs/forward.md §6)\n"
                               "Hard unilateral constraints (bdf1 with the contact QP, docs/contact.md §6); these\n"
                               "write DIR/states.csv only:\n"
                               "  ball-drop      a sphere dropped 0.5 m on the ground, restitution 0.5: bounce\n"
                               "                 apexes against e^2k h and the rest height against the radius\n"
                               "  block-slide    a box sliding at 2 m/s with mu 0.5: distance against v0^2/(2 mu g)\n"
                               "  box-stack      three boxes stacked on the ground: drift per second once settled\n"
                               "  limit-pendulum a rod released horizontally onto a joint limit at -90 deg,\n"
                               "                 restitution 0.5: kinetic energy after the stop against e^2 before");
                           return [f] {
                             const std::string out = f->out.empty() ? "scene-" + f->name : f->out;
                             if (f->name == kSplineLeg) {
                               validation::SplineLegOptions o;
                               o.model_path = f->model.empty() ? bundledModel("spline_leg.osim") : f->model;
                               o.out_dir = out;
                               if (f->duration > 0) o.duration = f->duration;
                               validation::SplineLegResult r;
                               try {
                                 r = validation::runSplineLegScene(o, std::cout);
                               } catch (const osim::ConvertError& e) {  // the model is the user's input
                                 std::cerr << "error: " << e.what() << "\n";
                                 return 2;
                               }
                               std::cout << "wrote " << r.files.size() << " files to " << out << "\n";
                               return 0;
                             }
                             if (!f->model.empty() || f->duration > 0)
                               throw UsageError{"--model and --duration are for the spline-leg scene"};
                             if (isContact(f->name)) {
                               scenes::runContactScene(f->name, out, std::cout);
                               std::cout << "wrote " << out << "/states.csv\n";
                               return 0;
                             }
                             if (isHybrid(f->name))
                               scenes::runHybridScene(f->name, out, std::cout);
                             else
                               scenes::runDeformableScene(f->name, out, std::cout);
                             std::cout << "wrote " << out << "/states.csv, " << out << "/" << f->name << ".pvd\n";
                             return 0;
                           };
                         }});

}  // namespace
}  // namespace redmax::cli
