#pragma once
// Tetrahedral meshes of deformable bodies (docs/deformable.md §3): a procedural box mesher and
// legacy VTK (ASCII unstructured grid) reading and writing, so that meshes can come from other
// tools and results can be viewed in ParaView.
#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/spatial/types.hpp"

namespace redmax {

/// Bad mesh input: the message is "FILE:LINE: what is wrong" (or "FILE: ..." without a line).
/// An invalid_argument: user input, exit status 2 in the CLI.
class MeshError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Rest positions (m) and tetrahedra (node indices, positively oriented: (x1-x0, x2-x0, x3-x0)
/// has a positive determinant).
struct TetMesh {
  std::vector<Vec3> nodes;
  std::vector<std::array<int, 4>> tets;
  int numNodes() const { return static_cast<int>(nodes.size()); }
  int numTets() const { return static_cast<int>(tets.size()); }
};

/// How each cube of a box mesh is split: 5 tets (alternating per cube so faces conform) or 6
/// (Kuhn's split along the main diagonal, the same in every cube).
enum class CubeSplit { Five, Six };

/// Box [origin, origin + size] of nx x ny x nz cubes, each split into tets; node (i, j, k) has
/// index i + (nx + 1) (j + (ny + 1) k). Throws std::invalid_argument for a count < 1 or a
/// non-positive size.
TetMesh makeBoxTetMesh(const Vec3& size, int nx, int ny, int nz, const Vec3& origin = Vec3::Zero(),
                       CubeSplit split = CubeSplit::Six);

/// Signed volume of tet t at node positions x.
double tetVolume(const std::vector<Vec3>& x, const std::array<int, 4>& t);

/// What readVtkTetMesh found beside the tets.
struct VtkReadInfo {
  int skipped_cells = 0;  // vertex, line and triangle cells (e.g. a mesher's boundary), not used
};

/// Read a legacy ASCII VTK unstructured grid (DATASET UNSTRUCTURED_GRID, POINTS, CELLS,
/// CELL_TYPES; tets are cell type 10). Vertex, line and triangle cells are skipped and counted in
/// *info; any other cell type, a BINARY file, a bad count or index, a non-finite coordinate or a
/// degenerate tet is a MeshError "FILE:LINE: ...". Negatively oriented tets are reordered.
TetMesh readVtkTetMesh(const std::string& path, VtkReadInfo* info = nullptr);

/// Write mesh with node positions x (nodes' size; empty: the rest positions), optional
/// per-node vectors (name, values of the nodes' size) and optional line cells (strands) as legacy
/// ASCII VTK, through a temporary file renamed into place. Throws std::runtime_error when the
/// file cannot be written.
void writeVtkTetMesh(const std::string& path, const TetMesh& mesh, const std::vector<Vec3>& x = {},
                     const std::vector<std::pair<std::string, std::vector<Vec3>>>& point_vectors = {},
                     const std::vector<std::array<int, 2>>& lines = {});

/// Write body to path through path.tmp renamed into place (no half-written outputs). Throws
/// std::runtime_error when the file cannot be written.
void writeAtomically(const std::string& path, const std::string& body);

/// ParaView collection (.pvd) of a time series: (time, file name relative to the .pvd) per frame.
void writePvd(const std::string& path, const std::vector<std::pair<double, std::string>>& frames);

}  // namespace redmax
