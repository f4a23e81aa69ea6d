// The trial's `redmax view` (view/view.hpp) as a report section: written into REPORT_DIR/view and
// linked from report.md, so a reader of a validate or gait-study report can look at the motion,
// the muscle paths and the mass points the numbers came from (docs/view.md).
#pragma once

#include <string>

#include "converter/build/muscle_mass.hpp"
#include "validation/report/report.hpp"
#include "view/view.hpp"

namespace redmax::validation {

struct TrialView {
  std::string model_file, motion_file;  ///< the trial's model and coordinates (or states) file
  osim::MuscleMassOptions mass;         ///< the mass points drawn
  std::string mass_note;                ///< how the report names that mass ("no muscle mass", ...)
};

/// Writes report_dir/view and adds a "View" section to `report`. Throws ReportError naming the
/// folder when the model, the motion or the folder cannot be read or written.
void addTrialView(Report& report, const std::string& report_dir, const TrialView& trial,
                  const view::ViewAssets& assets);

}  // namespace redmax::validation
