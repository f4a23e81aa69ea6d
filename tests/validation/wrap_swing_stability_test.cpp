// The running leg swinging freely with physiological mass in its gastrocnemii (Type III, smooth wrap
// model) under rk45 at rtol 1e-11, the run `WrapFlagsCli.RunningLegGastrocnemiiCarryMassAndConserveEnergy`
// makes from knee speed -4 rad/s, from knee speeds where it used to stall (docs/notes.md): the
// slide plane of OpenSim's cylinder construction was formed from two nearly parallel vectors when
// the muscle line passed close to its apex (core/geometry/constructions.hpp), and the round-off
// of its second derivatives kept rk45 at steps of 1e-11 s. Each 10 ms of output must take fewer
// than 20,000 steps (the whole second took 500-700).
#include <gtest/gtest.h>

#include <iostream>

#include "core/integrators/integrator.hpp"
#include "validation/simulate/simulate.hpp"

namespace redmax::validation {
namespace {

TEST(WrapSwingStability, TheGastrocnemiusOnsetRunsAtTightTolerances) {
  SimulationModelOptions o;
  o.muscle_mass.source = osim::MuscleMassOptions::Source::Physiological;
  o.muscle_mass.muscles = ".*_gas_r";
  o.muscle_mass.wrap_mass = true;
  o.muscle_mass.wrap.model = WrapModel::Smooth;
  const SimulationModel m = loadSimulationModel(std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg.osim", o);
  const System& sys = *m.system;
  const Model& md = sys.model();
  ASSERT_GT(m.muscle_mass, 0.2);
  for (double knee : {-4.972, -4.93, -4.88}) {  // three of the ten stalls among 64 speeds in [-5, -4.87]
    State s = sys.defaultState();
    s.qdot[md.findCoordinate("hip_flexion_r")] = 3.0;
    s.qdot[md.findCoordinate("knee_angle_r")] = knee;
    s.qdot[md.findCoordinate("ankle_angle_r")] = 2.0;
    IntegratorOptions io;
    io.rtol = 1e-11;
    io.atol = 1e-12;
    io.max_steps = 20000;
    auto integ = makeIntegrator("rk45", io);
    for (int k = 1; k <= 100; ++k) ASSERT_NO_THROW(integ->advance(sys, s, 0.01 * k)) << "knee " << knee << ", t " << s.t;
    std::cout << "[ measured ] knee speed " << knee << " rad/s: 1 s in " << integ->stats().steps << " steps, "
              << integ->stats().failed_steps << " failed\n";
    EXPECT_LT(integ->stats().steps, 5000) << knee;
  }
}

}  // namespace
}  // namespace redmax::validation
