#pragma once
// The intermediate model description: an OpenSim model as plain data, after the legacy upgrades
// of docs/opensim_compatibility.md §1.4 and with every socket resolved. No simulation state lives here.
//
// Frames follow the OpenSim/Simbody monogram notation: X_AB is the pose of frame B in frame A
// (a 4x4 homogeneous matrix, x_A = X_AB * x_B). For a joint, P is the parent body, F the joint
// frame on the parent, B the child body and M the joint frame on the child, so that
// X_GB = X_GP * X_PF * X_FM(q) * inverse(X_BM)   [semantics §2].
// Units are SI, angles radians. Body names refer to BodyDesc::name or to the ground's name.
#include <array>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/muscles/hill/parameters.hpp"
#include "core/spatial/types.hpp"

namespace redmax::osim {

/// R = Rx(a) Ry(b) Rz(c): OpenSim's body-fixed XYZ orientation (offset frames, wrap objects).
Mat3 rotationBodyFixedXYZ(const Vec3& angles);
/// pose [R p; 0 1] with R = rotationBodyFixedXYZ(orientation), p = translation
Mat4 makePose(const Vec3& translation, const Vec3& orientation);

// ---------------------------------------------------------------------------------------------
// functions (semantics §4): stored as data, evaluated by core/joints/functions.hpp builders

enum class FunctionKind {
  Constant,               ///< value
  Linear,                 ///< coefficients = [slopes..., intercept]; n+1 coefficients, n args
  Polynomial,             ///< coefficients in decreasing powers
  SimmSpline,             ///< x, y (NaturalCubicSpline and natCubicSpline are aliases)
  GCVSpline,              ///< half_order, error_variance, x, y (weights/coefficients ignored)
  Multiplier,             ///< scale * inner[0]
  PiecewiseLinear,        ///< x, y
  PiecewiseConstant,      ///< x, y
  Sine,                   ///< amplitude sin(omega x + phase) + offset
  Step,                   ///< start_time, end_time, start_value, end_value
  MultivariatePolynomial, ///< dimension, order, coefficients
  ExpressionBased,        ///< expression (not evaluable here: reported as unsupported)
};

struct FunctionDesc {
  FunctionKind kind = FunctionKind::Constant;
  std::string type = "Constant";  ///< OpenSim class after aliases (e.g. "SimmSpline")
  std::string written_type;       ///< tag as written in the file (e.g. "NaturalCubicSpline")
  int line = 0;
  double value = 0.0;
  std::vector<double> coefficients;
  std::vector<double> x, y;
  int half_order = 0;
  double error_variance = 0.0;
  double scale = 1.0;
  std::vector<FunctionDesc> inner;  ///< Multiplier: exactly one scaled function
  double amplitude = 1.0, omega = 1.0, phase = 0.0, offset = 0.0;
  double start_time = 0.99, end_time = 1.01, start_value = 0.0, end_value = 1.0;
  int dimension = 0, order = 0;
  std::string expression;

