#include "core/model/musculoskeletal_model.hpp"

#include <algorithm>

#include "core/muscles/hill/factory.hpp"

namespace redmax {

int MusculoskeletalModel::findMuscle(const std::string& name) const {
  for (int k = 0; k < numMuscles(); ++k)
    if (muscles_[k].name == name) return k;
  return -1;
}

double MusculoskeletalModel::muscleMass() const {
  double m = 0.0;
  for (const Muscle& mu : muscles_) m += mu.mass_points.totalMass();
  return m;
}

System MusculoskeletalModel::makeSystem(bool muscle_inertia) const {
  System sys(skeleton_);
  for (const auto& c : constraints_) sys.addConstraint(c);
  if (coordinate_map_) sys.setCoordinateMap(coordinate_map_);
  for (const auto& f : force_elements_) sys.addTerm(f);
  const bool massive = std::any_of(muscles_.begin(), muscles_.end(),
                                   [](const Muscle& m) { return m.mass_points.size() > 0; });
  if (muscle_inertia && massive)
    sys.addTerm(std::make_shared<MuscleTerm>(skeleton_, muscles_, settings_.muscle_term));
  return sys;
}

MusculoskeletalModelBuilder::MusculoskeletalModelBuilder(const Model& skeleton) : skeleton_(skeleton) {}

MusculoskeletalModelBuilder::MusculoskeletalModelBuilder(const MusculoskeletalModel& model)
    : skeleton_(model.skeleton_),
      muscles_(model.muscles_),
      muscle_classes_(model.muscle_classes_),
      muscle_models_(model.muscle_models_),
      muscle_parameters_(model.muscle_parameters_),
      constraints_(model.constraints_),
      coordinate_map_(model.coordinate_map_),
      force_elements_(model.force_elements_),
      settings_(model.settings_) {}

int MusculoskeletalModelBuilder::addMuscle(Muscle muscle, std::string opensim_class) {
  muscles_.push_back(std::move(muscle));
  muscle_classes_.push_back(std::move(opensim_class));
  muscle_models_.push_back(nullptr);
  muscle_parameters_.push_back(nullptr);
  return numMuscles() - 1;
}

namespace {
bool modelled(const std::string& cls) {
  const auto& known = hill::muscleModelClasses();
  return std::find(known.begin(), known.end(), cls) != known.end();
}
}  // namespace

int MusculoskeletalModelBuilder::addMuscle(Muscle muscle, std::string opensim_class,
                                           hill::MuscleParameters parameters) {
  if (parameters.name.empty()) parameters.name = muscle.name;
  auto model = modelled(opensim_class) ? hill::makeMuscleModel(opensim_class, parameters) : nullptr;
  const int k = addMuscle(std::move(muscle), std::move(opensim_class));
  muscle_models_[k] = std::move(model);
  muscle_parameters_[k] = std::make_shared<const hill::MuscleParameters>(std::move(parameters));
  return k;
}

Muscle& MusculoskeletalModelBuilder::muscle(int k) {
  if (k < 0 || k >= numMuscles()) throw ModelError("no muscle " + std::to_string(k));
  return muscles_[k];
}

void MusculoskeletalModelBuilder::setMuscleMassPoints(int k, MassPoints points) {
  muscle(k).mass_points = std::move(points);
}

void MusculoskeletalModelBuilder::overrideMuscleClass(const std::string& opensim_class) {
  // every model first, so that a refused property leaves the builder as it was
  std::vector<std::shared_ptr<const hill::MuscleModel>> models(muscle_models_.size());
  for (size_t k = 0; k < muscle_parameters_.size(); ++k)
    if (muscle_parameters_[k]) models[k] = hill::makeMuscleModel(opensim_class, *muscle_parameters_[k]);
  muscle_models_ = std::move(models);
  // muscles only: a PathSpring or PathActuator keeps its class
  for (size_t k = 0; k < muscle_classes_.size(); ++k)
    if (muscle_parameters_[k] || hill::isOpenSimMuscleClass(muscle_classes_[k])) muscle_classes_[k] = opensim_class;
}

void MusculoskeletalModelBuilder::addConstraint(std::shared_ptr<const Constraint> c) {
  if (!c) throw ModelError("addConstraint: null constraint");
  constraints_.push_back(std::move(c));
}

void MusculoskeletalModelBuilder::setCoordinateMap(std::shared_ptr<const CoordinateMap> map) {
  coordinate_map_ = std::move(map);
}

void MusculoskeletalModelBuilder::addForceElement(std::shared_ptr<const ForceTerm> term) {
  if (!term) throw ModelError("addForceElement: null force element");
  force_elements_.push_back(std::move(term));
}

MusculoskeletalModel MusculoskeletalModelBuilder::finalize() const {
  MusculoskeletalModel m;
  m.skeleton_ = skeleton_.finalize();
  for (const Muscle& mu : muscles_) validateMuscle(m.skeleton_, mu);
  if (coordinate_map_ && coordinate_map_->nr() != m.skeleton_.nr())
    throw ModelError("coordinate map for " + std::to_string(coordinate_map_->nr()) +
                     " coordinates on a skeleton with " + std::to_string(m.skeleton_.nr()));
  m.muscles_ = muscles_;
  m.muscle_classes_ = muscle_classes_;
  m.muscle_models_ = muscle_models_;
  m.muscle_parameters_ = muscle_parameters_;
  m.constraints_ = constraints_;
  m.coordinate_map_ = coordinate_map_;
  m.force_elements_ = force_elements_;
  m.settings_ = settings_;
  return m;
}

}  // namespace redmax
