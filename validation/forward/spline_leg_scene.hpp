#pragma once
// The dissertation's 6.2.10 scene (`redmax scene spline-leg`, docs/forward.md §6): a seated right
// leg (osim_models/spline_leg.osim) whose spline-joint knee and ankle are driven by six Hill-type
// muscles. Gastrocnemii at a constant low excitation, soleus and tibialis anterior on a
// proportional controller of the ankle angle, rectus femoris then semimembranosus excited by
// hand, so the knee extends, then flexes. Four runs through the ForwardTool: spline or revolute
// knee, muscles lumped into the bones (OpenSim's view) or carrying their physiological mass in
// mass points that follow the fibre. The revolute model is the spline model with the knee's two
// translation splines replaced by their values at the default knee angle (written beside the
// results), so both knees start from the same pose.
#include <iosfwd>
#include <string>
#include <vector>

#include "validation/forward/forward_tool.hpp"

namespace redmax::validation {

struct SplineLegOptions {
  std::string model_path;          ///< osim_models/spline_leg.osim
  std::string out_dir;             ///< results, plots and the generated setups and revolute model
  double duration = 1.2;           ///< s
  double tolerance = 1e-7;         ///< rk45 rtol = atol
  double report_interval = 0.005;  ///< s
  bool plots = true;               ///< gnuplot figures (absent gnuplot: reported, not an error)
};

struct SplineLegRun {
  std::string name;  ///< spline_lumped, spline_inertial, revolute_lumped, revolute_inertial
  bool spline = true, inertial = false;
  ForwardResult result;
  double muscle_mass = 0.0;                     ///< kg in mass points
  std::vector<std::string> muscles;             ///< actuated muscles, control order
  std::vector<std::vector<double>> tendon_force;  ///< [muscle][row], N
  std::vector<std::vector<double>> fiber_length;  ///< [muscle][row], m
  std::vector<double> knee, ankle;                ///< rad, per row
};

struct SplineLegResult {
  std::vector<SplineLegRun> runs;
  /// largest distance (m) between the spline knee's tibia origin and the revolute knee's fixed
  /// one, in the femur frame, over the knee angles the spline runs visit
  double knee_centre_offset = 0.0;
  std::vector<std::string> files;  ///< everything written (states, forces, summary, plots)
  std::vector<std::string> plot_notes;  ///< plots not drawn, and why
};

/// Run the four variants, write DIR/<run>_states.sto, DIR/<run>_forces.sto, DIR/summary.txt and
/// the plots; progress and the summary go to `out`. Throws what the ForwardTool throws on bad
/// input and std::runtime_error when a run fails (naming it and the failure).
SplineLegResult runSplineLegScene(const SplineLegOptions& options, std::ostream& out);

/// The revolute-knee variant of a model with a CustomJoint `joint` whose translations are
/// functions of its coordinate: those translation functions replaced by Constants equal to their
/// value at `angle`. Returns the XML text; throws osim::ConvertError when the joint is absent.
std::string revoluteKneeModel(const std::string& model_path, const std::string& joint, double angle);

}  // namespace redmax::validation
