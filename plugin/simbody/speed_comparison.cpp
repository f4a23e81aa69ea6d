#include "plugin/simbody/speed_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <time.h>
#include <unistd.h>

#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/skeleton/kinematics.hpp"
#include "plugin/simbody/simbody_engine.hpp"

namespace redmax::simbody {

namespace {

// the Simbody integrator closest to each core integrator (same order and step control)
const std::map<std::string, std::string>& simbodyCounterpart() {
  static const std::map<std::string, std::string> m = {{"euler", "semi-explicit-euler"},
                                                       {"bdf1", "semi-explicit-euler"},
                                                       {"sdirk2", "semi-explicit-euler2"},
                                                       {"rk45", "rk-merson"},
                                                       {"cvode", "cpodes"}};
  return m;
}

// integrator pair stepping from the same initial state, restarting both every reset_every steps
struct IntegratorPair {
  std::unique_ptr<Integrator> core;
  std::unique_ptr<SimbodyEngine> sb;
  State s0, s;
  long core_calls = 0, sb_calls = 0;
  long sb_steps_done = 0;  // Simbody internal steps before the last restart
};

}  // namespace

struct SpeedComparison::Impl {
  std::string scene;
  SpeedOptions opt;
  System sys;
  State s0;
  VecX qddot;          // random accelerations for inverse dynamics (core)
  VecX udot;           // the same in Simbody's u space
  SimbodyEngine engine;
  // one workspace per op so that no op sees another's results
  SkeletonWorkspace ws_kin, ws_mass;
  DynamicsWorkspace ws_id, ws_fd;
  MatX M_r, M_u;
  VecX tau, f_u, qddot_out;
  std::vector<std::unique_ptr<IntegratorPair>> pairs;
  std::vector<SpeedOp> ops;
  std::vector<std::string> skipped;

