// Fuzz target for the TRC marker reader (converter/trc_file.hpp). A successful read is also
// written back (in mm) and read again: the writer's output must be readable.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "converter/trc_file.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = redmax::fuzz::writeInput("input.trc", data, size);
  redmax::osim::MarkerTable t;
  if (!redmax::fuzz::acceptingProjectErrors([&] { t = redmax::osim::readTrc(path); })) return 0;
  redmax::fuzz::acceptingProjectErrors([&] {
    const std::string text = redmax::osim::formatTrc(t, "mm");
    const std::string again = redmax::fuzz::writeInput(
        "again.trc", reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
    (void)redmax::osim::readTrc(again);
  });
  return 0;
}
