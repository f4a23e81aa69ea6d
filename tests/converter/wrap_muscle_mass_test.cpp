// MuscleMassOptions::wrap_mass: the running leg's gastrocnemii (origin on the femur, one quadrant
// cylinder at the knee, insertion on the calcaneus: the shape core/muscles/wrap_muscle.hpp moves
// mass over) take their physiological mass, taken from the bones at the mass points' positions, so
// the root 6x6 block of M (total mass, centre of mass and inertia of the whole leg) is unchanged at
// the default pose. Without the option they stay lumped, as before.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "converter/build/build_core_model.hpp"
#include "converter/build/muscle_mass.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

int findEntry(const MuscleMassPlan& p, const std::string& name) {
  for (size_t k = 0; k < p.muscles.size(); ++k)
    if (p.muscles[k].name == name) return static_cast<int>(k);
  return -1;
}

TEST(WrapMuscleMass, RunningLegGastrocnemiiTakeMassWithWrapMass) {
  const ModelDescription d = readOsimModel(std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg.osim");
  BuildOptions bo;
  bo.constraints = false;
  MuscleMassOptions o;
  o.source = MuscleMassOptions::Source::Physiological;
  {
    const MuscleMassModel lumped = applyMuscleMass(d, bo, o);
    const int mg = findEntry(lumped.plan, "med_gas_r");
    ASSERT_GE(mg, 0);
    EXPECT_EQ(lumped.plan.muscles[mg].mass, 0.0);
    EXPECT_NE(lumped.plan.muscles[mg].lumped_why.find("Type III"), std::string::npos);
  }
  o.wrap_mass = true;
  const MuscleMassModel r = applyMuscleMass(d, bo, o);
  for (const char* name : {"med_gas_r", "lat_gas_r"}) {
    const int k = findEntry(r.plan, name);
    ASSERT_GE(k, 0);
    const double phys = physiologicalMass(d.muscles[r.build.muscle_source[k]], o);
    EXPECT_GT(phys, 0.0);
    EXPECT_NEAR(r.plan.muscles[k].mass, phys, 1e-15) << name << ": " << r.plan.muscles[k].lumped_why;
    EXPECT_EQ(r.build.model.muscles()[k].mass_points.size(), 20) << name;
    std::printf("[ measured ] running_leg %s: %.4f kg over 20 mass points (Type III, smooth wrap)\n", name,
                r.plan.muscles[k].mass);
  }
  // the mass came from the bones where the points sit: the whole leg's inertia is unchanged
  const BuildResult before = buildCoreModel(d, bo);
  System s0(before.model), s1(r.build.model);
  s1.addTerm(std::make_shared<MuscleTerm>(r.build.model, r.build.model.muscles()));
  State st;
  st.q = before.model.skeleton().defaultQ();
  st.qdot = VecX::Zero(st.q.size());
  DynamicsWorkspace w0(s0.model()), w1(s1.model());
  s0.calcMassAndForce(st, w0);
  s1.calcMassAndForce(st, w1);
  const MatX A = w0.M.topLeftCorner(6, 6), B = w1.M.topLeftCorner(6, 6);
  const double diff = (A - B).norm() / A.norm();
  std::printf("[ measured ] running_leg with wrapping muscle mass: root block of M differs by %.1e relative\n", diff);
  EXPECT_LE(diff, 1e-10);
  EXPECT_GT((w1.M - w0.M).norm(), 1e-6 * w0.M.norm());
}

// a wrapping muscle whose path the wrap model refuses stays lumped, and the plan gives the model's
// own reason: arm26's TRIlong (two cylinders and an ellipsoid that can act on one segment) is
// refused by the smooth model and taken by the exact one; subject_walk_armless's med_gas_r (two
// cylinders on one segment) is taken by the smooth model's composition since issue 22
TEST(WrapMuscleMass, RefusedWrappingMuscleStaysLumpedWithTheModelsReason) {
  REDMAX_REQUIRE_SHARED();
  BuildOptions bo;
  bo.constraints = false;
  MuscleMassOptions o;
  o.source = MuscleMassOptions::Source::Physiological;
  o.wrap_mass = true;
  o.wrap.model = WrapModel::Smooth;
  {
    const ModelDescription d = readOsimModel(std::string(REDMAX_SHARED_DIR) +
                                             "/opensim/opensim-core/OpenSim/Moco/Test/subject_walk_armless_18musc.osim");
    o.muscles = "med_gas_r";  // all of them would leave tibia_r non-physical
    const MuscleMassModel r = applyMuscleMass(d, bo, o);
    const int k = findEntry(r.plan, "med_gas_r");
    ASSERT_GE(k, 0);
    EXPECT_GT(r.plan.muscles[k].mass, 0.0) << r.plan.muscles[k].lumped_why;
    EXPECT_EQ(r.plan.muscles[k].lumped_why, "");
  }
  const ModelDescription d =
      readOsimModel(std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-models/Models/Arm26/arm26.osim");
  o.muscles = "TRIlong";
  const MuscleMassModel r = applyMuscleMass(d, bo, o);
  const int k = findEntry(r.plan, "TRIlong");
  ASSERT_GE(k, 0);
  // the reason, asked of the plain build's muscle independently of the plan
  Muscle mu = buildCoreModel(d, bo).model.muscles()[k];
  ASSERT_EQ(mu.name, "TRIlong");
  mu.wrap.model = WrapModel::Smooth;
  const std::string why = wrapMassPointsUnsupportedReason(mu);
  ASSERT_FALSE(why.empty());
  EXPECT_NE(why.find("composes cylinders and spheres"), std::string::npos) << why;
  EXPECT_EQ(r.plan.muscles[k].mass, 0.0);
  EXPECT_EQ(r.plan.muscles[k].lumped_why, "Type III path (" + why + ")");
  o.wrap.model = WrapModel::Exact;
  const MuscleMassModel e = applyMuscleMass(d, bo, o);
  EXPECT_GT(e.plan.muscles[k].mass, 0.0) << e.plan.muscles[k].lumped_why;
  EXPECT_EQ(e.plan.muscles[k].lumped_why, "");
}

}  // namespace
}  // namespace redmax::osim
