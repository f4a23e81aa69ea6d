// Fuzz target for the legacy VTK tet-mesh reader (core/deformable/tet_mesh.hpp). A successful read
// is written back and read again: the writer's output must be readable, with the same mesh.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "core/deformable/tet_mesh.hpp"
#include "fuzz/fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = redmax::fuzz::writeInput("input.vtk", data, size);
  redmax::TetMesh m;
  if (!redmax::fuzz::acceptingProjectErrors([&] { m = redmax::readVtkTetMesh(path); })) return 0;
  const std::string again = redmax::fuzz::tempDir() + "/again.vtk";
  redmax::writeVtkTetMesh(again, m);
  const redmax::TetMesh r = redmax::readVtkTetMesh(again);
  if (r.nodes != m.nodes || r.tets != m.tets) std::abort();  // the round trip must be exact
  return 0;
}
