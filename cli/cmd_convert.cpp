// `redmax convert`: read an OpenSim model, print a summary, optionally write the intermediate
// description as JSON. Errors are `error: FILE:LINE: what` with exit code 2 (docs/commands.md §1).
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/flags.hpp"
#include "converter/atomic_file.hpp"
#include "converter/json_writer.hpp"
#include "converter/osim_reader.hpp"

namespace redmax::cli {
namespace {

struct ConvertFlags {
  std::vector<std::string> models;
  std::string json;
  bool strict = false, quiet = false;
};

int runConvert(const ConvertFlags& f, const CLI::App& app) {
  if (f.models.size() != 1)
    throw UsageError{f.models.empty() ? "convert needs a MODEL.osim" : "convert takes one MODEL.osim"};
  const std::string model_path = f.models[0];
  try {
    const osim::ModelDescription d = osim::readOsimModel(model_path);
    if (f.strict && !d.unsupported.empty()) {
      // --strict: anything read but not modelled is an error; name the first, count the rest
      const auto& u = d.unsupported.front();
      std::cerr << "error: " << osim::ConvertError(model_path, u.line, "unsupported: " + u.what).what()
                << "\n";
      if (d.unsupported.size() > 1)
        std::cerr << "error: ... and " << d.unsupported.size() - 1
                  << " more unsupported items (run without --strict to list them)\n";
      return 2;
    }
    // write the JSON first: a failed write must not be preceded by a success summary
    if (given(app, "--json")) osim::writeFileAtomic(f.json, osim::describeAsJson(d));
    if (!f.quiet) std::cout << osim::formatSummary(d);
    return 0;
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

CommandRegistration reg(
    {"convert", "read an OpenSim .osim model; print a summary, optionally write JSON", [](CLI::App& app) {
       auto f = std::make_shared<ConvertFlags>();
       app.add_option("MODEL", f->models, "the OpenSim model to read (.osim)")
           ->type_name("MODEL.osim")
           ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
       app.add_option("--json", f->json,
                      "also write the intermediate description (written atomically): name,\n"
                      "osim_version, bodies, joints, coordinates (in OpenSim's multibody-tree\n"
                      "order), constraints, muscles, forces, wrap_objects, markers, tree,\n"
                      "unsupported, warnings")
           ->type_name("OUT.json");
       app.add_flag("--strict", f->strict, "treat any unsupported item as an error (exit 2)");
       app.add_flag("--quiet", f->quiet, "do not print the summary");
       app.footer(
           "usage: redmax convert MODEL.osim [--json OUT.json] [--strict] [--quiet]\n"
           "Reads an OpenSim model (file versions 10901 to 40600; legacy files are upgraded as OpenSim\n"
           "upgrades them) and prints a summary: bodies, degrees of freedom, joints by type, muscles by\n"
           "path type (I straight, II via/conditional/moving points, III wrapping), constraints, and\n"
           "the items that are read but not modelled.\n"
           "Errors are printed as `error: FILE:LINE: what` with exit code 2.");
       return [f, &app] { return runConvert(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
