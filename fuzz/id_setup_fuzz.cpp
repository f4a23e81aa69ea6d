// Fuzz target for InverseDynamicsTool setup files: the reader (converter/id_setup.hpp) and the
// merge of settings (resolveIdSettings in converter/id/inverse_dynamics_tool.hpp), which checks
// times and cut-off frequencies. Files named in the setup are resolved, not opened.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/id_setup.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = redmax::fuzz::writeInput("setup.xml", data, size);
  if (!redmax::fuzz::acceptingProjectErrors([&] { (void)redmax::osim::readInverseDynamicsSetup(path); })) return 0;
  redmax::fuzz::acceptingProjectErrors([&] {
    redmax::osim::IdToolSettings s;
    s.setup_file = path;
    (void)redmax::osim::resolveIdSettings(s);
  });
  return 0;
}
