// Fuzz target for ForwardTool setup files (converter/forward_setup.hpp): controllers, functions
// of PrescribedControllers, times and tolerances. Files named in the setup are resolved, not opened.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "converter/forward_setup.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = redmax::fuzz::writeInput("setup.xml", data, size);
  redmax::fuzz::acceptingProjectErrors([&] { (void)redmax::osim::readForwardSetup(path); });
  return 0;
}
