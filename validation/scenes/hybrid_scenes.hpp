#pragma once
// Hybrid-dynamics scenes of [D Sec. 6.1.2-6.1.3] built in code (docs/deformable.md §6): the hand
// (DIP = 0.5 PIP by hyper-reduced coordinates, fingertips prescribed in maximal coordinates, the
// elbow prescribed in reduced coordinates) and the starfish (a 20-joint skeleton inside a
// co-rotated FEM mesh, some joints prescribed, fully implicit). Used by `redmax scene NAME`.
#include <array>
#include <ostream>
#include <string>
#include <vector>

#include "core/deformable/tet_mesh.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::scenes {

/// A recorded run: skeleton coordinates, extra columns and points (for the VTK series) per frame.
struct HybridRun {
  std::vector<double> t;
  std::vector<std::string> columns;          // names of each row's entries (after time)
  std::vector<VecX> rows;                    // per frame: the values of `columns`
  std::vector<std::vector<Vec3>> points;     // per frame
  TetMesh mesh;                              // tets over `points` (empty for the hand)
  std::vector<std::array<int, 2>> lines;     // segments over `points`
};

/// The hand [D Sec. 6.1.3]: an upper arm fixed in the world, the forearm on an elbow hinge (z),
/// a palm on a 2-dof wrist (flexion z, deviation y), four fingers each with a 2-dof MCP
/// (flexion, abduction), PIP and DIP hinges; gravity -9.81 y. Coordinate order: elbow, wrist
/// flexion, wrist deviation, then per finger MCP flexion, MCP abduction, PIP, DIP.
Model handModel();

struct HandOptions {
  double dt = 1e-3, duration = 2.0, frame_interval = 0.02;
  std::string integrator = "bdf1";
  double elbow_amplitude = 0.02, elbow_frequency = 0.5;   // rad, Hz: elbow(t) = e0 + A sin(2 pi f t)
  double tip_radius = 0.002, tip_frequency = 1.0;        // m, Hz: each tip circles in the xy-plane
  bool project = true;  // project positions (tolerance 1e-14) and velocities after every step
};

struct HandResult {
  HybridRun run;
  int nr = 0, nR = 0, rows = 0;          // skeleton and hyper-reduced coordinates, constraint rows
  // largest errors over all steps, after the step's projection and within the step before it
  double point_error = 0.0, angle_error = 0.0;            // m, rad
  double point_step_error = 0.0, angle_step_error = 0.0;  // m, rad
  double coupling_deviation = 0.0;  // largest |DIP - 0.5 PIP| (rad)
  double max_elbow_torque = 0.0;    // N m, the elbow prescription's multiplier
  double max_tip_force = 0.0;       // N, largest fingertip prescription force
};
HandResult runHand(const HandOptions& opt);

/// A star-shaped slab of tets in the xz-plane [D Sec. 6.1.2]: `arms` arms of outer radius r_out
/// around a disc of radius r_in, `angles` nodes around, `rings` rings out to the rim,
/// `layers` + 1 node layers through the thickness (centred on y = 0); each prism is split into 3
/// tets by the smallest-index rule, so faces conform. The rim radius at angle a (from the x axis)
/// is r_in + (r_out - r_in) ((1 + cos(arms a)) / 2)^2.
TetMesh makeStarTetMesh(int arms = 5, double r_in = 0.05, double r_out = 0.45, double thickness = 0.06,
                        int angles = 20, int rings = 4, int layers = 2);

/// The starfish [D Sec. 6.1.2]: five arms of four hinged links (20 joints) from a disc on a free
/// joint, inside a co-rotated FEM mesh (makeStarTetMesh, 243 nodes) whose nodes at the disc are on
/// the disc and whose nodes next to a link are attached to it [D Eq. 4.90]; the disc's centre
/// prescribed (a point in maximal coordinates, bobbing (0, B sin(2 pi f_d t), 0)), its orientation
/// passive; the first joint of every arm prescribed (q = A sin(2 pi f t + 2 pi a / 5) -
/// A sin(2 pi a / 5)), the other 15 and the free nodes passive, gravity -9.81 y; bdf1 with the
/// mesh's K and D (fully implicit coupling).
struct StarfishOptions {
  double E = 1e5, nu = 0.3, rho = 1000.0;                 // Pa, -, kg/m^3
  double rayleigh_mass = 1.0, rayleigh_stiffness = 0.01;  // 1/s, s
  double link_mass = 0.05, disc_mass = 0.2;              // kg
  double disc_amplitude = 0.02, disc_frequency = 0.5;     // m, Hz
  double amplitude = 0.3, frequency = 1.0;                // rad, Hz
  double dt = 2e-3, duration = 2.0, frame_interval = 0.04;
  std::string integrator = "bdf1";
};

struct StarfishResult {
  HybridRun run;
  int joints = 0, prescribed = 0, nodes = 0, attached = 0, tets = 0, ndof = 0, steps = 0;
  double wall_seconds = 0.0;            // measured, not asserted
  double prescribed_error = 0.0;        // largest |q_k - q_p(t)| of the prescribed joints (rad)
  double max_torque = 0.0;              // largest prescribed-joint torque at the frames (N m)
  double point_error = 0.0;             // largest |x_disc - x_p(t)| (m)
  double max_disc_force = 0.0;          // largest force the disc's prescription takes (N)
  double min_volume_ratio = 0.0;        // smallest tet volume / rest volume over all frames
  double max_kinetic = 0.0, final_kinetic = 0.0;  // J (kinetic energy of skeleton and mesh)
};
StarfishResult runStarfish(const StarfishOptions& opt);

/// the names `redmax scene` accepts from here
std::vector<std::string> hybridSceneNames();

/// Run scene `name` with its defaults, write out_dir/states.csv and a VTK series (NAME_NNNN.vtk,
/// NAME.pvd) and a summary on `summary`. Throws std::invalid_argument for an unknown name.
void runHybridScene(const std::string& name, const std::string& out_dir, std::ostream& summary);

}  // namespace redmax::scenes
