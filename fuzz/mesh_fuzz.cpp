// Fuzz target for the display-mesh reader (converter/mesh_file.hpp): .vtp with inline, appended,
// raw and zlib-compressed arrays, .obj and .stl. XML ('<' first) is read as .vtp, otherwise the
// input's length picks .obj or .stl. The reader's answer to bad input is a std::runtime_error with
// the reason (it is a drawing aid, not a model file); an empty message, any other exception or a
// crash is a bug. A mesh that is read must only name its own vertices.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "converter/mesh_file.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const char* name = size > 0 && data[0] == '<' ? "input.vtp" : size % 2 ? "input.obj" : "input.stl";
  const std::string path = redmax::fuzz::writeInput(name, data, size);
  redmax::osim::TriangleMesh m;
  try {
    m = redmax::osim::readMeshFile(path);
  } catch (const redmax::osim::ConvertError& e) {  // malformed XML
    redmax::fuzz::acceptError(e);
    return 0;
  } catch (const std::runtime_error& e) {
    redmax::fuzz::acceptError(e);
    return 0;
  }
  for (int i : m.triangles)
    if (i < 0 || i >= m.numVertices()) std::abort();
  return 0;
}
