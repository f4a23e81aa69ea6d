#pragma once
// Output shared by the scenes that `redmax scene` runs (deformable_scenes, hybrid_scenes): files
// go through writeAtomically (core/deformable/tet_mesh.hpp), so a failed run leaves no
// half-written output.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "core/deformable/tet_mesh.hpp"

namespace redmax::scenes {

/// CSV with a header of `columns` and one row per entry of `rows` (each columns.size() long)
void writeCsv(const std::filesystem::path& path, const std::vector<std::string>& columns,
              const std::vector<VecX>& rows);

/// NAME_NNNN.vtk per frame (mesh's tets and `lines` at the frame's points, with the displacement
/// from the first frame) and NAME.pvd
void writeSeries(const std::filesystem::path& dir, const std::string& name, const TetMesh& mesh,
                 const std::vector<std::array<int, 2>>& lines, const std::vector<double>& t,
                 const std::vector<std::vector<Vec3>>& points);

}  // namespace redmax::scenes
