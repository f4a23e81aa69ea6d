#pragma once
// The last step of the converter: the plain-data model description (converter/model_description.hpp)
// -> one core MusculoskeletalModel (core/model/musculoskeletal_model.hpp: the skeleton Model, its
// constraints, an optional coordinate map, and muscles), so that converted OpenSim models run in
// the REDMAX core, plus the bookkeeping that ties it to the description.
//
// Bodies. Core bodies are created in the description's mobilizer order (tree.mobilizers, the
// order Simbody creates MobilizedBodies, docs/opensim_compatibility.md §3.1), so parents precede children
// and the core's q vector is the description's coordinate list, i.e. OpenSim's multibody-tree
// order (ID columns come out in OpenSim's order). Mass, COM and inertia (about the COM, products
// as matrix entries) are taken as given; a massless body keeps zero inertia (Simbody zeroes the
// inertia of a massless body). A body split to cut a loop shares its master's mass properties
// equally with its slaves and is welded to them (a WeldConstraint from the tree builder).
//
// Joints (3.2-3.3), X_PF and X_BM as composed through offset-frame chains:
//   WeldJoint -> Fixed;  PinJoint -> Revolute z;  SliderJoint -> Prismatic x;
//   UniversalJoint -> Universal (x then y);  GimbalJoint, BallJoint -> SphericalEuler XYZ;
//   FreeJoint -> Free3D::opensim();  PlanarJoint -> FunctionBased (rz, tx, ty),
//     X_FM = (Rz(rz), (tx, ty, 0) in F);  EllipsoidJoint -> Ellipsoid;
//   ScapulothoracicJoint -> Composite{Ellipsoid, constant offset, Revolute z} with the frames of
//     Simbody's Ellipsoid -> massless -> Pin (winging) -> massless -> Weld chain folded into E_pf
//     and E_bm (see build_core_model.cpp);
//   CustomJoint -> FunctionBased (axes as written, coordinate lists in mobility order, functions
//     from functions_to_core.hpp; Simbody-compatible velocity terms by BuildOptions).
// Every core joint uses qdot = dq/dt; OpenSim's Euler-rate quirk for Ball/Free/Ellipsoid in ID is
// not reproduced here. A joint the tree builder reversed (its child is inboard) becomes
// Reversed{joint} with E_pf = X_BM and E_bm = X_PF, so its coordinates keep their meaning.
//
// Constraints (section 5), each optional: CoordinateCouplerConstraint -> CoordinateCoupler, or an
// elimination in a CoordinateMap; WeldConstraint (file and loop closures) -> WeldConstraint;
// PointConstraint -> PointConstraint; locked coordinates -> PrescribedCoordinate::makeLocked at
// the default value; prescribed coordinates with a function -> PrescribedCoordinate. Inverse
// dynamics ignores all of them (OpenSim's ID does); forward simulation wants them.
//
// Muscles (section 6): every force with a path -> a core Muscle (PathPoint -> fixed point,
// ConditionalPathPoint -> conditional point, MovingPathPoint -> moving point whose functions see
// the coordinate clamped to its range, as OpenSim's do). Locations given in offset frames are
// moved into the body frame. Each PathWrap becomes a core PathWrap (surface, body, pose in the
// body, method, range) in MusclePath::wraps, which calcPathLength follows as OpenSim does. No mass:
// addMusclePointMasses() gives muscles mass points.
#include <memory>
#include <string>
#include <vector>

#include "converter/error.hpp"
#include "converter/model_description.hpp"
#include "core/dynamics/constraint.hpp"
#include "core/dynamics/coordinate_map.hpp"
#include "core/dynamics/system.hpp"
#include "core/model/musculoskeletal_model.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::osim {

/// how CoordinateCouplerConstraints are handled when constraints are on
enum class CouplerHandling {
  Constraint,  ///< a CoordinateCoupler row in the KKT system
  Eliminate    ///< the dependent coordinate becomes a function of the others (CoordinateMap)
};

