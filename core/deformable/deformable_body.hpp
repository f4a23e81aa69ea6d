#pragma once
// A deformable body in node space [D Sec. 4.6.3]: N nodes with rest positions and lumped masses,
// mass-spring strands [D Eq. 4.87-4.89] and co-rotated linear tetrahedra (core/deformable/
// elements.hpp), and Rayleigh damping D = alpha M + beta K(x). How the nodes enter a System
// (free, on a body, fixed in the world) is the DeformableTerm's (core/deformable/deformable_term.hpp).
#include <array>
#include <vector>

#include <Eigen/Sparse>

#include "core/deformable/tet_mesh.hpp"
#include "core/spatial/types.hpp"

namespace redmax {

using SparseMat = Eigen::SparseMatrix<double>;

/// Axial spring between nodes a and b [D Eq. 4.88]: rest length L (m), stiffness k (J; V = k/2 eps^2).
struct Spring {
  int a = 0, b = 0;
  double rest_length = 0.0;
  double stiffness = 0.0;
};

/// Co-rotated linear tetrahedron: nodes, inverse rest shape Dm^-1, rest volume, Lame parameters.
struct Tet {
  std::array<int, 4> n{};
  Mat3 Dm_inv = Mat3::Identity();
  double volume = 0.0;
  double mu = 0.0, lambda = 0.0;
};

/// How a tet's mass reaches its nodes: lumped (a quarter to each node: a diagonal mass matrix) or
/// consistent (the linear shape functions' mass matrix rho V / 20 (1 + delta_ab) per node pair)
enum class MassModel { Lumped, Consistent };

struct DeformableBody {
  std::vector<Vec3> rest;    // rest positions X (world, m)                (N)
  /// node masses (kg) (N): the lumped masses, which are also the row sums of a consistent mass
  /// matrix, so gravity loads (M_x g = mass g per node) are the same in both models
  std::vector<double> mass;
  /// the consistent node mass matrix (N x N, kg; one entry per node pair, times I3 per coordinate);
  /// empty: the diagonal of `mass`
  SparseMat node_mass;
  std::vector<Spring> springs;
  std::vector<Tet> tets;
  double rayleigh_mass = 0.0;       // alpha (1/s)
  double rayleigh_stiffness = 0.0;  // beta (s)
  TetMesh mesh;                     // the tets as a mesh (VTK output); empty for strands
  int numNodes() const { return static_cast<int>(rest.size()); }
};

/// A strand of springs through `points` (in order): each segment of rest length L_i gets
/// stiffness k (J) and each node half the mass of its segments, total `mass` spread by length.
/// Throws std::invalid_argument for fewer than 2 points, a zero-length segment or a non-positive
/// mass or stiffness.
DeformableBody makeStrand(const std::vector<Vec3>& points, double mass, double stiffness);

/// Co-rotated FEM body of `mesh` with Young's modulus E (Pa), Poisson's ratio nu in [0, 0.5) and
/// density rho (kg/m^3), with lumped (default) or consistent mass.
/// Throws std::invalid_argument for bad parameters or a degenerate tet.
DeformableBody makeFemBody(const TetMesh& mesh, double E, double nu, double rho, MassModel mass = MassModel::Lumped);

/// The 3N x 3N node-coordinate mass matrix M_x: node_mass (x) I3, or diag(mass) (x) I3.
SparseMat nodeMassMatrix(const DeformableBody& body);

/// Node-space evaluation at positions x (3N): elastic energy, elastic forces f (3N) and, when
/// asked, the stiffness K = -df/dx (3N x 3N, symmetric: the exact Hessian of the energy).
struct ElasticEvaluation {
  double energy = 0.0;
  VecX f;
  SparseMat K;
};
void evalElastic(const DeformableBody& body, const VecX& x, bool stiffness, ElasticEvaluation& out);

/// The rest positions stacked (3N).
VecX restPositions(const DeformableBody& body);

}  // namespace redmax
