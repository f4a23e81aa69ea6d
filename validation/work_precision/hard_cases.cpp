#include "validation/work_precision/hard_cases.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <regex>
#include <sstream>

#include "core/dynamics/muscle_term.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/muscles/path.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/report/csv.hpp"
#include "validation/report/json_value.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "validation/scenes/scenes.hpp"
#include "validation/scenes/wrap_pendulums.hpp"
#include "validation/work_precision/work_precision.hpp"

namespace redmax::validation {
namespace {

double cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

std::string fmt(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

double energy(const System& sys, const State& s) {
  DynamicsWorkspace ws(sys.model());
  return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
}

bool adaptive(const std::string& integrator) { return integrator == "rk45" || integrator == "cvode"; }

/// thin rod of length L along -y from its joint (COM slightly off-axis), radius 0.02
void rod(double m, double L, Vec3& com, Mat3& I) {
  com = Vec3(0.0, -0.5 * L, 0.0);
  I = Mat3::Zero();
  I(0, 0) = I(2, 2) = m * (L * L / 12.0 + 0.0001);
  I(1, 1) = 0.5 * m * 0.0004;
}

/// a ForceTerm that turns NaN from time t_nan on (a broken actuator or a bad data table)
class NanAfter final : public ForceTerm {
 public:
  explicit NanAfter(double t_nan) : t_nan_(t_nan) {}
  std::string name() const override { return "nan_after"; }
  void addForce(const Model&, const State& s, const TermContext&, VecX& f) const override {
    if (s.t >= t_nan_) f[0] += std::numeric_limits<double>::quiet_NaN();
  }

 private:
  double t_nan_;
};

/// the core names an entry "q[k]" or "qdot[k]"; add the coordinate's name (reports are for people)
std::string nameCoordinate(const Model& model, const std::string& what) {
  static const std::regex entry(R"((q|qdot|qddot)\[(\d+)\])");
  std::smatch mt;
  if (!std::regex_search(what, mt, entry)) return what;
  const int k = std::stoi(mt[2].str());
  if (k < 0 || k >= model.nr()) return what;
  return what + " (coordinate '" + model.coordinates()[k].name + "')";
}

}  // namespace

HardRun integrateHardCase(const System& sys, const State& s0, const std::string& integrator, double value,
                          double duration, double sample_dt,
                          const std::function<std::string(const State&, double)>& check) {
  IntegratorOptions opt;
  if (adaptive(integrator)) {
    opt.rtol = value;
    opt.atol = 1e-2 * value;
  } else {
    opt.dt = value;
  }
  auto integ = makeIntegrator(integrator, opt);
  HardRun r;
  r.integrator = integrator;
  r.value = value;
  State s = s0;
  r.energy0 = energy(sys, s);
  const double c0 = cpuSeconds();
  const int n = std::max(1, static_cast<int>(std::lround(duration / sample_dt)));
  r.ok = true;
  for (int k = 1; k <= n; ++k) {
    try {
      integ->advance(sys, s, s0.t + duration * k / n);
    } catch (const SimulationError& e) {
      r.ok = false;
      r.failure = nameCoordinate(sys.model(), e.what());
      r.failure_time = e.time;
      break;
    }
    const double E = energy(sys, s);
    r.t_reached = s.t;
    r.max_energy_err = std::max(r.max_energy_err, std::abs(E - r.energy0));
    r.final_energy_err = E - r.energy0;
    if (check) {
      std::string why;
      try {
        why = check(s, E);
      } catch (const SimulationError& e) {
        why = e.what();
      }
      if (!why.empty()) {
        r.ok = false;
        r.failure = why;
        r.failure_time = s.t;
        break;
      }
    }
  }
  r.cpu_s = cpuSeconds() - c0;
  r.stats = integ->stats();
  return r;
}

double checkJointSingularities(const Model& model, const State& s, double threshold, double h) {
  double dmin = 1.0;
  for (const JointSlot& j : model.joints()) {
    const double d = j.joint.singularityDistance(s.q.segment(j.q_index, j.nq));
    if (d < threshold) {
      std::ostringstream os;
      os << "joint '" << j.name << "' (" << j.joint.typeName() << ") reached a coordinate singularity: distance "
         << d << " < " << threshold << " at t = " << s.t << " s (step h = " << h << " s)";
      throw SimulationError(os.str(), s.t, h);
    }
    dmin = std::min(dmin, d);
  }
  return dmin;
}

// ---- 1. spinning body ------------------------------------------------------------------------

SpinCase runSpinCase(double duration) {
  // the scene of tests/core/integrators/spinning_body_test.cpp: principal moments 1, 2, 3 in
  // rotated axes, 10 rev/s about the major axis plus a tilt that makes it precess
  ModelBuilder b("spinning_body");
  b.setGravity(Vec3::Zero());
  const Mat3 R = expSO3(Vec3(0.3, -0.5, 0.2));
  const Mat3 I = R * Vec3(1.0, 2.0, 3.0).asDiagonal() * R.transpose();
  b.addBody("body", 2.0, Vec3::Zero(), I, -1, "ball", SphericalExp{});
  System sys(b.finalize());
  const Model& m = sys.model();
  State s = sys.defaultState();
  s.qdot = R * Vec3(4.0, -3.0, 20.0 * M_PI);  // S = I at q = 0
  auto momentum = [&](const State& st) {
    SkeletonWorkspace ws(m);
    calcKinematics(m, st, ws);
    return Vec3(ws.E_wi[0].topLeftCorner<3, 3>() * (m.bodies()[0].inertia_com * ws.phi[0].head<3>()));
  };
  const double E0 = energy(sys, s);
  const Vec3 L0 = momentum(s);
  IntegratorOptions opt;
  opt.rtol = 1e-10;
  opt.atol = 1e-12;
  auto integ = makeIntegrator("rk45", opt);
  SpinCase c;
  double angle = 0.0;
  const int n = static_cast<int>(std::lround(duration / 0.01));
  for (int k = 1; k <= n; ++k) {
    integ->advance(sys, s, 0.01 * k);
    c.energy_err_rel = std::max(c.energy_err_rel, std::abs(energy(sys, s) - E0) / E0);
    c.momentum_err_rel = std::max(c.momentum_err_rel, (momentum(s) - L0).norm() / L0.norm());
    c.max_q_norm = std::max(c.max_q_norm, s.q.norm());
    SkeletonWorkspace ws(m);
    calcKinematics(m, s, ws);
    angle += 0.01 * ws.phi[0].head<3>().norm();
  }
  c.revolutions = angle / (2.0 * M_PI);
  c.chart_switches = integ->stats().reparameterizations;
  return c;
}

// ---- 2. gimbal lock --------------------------------------------------------------------------

namespace {
/// one body on an XYZ Euler joint, no gravity, spinning about its major axis y (stable) with a
/// small wobble, so that q2 runs to within ~1e-4 of pi/2 in 0.2 s (the singular set is reached
/// only by special trajectories; a generic one comes close and turns back)
System gimbalSystem(State& s) {
  ModelBuilder b("gimbal");
  b.setGravity(Vec3::Zero());
  b.addBody("body", 1.0, Vec3::Zero(), Vec3(1.0, 2.0, 1.5).asDiagonal().toDenseMatrix(), -1, "ball",
            SphericalEuler{});
  System sys(b.finalize());
  s = sys.defaultState();
  s.q << 0.0, 1.2, 0.0;
  s.qdot << 2e-4, 2.0, 1e-4;
  return sys;
}
}  // namespace

GimbalCase runGimbalCase(const std::string& integrator, double threshold) {
  State s0;
  const System sys = gimbalSystem(s0);
  const double value = adaptive(integrator) ? 1e-8 : 1e-4;
  GimbalCase c;
  auto guard = [&](const State& s, double) {
    if (!s.q.allFinite() || !s.qdot.allFinite()) c.state_finite = false;
    c.min_distance = std::min(c.min_distance, std::abs(std::cos(s.q[1])));
    // the step reported: the fixed step, or for adaptive methods the check interval
    checkJointSingularities(sys.model(), s, threshold, adaptive(integrator) ? 1e-4 : value);
    return std::string();
  };
  const HardRun r = integrateHardCase(sys, s0, integrator, value, 1.0, 1e-4, guard);
  c.reported = !r.ok;
  c.message = r.failure;
  c.report_time = r.failure_time;
  // without the guard: what does the integrator do through the singularity?
  double dmin = 1.0;
  const HardRun u = integrateHardCase(sys, s0, integrator, value, 1.0, 1e-4, [&](const State& s, double) {
    dmin = std::min(dmin, std::abs(std::cos(s.q[1])));
    return std::string();
  });
  c.unguarded_min_distance = dmin;
  c.unguarded = u.ok ? "closest |cos q2| " + fmt(dmin) + ", max |dE| " + fmt(u.max_energy_err) + " J of " + fmt(u.energy0) + " J"
                     : "stops at t = " + fmt(u.failure_time) + " s: " + u.failure.substr(0, 80);
  return c;
}

// ---- 3. light distal link, heavy muscle ------------------------------------------------------

System makeLightDistalSystem(State& initial) {
  ModelBuilder b("light_distal");
  b.setGravity(Vec3(0, -9.81, 0));
  const double L = 0.5;
  Vec3 c;
  Mat3 I;
  rod(1.0, L, c, I);
  const int b1 = b.addBody("link1", 1.0, c, I, -1, "pin1", Revolute{Vec3::UnitZ()});
  rod(0.01, L, c, I);
  const int b2 = b.addBody("link2", 0.01, c, I, b1, "pin2", Revolute{Vec3::UnitZ()}, makeTranslation(Vec3(0, -L, 0)));
  Model m = b.finalize();
  Muscle mu;
  mu.name = "heavy";
  mu.path.points = {makeFixedPoint(b1, Vec3(0.05, -0.2, 0)), makeFixedPoint(b2, Vec3(0.03, -0.35, 0))};
  MassPointOptions mo;
  mo.count = 20;
  mo.region = MassPointOptions::Region::WholePath;
  mu.mass_points = makeMassPoints(1.0, 0.3, 0.1, mo);
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(sys.model(), std::vector<Muscle>{mu}));
  initial = sys.defaultState();
  initial.q << 0.8, -0.4;
  return sys;
}

std::vector<HardRun> runLightDistalCase(bool quick) {
  State s0;
  const System sys = makeLightDistalSystem(s0);
  const double T = quick ? 0.5 : 2.0;
  // energy scale: the potential range of the whole system, 2 kg x g x 1 m
  const double scale = 2.0 * 9.81;
  std::vector<HardRun> runs;
  for (const std::string integ : {"euler", "symplectic", "bdf1", "rk45"}) {
    const std::vector<double> ladder = adaptive(integ) ? std::vector<double>{1e-3, 1e-6, 1e-9}
                                                       : std::vector<double>{1e-2, 3e-3, 1e-3, 3e-4, 1e-4};
    for (double v : ladder) {
      runs.push_back(integrateHardCase(sys, s0, integ, v, T, 0.01, [&](const State&, double E) {
        // a run whose energy moved by more than the whole potential range has blown up
        return std::abs(E - energy(sys, s0)) > scale ? "energy left the physical range" : std::string();
      }));
    }
  }
  return runs;
}

// ---- 4. stiff spring -------------------------------------------------------------------------

namespace {
constexpr double kStiffK = 1e4, kStiffI = 0.01;  // omega = sqrt(k / I) = 1000 rad/s
System stiffSystem(State& s) {
  ModelBuilder b("stiff_spring");
  b.setGravity(Vec3::Zero());
  b.addBody("disc", 1.0, Vec3::Zero(), kStiffI * Mat3::Identity(), -1, "hinge", Revolute{Vec3::UnitZ()});
  b.coordinateAt(0).stiffness = kStiffK;
  Model m = b.finalize();
  System sys(m);
  s = sys.defaultState();
  s.q[0] = 0.1;
  return sys;
}
}  // namespace

bool stiffStable(const std::string& integrator, double h) {
  State s0;
  const System sys = stiffSystem(s0);
  const double E0 = energy(sys, s0);
  const HardRun r = integrateHardCase(sys, s0, integrator, h, 2000 * h, 100 * h, [&](const State&, double E) {
    return E > 1e6 * E0 ? "energy grew by 1e6" : std::string();
  });
  return r.ok;
}

StiffCase runStiffCase() {
  StiffCase c;
  c.omega = std::sqrt(kStiffK / kStiffI);
  c.euler_theory = 2.0 / c.omega;
  State s0;
  const System sys = stiffSystem(s0);
  const double E0 = energy(sys, s0);
  for (const std::string integ : {"euler", "bdf1"}) {
    for (double h = 1e-4; h <= 1.0 + 1e-12; h *= std::sqrt(10.0)) {
      HardRun r = integrateHardCase(sys, s0, integ, h, std::max(1.0, 200 * h), std::max(1e-2, h),
                                    [&](const State&, double E) {
                                      return E > 1e6 * E0 ? "energy grew by 1e6" : std::string();
                                    });
      if (r.ok && integ == "bdf1") c.bdf1_largest_stable = h;
      c.ladder.push_back(std::move(r));
    }
  }
  // bisect euler's limit between 0.5 and 2 times the theory, relative resolution 1e-3
  double lo = 0.5 * c.euler_theory, hi = 2.0 * c.euler_theory;
  while (hi / lo > 1.001) {
    const double mid = std::sqrt(lo * hi);
    (stiffStable("euler", mid) ? lo : hi) = mid;
  }
  c.euler_largest_stable = lo;
  return c;
}

// ---- 5. long run -----------------------------------------------------------------------------

HardRun runLongRunCase(const std::string& models_dir, double duration, double rtol) {
  const WorkPrecisionScene scene = makeWorkPrecisionScene("pendulum_straight", models_dir);
  return integrateHardCase(scene.system, scene.initial, "rk45", rtol, duration, 0.05);
}

// ---- 6. conditional path point ---------------------------------------------------------------

namespace {
/// the double pendulum (1 kg, 1 m links) with a 0.3 kg muscle whose middle point (fixed in the
/// world, so that mass points sliding past it keep their kinetic energy continuous) is
/// active while -3 <= q2 <= 0.3 (the lower edge is never reached); after the muscle of
/// tests/core/muscles/conditional_switch_test.cpp, whose point rides on link 1
System conditionalSystem(State& s) {
  System sys(scenes::doublePendulum());
  Muscle mu;
  mu.name = "conditional";
  mu.path.points = {makeFixedPoint(-1, Vec3(-0.3, 0.2, 0)), makeConditionalPoint(-1, Vec3(0.15, -0.8, 0), 1, -3.0, 0.3),
                    makeFixedPoint(1, Vec3(0.1, -0.6, 0))};
  mu.mass_points = makeMassPoints(0.3, 0.25, 0.15, {});
  sys.addTerm(std::make_shared<MuscleTerm>(sys.model(), std::vector<Muscle>{mu}));
  s = sys.defaultState();
  s.q << 0.6, -0.2;
  s.qdot << 0.0, 3.0;
  return sys;
}
}  // namespace

ConditionalCase runConditionalCase(double duration) {
  State s0;
  const System sys = conditionalSystem(s0);
  const double edge = 0.3 + kConditionalTolerance;
  IntegratorOptions opt;
  opt.rtol = 1e-10;
  opt.atol = 1e-12;
  auto integ = makeIntegrator("rk45", opt);
  ConditionalCase c;
  {
    DynamicsWorkspace ws(sys.model());
    c.energy_scale = sys.kineticEnergy(s0, ws);
  }
  State s = s0, prev = s0;
  double E_prev = energy(sys, s0);
  const double dt = 1e-3;
  const int n = static_cast<int>(std::lround(duration / dt));
  for (int k = 1; k <= n; ++k) {
    integ->advance(sys, s, dt * k);
    const double E = energy(sys, s);
    const bool a0 = prev.q[1] <= edge, a1 = s.q[1] <= edge;
    if (a0 != a1) {
      // the switch state, interpolated linearly in the sample interval; energy on both branches
      const double w = (edge - prev.q[1]) / (s.q[1] - prev.q[1]);
      State x = prev;
      x.q = prev.q + w * (s.q - prev.q);
      x.qdot = prev.qdot + w * (s.qdot - prev.qdot);
      State before = x, after = x;
      const double side = a0 ? -1.0 : 1.0;  // before the switch q2 lies on the active side when a0
      before.q[1] = edge + side * 1e-10;
      after.q[1] = edge - side * 1e-10;
      c.switches.push_back({x.t, E - E_prev, energy(sys, after) - energy(sys, before)});
    } else {
      c.smooth_drift = std::max(c.smooth_drift, std::abs(E - E_prev));
    }
    prev = s;
    E_prev = E;
  }
  return c;
}

// ---- 7. NaN mid-run --------------------------------------------------------------------------

NanCase runNanCase(const std::string& integrator) {
  System sys(scenes::doublePendulum());
  sys.addTerm(std::make_shared<NanAfter>(0.25));
  State s0 = sys.defaultState();
  s0.q << 0.5, 0.2;
  const HardRun r = integrateHardCase(sys, s0, integrator, adaptive(integrator) ? 1e-6 : 1e-3, 1.0, 0.01);
  NanCase c;
  c.integrator = integrator;
  c.stopped = !r.ok;
  c.message = r.failure;
  c.time = r.failure_time;
  const auto pos = r.failure.find("h = ");
  if (pos != std::string::npos) c.step = std::atof(r.failure.c_str() + pos + 4);
  return c;
}

// ---- 8. finger flick -------------------------------------------------------------------------

std::vector<FlickStudyRow> runFlickCase(const std::string& models_dir, bool quick) {
  FlickOptions base;
  base.model_path = models_dir + "/finger.osim";
  const std::vector<std::string> integrators =
      quick ? std::vector<std::string>{"euler"} : std::vector<std::string>{"euler", "symplectic", "bdf1", "sdirk2"};
  const std::vector<double> dts = quick ? std::vector<double>{1e-3} : std::vector<double>{1e-3, 5e-4};
  return runFlickStudy(base, integrators, {true}, 0.2, dts);
}

// ---- 9. wrap contact changes -----------------------------------------------------------------

namespace {

std::string wrapModelName(WrapModel model) {
  switch (model) {
    case WrapModel::Smooth: return "smooth";
    case WrapModel::Exact: return "exact_fd";
    case WrapModel::Neural: return "neural";
  }
  return "wrap model " + std::to_string(static_cast<int>(model));
}

// rk45 rtol = atol = 1e-12 from s0, total energy and the penetration every 10 ms; the jumps at
// the penetration's sign changes; `monitor` (may be null) gets the integrator's wrap-model counts
// (the energy samples' own evaluations are not counted)
void measureWrapJumps(const System& sys, const State& s0, const Muscle& mu, double duration, WrapJumpCase& c,
                      WrapFallbackMonitor* monitor = nullptr) {
  const Model& m = sys.model();
  IntegratorOptions io;
  io.rtol = 1e-12;
  io.atol = 1e-12;
  auto integ = makeIntegrator("rk45", io);
  const int n = static_cast<int>(std::lround(duration / 0.01));
  std::vector<double> E(n + 1), d(n + 1);
  State s = s0;
  E[0] = c.energy0 = energy(sys, s);
  d[0] = wrapPenetration(m, mu, s);
  const double c0 = cpuSeconds();
  for (int k = 1; k <= n; ++k) {
    integ->advance(sys, s, s0.t + 0.01 * k);
    if (monitor) takeWrapFallbackCounts(sys, *integ->lastWorkspace(), *monitor);
    E[k] = energy(sys, s);
    d[k] = wrapPenetration(m, mu, s);
    c.drift = std::max(c.drift, std::abs(E[k] - c.energy0));
  }
  c.cpu_s = cpuSeconds() - c0;
  c.steps = integ->stats().steps;
  // a contact change between samples k-1 and k; its net energy change over a 50 ms window (the
  // exact model's FD Jdot spikes while its stencil straddles the change, so the energy swings
  // inside the window before settling at its new level)
  std::vector<char> change(n + 1, 0);
  for (int k = 1; k <= n; ++k) change[k] = (d[k] > 0) != (d[k - 1] > 0);
  c.min_jump = std::numeric_limits<double>::infinity();
  for (int k = 1; k <= n; ++k) {
    if (!change[k]) continue;
    ++c.contact_changes;
    if (k < 3 || k + 2 > n) continue;
    WrapContactChange w;
    w.time = s0.t + 0.01 * k;
    w.wrapping = d[k] > 0;
    w.jump = E[k + 2] - E[k - 3];
    for (int j = k - 2; j <= k + 2; ++j) w.transient = std::max(w.transient, std::abs(E[j] - E[k - 3]));
    c.max_jump = std::max(c.max_jump, std::abs(w.jump));
    c.min_jump = std::min(c.min_jump, std::abs(w.jump));
    c.changes.push_back(w);
  }
  if (c.changes.empty()) c.min_jump = 0.0;
  for (int k = 1; k <= n; ++k) {
    bool near = false;
    for (int j = std::max(1, k - 4); j <= std::min(n, k + 4); ++j) near = near || change[j];
    if (!near) c.quiet_change = std::max(c.quiet_change, std::abs(E[k] - E[k - 1]));
  }
}

}  // namespace

WrapJumpCase runWrapJumpCase(const std::string& models_dir, WrapModel model, double duration) {
  const WrapPendulum p = makeWrapPendulum(models_dir, model, 1.0);
  WrapJumpCase c;
  c.model = wrapModelName(model);
  c.scene = "osim";
  measureWrapJumps(p.system, p.initial, p.muscle, duration, c);
  return c;
}

WrapJumpCase runWrapJumpCaseInBox(WrapMassOptions wrap, double duration) {
  const scenes::WrapPendulumSpec spec;
  std::optional<WrapFallbackMonitor> monitor;
  if (wrap.model == WrapModel::Neural) monitor.emplace();
  const Muscle mu = scenes::makeWrapPendulumMuscle(spec, wrap);
  const Model m = scenes::doublePendulum();
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{mu}));
  State s0 = sys.defaultState();
  s0.q << spec.q1, spec.q2;
  s0.qdot.setZero();
  WrapJumpCase c;
  c.model = wrapModelName(wrap.model);
  c.scene = "in_box";
  measureWrapJumps(sys, s0, mu, duration, c, monitor ? &*monitor : nullptr);
  if (monitor) {
    c.evaluations = monitor->evaluations(mu.name);
    c.fallbacks = monitor->fallbacks(mu.name);
  }
  return c;
}

