// Workspaces own all scratch (issue 15): one System with inertial muscles (a MuscleTerm) and
// per-evaluation external loads (DynamicsWorkspace::loads), shared by 4 threads that each own a
// DynamicsWorkspace, gives bit-identical (==) inverse dynamics, forward dynamics and energies to a
// serial run; states are dealt round-robin and solved backwards. The term's scratch holds one
// evaluation: after calcMassAndForce it is tagged with the workspace's evaluation counter, a new
// state moves the counter on, and a workspace bound to another system gets new slots.
// The network wrap model's fallback counts, summed over the threads' workspaces, equal the serial
// run's. (The real-model version, sets E and F, is tests/validation/thread_safety_test.cpp.)
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <thread>
#include <vector>

#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "tests/core/dynamics/random_muscle.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "validation/scenes/scenes.hpp"
#include "validation/scenes/wrap_pendulums.hpp"

namespace redmax {
namespace {


struct Sample {
  State s;
  VecX qddot;
  ExternalLoads loads;
};

struct Result {
  VecX tau, qddot;
  double T = 0.0, V = 0.0;
};

Result evaluate(const System& sys, const Sample& x, DynamicsWorkspace& ws) {
  Result r;
  ws.loads = x.loads;
  r.tau = sys.inverseDynamics(x.s, x.qddot, ws);
  r.qddot = sys.forwardDynamics(x.s, ws);
  r.T = sys.kineticEnergy(x.s, ws);
  r.V = sys.potentialEnergy(x.s, ws);
  return r;
}

TEST(ThreadSafety, FourThreadsOnOneSystemEqualTheSerialRunBitForBit) {
  const Model m = scenes::randomTree(8, 31, scenes::TreeJoints::SimbodyComparable);
  std::mt19937 rng(11);
  std::vector<Muscle> muscles;
  for (int k = 0; k < 4; ++k) muscles.push_back(test::randomViaMuscle(m, rng, 0.2 + 0.1 * k, "m" + std::to_string(k)));
  muscles.push_back(test::randomViaMuscle(m, rng, 0.0, "massless"));
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, muscles));
  std::vector<Sample> samples(48);
  for (Sample& x : samples) {
    x.s = test::randomState(m.nr(), rng);
    x.qddot = test::randomState(m.nr(), rng).qdot;
    const int body = static_cast<int>(rng() % static_cast<unsigned>(m.nb()));
    x.loads.point_forces.push_back({body, test::randomVec(rng, 0.2), test::randomVec(rng, 50.0)});
    x.loads.wrenches.push_back({body, test::randomVec(rng, 5.0), Vec3::Zero()});
  }

  std::vector<Result> serial;
  DynamicsWorkspace ws(sys);
  for (const Sample& x : samples) serial.push_back(evaluate(sys, x, ws));

  constexpr int kThreads = 4;
  std::vector<Result> parallel(samples.size());
  std::vector<std::thread> pool;
  for (int j = 0; j < kThreads; ++j)
    pool.emplace_back([&, j] {
      DynamicsWorkspace own(sys.model());  // slots made on first use
      for (long k = static_cast<long>(samples.size()) - 1; k >= 0; --k)
        if (k % kThreads == j) parallel[static_cast<size_t>(k)] = evaluate(sys, samples[static_cast<size_t>(k)], own);
    });
  for (auto& th : pool) th.join();

  for (size_t k = 0; k < samples.size(); ++k) {
    EXPECT_TRUE(parallel[k].tau == serial[k].tau) << "sample " << k;
    EXPECT_TRUE(parallel[k].qddot == serial[k].qddot) << "sample " << k;
    EXPECT_EQ(parallel[k].T, serial[k].T) << "sample " << k;
    EXPECT_EQ(parallel[k].V, serial[k].V) << "sample " << k;
  }
  // the loads are an input: they change tau (the check above compares something)
  DynamicsWorkspace bare(sys);
  EXPECT_FALSE(sys.inverseDynamics(samples[0].s, samples[0].qddot, bare) == serial[0].tau);
}

