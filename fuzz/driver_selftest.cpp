// A target with planted bugs, so that a ctest can show the standalone driver finds and saves them:
// an abort once a numeric field has been replaced by "nan" (the driver's numeric mutation).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view s(reinterpret_cast<const char*>(data), size);
  if (s.find("nan") != std::string_view::npos) std::abort();
  return 0;
}