// ---- everything ------------------------------------------------------------------------------

HardCasesResult runHardCases(const std::string& models_dir, bool quick, std::ostream* progress) {
  HardCasesResult res;
  const double c0 = cpuSeconds();
  auto say = [&](const std::string& what) {
    if (progress) *progress << "hard cases: " << what << std::endl;
  };
  auto add = [&](std::string name, std::string setup, std::string measured, std::string bound, bool passed) {
    res.rows.push_back({std::move(name), std::move(setup), std::move(measured), std::move(bound), passed});
  };

  say("spinning body (exponential coordinates)");
  {
    const SpinCase c = runSpinCase(quick ? 2.0 : 10.0);
    add("spin", "SphericalExp, torque-free asymmetric body, rk45 rtol 1e-10, " + fmt(c.revolutions) + " revolutions",
        std::to_string(c.chart_switches) + " chart switches, max |q| " + fmt(c.max_q_norm) + ", rel. energy error " +
            fmt(c.energy_err_rel) + ", rel. momentum error " + fmt(c.momentum_err_rel),
        "errors <= 1e-7, |q| <= 1.5 pi",
        c.energy_err_rel <= 1e-7 && c.momentum_err_rel <= 1e-7 && c.max_q_norm <= 1.5 * M_PI + 1e-12);
  }
  say("gimbal lock (Euler angles)");
  for (const std::string integ : {"rk45", "euler"}) {
    const GimbalCase c = runGimbalCase(integ, 1e-3);
    add("gimbal " + integ, "SphericalEuler XYZ tumbling into q2 = pi/2, guard |cos q2| >= 1e-3",
        (c.reported ? "reported at t = " + fmt(c.report_time) + " s" : std::string("not reported")) +
            ", closest |cos q2| " + fmt(c.min_distance) + "; unguarded: " + c.unguarded,
        "SimulationError naming the joint, no NaN", c.reported && c.state_finite);
  }
  say("light distal link, heavy muscle");
  {
    const auto runs = runLightDistalCase(quick);
    for (const std::string integ : {"euler", "symplectic", "bdf1", "rk45"}) {
      std::string ok, bad;
      for (const auto& r : runs) {
        if (r.integrator != integ) continue;
        std::string& dst = r.ok ? ok : bad;
        dst += (dst.empty() ? "" : ", ") + fmt(r.value) + (r.ok ? " (drift " + fmt(r.max_energy_err) + " J)" : "");
      }
      add("light distal " + integ, "0.01 kg distal link, 1 kg muscle, " + std::string(quick ? "0.5" : "2") + " s",
          "survive: " + (ok.empty() ? "none" : ok) + "; fail: " + (bad.empty() ? "none" : bad), "measured", true);
    }
  }
  say("stiff spring");
  {
    const StiffCase c = runStiffCase();
    bool bdf1_all = true;
    for (const auto& r : c.ladder)
      if (r.integrator == "bdf1" && !r.ok) bdf1_all = false;
    add("stiff euler", "hinge, omega = " + fmt(c.omega) + " rad/s, symplectic Euler",
        "largest stable h " + fmt(c.euler_largest_stable) + " s (theory 2/omega = " + fmt(c.euler_theory) + " s)",
        "within 1% of 2/omega", std::abs(c.euler_largest_stable / c.euler_theory - 1.0) < 0.01);
    add("stiff bdf1", "same, linearly implicit bdf1",
        "stable at every step of the ladder 1e-4 ... 1 s (largest " + fmt(c.bdf1_largest_stable) + " s, omega h = " +
            fmt(c.omega * c.bdf1_largest_stable) + ")",
        "stable where euler diverges", bdf1_all);
  }
  say("long run (60 s)");
  {
    const HardRun r = runLongRunCase(models_dir, 60.0, 1e-10);
    add("long run", "pendulum_straight (1 kg muscle, 20 points), 60 s, rk45 rtol 1e-10",
        "max |dE| " + fmt(r.max_energy_err) + " J, " + fmt(r.max_energy_err / 60.0) + " J/s; " +
            std::to_string(r.stats.steps) + " steps, " + fmt(r.cpu_s) + " s CPU",
        "|dE| <= 1e-7 J", r.ok && r.max_energy_err <= 1e-7);
  }
  say("conditional path point");
  {
    const ConditionalCase c = runConditionalCase(quick ? 2.0 : 5.0);
    double jmax = 0.0, dev = 0.0;
    for (const auto& s : c.switches) {
      jmax = std::max(jmax, std::abs(s.measured));
      dev = std::max(dev, std::abs(s.measured - s.predicted));
    }
    add("conditional", "double pendulum, 0.3 kg muscle, point active for q2 <= 0.3, rk45 rtol 1e-10",
        std::to_string(c.switches.size()) + " switches, largest |jump| " + fmt(jmax) +
            " J, max |measured - predicted| " + fmt(dev) + " J, drift between switches " + fmt(c.smooth_drift) + " J",
        "jump = predicted kinetic+potential change", !c.switches.empty() && dev <= 0.02 * jmax + 1e-7);
  }
  say("wrap contact changes (smooth and exact-FD path models)");
  for (const WrapModel wm : {WrapModel::Smooth, WrapModel::Exact}) {
    const WrapJumpCase c = runWrapJumpCase(models_dir, wm, 3.0);
    const bool smooth = wm == WrapModel::Smooth;
    const std::string name = "wrap jump " + c.model;
    add(name,
        "wrapping double pendulum, 1 kg muscle (20 points), " +
            std::string(smooth ? "smooth model (exact J, Jdot)" : "exact library, J and Jdot by central differences") +
            ", 3 s rk45 rtol 1e-12",
        std::to_string(c.contact_changes) + " contact changes, |net energy jump| " + fmt(c.min_jump) + " .. " +
            fmt(c.max_jump) + " J (50 ms window), largest 10 ms change away from them " + fmt(c.quiet_change) +
            " J, max |E - E0| " + fmt(c.drift) + " J of |E0| " + fmt(std::abs(c.energy0)) + " J",
        smooth ? "jump < 1e-8 J" : "jump > 1e-6 J (J jumps at the contact change)",
        !c.changes.empty() && (smooth ? c.max_jump < 1e-8 : c.min_jump > 1e-6));
    res.wrap_jumps.push_back(c);
  }
  // the committed networks were trained for end points within 3 radii of the axis: the osim
  // pendulum (5 radii) would run on the smooth fallback throughout, so the network's row is taken
  // on the code-built pendulum inside the box, with the smooth and exact-FD rows beside it
  {
    // osim_models/networks/cylinder_3x64.txt (defaultWrapNetworkPath's file, beside the scenes)
    const std::filesystem::path net_file = std::filesystem::path(models_dir) / "networks" / "cylinder_3x64.txt";
    const std::string net = std::filesystem::is_regular_file(net_file) ? net_file.string() : "";
    for (const WrapModel wm : {WrapModel::Smooth, WrapModel::Exact, WrapModel::Neural}) {
      WrapMassOptions wo;
      wo.model = wm;
      if (wm == WrapModel::Neural) {
        if (net.empty()) {
          add("wrap jump in box neural", "no committed cylinder network", "-", "-", true);
          continue;
        }
        wo.network = loadWrapNetwork(net);
      }
      const WrapJumpCase c = runWrapJumpCaseInBox(wo, 3.0);
      const bool exact = wm == WrapModel::Exact;
      add("wrap jump in box " + c.model,
          "code-built wrapping pendulum, end points 2.8 radii from the axis (scenes::WrapPendulumSpec), 1 kg "
          "muscle (20 points), " +
              std::string(wm == WrapModel::Neural ? "network cylinder_3x64 (exact J, Jdot of the MLP)"
                          : exact                 ? "exact library, FD J and Jdot"
                                                  : "smooth model") +
              ", 3 s rk45 rtol 1e-12",
          std::to_string(c.contact_changes) + " contact changes, |net energy jump| " + fmt(c.min_jump) + " .. " +
              fmt(c.max_jump) + " J, max |E - E0| " + fmt(c.drift) + " J" +
              (wm == WrapModel::Neural ? ", " + std::to_string(c.fallbacks) + " of " + std::to_string(c.evaluations) +
                                             " evaluations fell back to the smooth model"
                                       : std::string()),
          exact ? "jump > 1e-6 J" : "jump < 1e-8 J",
          !c.changes.empty() && (exact ? c.min_jump > 1e-6 : c.max_jump < 1e-8));
      res.wrap_jumps.push_back(c);
    }
  }
  say("finger flick");
  {
    res.flick = runFlickCase(models_dir, quick);
    // one row per integrator and step: lumped against inertial
    for (std::size_t i = 0; i + 1 < res.flick.size(); i += 2) {
      const FlickStudyRow& a = res.flick[i];
      const FlickStudyRow& b = res.flick[i + 1];  // runFlickStudy: lumped, then inertial
      auto part = [](const FlickStudyRow& r) {
        return r.variant + " " + fmt(r.artifact.largest_survived) + " N = " +
               fmt(1e3 * 0.002 * r.artifact.largest_survived) + " mN s (no artifact), " +
               fmt(r.divergence.largest_survived) + " N = " + fmt(1e3 * 0.002 * r.divergence.largest_survived) +
               " mN s (no divergence)";
      };
      const bool bracketed = a.artifact.largest_survived > 0 && b.artifact.largest_survived > 0 &&
                             a.divergence.largest_survived > 0 && b.divergence.largest_survived > 0;
      add("flick " + a.integrator + " dt " + fmt(1e3 * a.dt) + " ms",
          "finger, gravity, fingertip force for 2 ms, 1 s; inertial: FDP, FDS 0.2 kg each",
          part(a) + "; " + part(b) + "; inertial/lumped " +
              fmt(b.artifact.largest_survived / a.artifact.largest_survived),
          "largest survived, bisected to 1%", bracketed);
    }
  }
  say("NaN mid-run");
  for (const std::string integ : {"euler", "bdf1", "rk45", "cvode"}) {
    const NanCase c = runNanCase(integ);
    add("nan " + integ, "force NaN from t = 0.25 s", c.stopped ? c.message.substr(0, 240) : "not stopped",
        "stops naming time, coordinate, step", c.stopped && c.time >= 0.25 - 1e-9 && c.time < 0.3);
  }
  res.cpu_s = cpuSeconds() - c0;
  return res;
}

