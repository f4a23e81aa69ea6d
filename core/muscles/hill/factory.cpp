#include "core/muscles/hill/factory.hpp"

#include "core/muscles/hill/degroote_fregly2016_muscle.hpp"
#include "core/muscles/hill/millard2012_equilibrium_muscle.hpp"
#include "core/muscles/hill/rigid_tendon_muscle.hpp"
#include "core/muscles/hill/thelen2003_muscle.hpp"

namespace redmax::hill {

const std::vector<std::string>& muscleModelClasses() {
  static const std::vector<std::string> names = {"Thelen2003Muscle", "Thelen2003Muscle_Deprecated",
                                                 "Millard2012EquilibriumMuscle", "DeGrooteFregly2016Muscle",
                                                 "RigidTendonMuscle", "Schutte1993Muscle_Deprecated"};
  return names;
}

bool isOpenSimMuscleClass(const std::string& cls) {
  static const std::vector<std::string> all = {
      "Thelen2003Muscle",         "Thelen2003Muscle_Deprecated",   "Millard2012EquilibriumMuscle",
      "Millard2012AccelerationMuscle", "DeGrooteFregly2016Muscle", "RigidTendonMuscle",
      "Schutte1993Muscle_Deprecated",  "Delp1990Muscle_Deprecated"};
  for (const auto& c : all)
    if (c == cls) return true;
  return false;
}

std::shared_ptr<const MuscleModel> makeMuscleModel(const std::string& cls, const MuscleParameters& p) {
  if (cls == "Thelen2003Muscle") return std::make_shared<Thelen2003Muscle>(p);
  if (cls == "Thelen2003Muscle_Deprecated") return std::make_shared<Thelen2003MuscleDeprecated>(p);
  if (cls == "Millard2012EquilibriumMuscle") return std::make_shared<Millard2012EquilibriumMuscle>(p);
  if (cls == "DeGrooteFregly2016Muscle") return std::make_shared<DeGrooteFregly2016Muscle>(p);
  if (cls == "RigidTendonMuscle") return std::make_shared<RigidTendonMuscle>(p);
  if (cls == "Schutte1993Muscle_Deprecated") return std::make_shared<Schutte1993MuscleDeprecated>(p);
  std::string known;
  for (const auto& c : muscleModelClasses()) known += (known.empty() ? "" : ", ") + c;
  throw MuscleModelError("muscle '" + p.name + "': no muscle model for class '" + cls + "' (modelled: " +
                         known + ")");
}

}  // namespace redmax::hill
