#pragma once
// makeMuscleModel: an OpenSim muscle class name and its XML properties -> the model.
#include <memory>
#include <string>
#include <vector>

#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill {

/// The muscle classes makeMuscleModel builds (OpenSim 4 names).
const std::vector<std::string>& muscleModelClasses();

/// Whether `opensim_class` is one of OpenSim's Muscle classes (modelled or not: Delp1990Muscle,
/// Millard2012AccelerationMuscle, ... are muscles redmax reads but does not model).
bool isOpenSimMuscleClass(const std::string& opensim_class);

/// The model of OpenSim class `opensim_class` from `parameters` (OpenSim's defaults for absent
/// properties). Throws MuscleParameterError for a value the class refuses and MuscleModelError
/// naming the supported classes for an unknown class.
std::shared_ptr<const MuscleModel> makeMuscleModel(const std::string& opensim_class,
                                                   const MuscleParameters& parameters);

}  // namespace redmax::hill
