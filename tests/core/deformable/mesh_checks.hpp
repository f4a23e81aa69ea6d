#pragma once
// Checks of a tet mesh shared by the mesher tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>

#include "core/deformable/tet_mesh.hpp"

namespace redmax::testing {

/// Expects every triangular face to belong to at most two tets (a conforming mesh) and returns
/// the number that belong to one (the boundary).
inline int boundaryFaces(const TetMesh& m) {
  std::map<std::array<int, 3>, int> faces;
  for (const auto& t : m.tets)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f;
      int k = 0;
      for (int a = 0; a < 4; ++a)
        if (a != skip) f[k++] = t[a];
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  int boundary = 0;
  for (const auto& [f, count] : faces) {
    EXPECT_LE(count, 2);
    boundary += count == 1;
  }
  return boundary;
}

}  // namespace redmax::testing
