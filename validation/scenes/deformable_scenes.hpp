#pragma once
// Deformable scenes built in code (docs/deformable.md §4): the FEM cantilever against beam
// theory, a mass-spring strand's energy, and a soft block on a swinging rigid link. Used by
// `redmax scene NAME` (cli/cmd_scene.cpp), the tests and the benchmarks.
#include <array>
#include <ostream>
#include <string>
#include <vector>

#include "core/deformable/node_solver.hpp"
#include "core/deformable/tet_mesh.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::scenes {

/// A steel-free toy beam: length x width x width, clamped at x = 0 (every node there fixed), sagging
/// under its own weight along -y; refinement k gives 10k x k x k cubes.
struct CantileverOptions {
  double length = 1.0, width = 0.1;  // m
  double E = 1e9, nu = 0.0, rho = 1000.0, g = 9.81;
  int refinement = 4;
  CubeSplit split = CubeSplit::Six;
};

struct CantileverResult {
  double tip_deflection = 0.0;  // mean downward displacement of the nodes at x = length (m)
  double beam_theory = 0.0;     // Euler-Bernoulli w L^4 / (8 E I), w = rho g A (m)
  StaticResult solve;
  TetMesh mesh;
  VecX x;                       // deformed node positions (3N)
};

CantileverResult solveCantilever(const CantileverOptions& opt);

/// One 1 m, 1 kg rigid link hinged about z at the origin, hanging along -y, gravity -9.81 y.
Model singlePendulum();

/// Positions, energies and coordinates of a simulated scene at its output times.
struct DeformableRun {
  std::vector<double> t;                     // output times (s)
  std::vector<VecX> q;                       // system coordinates at each output
  std::vector<double> energy;                // kinetic + potential (J)
  std::vector<std::vector<Vec3>> nodes;      // node positions at each output
  std::vector<std::string> coordinates;      // names of q's entries
  TetMesh mesh;                              // tets (empty for a strand) with rest positions
  std::vector<std::array<int, 2>> lines;     // strand segments
};

/// A strand of `segments` springs, straight along +x from a node fixed at the origin, released at
/// rest under gravity; zero damping.
struct StrandOptions {
  int segments = 10;
  double length = 1.0, mass = 0.1, stiffness = 10.0;  // m, kg, J (V = k/2 eps^2 per segment)
  double dt = 1e-4, duration = 2.0, frame_interval = 0.02;
  std::string integrator = "symplectic";
  double tolerance = 1e-8;  // rtol of adaptive integrators (atol 1e-2 of it)
};
DeformableRun runStrand(const StrandOptions& opt);

/// A soft block (0.2 x 0.1 x 0.1 m, 2k x k x k cubes, co-rotated FEM) whose top face is attached
/// to the tip of singlePendulum(), released at rest from angle q0 undeformed. `rigid` attaches
/// every node to the link: the rigid limit of the same lumped masses.
struct SoftPendulumOptions {
  double E = 1e6, nu = 0.3, rho = 500.0;
  double rayleigh_mass = 0.0, rayleigh_stiffness = 0.0;
  int refinement = 2;
  bool rigid = false;
  double q0 = 1.0;
  double dt = 1e-3, duration = 1.0, frame_interval = 0.02;
  std::string integrator = "bdf1";
  double tolerance = 1e-8;  // rtol of adaptive integrators (atol 1e-2 of it)
};
DeformableRun runSoftPendulum(const SoftPendulumOptions& opt);

/// A muscle inserting on soft tissue (issue 24): singlePendulum() with a soft block on its tip (as
/// SoftPendulumOptions), and a Thelen2003 muscle from a point fixed in the world to a free node at
/// the block's far bottom corner, with inertial mass points (Type I chain through the node's
/// coordinates, musclePointAtNode). From rest, constant excitation: the muscle pulls the soft
/// tissue, which deforms and swings the link. `rigid` attaches every node to the link (the
/// insertion is then a point of the link): the rigid limit of the same masses.
struct SoftInsertionOptions {
  double E = 2e5, nu = 0.3, rho = 1000.0;
  double rayleigh_mass = 1.0, rayleigh_stiffness = 0.0;
  int refinement = 2;
  bool rigid = false;
  double excitation = 0.5;
  double max_isometric_force = 300.0, optimal_fiber_length = 0.3, tendon_slack_length = 0.5;  // N, m, m
  double muscle_mass = 0.2;  // kg, spread over the fibre's share of the path
  int mass_points = 10;
  double dt = 1e-3, duration = 0.6, frame_interval = 0.02;
  std::string integrator = "bdf1";
  double tolerance = 1e-8;  // rtol of adaptive integrators (atol 1e-2 of it)
};
struct SoftInsertionRun {
  DeformableRun run;
  std::vector<double> tendon_force;      // N, at each output
  std::vector<double> insertion_offset;  // m: the insertion node's distance from where the link would carry it
  int insertion_node = -1;
};
SoftInsertionRun runSoftInsertion(const SoftInsertionOptions& opt);

/// the names `redmax scene` accepts
std::vector<std::string> deformableSceneNames();

/// Run scene `name` with its defaults and write into out_dir (created): states.csv (time and
/// coordinates, or node displacements for the static cantilever), NAME_NNNN.vtk per output frame
/// and NAME.pvd; a summary on `summary`. Throws std::invalid_argument for an unknown name.
void runDeformableScene(const std::string& name, const std::string& out_dir, std::ostream& summary);

}  // namespace redmax::scenes
