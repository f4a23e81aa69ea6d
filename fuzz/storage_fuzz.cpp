// Fuzz target for the .sto/.mot reader (converter/storage.hpp). The file extension changes how
// degrees are decided, so the input's length picks it (even: .sto, odd: .mot). A successful read
// is also written back and read again: the writer's output must be readable.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "converter/storage.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      redmax::fuzz::writeInput(size % 2 ? "input.mot" : "input.sto", data, size);
  redmax::osim::Storage s;
  if (!redmax::fuzz::acceptingProjectErrors([&] { s = redmax::osim::readStorage(path); })) return 0;
  redmax::fuzz::acceptingProjectErrors([&] {
    const std::string text = redmax::osim::formatStorage(s);
    const std::string again = redmax::fuzz::writeInput(
        "again.sto", reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
    (void)redmax::osim::readStorage(again);
  });
  return 0;
}
