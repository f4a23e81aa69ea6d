// Fuzz target for OpenSim controls (converter/controls.hpp): ControlSet XML or a controls table
// (the input's length picks .xml or .sto); a successful read is evaluated at a few times,
// including before the first and after the last node.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "converter/controls.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = redmax::fuzz::writeInput(size % 2 ? "controls.sto" : "controls.xml", data, size);
  redmax::osim::ControlSetDesc cs;
  if (!redmax::fuzz::acceptingProjectErrors([&] { cs = redmax::osim::readControlSet(path); })) return 0;
  for (const auto& c : cs.controls)
    for (double t : {-1e3, -1.0, 0.0, 0.5, 1.0, 1e3}) {
      (void)c.value(t);
      (void)c.minValue(t);
      (void)c.maxValue(t);
    }
  return 0;
}
