#pragma once
// Options and index maps of the core -> Simbody conversion, without Simbody headers, so that code
// which only drives the plugin (benchmarks, the CLI) stays cheap to compile.
#include <stdexcept>

namespace redmax::simbody {

/// How a core SphericalEuler (XYZ) joint becomes a Simbody mobilizer.
enum class SphericalAs {
  Gimbal,  // q = body-fixed XYZ angles, u = qdot
  Ball     // Euler-angle Ball: same q, u = angular velocity w_FM expressed in F
};

struct SimbodyBuildOptions {
  SphericalAs spherical = SphericalAs::Gimbal;
  /// Force::UniformGravity with the model's gravity
  bool gravity = true;
  /// Force::MobilityLinearSpring / MobilityLinearDamper for coordinates with nonzero stiffness or
  /// damping. Only exact where u = qdot (the spring acts on q, the damper on u): a spring or damper
  /// on a rotational coordinate of a Ball or Free mobilizer is rejected with SimbodyBuildError.
  bool joint_springs = true;
};

enum class MobilizerKind { Weld, Pin, Slider, Gimbal, Ball, Universal, Free, FunctionBased, Ellipsoid };

/// Where one core joint lives in Simbody's q and u vectors.
struct MobilizerMap {
  MobilizerKind kind = MobilizerKind::Weld;
  int q_index = 0;    // first core coordinate
  int nq = 0;         // core coordinates (== Simbody nq == nu with Euler angles)
  int simbody_q = 0;  // first Simbody q (matter subsystem indexing)
  int simbody_u = 0;  // first Simbody u
  bool u_is_qdot = true;  // false for Ball, Free and Ellipsoid: u = T qdot (calcVelocityMap)
  bool reversed = false;  // Direction::Reverse (core Reversed joint); kind is the inner joint's
};

/// Construction failed: a joint type without a Simbody counterpart, an invalid inertia, a spring on
/// a mobilizer where q and u differ.
class SimbodyBuildError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace redmax::simbody
