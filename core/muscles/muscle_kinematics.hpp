#pragma once
// The whole muscle pipeline for one musculotendon or a list of them, in stage order:
//   calcPathPoints -> (Type II) calcEulerianCoordinates -> mass points (straight / via_point),
// giving x_a, J_ar = J_am J_mr and Jdot_ar = Jdot_am J_mr + J_am Jdot_mr [D Eq. 5.4-5.5].
// Muscles without mass points stop after the path stage (length and lengthening speed only).
#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/fibre_placement.hpp"
#include "core/muscles/straight.hpp"
#include "core/muscles/via_point.hpp"

namespace redmax {

/// One muscle: path stage, then Eulerian and mass-point stages when it has mass points. With
/// `velocity` also every d/dt quantity (needs the skeleton workspace at Stage::Velocity).
/// Type III paths with mass points go through calcWrapMassPoints (core/muscles/wrap_muscle.hpp).
/// Throws MuscleError for a degenerate path under mass points (or an end point inside a wrap
/// surface), std::logic_error for an unsupported Type III shape with mass points (validateMuscle
/// rejects those up front).
void calcMuscleKinematics(const Model& model, const State& state, const SkeletonWorkspace& sk,
                          const Muscle& muscle, MuscleKinematics& mk, bool velocity = true);
/// The same; a fibre-following muscle (Muscle::fibre) places its points from its states `fs`
/// (fs.z null: equilibrium; core/muscles/fibre_placement.hpp), the others ignore `fs`.
void calcMuscleKinematics(const Model& model, const State& state, const SkeletonWorkspace& sk,
                          const Muscle& muscle, MuscleKinematics& mk, bool velocity, const FibreStates& fs);

/// The mass-point stage alone, after the path stage (mk.x_w, J_xr, segments; velocity fields with
/// mk.velocity): Type I formulas for two active points, else Eulerian coordinates and the EOL
/// construction. Throws MuscleError (naming `muscle_name`) for a degenerate path.
void calcMassPointStage(const MassPoints& mp, MuscleKinematics& mk, const std::string& muscle_name = "");

/// Every muscle of `muscles` into ws.muscles (built as MuscleWorkspace(model, muscles)).
void calcMuscleKinematics(const Model& model, const State& state, const SkeletonWorkspace& sk,
                          const std::vector<Muscle>& muscles, MuscleWorkspace& ws, bool velocity = true);

/// Mass-point kinetic energy 1/2 sum m_a |J_ar qdot + v_z|^2 (qdot with all nr entries) and gravitational potential
/// -sum m_a g . x_a (world origin reference, as the skeleton's), after calcMuscleKinematics.
double muscleKineticEnergy(const MassPoints& mp, const MuscleKinematics& mk, const VecX& qdot);
double musclePotentialEnergy(const MassPoints& mp, const MuscleKinematics& mk, const Vec3& gravity);

}  // namespace redmax
