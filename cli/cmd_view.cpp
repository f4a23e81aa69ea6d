// `redmax view`: a folder that shows the model, a motion, the muscle paths and mass points in a
// browser opened from disk (docs/view.md). The work is view/view.hpp; this file parses the flags,
// finds the page's files and prints the summary.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/muscle_mass_flags.hpp"
#include "converter/osim_reader.hpp"
#include "view/view.hpp"

namespace redmax::cli {
namespace {

namespace fs = std::filesystem;

struct ViewFlags {
  std::vector<std::string> models;
  std::string motion, out;
  MuscleMassFlags mass;
  bool quiet = false;
};

int runView(const ViewFlags& f, const CLI::App& app) {
  if (f.models.size() != 1)
    throw UsageError{f.models.empty() ? "view needs a MODEL.osim" : "view takes one MODEL.osim"};
  if (!given(app, "--out")) throw UsageError{"view needs --out DIR"};
  view::ViewInput in;
  in.mass = parseMuscleMassFlags(f.mass);
  view::ViewAssets assets;
  try {
    assets = view::findViewAssets(viewAssetFolders());
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  view::ViewSummary sum;
  try {
    in.description = osim::readOsimModel(f.models[0]);
    if (given(app, "--motion")) {
      in.motion_file = f.motion;
      in.motion = osim::readStorage(f.motion);
    }
    sum = view::writeView(in, assets, f.out);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {  // muscle-mass options the model refuses
    std::cerr << "error: " << f.models[0] << ": " << e.what() << "\n";
    return 2;
  } catch (const std::runtime_error& e) {
    std::cerr << "error: " << e.what() << "\n(nothing written to " << f.out << ")\n";
    return 1;
  }
  if (!f.quiet) {
    std::cerr << sum.mass_plan;
    for (const std::string& m : sum.messages) std::cerr << "note: " << m << "\n";
    std::printf("view: %d frames, %d bodies (%d meshes), %d muscles, %d mass points (%.6g kg), %.1f MB -> %s\n",
                sum.frames, sum.bodies, sum.meshes, sum.muscles, sum.mass_points, sum.muscle_mass,
                static_cast<double>(sum.bytes) / 1e6, (fs::path(f.out) / "index.html").string().c_str());
  }
  return 0;
}

CommandRegistration reg(
    {"view", "a browser view of a model, a motion, muscle paths and mass points", [](CLI::App& app) {
       auto f = std::make_shared<ViewFlags>();
       app.add_option("MODEL", f->models, "the OpenSim model (.osim)")
           ->type_name("MODEL.osim")
           ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
       app.add_option("--motion", f->motion,
                      "coordinates (.mot) or states (.sto) to play; columns named as coordinates or\n"
                      "state names, degrees converted; coordinates absent keep their defaults;\n"
                      "constraints are not enforced. Default: the default pose")
           ->type_name("Q.mot|STATES.sto");
       app.add_option("--out", f->out,
                      "the folder to write (index.html, data.js, view.js, view.css, three.min.js);\n"
                      "an earlier view there is replaced, any other content refused; required")
           ->type_name("DIR");
       app.add_flag("--quiet", f->quiet, "no summary and no notes");
       addMuscleMassFlags(app, f->mass);
       app.footer(std::string(
           "usage: redmax view MODEL.osim [--motion Q.mot|STATES.sto] [MUSCLE-MASS OPTIONS] --out DIR\n"
           "Writes a folder that a browser opens from disk (DIR/index.html; no server, no network):\n"
           "bodies (the model's .vtp/.obj/.stl meshes found beside it or in its Geometry folder, else\n"
           "ellipsoids of their inertia), joint frames, muscle paths with path, via and wrap points (the\n"
           "path as OpenSim wraps it), wrap surfaces, mass points sized by mass; a timeline that plays\n"
           "the motion; a muscle's length and mass on selection. DIR/index.html#t=SECONDS opens at that\n"
           "time. What the page cannot draw (meshes not found or not read) it says above the view.\n"
           "Exit codes: 0 success, 1 a path that cannot be evaluated at a frame, 2 bad input or usage\n"
           "(nothing is written then).\n") +
           muscleMassFooter());
       return [f, &app] { return runView(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
