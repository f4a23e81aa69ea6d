// One model, many threads (issue 15): a CoreIdEngine (its System, MuscleTerm and model) is
// immutable while it solves frames with a caller's CoreIdWorkspace, so threads that share one
// engine, each with its own workspace, give bit-identical torques (==, not near) to a serial run.
// Sets E (gait2392, 92 muscles with physiological mass, the wrapping ones over the smooth wrap
// model) and F (gait10dof18musc); frames dealt to 4 threads round-robin and solved backwards, so
// every workspace sees states in an order the serial run never does. Skipped without ../shared.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"

namespace {

namespace fs = std::filesystem;
using namespace redmax;
using namespace redmax::osim;

struct Trial {
  const char* name;
  std::string setup, model;
};

Trial setE() {
  const std::string b = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  return {"E", b + "opensim-models/Pipelines/Gait2392_Simbody/subject01_Setup_InverseDynamics.xml",
          b + "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim"};
}
Trial setF() {
  const std::string b = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  return {"F", b + "opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/walk_Setup_ID.xml",
          b + "opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim"};
}

struct Frame {
  double t = 0.0;
  VecX q, v, a;
  std::vector<IdLoadSample> loads;
};

void checkThreads(const Trial& tr) {
  for (const auto& f : {tr.setup, tr.model})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  IdToolSettings s;
  s.setup_file = tr.setup;
  s.model_file = tr.model;
  s.muscle_mass.source = MuscleMassOptions::Source::Physiological;
  const InverseDynamicsTool tool(resolveIdSettings(s));
  CoreIdEngine engine(tool.musculoskeletalModel(), tool.engineOptions());
  ASSERT_GT(engine.muscleMass(), 0.0) << "set " << tr.name << ": no muscle mass, nothing to share";

  std::vector<Frame> frames(static_cast<size_t>(tool.numFrames()));
  ASSERT_GT(frames.size(), 8u);
  for (size_t k = 0; k < frames.size(); ++k) {
    Frame& fr = frames[k];
    fr.t = tool.frameTime(static_cast<int>(k));
    tool.calcInputs(fr.t, fr.q, fr.v, fr.a, fr.loads);
  }

  // serial reference: the engine's own workspace, frames in order (the IdEngine interface)
  std::vector<VecX> serial(frames.size());
  for (size_t k = 0; k < frames.size(); ++k) {
    const Frame& fr = frames[k];
    engine.calcGeneralizedForces(fr.t, fr.q, fr.v, fr.a, fr.loads, serial[k]);
  }

  // four threads on the one engine, each with its own workspace, frames k = j mod 4 backwards
  const CoreIdEngine& shared = engine;
  constexpr int kThreads = 4;
  std::vector<VecX> parallel(frames.size());
  std::vector<std::string> errors(kThreads);
  std::vector<std::thread> pool;
  for (int j = 0; j < kThreads; ++j) {
    pool.emplace_back([&, j] {
      try {
        CoreIdWorkspace ws(shared.system());
        for (long k = static_cast<long>(frames.size()) - 1; k >= 0; --k) {
          if (k % kThreads != j) continue;
          const Frame& fr = frames[static_cast<size_t>(k)];
          shared.calcGeneralizedForces(fr.t, fr.q, fr.v, fr.a, fr.loads, parallel[static_cast<size_t>(k)], ws);
        }
      } catch (const std::exception& e) {
        errors[static_cast<size_t>(j)] = e.what();
      }
    });
  }
  for (auto& th : pool) th.join();
  for (int j = 0; j < kThreads; ++j) ASSERT_EQ(errors[static_cast<size_t>(j)], "") << "thread " << j;

  int differing = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    ASSERT_EQ(parallel[k].size(), serial[k].size()) << "frame " << k;
    for (int i = 0; i < serial[k].size(); ++i) {
      if (parallel[k][i] == serial[k][i]) continue;  // bit-identical, not near
      if (++differing <= 5)
        ADD_FAILURE() << "set " << tr.name << " frame " << k << " coordinate " << i << ": threads "
                      << parallel[k][i] << ", serial " << serial[k][i];
    }
  }
  EXPECT_EQ(differing, 0);
  std::printf("[ measured ] set %s: %zu frames, %.2f kg of muscle mass, %d threads: %d entries differ from the "
              "serial run\n",
              tr.name, frames.size(), engine.muscleMass(), kThreads, differing);
}

TEST(ThreadSafety, SetEFourThreadsOnOneEngineEqualTheSerialRunBitForBit) { checkThreads(setE()); }
TEST(ThreadSafety, SetFFourThreadsOnOneEngineEqualTheSerialRunBitForBit) { checkThreads(setF()); }

}  // namespace
