// Muscle mass is one edit of the built model (converter/build/muscle_mass.hpp, addMuscleMass):
// the core bodies' mass properties and the muscles' mass points it produces are bit for bit those
// of a model rebuilt from the edited description, as the converter built it before the edit path
// existed; and an already-built model (the ID tool's) gives the same model as applyMuscleMass.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "converter/build/muscle_mass.hpp"
#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using Source = MuscleMassOptions::Source;

std::string scenePath(const std::string& file) {
  return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + file;
}

void expectSameModel(const MusculoskeletalModel& a, const MusculoskeletalModel& b) {
  ASSERT_EQ(a.nb(), b.nb());
  ASSERT_EQ(a.nr(), b.nr());
  for (int i = 0; i < a.nb(); ++i) {
    const Body& x = a.skeleton().bodies()[i];
    const Body& y = b.skeleton().bodies()[i];
    EXPECT_EQ(x.mass, y.mass) << x.name;
    EXPECT_EQ(x.com, y.com) << x.name;
    EXPECT_EQ(x.inertia_com, y.inertia_com) << x.name;
    EXPECT_EQ(x.M, y.M) << x.name;
  }
  ASSERT_EQ(a.numMuscles(), b.numMuscles());
  for (int k = 0; k < a.numMuscles(); ++k) {
    const Muscle& x = a.muscles()[k];
    const Muscle& y = b.muscles()[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.mass_points.alpha, y.mass_points.alpha) << x.name;
    EXPECT_EQ(x.mass_points.mass, y.mass_points.mass) << x.name;
  }
  EXPECT_EQ(a.muscleClasses(), b.muscleClasses());
}

// the rebuild the edit replaces: the edited description built again, muscles given the plan's mass
MusculoskeletalModel rebuilt(const MuscleMassModel& mm, const BuildOptions& bo) {
  BuildOptions with = bo;
  with.muscles = true;
  const BuildResult r = buildCoreModel(mm.description, with);
  MusculoskeletalModelBuilder b(r.model);
  const MassPointOptions mpo{mm.plan.options.mass_points, mm.plan.options.region};
  for (int k = 0; k < b.numMuscles(); ++k) {
    const double m = mm.plan.muscles[k].mass;
    if (m > 0.0)
      b.setMuscleMassPoints(k, makeMassPoints(m, b.muscle(k).optimal_fiber_length,
                                              b.muscle(k).tendon_slack_length, mpo));
  }
  return b.finalize();
}

TEST(MuscleMassEdit, EqualsARebuildFromTheEditedDescription) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  BuildOptions bo;
  bo.constraints = false;
  MuscleMassOptions phys;
  phys.source = Source::Physiological;
  MuscleMassOptions transfer;
  transfer.source = Source::Transfer;
  transfer.transfer_body = "tibia_r";
  transfer.transfer_fraction = 0.4;
  for (const MuscleMassOptions& o : {phys, transfer}) {
    SCOPED_TRACE(toString(o.source));
    const MuscleMassModel mm = applyMuscleMass(d, bo, o);
    ASSERT_FALSE(mm.plan.bodies.empty());
    EXPECT_GT(mm.plan.total_muscle_mass, 0.0);
    expectSameModel(mm.build.model, rebuilt(mm, bo));

    // the same edit on a model built beforehand with its muscles
    BuildOptions with = bo;
    with.muscles = true;
    const MuscleMassModel once = addMuscleMass(d, buildCoreModel(d, with), o);
    expectSameModel(once.build.model, mm.build.model);
    EXPECT_EQ(once.plan.total_muscle_mass, mm.plan.total_muscle_mass);
  }
}

TEST(MuscleMassEdit, Gait2392EqualsARebuild) {
  REDMAX_REQUIRE_SHARED();
  const ModelDescription d =
      readOsimModel(test::sharedOpenSim("opensim-models/Models/Gait2392_Simbody/gait2392_thelen2003muscle.osim"));
  BuildOptions bo;
  bo.constraints = false;
  MuscleMassOptions o;
  o.source = Source::Physiological;
  const MuscleMassModel mm = applyMuscleMass(d, bo, o);
  EXPECT_GT(mm.plan.bodies.size(), 3u);
  expectSameModel(mm.build.model, rebuilt(mm, bo));
}

TEST(MuscleMassEdit, NeedsTheMusclesBuilt) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  BuildOptions bo;
  bo.constraints = false;
  bo.muscles = false;
  MuscleMassOptions o;
  o.source = Source::Physiological;
  EXPECT_THROW(addMuscleMass(d, buildCoreModel(d, bo), o), std::invalid_argument);
}

}  // namespace
}  // namespace redmax::osim
