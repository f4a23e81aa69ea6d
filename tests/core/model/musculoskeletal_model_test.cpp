// The musculoskeletal aggregate and the builders' edit path: a finished model is never changed in
// place; a builder started from it edits a copy and re-derives everything on finalize().
#include <gtest/gtest.h>

#include <memory>

#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/coordinate_map.hpp"
#include "core/model/musculoskeletal_model.hpp"
#include "core/muscles/path.hpp"
#include "core/spatial/se3.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

Muscle straightMuscle(double mass) {
  Muscle mu;
  mu.name = "straight";
  mu.path.points = {makeFixedPoint(0, Vec3(0.1, -0.1, 0), "origin"), makeFixedPoint(1, Vec3(0.05, -0.7, 0), "insertion")};
  mu.optimal_fiber_length = 0.6;
  mu.tendon_slack_length = 0.4;
  if (mass > 0.0) mu.mass_points = makeMassPoints(mass, 0.6, 0.4, {});
  return mu;
}

TEST(ModelBuilderEdit, StartsFromAModelAndRederivesTheSpatialInertia) {
  const Model m = scenes::doublePendulum();
  const Model same = ModelBuilder(m).finalize();
  ASSERT_EQ(same.nb(), m.nb());
  ASSERT_EQ(same.nr(), m.nr());
  for (int i = 0; i < m.nb(); ++i) {
    EXPECT_EQ(same.bodies()[i].M, m.bodies()[i].M);
    EXPECT_EQ(same.ancestors(i), m.ancestors(i));
  }

  ModelBuilder edit(m);
  const Vec3 com(0.01, -0.2, 0.03);
  const Mat3 I = Vec3(0.02, 0.03, 0.04).asDiagonal();
  edit.setBodyMassProperties(1, 2.5, com, I);
  edit.coordinateAt(0).stiffness = 7.0;
  edit.setGravity(Vec3::Zero());
  const Model e = edit.finalize();
  EXPECT_EQ(e.bodies()[1].mass, 2.5);
  EXPECT_EQ(e.bodies()[1].M, spatialInertia(2.5, com, I));
  EXPECT_EQ(e.bodies()[0].M, m.bodies()[0].M);
  EXPECT_EQ(e.coordinates()[0].stiffness, 7.0);
  EXPECT_EQ(e.gravity(), Vec3::Zero());
  // the original is untouched
  EXPECT_NE(m.bodies()[1].mass, 2.5);
  EXPECT_EQ(m.coordinates()[0].stiffness, 0.0);
  EXPECT_NE(m.gravity(), Vec3::Zero());

  EXPECT_THROW(edit.setBodyMassProperties(m.nb(), 1.0, com, I), ModelError);
  EXPECT_THROW(edit.coordinateAt(m.nr()), ModelError);
  edit.setBodyMassProperties(0, -1.0, com, I);
  EXPECT_THROW(edit.finalize(), ModelError);
}

TEST(MusculoskeletalModel, HoldsWhatDefinesTheModelAndEditsThroughItsBuilder) {
  const Model skel = scenes::doublePendulum();
  MusculoskeletalModelBuilder b(skel);
  b.addMuscle(straightMuscle(0.0), "Thelen2003Muscle");
  b.addConstraint(PrescribedCoordinate::makeLocked(skel, 1, 0.2));
  b.settings().muscle_term.quadratic_velocity = false;
  const MusculoskeletalModel m = b.finalize();
  ASSERT_EQ(m.numMuscles(), 1);
  EXPECT_EQ(m.findMuscle("straight"), 0);
  EXPECT_EQ(m.findMuscle("none"), -1);
  EXPECT_EQ(m.muscleClasses()[0], "Thelen2003Muscle");
  EXPECT_EQ(m.muscleMass(), 0.0);
  EXPECT_EQ(m.constraints().size(), 1u);
  EXPECT_FALSE(m.settings().muscle_term.quadratic_velocity);
  const Model& as_skeleton = m;  // the aggregate passes where a skeleton is read
  EXPECT_EQ(&as_skeleton, &m.skeleton());
  // massless muscles add no term
  EXPECT_EQ(m.makeSystem(true).terms().size(), 0u);
  EXPECT_EQ(m.makeSystem().numConstraintRows(), 1);

  // the edit: body mass into the muscle, and a class override; the original stays as it was
  MusculoskeletalModelBuilder edit(m);
  const Body& b1 = m.skeleton().bodies()[1];
  edit.skeleton().setBodyMassProperties(1, b1.mass - 0.3, b1.com, b1.inertia_com);
  edit.setMuscleMassPoints(0, makeMassPoints(0.3, 0.6, 0.4, {}));
  edit.overrideMuscleClass("Millard2012EquilibriumMuscle");
  const MusculoskeletalModel e = edit.finalize();
  EXPECT_NEAR(e.muscleMass(), 0.3, 1e-15);
  EXPECT_EQ(e.skeleton().bodies()[1].M, spatialInertia(b1.mass - 0.3, b1.com, b1.inertia_com));
  EXPECT_EQ(e.muscleClasses()[0], "Millard2012EquilibriumMuscle");
  EXPECT_EQ(m.muscleMass(), 0.0);
  EXPECT_EQ(m.muscleClasses()[0], "Thelen2003Muscle");
  EXPECT_EQ(m.skeleton().bodies()[1].mass, b1.mass);
  const System with = e.makeSystem(true);
  ASSERT_EQ(with.terms().size(), 1u);
  EXPECT_EQ(with.terms()[0]->name(), "muscle_mass");
}

TEST(MusculoskeletalModel, FinalizeValidates) {
  const Model skel = scenes::doublePendulum();
  MusculoskeletalModelBuilder bad_muscle(skel);
  Muscle mu = straightMuscle(0.1);
  mu.path.points[1].body = skel.nb();  // no such body
  bad_muscle.addMuscle(mu);
  EXPECT_THROW(bad_muscle.finalize(), ModelError);

  // a coordinate map made for another skeleton
  const Model other = scenes::randomTree(4, 3);
  ASSERT_NE(other.nr(), skel.nr());
  MusculoskeletalModelBuilder bad_map(skel);
  bad_map.setCoordinateMap(std::make_shared<CoordinateMap>(other));
  EXPECT_THROW(bad_map.finalize(), ModelError);

  MusculoskeletalModelBuilder b(skel);
  EXPECT_THROW(b.muscle(0), ModelError);
  EXPECT_THROW(b.addConstraint(nullptr), ModelError);
  EXPECT_THROW(b.addForceElement(nullptr), ModelError);
}

}  // namespace
}  // namespace redmax
