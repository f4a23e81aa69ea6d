#pragma once
// The hard-contact scenes of validation/scenes/contact_scenes.hpp built in MuJoCo (issue 21, the
// peer comparison of docs/contact.md §6.4a): same masses, sizes, drop height, initial speed,
// friction, time step and gravity, from MJCF text (written to a temporary file, mj_loadXML).
// MuJoCo is z-up, redmax's scenes y-up: the results below are scalars (heights, distances), so
// the axes never meet. MuJoCo's contacts are soft constraints (solref/solimp), so it penetrates
// by design and has no restitution coefficient: MjContactParams chooses its contact model.
// Built only when libmujoco-dev is installed (validation/CMakeLists.txt); nothing else in the
// project includes this header or MuJoCo's. The header holds no MuJoCo type.
#include <memory>
#include <string>
#include <vector>

#include "validation/scenes/contact_scenes.hpp"

namespace redmax::peers {

/// MuJoCo's contact model for a scene. Empty strings keep MuJoCo's defaults (solref "0.02 1",
/// solimp "0.9 0.95 0.001", the pyramidal cone, the Newton solver, semi-implicit Euler).
struct MjContactParams {
  std::string solref;         // e.g. "-20000 -30" (direct format: -stiffness, -damping)
  std::string solimp;
  bool elliptic_cone = false;
};

/// a bouncing contact: solref in the direct format (-stiffness, -damping) with the damping of a
/// linear spring-damper whose restitution is `e` (ratio z = -ln e / sqrt(pi^2 + ln^2 e), damping
/// 2 z sqrt(k)). MuJoCo's impedance (solimp) scales both, so the bounce is near e, not e.
MjContactParams bouncyContact(double e, double stiffness = 1e5);

/// one loaded MuJoCo model and its data; not copyable
class MujocoModel {
 public:
  /// compiles `mjcf` (written to a temporary file that is removed again); throws
  /// std::runtime_error with MuJoCo's message when it does not load
  explicit MujocoModel(const std::string& mjcf);
  ~MujocoModel();
  MujocoModel(const MujocoModel&) = delete;
  MujocoModel& operator=(const MujocoModel&) = delete;

  void reset();  // the model's initial state (qpos0, zero speeds unless the keyframe sets them)
  void step();   // one mj_step
  double time() const;
  double qpos(int i) const;
  double qvel(int i) const;
  int contacts() const;           // contacts found at the last step's start
  double penetration() const;     // largest -dist over those contacts (m), 0 without any
  double timestep() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// MuJoCo's version string (mj_versionString)
std::string mujocoVersion();

// ---- the scenes' MJCF (the options are redmax's own, so both sides read the same numbers)
std::string ballDropMjcf(const scenes::BallDropOptions& o, const MjContactParams& p);
std::string blockSlideMjcf(const scenes::BlockSlideOptions& o, const MjContactParams& p);
std::string boxStackMjcf(const scenes::BoxStackOptions& o, const MjContactParams& p);

/// a time series of one scalar per step (t = 0 first)
struct Trajectory {
  std::vector<double> t, y;
};

struct MjBallDropResult {
  Trajectory height;            // the sphere's bottom above ground (m)
  std::vector<double> apexes;   // bottom heights at the apexes after each bounce (m)
  double first_impact = -1.0;   // end of the first step whose speed change is not free fall (s)
  double rest_height = 0.0;     // centre height at the end (m)
  double max_penetration = 0.0; // largest over the run (m)
  long steps = 0;
};
/// runs `m` (from ballDropMjcf(o, ...)) for o.duration
MjBallDropResult runBallDrop(MujocoModel& m, const scenes::BallDropOptions& o);

struct MjBlockSlideResult {
  Trajectory x;                 // distance travelled (m)
  double distance = 0.0;        // at the end (m)
  double stop_time = -1.0;      // first time the speed is below 1e-3 m/s (s), -1 if never
  double final_speed = 0.0;
  double max_penetration = 0.0;
  long steps = 0;
};
MjBlockSlideResult runBlockSlide(MujocoModel& m, const scenes::BlockSlideOptions& o);

struct MjBoxStackResult {
  double drift_per_second = 0.0;  // largest |centre change| of a box over the last second / 1 s
  double max_penetration = 0.0;   // at the end (m)
  double final_max_speed = 0.0;   // largest |qvel| at the end
  long steps = 0;
};
MjBoxStackResult runBoxStack(MujocoModel& m, const scenes::BoxStackOptions& o);

/// the step (end time) at which a redmax or MuJoCo vertical speed record first departs from free
/// fall: |v_{k+1} - (v_k - g h)| > 1e-9 (s), -1 if never. `v` is sampled at every step from t = 0.
double firstImpactTime(const std::vector<double>& t, const std::vector<double>& v, double g);

}  // namespace redmax::peers
