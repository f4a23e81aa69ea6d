// Fuzz target for the .osim reader (converter/osim_reader.hpp) and, on what it returns, the core
// builder (converter/build/build_core_model.hpp): a model that parses but is inconsistent must be
// rejected with one of the project's errors, never crash the builder. A model that builds is also evaluated
// (kinematics with J_mr and Jdot_mr at the default pose and a perturbed one): the functions and
// joints the reader let through must not crash or hang there either (NaN results are allowed).
#include <cstddef>
#include <cstdint>
#include <exception>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "core/skeleton/kinematics.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = redmax::fuzz::writeInput("input.osim", data, size);
  redmax::osim::ModelDescription d;
  if (!redmax::fuzz::acceptingProjectErrors([&] { d = redmax::osim::readOsimModel(path); })) return 0;
  // exact and Simbody-compatible builds take different joint paths; the builder with constraints
  // and muscles (the default) exercises the most code
  for (const bool compat : {false, true}) {
    redmax::osim::BuildOptions opt;
    opt.simbody_compat = compat;
    redmax::fuzz::acceptingProjectErrors([&] {
      const redmax::osim::BuildResult r = redmax::osim::buildCoreModel(d, opt);
      const redmax::Model& m = r.model;
      redmax::VecX q(m.nr()), qdot = redmax::VecX::Ones(m.nr());
      for (int k = 0; k < m.nr(); ++k) q[k] = m.coordinates()[k].default_value;
      redmax::SkeletonWorkspace ws(m);
      redmax::calcKinematics(m, redmax::State{0.0, q, qdot}, ws);
      q.array() += 0.5;
      redmax::calcKinematics(m, redmax::State{0.0, q, qdot}, ws);
    });
  }
  return 0;
}
