#include "validation/scenes/contact_scenes.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "core/dynamics/system.hpp"
#include "core/joints/basic_joints.hpp"
#include "core/joints/free_joints.hpp"
#include "core/spatial/se3.hpp"
#include "validation/scenes/scene_io.hpp"

namespace redmax::scenes {
namespace {

constexpr double kG = 9.81;

// the ground half-space: fills y < 0 (its frame's x axis points down, so the outward normal is +y)
CollisionGeometry ground() {
  CollisionGeometry g;
  g.name = "ground";
  g.shape = CollisionShape::HalfSpace;
  g.X_body = makeE(rotationAxisAngle(Vec3::UnitZ(), -M_PI / 2), Vec3::Zero());
  return g;
}

Mat3 boxInertia(double m, const Vec3& h) {
  return Vec3(m / 3 * (h.y() * h.y() + h.z() * h.z()), m / 3 * (h.x() * h.x() + h.z() * h.z()),
              m / 3 * (h.x() * h.x() + h.y() * h.y()))
      .asDiagonal();
}

// run with bdf1, recording every step
ContactRun record(const System& sys, State s, double dt, double duration,
                  const std::function<void(const State&)>& each = nullptr) {
  ContactRun run;
  run.columns.push_back("time");
  for (const auto& c : sys.model().coordinates()) run.columns.push_back(c.name);
  for (const auto& c : sys.model().coordinates()) run.columns.push_back(c.name + "_speed");
  IntegratorOptions io;
  io.dt = dt;
  auto integ = makeIntegrator("bdf1", io);
  const long n = std::lround(duration / dt);
  auto row = [&] {
    VecX r(1 + 2 * s.q.size());
    r << s.t, s.q, s.qdot;
    run.rows.push_back(r);
  };
  row();
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < n; ++k) {
    integ->advance(sys, s, (k + 1) * dt);
    row();
    if (each) each(s);
  }
  run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  run.stats = integ->stats();
  return run;
}

}  // namespace

std::shared_ptr<System> makeBallDrop(const BallDropOptions& o, State& s) {
  ModelBuilder b("ball_drop");
  b.setGravity(Vec3(0, -kG, 0));
  const double I = 0.4 * o.mass * o.radius * o.radius;
  b.addBody("ball", o.mass, Vec3::Zero(), Vec3(I, I, I).asDiagonal(), -1, "free", Free3D{});
  auto sys = std::make_shared<System>(b.finalize());
  CollisionGeometry ball;
  ball.name = "ball";
  ball.body = 0;
  ball.radius = o.radius;
  sys->setUnilateral(std::make_shared<UnilateralConstraints>(
      sys->model(), std::vector<CollisionGeometry>{ground(), ball},
      std::vector<CollisionPair>{{0, 1, o.friction, o.restitution}}, std::vector<JointLimit>{}));
  s = sys->defaultState();
  s.q[1] = o.drop_height + o.radius;
  return sys;
}

BallDropResult runBallDrop(const BallDropOptions& o) {
  State s;
  auto sys = makeBallDrop(o, s);
  BallDropResult r;
  // apexes: the top of each upward flight after an impact
  double prev_v = 0.0;
  bool bounced = false;
  r.run = record(*sys, s, o.dt, o.duration, [&](const State& st) {
    const double v = st.qdot[1];
    if (prev_v < 0.0 && v > 0.0) bounced = true;
    if (bounced && prev_v > 0.0 && v <= 0.0) r.apexes.push_back(st.q[1] - o.radius);
    prev_v = v;
  });
  r.rest_height = r.run.rows.back()[2];
  return r;
}

std::shared_ptr<System> makeBlockSlide(const BlockSlideOptions& o, State& s) {
  ModelBuilder b("block_slide");
  b.setGravity(Vec3(0, -kG, 0));
  b.addBody("block", o.mass, Vec3::Zero(), boxInertia(o.mass, o.half_extents), -1, "free", Free3D{});
  auto sys = std::make_shared<System>(b.finalize());
  CollisionGeometry box;
  box.name = "block";
  box.shape = CollisionShape::Box;
  box.body = 0;
  box.half_extents = o.half_extents;
  sys->setUnilateral(std::make_shared<UnilateralConstraints>(
      sys->model(), std::vector<CollisionGeometry>{ground(), box},
      std::vector<CollisionPair>{{0, 1, o.friction, 0.0}}, std::vector<JointLimit>{}));
  s = sys->defaultState();
  s.q[1] = o.half_extents.y();
  s.qdot[0] = o.v0;
  return sys;
}