// The network wrap model counts its fallbacks in each workspace (no shared counter): two wrapping
// muscles, one inside the committed network's training box (the network) and one outside it (the
// smooth fallback), evaluated by 4 threads give the serial run's results and, summed over the
// threads' workspaces, its counts.
TEST(ThreadSafety, NetworkWrapFallbackCountsSummedOverThreadsEqualTheSerialRun) {
  const Model m = scenes::doublePendulum();
  WrapMassOptions neural;
  neural.model = WrapModel::Neural;
  neural.network = loadWrapNetwork(std::string(REDMAX_SOURCE_DIR) + "/osim_models/networks/cylinder_3x64.txt");
  Muscle in_box = scenes::makeWrapPendulumMuscle(scenes::WrapPendulumSpec{}, neural);
  in_box.name = "in_box";
  scenes::WrapPendulumSpec far;  // osim_models/double_pendulum_wrap.osim's end points, 5 radii out
  far.origin = Vec3(-0.1, -0.6, 0);
  far.insertion = Vec3(-0.1, -0.4, 0);
  Muscle outside = scenes::makeWrapPendulumMuscle(far, neural);
  outside.name = "outside";
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{in_box, outside}));
  std::mt19937 rng(5);
  std::vector<Sample> samples(24);
  for (Sample& x : samples) {
    x.s = test::randomState(m.nr(), rng, 0.3);
    x.qddot = test::randomState(m.nr(), rng).qdot;
  }

  std::vector<Result> serial;
  DynamicsWorkspace ws(sys);
  for (const Sample& x : samples) serial.push_back(evaluate(sys, x, ws));
  WrapFallbackMonitor serial_counts;
  takeWrapFallbackCounts(sys, ws, serial_counts);

  constexpr int kThreads = 4;
  std::vector<Result> parallel(samples.size());
  std::vector<DynamicsWorkspace> own;
  for (int j = 0; j < kThreads; ++j) own.emplace_back(sys);
  std::vector<std::thread> pool;
  for (int j = 0; j < kThreads; ++j)
    pool.emplace_back([&, j] {
      for (size_t k = 0; k < samples.size(); ++k)
        if (static_cast<int>(k % kThreads) == j) parallel[k] = evaluate(sys, samples[k], own[j]);
    });
  for (auto& th : pool) th.join();
  WrapFallbackMonitor summed;
  for (DynamicsWorkspace& w : own) takeWrapFallbackCounts(sys, w, summed);

  for (size_t k = 0; k < samples.size(); ++k) {
    EXPECT_TRUE(parallel[k].tau == serial[k].tau) << "sample " << k;
    EXPECT_TRUE(parallel[k].qddot == serial[k].qddot) << "sample " << k;
  }
  const auto a = serial_counts.counts(), b = summed.counts();
  ASSERT_EQ(a.size(), 2u);
  for (const auto& [name, c] : a) {
    ASSERT_EQ(b.count(name), 1u) << name;
    EXPECT_EQ(b.at(name).evaluations, c.evaluations) << name;
    EXPECT_EQ(b.at(name).fallbacks, c.fallbacks) << name;
    EXPECT_EQ(b.at(name).by_reason, c.by_reason) << name;
  }
  // both paths ran
  EXPECT_GE(a.at("in_box").evaluations, static_cast<long>(samples.size()));
  EXPECT_LT(a.at("in_box").fallbacks, a.at("in_box").evaluations);
  EXPECT_EQ(a.at("outside").fallbacks, a.at("outside").evaluations);
  // taking zeroes the workspace's counts: nothing is added twice
  takeWrapFallbackCounts(sys, ws, serial_counts);
  EXPECT_EQ(serial_counts.evaluations("in_box"), a.at("in_box").evaluations);
}

TEST(ThreadSafety, TermScratchHoldsOneEvaluationOfItsSystem) {
  const Model m = scenes::randomTree(5, 7, scenes::TreeJoints::SimbodyComparable);
  std::mt19937 rng(3);
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{test::randomViaMuscle(m, rng, 0.5, "a")}));
  DynamicsWorkspace ws(m);
  EXPECT_EQ(ws.system_id, 0u);
  const State s = test::randomState(m.nr(), rng);
  sys.calcMassAndForce(s, ws);
  EXPECT_EQ(ws.system_id, sys.id());
  ASSERT_EQ(ws.term_scratch.size(), 1u);
  ASSERT_NE(ws.term_scratch[0], nullptr);
  const std::uint64_t e1 = ws.evaluation;
  EXPECT_EQ(ws.term_scratch[0]->evaluation, e1);
  // Mdot qdot at the same state reuses the evaluation; a new state moves the counter on
  VecX Mdv;
  sys.calcMassDotTimesVelocity(s, ws, Mdv);
  EXPECT_EQ(ws.evaluation, e1);
  sys.calcMassAndForce(test::randomState(m.nr(), rng), ws);
  EXPECT_GT(ws.evaluation, e1);
  EXPECT_EQ(ws.term_scratch[0]->evaluation, ws.evaluation);
  // a copy of the system is another system; so is the system after a change
  const System copy = sys;
  EXPECT_NE(copy.id(), sys.id());
  const std::uint64_t before = sys.id();
  System changed = sys;
  const std::uint64_t copied = changed.id();
  changed.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{test::randomViaMuscle(m, rng, 0.1, "b")}));
  EXPECT_NE(changed.id(), copied);
  EXPECT_EQ(sys.id(), before);
  changed.calcMassAndForce(s, ws);
  EXPECT_EQ(ws.system_id, changed.id());
  EXPECT_EQ(ws.term_scratch.size(), 2u);
}

}  // namespace
}  // namespace redmax
