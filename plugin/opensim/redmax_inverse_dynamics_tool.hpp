#pragma once
// RedmaxInverseDynamicsTool: OpenSim's InverseDynamicsTool with muscle mass (docs/muscle_mass.md,
// MUSCLE-MASS OPTIONS), as an OpenSim object type that `opensim-cmd -L libredmax_opensim.so
// run-tool SETUP.xml` runs.
//
// The setup file is an InverseDynamicsTool setup whose element is <RedmaxInverseDynamicsTool>;
// every InverseDynamicsTool property keeps its meaning (model_file, coordinates_file,
// lowpass_cutoff_frequency_for_coordinates, time_range, forces_to_exclude, external_loads_file,
// results_directory, output_gen_force_file; joints_to_report_body_forces is not supported), plus:
//   muscle_mass        none | physiological | transfer            (default none)
//   muscles            all | top:K | regular expression            (default all)
//   mass_points        points per muscle                           (default 20)
//   specific_tension   Pa                                          (default 0.6e6)
//   muscle_density     kg/m^3                                      (default 1059.7)
//   transfer_body      body name (transfer only)
//   transfer_fraction  in [0, 1) (transfer only)
//   full_precision     write %.16e instead of OpenSim's %16.8lf    (default false)
//
// What run() computes, per output frame t (docs/opensim_compatibility.md §7 for OpenSim's part):
//   1. OpenSim's own input processing and solver on the OpenSim model: the coordinates file
//      padded, filtered, converted to radians and splined as OpenSim does; q, u, udot from the
//      splines; tau_osim = InverseDynamicsSolver::solve (calcResidualForceIgnoringConstraints).
//   2. With muscle mass: redmax's converter reads the same .osim and applyMuscleMass
//      (converter/build/muscle_mass.hpp) decides each muscle's mass points and the bodies' new mass
//      properties; those are written into the OpenSim model before its system is built, and
//      tau = tau_osim + f_u, with f_u the mass points' generalized forces computed on OpenSim's
//      own Simbody system (plugin/opensim/matter_muscle_inertia.hpp) [D Eq. 5.4-5.7].
//   3. The result is written as `redmax id` writes it: name "Inverse Dynamics Generalized
//      Forces", version=1, inDegrees=no, time then <coord>_moment (Rotational) or <coord>_force in
//      u order, N m or N; atomically (converter/atomic_file.hpp).
// Relative paths are resolved against the setup file's folder.
#include <memory>
#include <string>
#include <vector>

#include <OpenSim/Common/Function.h>  // InverseDynamicsTool.h needs it complete
#include <OpenSim/Tools/InverseDynamicsTool.h>

#include "converter/build/muscle_mass.hpp"
#include "converter/storage.hpp"

namespace redmax::opensim {

class RedmaxInverseDynamicsTool : public OpenSim::InverseDynamicsTool {
  OpenSim_DECLARE_CONCRETE_OBJECT(RedmaxInverseDynamicsTool, OpenSim::InverseDynamicsTool);

 public:
  OpenSim_DECLARE_PROPERTY(muscle_mass, std::string,
                           "Muscle mass source: none (the model as OpenSim sees it), physiological or transfer.");
  OpenSim_DECLARE_PROPERTY(muscles, std::string,
                           "Which muscles get mass: all, top:K, or a regular expression matched against the whole name.");
  OpenSim_DECLARE_PROPERTY(mass_points, int, "Mass points per muscle (>= 1).");
  OpenSim_DECLARE_PROPERTY(specific_tension, double,
                           "Specific tension (Pa): physiological mass = density * F_max / tension * optimal fiber length.");
  OpenSim_DECLARE_PROPERTY(muscle_density, double, "Muscle density (kg/m^3).");
  OpenSim_DECLARE_PROPERTY(transfer_body, std::string,
                           "transfer only: the body whose mass moves into the muscles that span it.");
  OpenSim_DECLARE_PROPERTY(transfer_fraction, double, "transfer only: the fraction of the body's mass moved, in [0, 1).");
  OpenSim_DECLARE_PROPERTY(full_precision, bool, "Write %.16e instead of OpenSim's %16.8lf.");

  RedmaxInverseDynamicsTool();
  /// read a setup file (element <RedmaxInverseDynamicsTool>)
  explicit RedmaxInverseDynamicsTool(const std::string& setup_file);

  /// Solve and write the output file. Throws OpenSim::Exception with "FILE: message" for bad
  /// input (unreadable files, bad muscle-mass options, a model redmax cannot convert for muscle
  /// mass) and a frame with non-finite generalized forces; returns true on success.
  bool run() override;

  /// the muscle-mass options of the properties; throws std::invalid_argument for bad values
  osim::MuscleMassOptions muscleMassOptions() const;
  /// the result of the last run() (also written to the output file)
  const osim::Storage& result() const { return result_; }
  /// what the muscle-mass options did in the last run() (empty plan for none)
  const osim::MuscleMassPlan& muscleMassPlan() const { return plan_; }
  /// the output file the last run() wrote
  const std::string& outputPath() const { return output_path_; }

 private:
  void constructProperties();
  osim::Storage result_;
  osim::MuscleMassPlan plan_;
  std::string output_path_;
};

/// Register the plugin's object types with OpenSim (done when the library is loaded; call it
/// again harmlessly from programs that link the library).
void registerTypes();

}  // namespace redmax::opensim

/// C entry point with OpenSim's plugin naming (RegisterTypes_<library>)
extern "C" void RegisterTypes_redmax_opensim();