BlockSlideResult runBlockSlide(const BlockSlideOptions& o) {
  State s;
  auto sys = makeBlockSlide(o, s);
  BlockSlideResult r;
  r.run = record(*sys, s, o.dt, o.duration, [&](const State& st) {
    if (r.stop_time < 0.0 && std::abs(st.qdot[0]) < 1e-9) r.stop_time = st.t;
    r.max_tilt = std::max(r.max_tilt, st.q.tail(3).cwiseAbs().maxCoeff());
  });
  r.distance = r.run.rows.back()[1];
  r.final_speed = r.run.rows.back().tail(6).head(3).norm();
  return r;
}

std::shared_ptr<System> makeBoxStack(const BoxStackOptions& o, State& s) {
  if (o.boxes < 1) throw std::invalid_argument("box-stack: needs at least one box");
  ModelBuilder b("box_stack");
  b.setGravity(Vec3(0, -kG, 0));
  const Vec3 h(o.half, o.half, o.half);
  std::vector<CollisionGeometry> geo{ground()};
  std::vector<CollisionPair> pairs;
  for (int i = 0; i < o.boxes; ++i) {
    b.addBody("box" + std::to_string(i), o.mass, Vec3::Zero(), boxInertia(o.mass, h), -1,
              "free" + std::to_string(i), Free3D{});
    CollisionGeometry box;
    box.name = "box" + std::to_string(i);
    box.shape = CollisionShape::Box;
    box.body = i;
    box.half_extents = h;
    const int below = i == 0 ? 0 : static_cast<int>(geo.size()) - 1;  // ground or the top of box i-1
    geo.push_back(box);
    pairs.push_back({below, static_cast<int>(geo.size()) - 1, o.friction, 0.0});
    CollisionGeometry top = ground();
    top.name = "box" + std::to_string(i) + "_top";
    top.body = i;
    top.X_body = makeE(rotationAxisAngle(Vec3::UnitZ(), -M_PI / 2), Vec3(0, o.half, 0));
    geo.push_back(top);
  }
  auto sys = std::make_shared<System>(b.finalize());
  sys->setUnilateral(std::make_shared<UnilateralConstraints>(sys->model(), geo, pairs, std::vector<JointLimit>{}));
  s = sys->defaultState();
  for (int i = 0; i < o.boxes; ++i) s.q[6 * i + 1] = o.half + i * (2 * o.half + o.initial_gap);
  return sys;
}

BoxStackResult runBoxStack(const BoxStackOptions& o) {
  State s;
  const std::shared_ptr<System> sys = makeBoxStack(o, s);
  const std::shared_ptr<const UnilateralConstraints> uc = sys->unilateral();
  BoxStackResult r;
  r.run = record(*sys, s, o.dt, o.duration);
  const VecX& last = r.run.rows.back();
  const long k1 = static_cast<long>(r.run.rows.size()) - 1 - std::lround(1.0 / o.dt);
  const VecX& earlier = r.run.rows[std::max(0L, k1)];
  const double span = last[0] - earlier[0];
  for (int i = 0; i < o.boxes; ++i)
    r.drift_per_second = std::max(r.drift_per_second, (last.segment(1 + 6 * i, 3) - earlier.segment(1 + 6 * i, 3)).norm() / span);
  const int n = sys->ndof();
  r.final_max_speed = last.tail(n).cwiseAbs().maxCoeff();
  State fin = sys->defaultState();
  fin.q = last.segment(1, n);
  DynamicsWorkspace ws(*sys);
  sys->kineticEnergy(fin, ws);  // kinematics of the final state
  for (double g : uc->gaps(sys->model(), fin, ws.sk)) r.max_penetration = std::max(r.max_penetration, -g);
  return r;
}

