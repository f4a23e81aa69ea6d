// How much fibre-following placement (core/muscles/fibre_placement.hpp) changes the inertia of
// long-tendon muscles on gait2392 (Thelen2003Muscle; shared OpenSim data): each muscle's
// contribution sum_a m_a |dx_a/dq_c|^2 to the diagonal of M at ankle_angle_r and knee_angle_r,
// physiological mass (--muscle-mass physiological), at the default pose and with the knee flexed
// 60 degrees and the ankle plantarflexed 20 degrees, for
//   uniform   the dissertation's equal strain: points at fixed arc fractions of the whole path
//   fibre/ID  fibre-following, no states: the tendon rigid at its equilibrium length (default
//             activation 0.05), so every length change goes to the fibre
//   fibre/FD  fibre-following with the fibre-length state (forward dynamics): at fixed fibre
//             length the tendon takes a length change, the fibre's points slide with its middle
// The printed table is what docs/muscle_mass.md quotes; the ratios are asserted near it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>
#include <string>

#include "converter/build/muscle_mass.hpp"
#include "converter/osim_reader.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

const std::string kGait2392 = "opensim-models/Models/Gait2392_Simbody/gait2392_thelen2003muscle.osim";

int coordinate(const ModelDescription& d, const BuildResult& r, const std::string& name) {
  for (size_t k = 0; k < d.coordinates.size(); ++k)
    if (d.coordinates[k].name == name) return r.coordinate_index[k];
  return -1;
}

// diag entries (c1, c2) of the muscle's mass matrix at q; fs.z null: no states
std::pair<double, double> diagonal(const Model& m, const Muscle& mu, const VecX& q, int c1, int c2,
                                   const FibreStates& fs) {
  State s;
  s.q = q;
  s.qdot = VecX::Zero(m.nr());
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  MuscleWorkspace ws(m, {mu});
  calcMuscleKinematics(m, s, sk, mu, ws.muscles[0], true, fs);
  const MatX J = expandColumns(ws.muscles[0].J_ar, ws.muscles[0], m.nr());
  double d1 = 0.0, d2 = 0.0;
  for (int a = 0; a < mu.mass_points.size(); ++a) {
    d1 += mu.mass_points.mass[a] * J.block<3, 1>(3 * a, c1).squaredNorm();
    d2 += mu.mass_points.mass[a] * J.block<3, 1>(3 * a, c2).squaredNorm();
  }
  return {d1, d2};
}

TEST(FibrePlacementInertia, Gait2392LongTendonMuscles) {
  REDMAX_REQUIRE_SHARED();
  const ModelDescription d = readOsimModel(test::sharedOpenSim(kGait2392));
  BuildOptions bo;
  bo.constraints = false;
  MuscleMassOptions o;
  o.source = MuscleMassOptions::Source::Physiological;
  o.muscles = "soleus_r|med_gas_r|lat_gas_r|tib_ant_r";
  const MuscleMassModel uni = applyMuscleMass(d, bo, o);
  o.placement = MuscleMassOptions::Placement::Fibre;
  const MuscleMassModel fib = applyMuscleMass(d, bo, o);
  const Model& m = fib.build.model.skeleton();
  const int ankle = coordinate(d, fib.build, "ankle_angle_r"), knee = coordinate(d, fib.build, "knee_angle_r");
  ASSERT_GE(ankle, 0);
  ASSERT_GE(knee, 0);
  VecX flexed = m.defaultQ();
  flexed[knee] = -60.0 * M_PI / 180.0;  // gait2392's knee flexes negative
  flexed[ankle] = -20.0 * M_PI / 180.0;
  const std::vector<std::string> names = {"soleus_r", "med_gas_r", "lat_gas_r", "tib_ant_r"};
  std::printf("muscle     pose     m (kg)  l_opt  l_ts   | M_ankle: uniform  fibre/ID  fibre/FD | M_knee: uniform  fibre/ID  fibre/FD (kg m^2)\n");
  for (const std::string& name : names) {
    const int k = fib.build.model.findMuscle(name);
    ASSERT_GE(k, 0) << name;
    const Muscle& mf = fib.build.model.muscles()[k];
    const Muscle& mu = uni.build.model.muscles()[k];
    ASSERT_TRUE(mf.fibre.enabled()) << name;
    ASSERT_FALSE(mu.fibre.enabled());
    for (const auto& [pose, q] : {std::pair{"default", m.defaultQ()}, std::pair{"flexed", flexed}}) {
      const auto u = diagonal(m, mu, q, ankle, knee, FibreStates{});
      const auto id = diagonal(m, mf, q, ankle, knee, FibreStates{});
      // the fibre-length state at its equilibrium (default activation)
      std::vector<double> z(mf.fibre.model->numStates());
      mf.fibre.model->defaultState(z.data());
      std::vector<Mat4> E;
      calcBodyPoses(m, q, E);
      hill::MusculotendonInput in;
      in.length = calcPathLength(m, mf.path, q, E);
      in.excitation = z[0];
      mf.fibre.model->equilibrate(in, z.data());
      const auto fd = diagonal(m, mf, q, ankle, knee, FibreStates{z.data(), z[0]});
      std::printf("%-10s %-8s %.4f  %.3f  %.3f  | %.3e  %.3e  %.3e | %.3e  %.3e  %.3e\n", name.c_str(), pose,
                  mf.mass_points.totalMass(), mf.optimal_fiber_length, mf.tendon_slack_length, u.first, id.first,
                  fd.first, u.second, id.second, fd.second);
      // measured ankle entry, fibre/uniform: ID 1.27-1.32 (every length change in the fibre, whose
      // distal points move with the insertion), FD 0.970-0.998 (the tendon takes it at fixed fibre)
      EXPECT_GT(id.first / u.first, 1.2);
      EXPECT_LT(id.first / u.first, 1.4);
      EXPECT_GT(fd.first / u.first, 0.95);
      EXPECT_LT(fd.first / u.first, 1.005);
    }
  }
}

}  // namespace
}  // namespace redmax::osim