void addHardCasesToReport(const HardCasesResult& r, Report& report) {
  CsvTable t;
  t.header = {"case", "setup", "measured", "bound", "passed"};
  std::string md = "| case | setup | measured | bound | ok |\n|---|---|---|---|---|\n";
  JsonValue& js = report.section("hard_cases");
  for (const auto& row : r.rows) {
    t.addRow({row.name, row.setup, row.measured, row.bound, row.passed ? "yes" : "no"});
    // a '|' inside a cell (|q|, |dE|) would end the markdown cell
    auto cell = [](std::string x) {
      for (std::size_t p = x.find('|'); p != std::string::npos; p = x.find('|', p + 2)) x.replace(p, 1, "\\|");
      return x;
    };
    md += "| " + cell(row.name) + " | " + cell(row.setup) + " | " + cell(row.measured) + " | " + cell(row.bound) +
          " | " + (row.passed ? "yes" : "NO") + " |\n";
    JsonValue o = JsonValue::object();
    o["setup"] = JsonValue(row.setup);
    o["measured"] = JsonValue(row.measured);
    o["bound"] = JsonValue(row.bound);
    o["passed"] = JsonValue(row.passed);
    js[row.name] = std::move(o);
    report.addCheck("hard case: " + row.name, row.passed, row.measured);
  }
  md += "\nCPU time of the hard cases: " + fmt(r.cpu_s) + " s.\n";
  report.addTable("hard_cases", t, "hard cases: setup, measured number, bound");
  if (!r.flick.empty()) {
    CsvTable f;
    f.header = {"integrator", "dt_s", "variant", "impulse_time_s", "artifact_survived_N", "artifact_failed_N",
                "artifact_survived_impulse_Ns", "divergence_survived_N", "divergence_failed_N",
                "divergence_survived_impulse_Ns", "artifact_runs", "divergence_runs", "first_failure"};
    JsonValue arr = JsonValue::array();
    for (const auto& row : r.flick) {
      f.addRow({row.integrator, formatNumber(row.dt), row.variant, formatNumber(0.002),
                formatNumber(row.artifact.largest_survived), formatNumber(row.artifact.smallest_failed),
                formatNumber(0.002 * row.artifact.largest_survived), formatNumber(row.divergence.largest_survived),
                formatNumber(row.divergence.smallest_failed), formatNumber(0.002 * row.divergence.largest_survived),
                std::to_string(row.artifact.runs.size()), std::to_string(row.divergence.runs.size()),
                row.artifact.first_failure});
      JsonValue o = JsonValue::object();
      o["integrator"] = JsonValue(row.integrator);
      o["dt"] = JsonValue(row.dt);
      o["variant"] = JsonValue(row.variant);
      o["artifact_survived_N"] = JsonValue(row.artifact.largest_survived);
      o["divergence_survived_N"] = JsonValue(row.divergence.largest_survived);
      arr.push(std::move(o));
    }
    js["flick"] = std::move(arr);
    report.addTable("hard_flick", f,
                    "finger flick: largest fingertip force (N) and impulse (N s, force x 2 ms) survived, lumped "
                    "vs inertial, per integrator and step");
    md += "\nFinger flick (" + std::string("hard_flick.csv") + "): largest fingertip force survived, first failing "
          "force in brackets\n\n" + formatFlickTable(r.flick);
  }
  if (!r.wrap_jumps.empty()) {
    CsvTable w;
    w.header = {"scene", "model", "change", "time_s", "direction", "net_jump_J", "transient_J"};
    for (const auto& c : r.wrap_jumps)
      for (std::size_t k = 0; k < c.changes.size(); ++k) {
        const auto& ch = c.changes[k];
        w.addRow({c.scene, c.model, std::to_string(k + 1), formatNumber(ch.time), ch.wrapping ? "wrap" : "unwrap",
                  formatNumber(ch.jump), formatNumber(ch.transient)});
      }
    report.addTable("hard_wrap_jumps", w,
                    "wrapping double pendulum: net energy change across each contact change, per path model");
  }
  report.addMarkdown("Hard cases", md);
}

}  // namespace redmax::validation
