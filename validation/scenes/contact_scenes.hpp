#pragma once
// Scenes with hard unilateral constraints (docs/contact.md §6), each with a closed-form check:
//   ball-drop       a sphere dropped on a ground half-space: bounce apexes against e^(2k) h0,
//                   the rest height against the radius
//   block-slide     a box sliding on the ground with Coulomb friction: the distance to rest
//                   against v0^2 / (2 mu g)
//   box-stack       boxes stacked on the ground (each on the top face of the one below, a
//                   half-space fixed in that box): the drift per second once settled
//   limit-pendulum  a pendulum released horizontally onto a joint limit at the bottom: the
//                   kinetic energy after the stop against e^2 times the energy before
// All run bdf1 (the linearly implicit Euler step with the contact QP). Used by `redmax scene`
// and the tests.
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "core/integrators/integrator.hpp"

namespace redmax::scenes {

/// a recorded run: time, every coordinate and speed, per step
struct ContactRun {
  std::vector<std::string> columns;  // t, then q and qdot names
  std::vector<VecX> rows;
  IntegratorStats stats;
  double wall_seconds = 0.0;
};

struct BallDropOptions {
  double radius = 0.1, mass = 1.0, drop_height = 0.5;  // m, kg, m (the sphere's bottom above ground)
  double restitution = 0.5, friction = 0.0;
  double dt = 1e-3, duration = 3.0;
};
struct BallDropResult {
  ContactRun run;
  std::vector<double> apexes;   // bottom heights at the apexes after each bounce (m)
  double rest_height = 0.0;     // centre height at the end (m)
};
BallDropResult runBallDrop(const BallDropOptions& o);
/// the ball-drop system (a free sphere over the ground half-space y < 0) and its initial state
std::shared_ptr<System> makeBallDrop(const BallDropOptions& o, State& initial);

struct BlockSlideOptions {
  Vec3 half_extents = Vec3(0.1, 0.05, 0.1);
  double mass = 1.0, v0 = 2.0, friction = 0.5;
  double dt = 1e-3, duration = 1.0;
};
struct BlockSlideResult {
  ContactRun run;
  double distance = 0.0;        // x travelled (m)
  double stop_time = -1.0;      // first time |v| < 1e-9 (s), -1 if it never stops
  double final_speed = 0.0;
  double max_tilt = 0.0;        // largest rotation coordinate magnitude (rad)
};
BlockSlideResult runBlockSlide(const BlockSlideOptions& o);
/// the block-slide system (a free box on the ground, sliding along +x) and its initial state
std::shared_ptr<System> makeBlockSlide(const BlockSlideOptions& o, State& initial);

struct BoxStackOptions {
  int boxes = 3;
  double half = 0.1, mass = 1.0, friction = 0.5;
  double dt = 1e-3, duration = 2.0;
  double initial_gap = 0.0;  // m between neighbours at the start (they fall onto each other)
};
struct BoxStackResult {
  ContactRun run;
  double drift_per_second = 0.0;  // largest |position change| of a box centre over the last second / 1 s
  double max_penetration = 0.0;   // at the end (m)
  double final_max_speed = 0.0;
};
BoxStackResult runBoxStack(const BoxStackOptions& o);
/// the box-stack system (free boxes, each box's corners against the top face of the one below)
/// and its initial state
std::shared_ptr<System> makeBoxStack(const BoxStackOptions& o, State& initial);

struct LimitPendulumOptions {
  double length = 1.0, mass = 1.0, restitution = 0.5;
  double dt = 1e-3, duration = 1.5;
};
struct LimitPendulumResult {
  ContactRun run;
  double energy_before = 0.0;   // kinetic energy at the start of the step that met the limit (J)
  double energy_after = 0.0;    // kinetic energy after it (J)
  double free_fall_energy = 0.0;  // m g L / 2 (J)
  double min_angle = 0.0;       // smallest angle reached (rad; the limit is -pi/2)
};
LimitPendulumResult runLimitPendulum(const LimitPendulumOptions& o);

std::vector<std::string> contactSceneNames();
/// run one of contactSceneNames() with its defaults, print a summary to `out`, write DIR/states.csv
void runContactScene(const std::string& name, const std::string& dir, std::ostream& out);

}  // namespace redmax::scenes