struct BuildOptions {
  /// FunctionBased (CustomJoint) joints reproduce Simbody's approximate velocity terms
  /// (function_based.hpp) instead of exact kinematics
  bool simbody_compat = false;
  /// master switch for everything constraint-like below (off: inverse dynamics, lengths)
  bool constraints = true;
  CouplerHandling couplers = CouplerHandling::Constraint;
  /// WeldConstraint / PointConstraint from the file and the loop-closure welds of split bodies
  bool body_constraints = true;
  /// coordinates with locked = true held at their default value
  bool locked_coordinates = true;
  /// coordinates with prescribed = true and a prescribed_function follow it in time
  bool prescribed_coordinates = true;
  /// build the muscles (every force with a geometry path)
  bool muscles = true;
};

struct BuildResult {
  /// The model: skeleton, constraints (empty when BuildOptions::constraints is false), the
  /// coordinate map when couplers are eliminated (null otherwise), and one muscle per built path
  /// force, massless (no mass points), in description order, read as its OpenSim class.
  /// Immutable: edits (muscle mass) go through a MusculoskeletalModelBuilder.
  MusculoskeletalModel model;

  // bookkeeping of the conversion (not model data)
  /// the options the model was built with
  BuildOptions options;
  /// index into ModelDescription::muscles of each built muscle
  std::vector<int> muscle_source;
  /// ModelDescription::bodies[k] -> core body index (-1 if it has none)
  std::vector<int> body_index;
  /// core body -> the description body whose mass properties it carries (a split body's slaves
  /// carry their master's), and the share of them it carries (1 / (1 + slaves))      (nb)
  std::vector<int> body_source;
  std::vector<double> body_mass_share;
  /// ModelDescription::coordinates[k] -> core coordinate index (-1 if it has none, e.g. the
  /// coordinates of a joint that is not modelled); the identity for every supported model
  std::vector<int> coordinate_index;
  /// items of the description that are not built, with the reason (the description's own
  /// unsupported list is not repeated here)
  std::vector<UnsupportedItem> unsupported;
  std::vector<std::string> warnings;

  /// a System over the model with the constraints and the coordinate map (no muscle term)
  System makeSystem() const { return model.makeSystem(); }
};

/// Build the core model. Throws ConvertError ("FILE:LINE: what") when the description cannot be
/// built: a function that cannot be evaluated on a joint axis, a joint whose coordinates do not
/// match its type, a tree body that is missing; and ModelError from the core for invalid data that
/// passed the reader. Items that can be left out without changing the skeleton (a muscle whose
/// path the core rejects, a constraint of an unsupported kind) go to BuildResult::unsupported.
BuildResult buildCoreModel(const ModelDescription& d, const BuildOptions& options = {});

/// The core mass properties of a body carrying `share` of description body b's (mass, centre of
/// mass, inertia about it); a massless body gets zero inertia, as Simbody does (`zeroed` set).
struct CoreMassProperties {
  double mass = 0.0;
  Vec3 com = Vec3::Zero();
  Mat3 inertia_com = Mat3::Zero();
  bool zeroed = false;  ///< a nonzero inertia of a massless body was set to zero
};
CoreMassProperties coreMassProperties(const BodyDesc& b, double share);

/// The muscles with mass points: muscle k gets masses[k] kg (0 keeps it massless) spread by
/// makeMassPoints over its fibre. Throws ModelError if the sizes differ, a mass is negative or
/// not finite, or a Type III (wrapping) muscle is given mass.
std::vector<Muscle> addMusclePointMasses(const std::vector<Muscle>& muscles,
                                         const std::vector<double>& masses,
                                         const MassPointOptions& options = {});

/// The core joint that reproduces one description joint between its frames F and M:
/// joint (forward direction, not reversed) and the constant frames F' = F * F_post, M' = M * M_post
/// it acts between (identity except for ScapulothoracicJoint). Throws ConvertError.
struct CoreJoint {
  Joint joint;
  Mat4 F_post = Mat4::Identity();
  Mat4 M_post = Mat4::Identity();
};
CoreJoint makeCoreJoint(const ModelDescription& d, const JointDesc& j, bool simbody_compat);

}  // namespace redmax::osim
