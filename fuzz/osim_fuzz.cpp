// Fuzz target for the .osim reader (converter/osim_reader.hpp) and, on what it returns, the core
// builder (converter/build/build_core_model.hpp): a model that parses but is inconsistent must be
// rejected with an exception, never crash the builder.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = redmax::fuzz::writeInput("input.osim", data, size);
  redmax::osim::ModelDescription d;
  try {
    d = redmax::osim::readOsimModel(path);
  } catch (const std::exception& e) {
    redmax::fuzz::acceptError(e);
    return 0;
  }
  // exact and Simbody-compatible builds take different joint paths; the builder with constraints
  // and muscles (the default) exercises the most code
  for (const bool compat : {false, true}) {
    redmax::osim::BuildOptions opt;
    opt.simbody_compat = compat;
    try {
      (void)redmax::osim::buildCoreModel(d, opt);
    } catch (const std::exception& e) {
      redmax::fuzz::acceptError(e);
    }
  }
  return 0;
}