  Impl(std::string name, const Model& model, const SpeedOptions& o)
      : scene(std::move(name)),
        opt(o),
        sys(model),
        engine(model, SimbodyBuildOptions{o.spherical, true, true}),
        ws_kin(model),
        ws_mass(model),
        ws_id(model),
        ws_fd(model) {}
};

SpeedComparison::SpeedComparison(std::string scene, const Model& model, const SpeedOptions& opt)
    : impl_(std::make_unique<Impl>(std::move(scene), model, opt)) {
  Impl& I = *impl_;
  const Model& m = I.sys.model();
  const int n = m.nr();

  // initial state: defaults plus a seeded perturbation, and random accelerations for ID
  std::mt19937 rng(opt.seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  I.s0 = I.sys.defaultState();
  for (int k = 0; k < n; ++k) {
    I.s0.q[k] += 0.2 * u(rng);
    I.s0.qdot[k] = 0.5 * u(rng);
  }
  I.qddot = VecX::NullaryExpr(n, [&] { return u(rng); });
  I.engine.setState(I.s0);
  VecX u_sb;
  I.engine.mapVelocities(I.s0.qdot, I.qddot, u_sb, I.udot);
  calcKinematics(m, I.s0, I.ws_mass);
  I.engine.realizePosition();

  auto& ops = I.ops;
  ops.push_back({"kinematics", "calcKinematics (E_wi, J_mr, phi, Jdot_mr)", "realize(Velocity)",
                 [&I] { calcKinematics(I.sys.model(), I.s0, I.ws_kin); },
                 [&I] {
                   I.engine.invalidatePositions();
                   I.engine.realizeVelocity();
                 },
                 nullptr});
  ops.push_back({"mass_matrix", "calcSkeletonMass (J_mr given)", "calcM (Position realized)",
                 [&I] { calcSkeletonMass(I.sys.model(), I.ws_mass, I.M_r); },
                 [&I] {
                   I.engine.realizePosition();  // no-op once realized
                   I.engine.calcMassMatrix(I.M_u);
                 },
                 nullptr});
  ops.push_back({"id_redmax", "System::inverseDynamics (kinematics, M_r, f_r, M qddot - f)",
                 "realize(Dynamics) + calcResidualForceIgnoringConstraints",
                 [&I] { I.tau = I.sys.inverseDynamics(I.s0, I.qddot, I.ws_id); },
                 [&I] {
                   I.engine.invalidatePositions();
                   I.engine.realizeDynamics();
                   I.engine.calcResidualForces(I.udot, I.f_u);
                 },
                 nullptr});
  ops.push_back({"id_recursive", "inverseDynamicsRecursive (RNEA)",
                 "realize(Dynamics) + calcResidualForceIgnoringConstraints",
                 [&I] { I.tau = inverseDynamicsRecursive(I.sys.model(), I.s0, I.qddot); },
                 [&I] {
                   I.engine.invalidatePositions();
                   I.engine.realizeDynamics();
                   I.engine.calcResidualForces(I.udot, I.f_u);
                 },
                 nullptr});
  ops.push_back({"forward_dynamics", "System::forwardDynamics (Auto route: ABA on the bare tree)", "realize(Acceleration)",
                 [&I] { I.qddot_out = I.sys.forwardDynamics(I.s0, I.ws_fd); },
                 [&I] {
                   I.engine.invalidatePositions();
                   I.engine.realizeAcceleration();
                 },
                 nullptr});

  // one step of each available integrator
  IntegratorOptions iopt;
  iopt.dt = opt.dt;
  iopt.rtol = opt.rtol;
  iopt.atol = opt.atol;
  for (const std::string& name : opt.integrators) {
    auto pair = std::make_unique<IntegratorPair>();
    try {
      pair->core = makeIntegrator(name, iopt);
    } catch (const std::exception& e) {
      I.skipped.push_back(name + ": " + e.what());
      continue;
    }
    const auto it = simbodyCounterpart().find(name);
    if (it == simbodyCounterpart().end()) {
      I.skipped.push_back(name + ": no Simbody counterpart chosen");
      continue;
    }
    pair->sb = std::make_unique<SimbodyEngine>(m, SimbodyBuildOptions{opt.spherical, true, true});
    pair->sb->setState(I.s0);
    pair->sb->initIntegrator(it->second, opt.dt, opt.rtol);
    pair->s0 = I.s0;
    pair->s = I.s0;
    IntegratorPair* P = pair.get();
    const int reset = std::max(1, opt.reset_every);
    const double dt = opt.dt;
    ops.push_back({"step_" + name, "makeIntegrator(\"" + name + "\")->advance by dt",
                   "SimTK " + it->second + " stepTo(t + dt)",
                   [&I, P, reset, dt] {
                     if (P->core_calls++ % reset == 0) P->s = P->s0;
                     P->core->advance(I.sys, P->s, P->s.t + dt);
                   },
                   [P, reset] {
                     if (P->sb_calls++ % reset == 0) {
                       P->sb_steps_done += P->sb->integratorSteps();
                       P->sb->setState(P->s0);
                     }
                     P->sb->stepIntegrator();
                   },
                   [P] {
                     // internal steps per call of dt: adaptive methods may take several, or none
                     // (output by interpolation)
                     char buf[160];
                     std::snprintf(buf, sizeof buf, "internal steps per call: redmax %.3g, Simbody %.3g",
                                   P->core_calls ? double(P->core->stats().steps) / P->core_calls : 0.0,
                                   P->sb_calls ? double(P->sb_steps_done + P->sb->integratorSteps()) / P->sb_calls
                                               : 0.0);
                     return std::string(buf);
                   }});
    I.pairs.push_back(std::move(pair));
  }
}

SpeedComparison::~SpeedComparison() = default;

const std::string& SpeedComparison::scene() const { return impl_->scene; }
int SpeedComparison::dof() const { return impl_->sys.model().nr(); }
std::vector<SpeedOp>& SpeedComparison::ops() { return impl_->ops; }
const std::vector<std::string>& SpeedComparison::skipped() const { return impl_->skipped; }

std::vector<SpeedRow> timeSpeedComparison(SpeedComparison& cmp, int repeats, int batches) {
  if (repeats < 1) throw std::invalid_argument("repeats must be at least 1");
  if (batches < 1) throw std::invalid_argument("batches must be at least 1");
  // CPU time of this thread: on a machine shared with other jobs, wall time mostly measures the
  // others; every op here is single-threaded compute, so its CPU time is its cost
  auto cpuNow = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e6 * static_cast<double>(ts.tv_sec) + 1e-3 * static_cast<double>(ts.tv_nsec);
  };
  auto timeBatch = [repeats, &cpuNow](const std::function<void()>& f) {
    const double t0 = cpuNow();
    for (int r = 0; r < repeats; ++r) f();
    return (cpuNow() - t0) / repeats;
  };
  std::vector<SpeedRow> rows;
  for (const SpeedOp& op : cmp.ops()) {
    SpeedRow row{cmp.scene(), cmp.dof(), op.name, op.redmax_what, op.simbody_what, INFINITY, INFINITY, ""};
    bool ok_r = true, ok_s = true;
    // one side failing (e.g. an integrator diverging on this scene) must not stop the other
    auto guarded = [&](bool& ok, const char* side, const std::function<void()>& f, double& best) {
      if (!ok) return;
      try {
        best = std::min(best, timeBatch(f));
      } catch (const std::exception& e) {
        ok = false;
        best = NAN;
        row.note += std::string(row.note.empty() ? "" : "; ") + side + " failed: " + e.what();
      }
    };
    // warm-up: caches, lazy allocations, first integrator initialisation (not timed)
    auto warm = [&](bool& ok, const char* side, const std::function<void()>& f, double& best) {
      try {
        f();
      } catch (const std::exception& e) {
        ok = false;
        best = NAN;
        row.note += std::string(row.note.empty() ? "" : "; ") + side + " failed: " + e.what();
      }
    };
    warm(ok_r, "redmax", op.redmax, row.redmax_us);
    warm(ok_s, "simbody", op.simbody, row.simbody_us);
    for (int b = 0; b < batches; ++b) {
      guarded(ok_r, "redmax", op.redmax, row.redmax_us);
      guarded(ok_s, "simbody", op.simbody, row.simbody_us);
    }
    if (op.remark) row.note += std::string(row.note.empty() ? "" : "; ") + op.remark();
    rows.push_back(row);
  }
  return rows;
}

double SpeedRow::ratio() const {
  if (!(redmax_us >= 0.0) || !(simbody_us > 0.0)) return NAN;
  return redmax_us / simbody_us;
}

std::string formatSpeedTable(const std::vector<SpeedRow>& rows) {
  std::ostringstream os;
  char line[256];
  std::snprintf(line, sizeof line, "%-12s %4s  %-18s %12s %12s %8s\n", "scene", "DoF", "operation",
                "redmax us", "Simbody us", "ratio");
  os << line;
  auto cell = [](double v, const char* fmt) {
    char buf[32];
    if (std::isfinite(v)) std::snprintf(buf, sizeof buf, fmt, v);
    else std::snprintf(buf, sizeof buf, "%s", "failed");
    return std::string(buf);
  };
  std::string notes;
  for (const SpeedRow& r : rows) {
    std::snprintf(line, sizeof line, "%-12s %4d  %-18s %12s %12s %8s\n", r.scene.c_str(), r.dof, r.op.c_str(),
                  cell(r.redmax_us, "%.3f").c_str(), cell(r.simbody_us, "%.3f").c_str(),
                  std::isfinite(r.ratio()) ? cell(r.ratio(), "%.3f").c_str() : "-");
    os << line;
    if (!r.note.empty()) notes += "  " + r.scene + " " + r.op + ": " + r.note + "\n";
  }
  if (!notes.empty()) os << "notes:\n" << notes;
  return os.str();
}

namespace {
std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"') out += "\\\"";
    else if (c == '\\') out += "\\\\";
    else if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}
std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
}  // namespace

void writeSpeedJson(const std::vector<SpeedRow>& rows, const std::string& path) {
  std::ostringstream os;
  os << "{\n  \"unit\": \"us\",\n  \"threads\": 1,\n  \"rows\": [";
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const SpeedRow& r = rows[k];
    os << (k ? ",\n" : "\n") << "    {\"scene\": " << jsonString(r.scene) << ", \"dof\": " << r.dof
       << ", \"operation\": " << jsonString(r.op) << ", \"redmax_us\": " << jsonNumber(r.redmax_us)
       << ", \"simbody_us\": " << jsonNumber(r.simbody_us) << ", \"ratio\": " << jsonNumber(r.ratio())
       << ", \"redmax\": " << jsonString(r.redmax_what) << ", \"simbody\": " << jsonString(r.simbody_what)
       << ", \"note\": " << jsonString(r.note) << "}";
  }
  os << "\n  ]\n}\n";
  // atomic: write beside the target, then rename over it
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path tmp = target.string() + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot open for writing");
    out << os.str();
    out.close();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error(path + ": write failed");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ec2;
    fs::remove(tmp, ec2);
    throw std::runtime_error(path + ": cannot rename temporary file into place: " + ec.message());
  }
}

}  // namespace redmax::simbody
