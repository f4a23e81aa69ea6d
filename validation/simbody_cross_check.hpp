#pragma once
// The Simbody engine of the engine cross-checks (core vs Simbody, with or without muscle mass),
// built the way OpenSim builds a model when its Simbody checks inertias: Debian's Simbody (a
// checking build) rejects body inertias that OpenSim's release builds keep (gait2392's toes break
// the triangle inequality), and OpenSim's Body::getInertia then substitutes an isotropic tensor
// (converter/build/inertia_fallback.hpp). A cross-check is only meaningful on one model, so when
// the fallback was needed the core must solve that same model again: `model` says which one.
#include <memory>
#include <string>
#include <vector>

#include "converter/id/id_engine.hpp"
#include "core/model/musculoskeletal_model.hpp"
#include "plugin/simbody/id_engine.hpp"

namespace redmax::validation {

/// A Simbody engine and the model it was built from.
struct SimbodyCrossCheckEngine {
  std::unique_ptr<simbody::SimbodyIdEngine> engine;
  /// bodies whose inertia got OpenSim's fallback (empty: the model as given)
  std::vector<std::string> replaced;
  /// the model with the fallback inertias (only when `replaced` is not empty; the core must solve
  /// this one for the comparison)
  std::shared_ptr<const MusculoskeletalModel> fallback_model;
  /// Simbody's complaint about the model as given (when `replaced` is not empty)
  std::string rejection;

  bool usedFallback() const { return !replaced.empty(); }
  /// "toes_r, toes_l"
  std::string replacedBodies() const;
};

/// Builds SimbodyIdEngine(model, options); when Simbody rejects the model (SimbodyBuildError) and
/// OpenSim's fallback changes some body inertia, builds it on an edit of the model with the
/// fallback. Rethrows the build error when the fallback changes nothing (a different problem), and
/// ModelError for muscles that do not fit.
SimbodyCrossCheckEngine makeSimbodyCrossCheckEngine(const MusculoskeletalModel& model,
                                                    const osim::IdEngineOptions& options);

/// The warning that says so: "Simbody rejects the inertia of toes_r (...); core vs simbody is
/// compared with OpenSim's isotropic fallback inertia for them in both engines"
std::string describeInertiaFallback(const SimbodyCrossCheckEngine& e);

}  // namespace redmax::validation