  /// number of arguments: Constant 0, Linear coefficients-1, MultivariatePolynomial dimension,
  /// Multiplier that of its inner function, otherwise 1
  int numArguments() const;
  /// true when this is a LinearFunction whose first slope is exactly +1 or -1 (§3.4)
  bool isUnitSlopeLinear() const;
};

// ---------------------------------------------------------------------------------------------
// bodies and frames

struct BodyDesc {
  std::string name;
  double mass = 0.0;
  Vec3 mass_center = Vec3::Zero();  ///< in the body frame
  /// [Ixx Iyy Izz Ixy Ixz Iyz] about the COM, body axes; products are matrix entries (§2)
  Eigen::Matrix<double, 6, 1> inertia = Eigen::Matrix<double, 6, 1>::Zero();
  int line = 0;
  /// 3x3 inertia about the COM in body axes
  Mat3 inertiaMatrix() const;
};

/// a PhysicalOffsetFrame (joint frames, body/ground/model components, constraint frames)
struct FrameDesc {
  std::string path;         ///< absolute component path, e.g. "/jointset/knee_r/femur_r_offset"
  std::string name;
  std::string parent_path;  ///< resolved absolute path of the frame it is offset from
  std::string base_body;    ///< body (or ground) the frame is fixed to
  Vec3 translation = Vec3::Zero();  ///< in the parent frame
  Vec3 orientation = Vec3::Zero();  ///< body-fixed XYZ angles relative to the parent frame
  Mat4 X_base = Mat4::Identity();   ///< pose of this frame in base_body (offset chain composed)
  int line = 0;
};

// ---------------------------------------------------------------------------------------------
// joints and coordinates

enum class JointKind {
  Weld, Pin, Slider, Ball, Gimbal, Universal, Free, Planar, Ellipsoid, Scapulothoracic, Custom,
  Unsupported  ///< an OpenSim joint class the converter does not model (listed in unsupported)
};

enum class MotionType { Rotational, Translational, Coupled, Undefined };
const char* toString(MotionType m);

/// one of the six axes of a CustomJoint's SpatialTransform (§3.3)
struct TransformAxisDesc {
  std::string name;                      ///< rotation1..3, translation1..3
  std::vector<std::string> coordinates;  ///< names, in listed order (the function's arguments)
  std::vector<int> mobilities;           ///< the same coordinates as mobility indices of the joint
  Vec3 axis = Vec3::UnitX();             ///< as written (not normalized), expressed in F
  FunctionDesc function;                 ///< value = angle (rad) or displacement (m)
  int line = 0;
};

struct JointDesc {
  std::string name;
  std::string type;  ///< OpenSim class, e.g. "CustomJoint"
  JointKind kind = JointKind::Unsupported;
  int line = 0;
  std::string parent_frame, child_frame;  ///< absolute paths of the socket frames
  std::string parent_body, child_body;    ///< base bodies of those frames
  Mat4 X_PF = Mat4::Identity();           ///< parent joint frame F in the parent body
  Mat4 X_BM = Mat4::Identity();           ///< child joint frame M in the child body
  /// indices into ModelDescription::coordinates, in the joint's mobility (q) order
  std::vector<int> coordinates;
  /// CustomJoint only: rotation1, rotation2, rotation3, translation1, translation2, translation3
  std::array<TransformAxisDesc, 6> spatial_transform;
  Vec3 radii = Vec3::Zero();  ///< EllipsoidJoint radii_x_y_z; Scapulothoracic thoracic radii
  Vec2 winging_origin = Vec2::Zero();  ///< Scapulothoracic winging axis origin (x, y)
  double winging_direction = 0.0;      ///< Scapulothoracic winging axis direction (rad)
  bool added = false;                  ///< FreeJoint added for a body no joint connects (§3.1)
  bool reversed_in_file = false;       ///< legacy <reverse>true: parent/child frames swapped
};

struct CoordinateDesc {
  std::string name;
  std::string joint;    ///< owning joint's name
  int joint_index = -1; ///< into ModelDescription::joints
  int mobility = 0;     ///< index within the joint's q
  MotionType motion_type = MotionType::Undefined;
  double default_value = 0.0, default_speed_value = 0.0;
  double range_min = -10.0, range_max = 10.0;
  bool clamped = false, locked = false, prescribed = false;
  bool is_free_to_satisfy_constraints = false;
  std::optional<FunctionDesc> prescribed_function;
  std::string legacy_motion_type;  ///< motion_type written by pre-4.0 files (informational)
  int declared_index = 0;          ///< position in file order (the q order is the list order)
  int line = 0;
};

// ---------------------------------------------------------------------------------------------
// constraints (§5)

enum class ConstraintKind { CoordinateCoupler, Weld, Point, Unsupported };

struct ConstraintDesc {
  std::string name;
  std::string type;  ///< OpenSim class
  ConstraintKind kind = ConstraintKind::Unsupported;
  bool enforced = true;
  int line = 0;
  /// "" for constraints from the file; otherwise why the tree builder made it (loop closure)
  std::string generated_by;
  // CoordinateCoupler: scale * f(independent) - dependent = 0
  std::vector<std::string> independent_coordinates;
  std::string dependent_coordinate;
  std::optional<FunctionDesc> function;
  double scale_factor = 1.0;
  // Weld: two frames held coincident; Point: two stations held coincident
  std::string frame1, frame2;              ///< Weld: frame paths
  std::string body1, body2;                ///< base bodies of frame1/frame2 (Weld), bodies (Point)
  Mat4 X_B1F1 = Mat4::Identity(), X_B2F2 = Mat4::Identity();  ///< Weld frames in their bodies
  Vec3 location1 = Vec3::Zero(), location2 = Vec3::Zero();    ///< Point: stations in body1/2
};

// ---------------------------------------------------------------------------------------------
// wrap objects and paths (§6)

struct WrapObjectDesc {
  std::string name;
  std::string type;   ///< WrapCylinder, WrapSphere, WrapEllipsoid, WrapTorus
  std::string frame;  ///< path of the frame that owns it
  std::string body;   ///< base body of that frame
  Vec3 xyz_body_rotation = Vec3::Zero(), translation = Vec3::Zero();  ///< relative to frame
  Mat4 X_body = Mat4::Identity();  ///< pose of the wrap object in body
  bool active = true;
  std::string quadrant = "all";
  int quadrant_axis = -1;  ///< 0, 1, 2 for x, y, z; -1 for all
  int quadrant_sign = 0;   ///< +1, -1; 0 for all
  double radius = 0.0, length = 0.0;             ///< cylinder (radius, length); sphere (radius)
  Vec3 dimensions = Vec3::Zero();                ///< ellipsoid semi-axes
  double inner_radius = 0.0, outer_radius = 0.0; ///< torus
  int line = 0;
};

enum class PathPointKind { Fixed, Conditional, Moving };

struct PathPointDesc {
  std::string name;
  PathPointKind kind = PathPointKind::Fixed;
  std::string frame;  ///< path of the frame the point is attached to
  std::string body;   ///< base body of that frame
  Vec3 location = Vec3::Zero();   ///< in frame (Fixed, Conditional)
  Mat4 X_body_frame = Mat4::Identity();  ///< pose of frame in body
  // Conditional: active iff range_min - 1e-5 <= q <= range_max + 1e-5
  std::string coordinate;
  double range_min = 0.0, range_max = 0.0;
  // Moving: location component k = functions[k](clamp(q)); coordinates[k] "" means f(0)
  std::array<FunctionDesc, 3> location_functions;
  std::array<std::string, 3> location_coordinates;
  int line = 0;
};

struct PathWrapDesc {
  std::string wrap_object;
  int wrap_index = -1;          ///< into ModelDescription::wrap_objects
  std::string method = "hybrid";
  int range_begin = -1, range_end = -1;  ///< 1-based path point indices; -1 = first/last
  int line = 0;
};

/// Type I: straight origin-insertion; II: via, conditional or moving points; III: any wrap
enum class PathType { I, II, III };
const char* toString(PathType t);

/// a force with a GeometryPath: muscles, PathActuator, PathSpring, ligaments
struct PathForceDesc {
  std::string name;
  std::string class_name;
  bool is_muscle = false;
  bool applies_force = true;
  double max_isometric_force = 1000.0, optimal_fiber_length = 0.1, tendon_slack_length = 0.2;
  double pennation_angle_at_optimal = 0.0, max_contraction_velocity = 10.0;
  double optimal_force = 1.0;                                      ///< PathActuator
  double resting_length = 0.0, stiffness = 0.0, dissipation = 0.0;  ///< PathSpring
  /// muscles: every numeric and boolean property the Hill models read (OpenSim 4 names; curve
  /// sub-objects as "ActiveForceLengthCurve/min_norm_active_fiber_length"), as written
  hill::MuscleParameters parameters;
  std::map<std::string, int> parameter_lines;  ///< property -> line it was read from
  std::vector<PathPointDesc> points;
  std::vector<PathWrapDesc> wraps;
  PathType path_type = PathType::I;
  /// the force_set_files file it came from; "" for the model's own ForceSet
  std::string source_file;
  int line = 0;
};

/// one ContactGeometrySet member (docs/contact.md §1): ContactSphere and ContactHalfSpace are
/// modelled; others (ContactMesh, ...) are kept with modelled = false and listed as unsupported
struct ContactGeometryDesc {
  std::string name;
  std::string class_name;  ///< ContactSphere, ContactHalfSpace, ContactMesh, ...
  std::string frame;       ///< path of the frame it is attached to
  std::string body;        ///< base body of that frame (ground_name for ground)
  /// pose of the geometry in its base body: frame offset * (location, body-fixed XYZ orientation)
  Mat4 X_body = Mat4::Identity();
  double radius = 0.0;     ///< ContactSphere
  bool modelled = false;
  int line = 0;
};

/// HuntCrossleyForce::ContactParameters: the material of every geometry it names
struct ContactParametersDesc {
  std::vector<std::string> geometry;  ///< ContactGeometrySet names
  double stiffness = 0.0, dissipation = 0.0;
  double static_friction = 0.0, dynamic_friction = 0.0, viscous_friction = 0.0;
  int line = 0;
};

/// any other ForceSet member: read and listed
struct ForceDesc {
  std::string name;
  std::string class_name;
  bool applies_force = true;
  bool modelled = false;   ///< false: its force is not computed by redmax (see unsupported)
  std::string coordinate;  ///< CoordinateActuator, CoordinateLimitForce, SpringGeneralizedForce
  double optimal_force = 1.0;
  /// Actuator min_control / max_control (OpenSim's defaults: -inf, +inf)
  double min_control = -std::numeric_limits<double>::infinity();
  double max_control = std::numeric_limits<double>::infinity();
  /// the bodies a force acts on, as description body names (ground: ModelDescription::
  /// ground_name): PointActuator `body`; TorqueActuator bodyA, bodyB; PointToPointSpring body1,
  /// body2 (the base bodies of their frames)
  std::string body1, body2;
  /// PointActuator: point (body frame, or ground with point_is_global) and direction (body frame,
  /// or ground with force_is_global), as written. TorqueActuator: axis in direction (bodyA's
  /// frame unless torque_is_global, kept in force_is_global). PointToPointSpring: point1, point2
  /// in their bodies' frames.
  Vec3 point1 = Vec3::Zero(), point2 = Vec3::Zero();
  Vec3 direction = Vec3::UnitX();
  bool point_is_global = false, force_is_global = false;
  /// CoordinateLimitForce, as written (degrees for a Rotational coordinate: N m/deg, deg, ...)
  double upper_stiffness = 1.0, upper_limit = 0.0, lower_stiffness = 1.0, lower_limit = 0.0;
  double damping = 0.001, transition = 0.1;
  /// SpringGeneralizedForce (stiffness, rest_length, viscosity) and PointToPointSpring
  /// (stiffness, rest_length), SI
  double stiffness = 0.0, rest_length = 0.0, viscosity = 0.0;
  /// BushingForce: rotational then translational stiffness and damping (N m/rad, N/m, ...), and
  /// frame1, frame2 as poses in body1, body2
  Vec6 bushing_stiffness = Vec6::Zero(), bushing_damping = Vec6::Zero();
  Mat4 X_body1 = Mat4::Identity(), X_body2 = Mat4::Identity();
  /// HuntCrossleyForce: its contact_parameters and transition_velocity (default 0.01 m/s)
  std::vector<ContactParametersDesc> contact_parameters;
  double transition_velocity = 0.01;
  /// SmoothSphereHalfSpaceForce: the sphere and half_space sockets (ContactGeometrySet names),
  /// its material in contact_parameters[0] and OpenSim's smoothing constants
  std::string sphere, half_space;
  double constant_contact_force = 1e-5, hertz_smoothing = 300.0, hunt_crossley_smoothing = 50.0;
  /// the force_set_files file it came from; "" for the model's own ForceSet
  std::string source_file;
  int line = 0;
};

struct ForceGroupDesc {
  std::string name;
  std::vector<std::string> members;
};

struct MarkerDesc {
  std::string name;
  std::string frame, body;
  Vec3 location = Vec3::Zero();  ///< in frame
  Mat4 X_body_frame = Mat4::Identity();
  int line = 0;
};

// ---------------------------------------------------------------------------------------------
// multibody tree (§3.1)

/// one Simbody mobilizer, in creation order (which is the q order)
struct MobilizerDesc {
  int joint = -1;             ///< into ModelDescription::joints
  std::string inboard_body;   ///< body already in the tree
  std::string outboard_body;  ///< body this mobilizer moves (a slave name for split loops)
  bool reversed = false;      ///< the joint's child is inboard (Direction::Reverse)
  int level = 1;
};

/// a body split to cut a loop: the slave carries the loop joint and is welded to its master
struct SlaveBodyDesc {
  std::string name;
  std::string master;
};

struct TreeDesc {
  std::vector<MobilizerDesc> mobilizers;
  std::vector<SlaveBodyDesc> slaves;
};

/// an item that was read but is not modelled, with the reason
struct UnsupportedItem {
  int line = 0;
  std::string what;
};

// ---------------------------------------------------------------------------------------------

struct ModelDescription {
  std::string name;
  std::string source_file;
  int osim_version = 0;
  Vec3 gravity = Vec3(0.0, -9.80665, 0.0);
  std::string ground_name = "ground";
  std::vector<BodyDesc> bodies;            ///< BodySet order, ground excluded
  std::vector<FrameDesc> frames;           ///< every PhysicalOffsetFrame
  std::vector<JointDesc> joints;           ///< JointSet order, then added FreeJoints
  std::vector<CoordinateDesc> coordinates; ///< multibody-tree (q) order, §3.1
  std::vector<ConstraintDesc> constraints; ///< file order, then tree-building loop closures
  std::vector<WrapObjectDesc> wrap_objects;
  std::vector<ContactGeometryDesc> contact_geometry;  ///< ContactGeometrySet order
  std::vector<PathForceDesc> muscles;      ///< every force with a path (muscles first-class)
  std::vector<ForceDesc> forces;           ///< all other forces
  std::vector<ForceGroupDesc> force_groups;
  std::vector<MarkerDesc> markers;
  TreeDesc tree;
  std::vector<UnsupportedItem> unsupported;
  std::vector<std::string> warnings;

  /// index lookups; -1 when absent
  int findBody(const std::string& name) const;
  int findJoint(const std::string& name) const;
  int findCoordinate(const std::string& name) const;
  int findWrapObject(const std::string& name) const;
  int findContactGeometry(const std::string& name) const;
  int numDofs() const { return static_cast<int>(coordinates.size()); }
};

}  // namespace redmax::osim
