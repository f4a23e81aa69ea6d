#pragma once
// OpenSim's fallback for an invalid body inertia (docs/opensim_compatibility.md §2: OpenSim's
// Body::getInertia). When SimTK::Inertia rejects the tensor about the centre of mass (negative
// moment, broken triangle inequality, a product larger than half a moment), OpenSim replaces it by
// an isotropic tensor diag = |(Ixx, Iyy, Izz)| / sqrt(3) with zero products. Only builds of
// Simbody that check (not NDEBUG) reject such tensors; release builds of OpenSim keep the values.
// Debian's Simbody checks, so a model like gait2392 (toes_r/l break the triangle inequality) can
// only be built in Simbody after this replacement: the engine cross-check then applies it to both
// engines, while the comparison with OpenSim's own results uses the values as given.
#include <string>
#include <vector>

#include "core/model/musculoskeletal_model.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::osim {

/// Simbody's test (SimTK::Inertia::isValidInertiaMatrix) of an inertia about the centre of mass,
/// body axes: finite, moments >= 0, triangle inequality, |2 I_yz| <= I_xx (and cyclic), with
/// Simbody's slop max(trace, 1) * eps^(7/8).
bool isValidInertia(const Mat3& I_com);

/// The isotropic replacement of an invalid tensor (diag = |(Ixx, Iyy, Izz)| / sqrt(3)).
Mat3 openSimFallbackInertia(const Mat3& I_com);

/// Replace every invalid body inertia of `model` (bodies with mass) by OpenSim's fallback and
/// update the body's spatial inertia. Returns the names of the bodies that changed.
std::vector<std::string> applyOpenSimInertiaFallback(Model& model);
/// The same on the skeleton of a musculoskeletal model (its builder re-validates the muscles).
std::vector<std::string> applyOpenSimInertiaFallback(MusculoskeletalModel& model);

}  // namespace redmax::osim
