#include "validation/simbody_cross_check.hpp"

#include "converter/build/inertia_fallback.hpp"
#include "plugin/simbody/simbody_options.hpp"

namespace redmax::validation {

std::string SimbodyCrossCheckEngine::replacedBodies() const {
  std::string s;
  for (const auto& b : replaced) s += (s.empty() ? "" : ", ") + b;
  return s;
}

SimbodyCrossCheckEngine makeSimbodyCrossCheckEngine(const MusculoskeletalModel& model,
                                                    const osim::IdEngineOptions& options) {
  SimbodyCrossCheckEngine r;
  try {
    r.engine = std::make_unique<simbody::SimbodyIdEngine>(model, options);
    return r;
  } catch (const simbody::SimbodyBuildError& e) {
    // an edit of the model through its builder (applyOpenSimInertiaFallback's aggregate overload)
    auto fallback = std::make_shared<MusculoskeletalModel>(model);
    r.replaced = osim::applyOpenSimInertiaFallback(*fallback);
    if (r.replaced.empty()) throw;  // not an inertia Simbody checks: nothing to fall back on
    r.rejection = e.what();
    r.fallback_model = fallback;
  }
  // a second rejection is a real build error: it propagates
  r.engine = std::make_unique<simbody::SimbodyIdEngine>(*r.fallback_model, options);
  return r;
}

std::string describeInertiaFallback(const SimbodyCrossCheckEngine& e) {
  if (!e.usedFallback()) return "";
  return "Simbody rejects the inertia of " + e.replacedBodies() + " (" + e.rejection +
         "); core vs simbody is compared with OpenSim's isotropic fallback inertia for them in both engines; "
         "every other comparison uses the inertia as given";
}

}  // namespace redmax::validation
