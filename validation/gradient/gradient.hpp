#pragma once
// `redmax gradient`: an OpenSim model, parameter and objective SPECs (docs/gradients.md §3) turned
// into an adjoint problem (core/adjoint/adjoint.hpp).
//
//   --params    groups separated by ';':
//                 torques:C[@K][=V],...   a constant generalized force on coordinate C (N m or N),
//                                         in K equal time pieces (default 1), start value V (0)
//                 excitations:M[@K][=V],...  the excitation of muscle M as K nodes of a piecewise-
//                                         linear function of time (default 1: constant), start
//                                         value V (default 0.1, within the muscle's bounds); with
//                                         this group the muscles pull (MuscleForceTerm: every
//                                         muscle with a Hill-type model, its activation and fibre
//                                         length in z, equilibrated at the start), the others at
//                                         their min_control
//                 q0:C[=V],...            the initial value of C (default: the model's)
//                 qdot0:C[=V],...         the initial speed of C
//                 masses:M,...            the mass of muscle M (needs --muscle-mass-kg M=KG)
//   --objective terms separated by ';', each [W*]TERM with weight W (default 1):
//                 point:BODY@x,y,z=X,Y,Z  W/2 |p - target|^2 for the point (x,y,z) of BODY (body
//                                         frame, m) against the ground point (X,Y,Z) at the end
//                 marker:NAME=X,Y,Z       the same for a marker of the model's MarkerSet
//                 track:MARKER=FILE.trc   W/2 sum_k h |p(t_k) - target(t_k)|^2 against a TRC's marker
//                 coords:FILE.mot[@C,...] W/2 sum_k h sum_c (q_c(t_k) - q_file(t_k))^2 over the
//                                         model's coordinates the motion has (or the named ones),
//                                         Rotational ones from degrees per the file's inDegrees,
//                                         linear between rows that must cover the run
//                 speed                   W/2 |qdot|^2 at the end
//                 effort                  W * integral of the squared generalized forces
//                 excitation              W * integral of the squared excitations (of the muscles
//                                         the excitation parameters drive)
#include <string>
#include <vector>

#include "core/adjoint/adjoint.hpp"
#include "validation/simulate/simulate.hpp"

namespace redmax::validation {

struct GradientSetup {
  adjoint::Problem problem;
  adjoint::Objective objective;
  VecX p0;                               ///< the parameter values the SPEC gives
  std::vector<std::string> param_names;  ///< e.g. "torque elbow_flexion piece 2/10", "mass BIClong"
  SimulationModel model;                 ///< the model at p0's system parameters
  std::vector<std::string> warnings;     ///< building the ForceSet's terms (also in model.build.warnings' style)
  std::vector<std::string> not_applied;  ///< forces and geometry the gradient's system leaves out, one line each
};

/// m's system plus the model's MuscleForceTerm (every muscle with a Hill-type model pulls), as
/// `redmax forward` builds it, with fibre-following mass points bound to the muscles' states.
std::shared_ptr<System> withMuscleForces(const SimulationModel& m);

/// Throws std::invalid_argument with a message naming the SPEC item for a bad SPEC (unknown
/// coordinate, body, muscle, malformed number), osim::ConvertError / ModelError for the model.
GradientSetup makeGradientSetup(const std::string& osim_path, const SimulationModelOptions& options,
                                const std::string& integrator, double duration, double dt,
                                const std::string& params_spec, const std::string& objective_spec);

}  // namespace redmax::validation
