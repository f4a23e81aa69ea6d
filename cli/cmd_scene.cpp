// `redmax scene NAME`: the deformable-body and hybrid-dynamics scenes built in code
// (docs/deformable.md §4, §6); this file only parses and calls validation/scenes/deformable_scenes
// and validation/scenes/hybrid_scenes.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/flags.hpp"
#include "validation/scenes/deformable_scenes.hpp"
#include "validation/scenes/hybrid_scenes.hpp"

namespace redmax::cli {
namespace {

std::vector<std::string> sceneNames() {
  std::vector<std::string> v = scenes::deformableSceneNames();
  for (const auto& n : scenes::hybridSceneNames()) v.push_back(n);
  return v;
}

bool isHybrid(const std::string& name) {
  for (const auto& n : scenes::hybridSceneNames())
    if (n == name) return true;
  return false;
}

struct SceneFlags {
  std::string name;
  std::string out;
};

constexpr const char* kSummary =
    "run a deformable-body or hybrid-dynamics scene (cantilever, strand, soft-pendulum, hand, starfish)";

CommandRegistration reg({"scene", kSummary, [](CLI::App& app) {
                           auto f = std::make_shared<SceneFlags>();
                           app.add_option("name", f->name, "the scene")
                               ->required()
                               ->type_name("cantilever|strand|soft-pendulum|hand|starfish")
                               ->check(oneOf(sceneNames()));
                           app.add_option("--out", f->out, "output folder (default: ./scene-NAME)")->type_name("DIR");
                           app.footer(
                               "Runs the scene and prints its summary; writes DIR/states.csv and a VTK series\n"
                               "(DIR/NAME_NNNN.vtk per output frame, DIR/NAME.pvd for ParaView).\n"
                               "  cantilever     FEM beam under its own weight, static; prints\n"
                               "                 `tip deflection D m, beam theory B m` (Euler-Bernoulli)\n"
                               "  strand         mass-spring chain falling from a fixed end, zero damping,\n"
                               "                 symplectic Euler; prints its energy change\n"
                               "  soft-pendulum  soft FEM block on a swinging rigid link (bdf1, fully implicit\n"
                               "                 coupling) against the same block held rigid\n"
                               "  hand           arm, elbow and four fingers with DIP = 0.5 PIP (hyper-reduced\n"
                               "                 coordinates), fingertips prescribed on circles (maximal\n"
                               "                 inverse dynamics), elbow angle prescribed; prints the largest\n"
                               "                 prescribed-point and prescribed-angle errors\n"
                               "  starfish       a free disc and five arms of four hinges inside a co-rotated\n"
                               "                 FEM star (243 nodes); the disc's centre and the first joints\n"
                               "                 prescribed, the rest passive (bdf1, fully implicit); prints\n"
                               "                 steps, wall time, the prescribed-joint and -point errors,\n"
                               "                 kinetic energy and the smallest tet volume ratio");
                           return [f] {
                             const std::string out = f->out.empty() ? "scene-" + f->name : f->out;
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
