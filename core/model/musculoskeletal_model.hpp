#pragma once
// The musculoskeletal model as one immutable aggregate (docs/design.md §4): the
// skeleton Model, its muscles, the constraints and the coordinate map that act on it, extra force
// elements (ForceTerms such as springs), and the settings that define the model. It is built once
// by a MusculoskeletalModelBuilder and read through const accessors afterwards; every edit (a
// body's mass, a muscle's mass points, a muscle-class override) goes through a builder started
// from the finished model, whose finalize() re-derives and re-validates everything.
//
// Layering: above core/dynamics (it holds Constraints, a CoordinateMap and ForceTerms), beside
// core/integrators; converter/, plugin/, validation/ and cli/ pass it instead of the
// (Model, muscles, options) triple.
#include <memory>
#include <string>
#include <vector>

#include "core/dynamics/constraint.hpp"
#include "core/dynamics/coordinate_map.hpp"
#include "core/dynamics/force_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/hill/parameters.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/skeleton/model.hpp"

namespace redmax {

/// Settings that are part of the model's definition (not of one run).
struct ModelSettings {
  /// FunctionBased (CustomJoint) joints were built with Simbody's approximate velocity terms
  /// (core/joints/function_based.hpp) rather than exact kinematics
  bool simbody_compat = false;
  /// how the muscles' mass points enter the dynamics (makeSystem(true))
  MuscleTermOptions muscle_term;
};

class MusculoskeletalModel {
 public:
  /// an empty model: no bodies, no muscles
  MusculoskeletalModel() = default;

  const Model& skeleton() const { return skeleton_; }
  /// the skeleton, so that the aggregate passes wherever skeleton-level code takes a Model
  operator const Model&() const { return skeleton_; }  // NOLINT(google-explicit-constructor)

  /// the muscles (path, fibre lengths, mass points; empty mass points = lumped)      (nmus)
  const std::vector<Muscle>& muscles() const { return muscles_; }
  /// the OpenSim class each muscle is read as ("" when unknown)                        (nmus)
  const std::vector<std::string>& muscleClasses() const { return muscle_classes_; }
  /// each muscle's force model (core/muscles/hill), null for a path force without one (a
  /// PathSpring, a muscle class redmax does not model, a muscle added without parameters)  (nmus)
  const std::vector<std::shared_ptr<const hill::MuscleModel>>& muscleModels() const { return muscle_models_; }
  /// each muscle's XML properties as read (null when it has none)                       (nmus)
  const std::vector<std::shared_ptr<const hill::MuscleParameters>>& muscleParameters() const {
    return muscle_parameters_;
  }
  /// constraints to add to a System
  const std::vector<std::shared_ptr<const Constraint>>& constraints() const { return constraints_; }
  /// hyper-reduced coordinates (null: the system's coordinates are q_r)
  const std::shared_ptr<const CoordinateMap>& coordinateMap() const { return coordinate_map_; }
  /// further force elements every System of this model carries (joint springs live in the
  /// skeleton's Coordinate, [D Eq. 4.75-4.77])
  const std::vector<std::shared_ptr<const ForceTerm>>& forceElements() const { return force_elements_; }
  const ModelSettings& settings() const { return settings_; }

  int nb() const { return skeleton_.nb(); }
  int nr() const { return skeleton_.nr(); }
  int numMuscles() const { return static_cast<int>(muscles_.size()); }
  /// index of the muscle with this name, -1 if absent
  int findMuscle(const std::string& name) const;
  /// total mass of the muscles' mass points, kg
  double muscleMass() const;

  /// A System over the skeleton with the constraints, the coordinate map and the force elements;
  /// with `muscle_inertia`, plus a MuscleTerm (settings().muscle_term) over the muscles when any
  /// of them carries mass points.
  System makeSystem(bool muscle_inertia = false) const;

 private:
  friend class MusculoskeletalModelBuilder;
  Model skeleton_;
  std::vector<Muscle> muscles_;
  std::vector<std::string> muscle_classes_;
  std::vector<std::shared_ptr<const hill::MuscleModel>> muscle_models_;
  std::vector<std::shared_ptr<const hill::MuscleParameters>> muscle_parameters_;
  std::vector<std::shared_ptr<const Constraint>> constraints_;
  std::shared_ptr<const CoordinateMap> coordinate_map_;
  std::vector<std::shared_ptr<const ForceTerm>> force_elements_;
  ModelSettings settings_;
};

/// Builds a MusculoskeletalModel, from a finished skeleton or as an edit of a finished model.
class MusculoskeletalModelBuilder {
 public:
  explicit MusculoskeletalModelBuilder(const Model& skeleton);
  /// start from a finished model: everything it holds, ready to be edited
  explicit MusculoskeletalModelBuilder(const MusculoskeletalModel& model);

  /// edits of the skeleton (mass properties, springs, gravity); finalize() re-derives it
  ModelBuilder& skeleton() { return skeleton_; }
  /// a skeleton built elsewhere replaces the current one (same tree: the muscles, constraints and
  /// coordinate map index into it)
  void setSkeleton(const Model& skeleton) { skeleton_ = ModelBuilder(skeleton); }

  /// append a muscle; `opensim_class` is the class it is read as. Returns its index.
  int addMuscle(Muscle muscle, std::string opensim_class = "");
  /// append a muscle with its XML properties: its force model is hill::makeMuscleModel(class,
  /// parameters) when redmax models the class (null otherwise). Throws hill::MuscleParameterError
  /// for a value the class refuses.
  int addMuscle(Muscle muscle, std::string opensim_class, hill::MuscleParameters parameters);
  int numMuscles() const { return static_cast<int>(muscles_.size()); }
  /// muscle k for editing (mass points, wrap model); finalize() validates it
  Muscle& muscle(int k);
  void setMuscleMassPoints(int k, MassPoints points);

  /// Read every muscle as OpenSim class `opensim_class` (OpenSim's Object::renameType, the
  /// CLI's --muscle-class): the same XML properties, read as that class, make each muscle's new
  /// force model (muscles without parameters are only renamed). Throws hill::MuscleModelError for
  /// a class redmax does not model and hill::MuscleParameterError for a property the new class
  /// refuses; the builder is unchanged then.
  void overrideMuscleClass(const std::string& opensim_class);

  void addConstraint(std::shared_ptr<const Constraint> c);
  void setCoordinateMap(std::shared_ptr<const CoordinateMap> map);
  void addForceElement(std::shared_ptr<const ForceTerm> term);
  ModelSettings& settings() { return settings_; }

  /// Finalize the skeleton, validate every muscle against it (validateMuscle) and check that the
  /// coordinate map fits it. Throws ModelError.
  MusculoskeletalModel finalize() const;

 private:
  ModelBuilder skeleton_;
  std::vector<Muscle> muscles_;
  std::vector<std::string> muscle_classes_;
  std::vector<std::shared_ptr<const hill::MuscleModel>> muscle_models_;
  std::vector<std::shared_ptr<const hill::MuscleParameters>> muscle_parameters_;
  std::vector<std::shared_ptr<const Constraint>> constraints_;
  std::shared_ptr<const CoordinateMap> coordinate_map_;
  std::vector<std::shared_ptr<const ForceTerm>> force_elements_;
  ModelSettings settings_;
};

}  // namespace redmax
