// `redmax forward`: OpenSim's ForwardTool on a setup file (docs/forward.md, docs/commands.md).
// The tool is validation/forward/forward_tool.hpp; this file parses flags, prints warnings and the
// summary. Exit codes: 0 success, 1 the run failed (nothing written), 2 bad input or usage.
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/forward_flags.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "validation/forward/forward_tool.hpp"

namespace redmax::cli {
namespace {

int runForward(const ForwardFlags& f, const CLI::App& app) {
  const validation::ForwardToolSettings s = parseForwardFlags(f, app);
  std::unique_ptr<validation::ForwardTool> tool;
  try {
    tool = std::make_unique<validation::ForwardTool>(s);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const ModelError& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 2;
  } catch (const hill::MuscleModelError& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 2;
  }
  if (!f.quiet) {
    for (const std::string& w : tool->warnings()) std::cerr << "warning: " << w << "\n";
    for (const std::string& w : tool->notApplied()) std::cerr << "warning: not applied: " << w << "\n";
  }
  validation::ForwardResult r;
  try {
    r = tool->run();
  } catch (const std::exception& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 1;
  }
  if (r.failed) {
    std::cerr << "error: " << f.setup << ": " << r.failure << "\n";
    return 1;
  }
  view::ViewSummary vs;
  try {
    vs = tool->write(r);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::runtime_error& e) {  // the view: the states and controls are written
    std::cerr << "error: " << tool->viewPath() << ": " << e.what() << "\n";
    return 1;
  }
  if (!f.quiet) {
    const auto& st = tool->setup();
    std::printf("forward: %s, t %.6g to %.6g s, %d states, %d controls, %s: %ld steps, %ld rhs, %.3f s wall\n",
                st.name.c_str(), st.initial_time, st.final_time, r.states.numColumns(), r.controls.numColumns(),
                s.integrator.c_str(), r.stats.steps, r.stats.rhs_evals, r.wall_s);
    std::printf("  -> %s\n  -> %s\n", tool->statesPath().c_str(), tool->controlsPath().c_str());
    if (vs.frames > 0)
      std::printf("  -> %s/index.html (%d frames, %d muscles, %d mass points)\n", tool->viewPath().c_str(), vs.frames,
                  vs.muscles, vs.mass_points);
  }
  return 0;
}

CommandRegistration reg(
    {"forward", "OpenSim's ForwardTool: muscle-driven forward simulation from a setup file", [](CLI::App& app) {
       auto f = std::make_shared<ForwardFlags>();
       addForwardFlags(app, *f);
       app.footer(
           "usage: redmax forward --setup FORWARD_SETUP.xml [--out-dir DIR] [--muscle-class CLASS]\n"
           "                      [--integrator NAME] [--report-interval S] [--tolerance T]\n"
           "                      [--strict] [--view] [MUSCLE-MASS OPTIONS]\n"
           "States are written under OpenSim 4 names: /jointset/J/C/value, /jointset/J/C/speed,\n"
           "/forceset/M/activation, /forceset/M/fiber_length.\n"
           "Exit codes: 0 success, 1 the run failed (nothing written; with --view: the view could\n"
           "not be written, the tables are), 2 bad input or usage.");
       return [f, &app] { return runForward(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
