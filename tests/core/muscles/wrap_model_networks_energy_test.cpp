// Energy with a model's own networks serving throughout (issue 22, docs/wrapping.md §3.2): a
// wrapping pendulum whose end points lie beyond the committed networks' training box, a network
// trained for its one wrap object by the `train-wrap --for` library (tools/wrap_training/
// model_networks.hpp) on the wrapped-segment ends of a smooth-model run, then an undamped rk45 run
// with the muscle's mass under the neural model: no fallback in any evaluation, and the energy
// conserved to the integrator's error, as with the smooth model on the same run.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "tools/wrap_training/model_networks.hpp"
#include "validation/scenes/scenes.hpp"
#include "validation/scenes/wrap_pendulums.hpp"

namespace redmax {
namespace {

// the poses of a smooth-model run of `spec` every 10 ms (the network's training trial)
std::vector<VecX> smoothRunPoses(const scenes::WrapPendulumSpec& spec, double duration) {
  const Model m = scenes::doublePendulum();
  WrapMassOptions sm;
  sm.model = WrapModel::Smooth;
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{scenes::makeWrapPendulumMuscle(spec, sm)}));
  State s = sys.defaultState();
  s.q << spec.q1, spec.q2;
  s.qdot.setZero();
  IntegratorOptions io;
  io.rtol = io.atol = 1e-9;
  auto integ = makeIntegrator("rk45", io);
  std::vector<VecX> poses{s.q};
  const int n = static_cast<int>(std::lround(duration * 100));
  for (int k = 1; k <= n; ++k) {
    integ->advance(sys, s, 0.01 * k);
    poses.push_back(s.q);
  }
  return poses;
}

TEST(ModelWrapNetworks, PendulumEnergyWithItsOwnNetworkServingThroughout) {
  // end points 0.35 m from the middle joint (4.4 radii from the axis, beyond the committed
  // networks' box of 3 radii), on the quadrant's active side
  scenes::WrapPendulumSpec spec;
  spec.origin = Vec3(-0.1, -0.65, 0.0);
  spec.insertion = Vec3(-0.1, -0.35, 0.0);
  const double duration = 3.0;
  const Model m = scenes::doublePendulum();
  WrapMassOptions sm;
  sm.model = WrapModel::Smooth;
  const Muscle mu = scenes::makeWrapPendulumMuscle(spec, sm);
  // the wrap object's inputs over the smooth run, and its network (train-wrap --for's defaults
  // but 4000 samples: seeded, a few seconds)
  const std::vector<WrapObjectInputs> inputs = collectWrapObjectInputs(m, {mu}, smoothRunPoses(spec, duration));
  ASSERT_EQ(inputs.size(), 1u);
  ASSERT_EQ(inputs[0].name, "joint_cylinder");
  ModelWrapTrainOptions o;
  o.train.hidden = {32, 32, 32};
  o.train.epochs = 40;
  o.train.batch = 64;
  o.train.learning_rate = 3e-3;
  o.train.seed = 1;
  o.samples = 4000;
  WrapErrorStats err;
  const auto net = std::make_shared<const Mlp>(trainWrapObjectNetwork(inputs[0], o, &err));

  WrapMassOptions nn;
  nn.model = WrapModel::Neural;
  nn.wrap_networks["joint_cylinder"] = net;
  const scenes::WrapPendulumRun r = scenes::runWrapPendulum(spec, nn, duration);
  const scenes::WrapPendulumRun s = scenes::runWrapPendulum(spec, sm, duration);
  // the committed generic network on the same run: its box does not reach these end points
  WrapMassOptions generic;
  generic.model = WrapModel::Neural;
  generic.network = loadWrapNetwork(std::string(REDMAX_SOURCE_DIR) + "/osim_models/networks/cylinder_3x64.txt");
  const scenes::WrapPendulumRun g = scenes::runWrapPendulum(spec, generic, 0.5);
  std::printf("pendulum, ends 4.4 radii off the axis, %.0f s rk45 1e-12, E0 %.4f J\n"
              "  network for its wrap object (fresh-sample RMS %.3g radii): drift %.3e J, %d contact changes, "
              "%ld steps, %ld/%ld fallbacks, %.2f s\n"
              "  smooth model: drift %.3e J, %d contact changes, %ld steps, %.2f s\n"
              "  committed cylinder_3x64 (0.5 s): %ld/%ld fallbacks (first: %s)\n",
              duration, r.E0, err.rms, r.max_drift, r.contact_changes, r.steps, r.fallbacks, r.evaluations, r.wall_s,
              s.max_drift, s.contact_changes, s.steps, s.wall_s, g.fallbacks, g.evaluations, g.first_fallback.c_str());
  ::testing::Test::RecordProperty("model_network_drift_J", std::to_string(r.max_drift));
  ::testing::Test::RecordProperty("smooth_drift_J", std::to_string(s.max_drift));
  // the model's network serves every evaluation
  EXPECT_EQ(r.fallbacks, 0) << r.first_fallback;
  EXPECT_GT(r.evaluations, 1000);
  EXPECT_GE(r.contact_changes, 2);
  EXPECT_GE(s.contact_changes, 2);
  // where the generic network cannot
  EXPECT_GT(g.fallbacks, 0);
  EXPECT_LT(err.rms, 0.03);  // radii (measured 0.010)
  // integrator error only, with either model (no jump: the network serves every evaluation);
  // measured 2.2e-11 J (network, 1396 steps) and 1.4e-10 J (smooth, 2011 steps)
  EXPECT_LE(r.max_drift, 1e-10);
  EXPECT_LE(s.max_drift, 1e-9);
}

}  // namespace
}  // namespace redmax
