#include "validation/report/trial_view.hpp"

#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"

namespace redmax::validation {

void addTrialView(Report& report, const std::string& report_dir, const TrialView& trial,
                  const view::ViewAssets& assets) {
  view::ViewInput in;
  in.mass = trial.mass;
  const std::string dir = (std::filesystem::path(report_dir) / "view").string();
  view::ViewSummary vs;
  try {
    in.description = osim::readOsimModel(trial.model_file);
    in.motion_file = trial.motion_file;
    in.motion = osim::readStorage(trial.motion_file);
    vs = view::writeView(in, assets, dir);
  } catch (const std::runtime_error& e) {
    throw ReportError(dir, e.what());
  }
  std::ostringstream md;
  md << "[view/index.html](view/index.html): the model along the whole coordinates file (" << vs.frames
     << " frames), muscle paths and " << vs.mass_points << " mass points (" << trial.mass_note
     << ") in a browser opened from disk; `view/index.html#t=SECONDS` opens at a time (docs/view.md).\n";
  report.addMarkdown("View", md.str());
}

}  // namespace redmax::validation