LimitPendulumResult runLimitPendulum(const LimitPendulumOptions& o) {
  ModelBuilder b("limit_pendulum");
  b.setGravity(Vec3(0, -kG, 0));
  const double L = o.length;
  // a thin rod along x from the hinge
  b.addBody("rod", o.mass, Vec3(L / 2, 0, 0), Vec3(1e-6, o.mass * L * L / 12, o.mass * L * L / 12).asDiagonal(), -1,
            "hinge", Revolute{});
  auto sys = std::make_shared<System>(b.finalize());
  JointLimit lim;
  lim.name = "hinge";
  lim.coordinate = 0;
  lim.lower = -M_PI / 2;  // hanging straight down
  lim.upper = M_PI;
  lim.restitution = o.restitution;
  sys->setUnilateral(std::make_shared<UnilateralConstraints>(sys->model(), std::vector<CollisionGeometry>{},
                                                             std::vector<CollisionPair>{}, std::vector<JointLimit>{lim}));
  const double I = o.mass * L * L / 3;  // about the hinge
  State s = sys->defaultState();
  LimitPendulumResult r;
  r.free_fall_energy = o.mass * kG * L / 2;
  double prev_w = 0.0;
  bool met = false;
  r.min_angle = 0.0;
  r.run = record(*sys, s, o.dt, o.duration, [&](const State& st) {
    const double w = st.qdot[0];
    if (!met && prev_w < 0.0 && w >= 0.0) {
      met = true;
      r.energy_before = 0.5 * I * prev_w * prev_w;
      r.energy_after = 0.5 * I * w * w;
    }
    prev_w = w;
    r.min_angle = std::min(r.min_angle, st.q[0]);
  });
  return r;
}

std::vector<std::string> contactSceneNames() { return {"ball-drop", "block-slide", "box-stack", "limit-pendulum"}; }

void runContactScene(const std::string& name, const std::string& dir, std::ostream& out) {
  ContactRun* run = nullptr;
  BallDropResult bd;
  BlockSlideResult bs;
  BoxStackResult st;
  LimitPendulumResult lp;
  if (name == "ball-drop") {
    const BallDropOptions o;
    bd = runBallDrop(o);
    run = &bd.run;
    out << "ball-drop: radius " << o.radius << " m from " << o.drop_height << " m, restitution " << o.restitution
        << ", dt " << o.dt << " s\n";
    double expect = o.drop_height;
    for (size_t k = 0; k < bd.apexes.size() && k < 4; ++k) {
      expect *= o.restitution * o.restitution;
      out << "  bounce " << k + 1 << " apex " << bd.apexes[k] << " m, e^2k h " << expect << " m\n";
    }
    out << "  rest height " << bd.rest_height << " m (radius " << o.radius << " m)\n";
  } else if (name == "block-slide") {
    const BlockSlideOptions o;
    bs = runBlockSlide(o);
    run = &bs.run;
    out << "block-slide: v0 " << o.v0 << " m/s, mu " << o.friction << ", dt " << o.dt << " s\n"
        << "  distance " << bs.distance << " m, v0^2/(2 mu g) " << o.v0 * o.v0 / (2 * o.friction * kG)
        << " m; stopped at " << bs.stop_time << " s (v0/(mu g) " << o.v0 / (o.friction * kG) << " s)\n";
  } else if (name == "box-stack") {
    const BoxStackOptions o;
    st = runBoxStack(o);
    run = &st.run;
    out << "box-stack: " << o.boxes << " boxes of " << 2 * o.half << " m, mu " << o.friction << ", dt " << o.dt
        << " s, " << o.duration << " s\n"
        << "  drift over the last second " << st.drift_per_second << " m/s, largest speed at the end "
        << st.final_max_speed << ", penetration at the end " << st.max_penetration << " m\n";
  } else if (name == "limit-pendulum") {
    const LimitPendulumOptions o;
    lp = runLimitPendulum(o);
    run = &lp.run;
    out << "limit-pendulum: rod " << o.length << " m released horizontally onto a limit at -90 deg, restitution "
        << o.restitution << ", dt " << o.dt << " s\n"
        << "  kinetic energy before the stop " << lp.energy_before << " J (m g L/2 " << lp.free_fall_energy
        << " J), after " << lp.energy_after << " J (e^2 before " << o.restitution * o.restitution * lp.energy_before
        << " J); lowest angle " << lp.min_angle << " rad\n";
  } else {
    throw std::invalid_argument("unknown contact scene '" + name + "'");
  }
  const IntegratorStats& s = run->stats;
  out << "  steps " << s.steps << ", contact steps " << s.unilateral_steps << ", most contacts " << s.max_contacts
      << ", QP iterations " << s.qp_iterations << " in " << s.qp_solves << " QPs, largest penetration "
      << s.max_penetration << ", wall " << run->wall_seconds << " s\n";
  std::filesystem::create_directories(dir);
  writeCsv(std::filesystem::path(dir) / "states.csv", run->columns, run->rows);
}

}  // namespace redmax::scenes
