// The reaching task (validation/optimize/reach.hpp, docs/gradients.md §7).
#include "validation/optimize/reach.hpp"

#include <LBFGS.h>
#include <LBFGSB.h>
#include <nlopt.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <exception>
#include <limits>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "converter/atomic_file.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/report/plot.hpp"

namespace redmax::validation {
namespace {

std::string joined(const std::vector<std::string>& v, const std::string& sep) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

Vec3 bodyPoint(const Model& model, const State& s, int body, const Vec3& x_i) {
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  return transformPoint(sk.E_wi[body], x_i);
}

bool isTrack(const ReachOptions& o) { return o.task == "track"; }

// thrown from inside an objective evaluation to end a method once the stop objective is met
struct Reached {};

// the evaluations of one method: counts, timing, the best point so far
class Tracker {
 public:
  Tracker(const ReachSetup& setup, ReachResult& result, const ReachProgress& progress)
      : setup_(setup), result_(result), progress_(progress), t0_(std::chrono::steady_clock::now()) {
    stop_ = stopObjective(setup.options);
    best_ = std::numeric_limits<double>::infinity();
  }

  /// x: the scaled parameters (u = scale x); gradient: dJ/dx
  double evaluate(const VecX& x, VecX* gradient) {
    const VecX u = setup_.scale.cwiseProduct(x);
    if (result_.simulations >= setup_.options.max_simulations) throw Exhausted{};
    adjoint::Result r;
    bool failed = false;
    try {
      r = adjoint::evaluate(setup_.gradient.problem, setup_.gradient.objective, u, gradient != nullptr);
    } catch (const SimulationError&) {
      // torques that make the arm spin until the fixed step diverges: an infinite objective, so
      // that line searches step back and simplex methods move away; the start must run
      if (result_.simulations == 0) throw;
      failed = true;
      ++result_.failed_simulations;
    } catch (const hill::MuscleModelError& e) {
      // excitations whose run drives a muscle model out of its domain (e.g. a damped fibre
      // velocity that does not converge): the same, a failed run
      if (result_.simulations == 0) throw SimulationError(e.what(), 0.0, setup_.options.dt);
      failed = true;
      ++result_.failed_simulations;
    }
    ReachEvaluation e;
    e.simulations = ++result_.simulations;
    e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    if (failed) {
      if (gradient) *gradient = VecX::Zero(u.size());
      e.objective = std::numeric_limits<double>::infinity();
      e.error = std::numeric_limits<double>::infinity();
      e.step_evaluations = result_.step_evaluations;
      e.best_objective = best_;
      result_.evaluations.push_back(e);
      if (progress_) progress_(result_.method, e);
      return e.objective;
    }
    if (gradient) {
      *gradient = setup_.scale.cwiseProduct(r.gradient);
      result_.gradient_route = adjoint::stepJacobiansText(r);
    }
    result_.step_evaluations += r.step_evaluations;
    e.step_evaluations = result_.step_evaluations;
    e.objective = r.objective;
    if (isTrack(setup_.options)) {
      e.error = trackingError(setup_.options, r.objective);
    } else {
      const auto& pt = setup_.gradient.objective.points.front();
      e.error = (bodyPoint(setup_.gradient.model.system->model(), r.final, pt.body, pt.x_i) - pt.target).norm();
    }
    if (r.objective < best_) {
      best_ = r.objective;
      result_.torques = u;
      result_.objective = r.objective;
      result_.error = e.error;
      result_.final_speed = r.final.qdot.norm();
    }
    e.best_objective = best_;
    result_.evaluations.push_back(e);
    if (progress_) progress_(result_.method, e);
    if (r.objective <= stop_) throw Reached{};
    return r.objective;
  }

  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }
  struct Exhausted {};

 private:
  const ReachSetup& setup_;
  ReachResult& result_;
  const ReachProgress& progress_;
  std::chrono::steady_clock::time_point t0_;
  double stop_ = 0.0, best_ = 0.0;
};

struct NloptData {
  Tracker* tracker = nullptr;
  nlopt_opt opt = nullptr;
  bool reached = false, exhausted = false;
  std::exception_ptr error;
};

double nloptObjective(unsigned n, const double* x, double* /*grad*/, void* data) {
  auto* d = static_cast<NloptData*>(data);
  try {
    return d->tracker->evaluate(Eigen::Map<const VecX>(x, n), nullptr);
  } catch (const Reached&) {
    d->reached = true;
  } catch (const Tracker::Exhausted&) {
    d->exhausted = true;
  } catch (...) {
    d->error = std::current_exception();
  }
  // a C callback must not throw: stop NLopt here (a NaN return alone does not stop Nelder-Mead)
  nlopt_force_stop(d->opt);
  return std::numeric_limits<double>::infinity();
}

void runNlopt(const ReachSetup& setup, nlopt_algorithm algorithm, Tracker& tracker, ReachResult& res) {
  const unsigned n = static_cast<unsigned>(setup.gradient.p0.size());
  const double box = setup.options.max_torque;
  std::vector<double> lo(n), hi(n), x(n, 0.0);
  for (unsigned i = 0; i < n; ++i) {
    x[i] = setup.x0[i];
    if (setup.bounded) {
      lo[i] = setup.lower[i];
      hi[i] = setup.upper[i];
    } else {
      hi[i] = box / setup.scale[i];
      lo[i] = -hi[i];
    }
  }
  // a method that converges (its step below xtol) short of the stop objective, e.g. against a
  // jump of the objective (a wrap the library switches off, docs/wrapping.md), starts again from
  // the best point with its first step, as long as the previous attempt improved the objective
  double last_best = std::numeric_limits<double>::infinity();
  for (;;) {
    nlopt_opt opt = nlopt_create(algorithm, n);
    if (!opt) throw std::runtime_error("NLopt: cannot create the optimizer");
    NloptData data;
    data.tracker = &tracker;
    data.opt = opt;
    nlopt_set_lower_bounds(opt, lo.data());
    nlopt_set_upper_bounds(opt, hi.data());
    nlopt_set_min_objective(opt, nloptObjective, &data);
    nlopt_set_xtol_rel(opt, 1e-10);
    nlopt_set_initial_step1(opt, setup.options.initial_step);  // rad/s^2, or excitation
    double f = 0.0;
    const nlopt_result r = nlopt_optimize(opt, x.data(), &f);
    nlopt_destroy(opt);
    if (data.reached) {
      res.stop = "reached the stop objective";
      return;
    }
    if (data.exhausted) {
      res.stop = "max simulations";
      return;
    }
    if (data.error) std::rethrow_exception(data.error);
    res.stop = std::string("NLopt: ") + nlopt_result_to_string(r);
    if (!(r == NLOPT_SUCCESS || r == NLOPT_XTOL_REACHED || r == NLOPT_FTOL_REACHED) || !(res.objective < last_best))
      return;
    last_best = res.objective;
    for (unsigned i = 0; i < n; ++i) x[i] = res.torques[i] / setup.scale[i];
    ++res.restarts;
  }
}

}  // namespace

double stopObjective(const ReachOptions& o) {
  if (o.stop_objective >= 0.0) return o.stop_objective;
  return 0.5 * o.tolerance * o.tolerance * (isTrack(o) ? o.duration : 1.0);
}

double trackingError(const ReachOptions& o, double objective) { return std::sqrt(2.0 * std::max(objective, 0.0) / o.duration); }

const std::vector<std::string>& reachMethods() {
  static const std::vector<std::string> m{"lbfgs", "nelder-mead", "bobyqa"};
  return m;
}

double startRate(const adjoint::Objective::CoordinateTrack& track, double time) {
  const auto& t = track.t;
  const auto& v = track.value;
  const size_t n = t.size();
  if (n < 2) return 0.0;
  if (n == 2) return (v[1] - v[0]) / (t[1] - t[0]);
  size_t i = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
  i = i == 0 ? 0 : i - 1;
  i = std::min(i, n - 3);
  // d/dt of the Lagrange quadratic through (t_i, v_i), (t_i+1, v_i+1), (t_i+2, v_i+2)
  const double a = t[i], b = t[i + 1], c = t[i + 2];
  return v[i] * ((time - b) + (time - c)) / ((a - b) * (a - c)) +
         v[i + 1] * ((time - a) + (time - c)) / ((b - a) * (b - c)) +
         v[i + 2] * ((time - a) + (time - b)) / ((c - a) * (c - b));
}

ReachSetup makeReachSetup(const ReachOptions& options) {
  ReachSetup s;
  s.options = options;
  const bool track = isTrack(options);
  if (!track && options.task != "reach") throw std::invalid_argument("--task '" + options.task + "': unknown (reach or track)");
  if (track && options.motion.empty() && options.objective.empty())
    throw std::invalid_argument("--task track: needs --motion FILE.mot and/or --objective SPEC with a tracking term");
  if (track && options.drive != "torques") throw std::invalid_argument("--task track: drives torques only");
  for (int k = 0; k < 3 && !track; ++k)
    if (!std::isfinite(options.target[k])) throw std::invalid_argument("--target: must be three finite numbers X,Y,Z (m)");
  if (!(options.tolerance > 0.0)) throw std::invalid_argument("--tolerance: must be > 0");
  const std::string& speeds = options.initial_speeds;
  if (speeds != "default" && speeds != "motion" && speeds != "free")
    throw std::invalid_argument("--initial-speeds '" + speeds + "': unknown (default, motion or free)");
  if (!track && speeds != "default") throw std::invalid_argument("--initial-speeds: needs --task track");
  // the coordinates: all of the model's unless named; validated by the gradient SPEC
  SimulationModel probe_model;
  std::vector<std::string> coords = options.coordinates;
  if (coords.empty()) {
    probe_model = loadSimulationModel(options.model_path, SimulationModelOptions{});
    coords = probe_model.coordinate_names;
    if (coords.empty()) throw std::invalid_argument(options.model_path + ": the model has no coordinates to drive");
  }
  for (const auto& c : coords)
    if (c.empty() || c.find_first_of(",;@=") != std::string::npos)
      throw std::invalid_argument("--coordinates '" + c + "': not a coordinate name");
  const bool excite = options.drive == "excitations";
  if (!excite && options.drive != "torques")
    throw std::invalid_argument("--drive '" + options.drive + "': unknown (torques or excitations)");
  std::vector<std::string> torque_items = coords;
  if (!options.torques_in_time.empty()) {
    // K, K~linear or K~cubic after each coordinate (the gradient's torques SPEC, docs/gradients.md §3)
    const std::string& t = options.torques_in_time;
    const auto tilde = t.find('~');
    const std::string count = t.substr(0, tilde), how = tilde == std::string::npos ? "" : t.substr(tilde + 1);
    char* end = nullptr;
    const long k = std::strtol(count.c_str(), &end, 10);
    if (count.empty() || *end != '\0' || k < 1 || k > 100000 || (tilde != std::string::npos && how != "linear" && how != "cubic") ||
        (how == "cubic" && k < 4))
      throw std::invalid_argument("--torques-in-time '" + t + "': expected K (constant pieces), K~linear or K~cubic "
                                  "(K >= 4 for cubic)");
    for (auto& c : torque_items) c += "@" + t;
  }
  std::string params = "torques:" + joined(torque_items, ",");
  if (excite) {
    if (options.nodes < 1) throw std::invalid_argument("--nodes: must be at least 1");
    std::vector<std::string> muscles = options.muscles;
    if (muscles.empty()) {
      const SimulationModel m = loadSimulationModel(options.model_path, SimulationModelOptions{});
      const auto& models = m.build.model.muscleModels();
      for (size_t k = 0; k < m.build.model.muscles().size(); ++k)
        if (k < models.size() && models[k]) muscles.push_back(m.build.model.muscles()[k].name);
      if (muscles.empty()) throw std::invalid_argument(options.model_path + ": no muscle has a Hill-type force model to excite");
    }
    std::vector<std::string> items;
    for (const auto& m : muscles) {
      if (m.empty() || m.find_first_of(",;@=") != std::string::npos)
        throw std::invalid_argument("--excite '" + m + "': not a muscle name");
      std::ostringstream item;
      item.precision(17);
      item << m << "@" << options.nodes << "=" << options.initial_excitation;
      items.push_back(item.str());
    }
    params = "excitations:" + joined(items, ",");
  }
  // track: the motion's coords: term first, then the further terms; reach: the point is added below
  std::string objective = "speed";
  if (track) {
    objective = options.motion.empty() ? "" : "coords:" + options.motion;
    if (!options.objective.empty()) objective += (objective.empty() ? "" : ";") + options.objective;
  }
  try {
    s.gradient = makeGradientSetup(options.model_path, options.model_options, options.integrator, options.duration,
                                   options.dt, params, objective);
  } catch (const std::invalid_argument& e) {
    // "--params 'torques:x': no coordinate named 'x'" in the reach command's words
    std::string what = e.what();
    const std::string p = "--params";
    const std::string motion_term = "--objective 'coords:" + options.motion + "'";
    if (track && !options.motion.empty() && what.rfind(motion_term, 0) == 0)
      what = "--motion '" + options.motion + "'" + what.substr(motion_term.size());
    if (what.rfind(p + " 'torques:", 0) == 0) what = "--coordinates '" + what.substr(p.size() + 10);
    if (what.rfind(p + " 'excitations:", 0) == 0) {
      // the item's value is the --initial-excitation, its name a --muscles entry
      const std::string item = what.substr(p.size() + 14);  // after "--params 'excitations:"
      const auto end = item.find("': ");
      const std::string reason = end == std::string::npos ? item : item.substr(end + 3);
      if (what.find("[min_control, max_control]") != std::string::npos)
        what = "--initial-excitation: " + reason;
      else
        what = "--excite '" + item.substr(0, item.find('@')) + "': " + reason;
    }
    throw std::invalid_argument(what);
  }
  const Model& model = s.gradient.model.system->model();
  if (track) {
    if (!s.gradient.objective.tracking())
      throw std::invalid_argument("--objective '" + options.objective +
                                  "': --task track needs a tracking term (coords:FILE.mot or track:MARKER=FILE.trc)");
    s.gradient.objective.speed_weight += options.rest_weight;
    // the run starts from the motion's pose at the start for the coordinates it tracks (at the
    // speeds initial_speeds names), projected onto the constraints as the default state is
    if (speeds != "default" && s.gradient.objective.coordinate_tracks.empty())
      throw std::invalid_argument("--initial-speeds " + speeds + ": needs --motion (the speeds are the tracked "
                                  "coordinates' rates)");
    GradientSetup& g = s.gradient;
    State& s0 = g.problem.initial;
    for (const auto& ct : g.objective.coordinate_tracks) {
      s0.q[ct.coordinate] = ct.at(s0.t);
      if (speeds == "motion") s0.qdot[ct.coordinate] = startRate(ct, s0.t);
      if (speeds == "free") {
        // the speed joins the parameters after the torques (the gradient's qdot0: kind; the
        // track's parameters are torques alone, so it goes last), from the motion's rate
        g.problem.initial_qdot.push_back(ct.coordinate);
        g.param_names.push_back("qdot0 " + g.model.coordinate_names.at(static_cast<size_t>(ct.coordinate)));
        g.p0.conservativeResize(g.p0.size() + 1);
        g.p0[g.p0.size() - 1] = startRate(ct, s0.t);
      }
    }
    const System& sys = *s.gradient.model.system;
    if (sys.numConstraintRows() > 0) {
      DynamicsWorkspace pws(sys.model());
      sys.projectPositions(s0, pws);
      sys.projectVelocities(s0, pws);
    }
  } else {
    adjoint::Objective::Point pt;
    pt.body = model.findBody(options.body);
    if (pt.body < 0) throw std::invalid_argument("--body '" + options.body + "': no body named so in " + options.model_path);
    pt.x_i = options.point;
    pt.target = options.target;
    s.gradient.objective = adjoint::Objective{};
    s.gradient.objective.points.push_back(pt);
    s.gradient.objective.speed_weight = options.rest_weight;
    s.gradient.objective.excitation_weight = excite ? options.excitation_weight : 0.0;
    s.start_point = bodyPoint(model, s.gradient.problem.initial, pt.body, pt.x_i);
  }
  const System& system = *s.gradient.model.system;
  DynamicsWorkspace ws(system);
  system.calcMassAndForce(s.gradient.problem.initial, ws);
  if (excite) {
    // excitations are dimensionless and bounded: no scaling, L-BFGS-B within the bounds
    const auto& ex = s.gradient.problem.excitations;
    const Eigen::Index n = static_cast<Eigen::Index>(ex.size());
    s.scale = VecX::Ones(n);
    s.x0 = s.gradient.p0;
    s.lower.resize(n);
    s.upper.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      s.lower[i] = ex[static_cast<size_t>(i)].min;
      s.upper[i] = ex[static_cast<size_t>(i)].max;
    }
    s.bounded = true;
    return s;
  }
  const auto& forces = s.gradient.problem.forces;
  // initial speeds (--initial-speeds free): unscaled, rad/s (measured on the reach arm, L-BFGS to
  // RMS 1e-6 rad: 117 simulations unscaled, 156 at 0.3 rad/s per unit, none converged at 3 or more)
  s.scale = VecX::Ones(s.gradient.p0.size());
  for (size_t i = 0; i < forces.size(); ++i) {
    const double m = ws.M(forces[i].coordinate, forces[i].coordinate);
    if (!(m > 0.0)) throw std::invalid_argument("--coordinates '" + s.gradient.param_names[i] + "': no inertia to drive");
    s.scale[static_cast<Eigen::Index>(i)] = m;
  }
  s.x0 = s.gradient.p0.cwiseQuotient(s.scale);
  return s;
}

ReachResult optimizeReach(const ReachSetup& setup, const std::string& method, const ReachProgress& progress) {
  ReachResult res;
  res.method = method;
  res.names = setup.gradient.param_names;
  res.torques = setup.gradient.p0;
  Tracker tracker(setup, res, progress);
  if (method == "lbfgs") {
    LBFGSpp::LBFGSParam<double> param;
    param.epsilon = 1e-10;
    param.epsilon_rel = 1e-10;
    param.max_iterations = 0;  // bounded by max_simulations instead
    // Wolfe steps keep s'y > 0, so the quasi-Newton matrix stays positive definite on this
    // non-convex objective (Armijo steps alone let LBFGSpp 0.1 produce ascent directions)
    param.linesearch = LBFGSpp::LBFGS_LINESEARCH_BACKTRACKING_STRONG_WOLFE;
    param.max_linesearch = 40;
    auto f = [&](const VecX& x, VecX& g) { return tracker.evaluate(x, &g); };
    // a failed line search restarts from the best point with an empty memory, as long as the
    // previous attempt improved the objective
    VecX x = setup.x0;
    double last_best = std::numeric_limits<double>::infinity();
    LBFGSpp::LBFGSBParam<double> bparam;
    bparam.epsilon = 1e-10;
    bparam.epsilon_rel = 1e-10;
    bparam.max_iterations = 0;
    bparam.max_linesearch = 40;
    for (;;) {
      double fx = 0.0;
      try {
        if (setup.bounded) {
          LBFGSpp::LBFGSBSolver<double> solver(bparam);
          solver.minimize(f, x, fx, setup.lower, setup.upper);
        } else {
          LBFGSpp::LBFGSSolver<double> solver(param);
          solver.minimize(f, x, fx);
        }
        res.stop = "gradient below 1e-10";
        break;
      } catch (const Reached&) {
        res.stop = "reached the stop objective";
        break;
      } catch (const Tracker::Exhausted&) {
        res.stop = "max simulations";
        break;
      } catch (const SimulationError&) {
        throw;
      } catch (const std::exception& e) {
        res.stop = std::string("line search: ") + e.what();
      }
      if (!(res.objective < last_best)) break;
      last_best = res.objective;
      x = res.torques.cwiseQuotient(setup.scale);
      ++res.restarts;
    }
  } else if (method == "nelder-mead") {
    runNlopt(setup, NLOPT_LN_NELDERMEAD, tracker, res);
  } else if (method == "bobyqa") {
    runNlopt(setup, NLOPT_LN_BOBYQA, tracker, res);
  } else {
    throw std::invalid_argument("--method '" + method + "': unknown (lbfgs, nelder-mead or bobyqa)");
  }
  res.seconds = tracker.seconds();
  res.reached = res.error <= setup.options.tolerance;
  return res;
}

ReachReplay replayReach(const ReachSetup& setup, const VecX& params) {
  ReachReplay rp;
  const GradientSetup& g = setup.gradient;
  const auto& pt = g.objective.points.front();
  auto handPath = [&](const adjoint::Trajectory& tr, std::vector<Vec3>& out) {
    const Model& model = tr.system->model();
    SkeletonWorkspace sk(model);
    for (const State& st : tr.states) {
      calcKinematics(model, st, sk);
      out.push_back(transformPoint(sk.E_wi[pt.body], pt.x_i));
    }
  };
  const adjoint::Trajectory tr = adjoint::simulateTrajectory(g.problem, params);
  for (const State& st : tr.states) rp.t.push_back(st.t);
  handPath(tr, rp.hand);
  const System& sys = *tr.system;
  const Model& model = sys.model();
  const MuscleForceTerm* mft = nullptr;
  size_t term = 0;
  for (size_t i = 0; i < sys.terms().size(); ++i)
    if (const auto* m = dynamic_cast<const MuscleForceTerm*>(sys.terms()[i].get())) {
      mft = m;
      term = i;
    }
  if (mft) {
    // the excited muscles, in parameter order
    std::vector<int> controls;
    for (const auto& e : g.problem.excitations)
      if (controls.empty() || controls.back() != e.control) controls.push_back(e.control);
    SkeletonWorkspace sk(model);
    rp.excitation.resize(controls.size());
    rp.tendon_force.resize(controls.size());
    for (int c : controls) rp.muscles.push_back(mft->actuated()[static_cast<size_t>(c - sys.controlOffset(term))].muscle.name);
    for (size_t j = 0; j < tr.states.size(); ++j) {
      const State& st = tr.states[j];
      calcKinematics(model, st, sk);
      const VecX& u = tr.controls[std::min(j, tr.controls.size() - 1)];  // the last state: the last step's
      for (size_t m = 0; m < controls.size(); ++m) {
        const int k = controls[m] - sys.controlOffset(term);
        const auto& a = mft->actuated()[static_cast<size_t>(k)];
        double length = 0.0, speed = 0.0;
        VecX dl_dq;
        mft->calcPath(model, st, sk, k, length, speed, dl_dq);
        hill::MuscleOutput out;
        VecX zdot(a.model->numStates());
        a.model->calc(st.z.data() + sys.stateOffset(term) + a.z_offset, {length, speed, u[controls[m]]}, out, zdot.data());
        rp.excitation[m].push_back(u[controls[m]]);
        rp.tendon_force[m].push_back(out.tendon_force);
      }
    }
  }
  if (g.model.muscle_mass > 0.0) {
    // the same parameters on the model without muscle mass
    ReachOptions lumped = setup.options;
    lumped.model_options.muscle_mass = osim::MuscleMassOptions{};
    lumped.model_options.explicit_masses.clear();
    const ReachSetup ls = makeReachSetup(lumped);
    handPath(adjoint::simulateTrajectory(ls.gradient.problem, params), rp.lumped_hand);
    rp.lumped_error = (rp.lumped_hand.back() - pt.target).norm();
  }
  return rp;
}

TrackReplay replayTrack(const ReachSetup& setup, const VecX& params) {
  TrackReplay rp;
  const GradientSetup& g = setup.gradient;
  const adjoint::Trajectory tr = adjoint::simulateTrajectory(g.problem, params);
  for (const State& st : tr.states) rp.t.push_back(st.t);
  const auto& names = g.model.coordinate_names;
  double sum = 0.0;
  long count = 0;
  for (const auto& ct : g.objective.coordinate_tracks) {
    rp.coordinates.push_back(static_cast<size_t>(ct.coordinate) < names.size() ? names[static_cast<size_t>(ct.coordinate)]
                                                                               : std::to_string(ct.coordinate));
    std::vector<double> q, target;
    for (size_t j = 0; j < tr.states.size(); ++j) {
      const State& st = tr.states[j];
      q.push_back(st.q[ct.coordinate]);
      target.push_back(ct.at(st.t));
      if (j > 0) {
        sum += (q.back() - target.back()) * (q.back() - target.back());
        ++count;
      }
    }
    rp.simulated.push_back(std::move(q));
    rp.target.push_back(std::move(target));
  }
  // per state, summed over the coordinates: the mean of the sum is what trackingError reports for
  // a unit-weight coords: term
  const double states = static_cast<double>(tr.states.size() > 1 ? tr.states.size() - 1 : 1);
  rp.rms = count ? std::sqrt(sum / states) : 0.0;
  return rp;
}

namespace {

std::string fmt(double v, int digits = 6) {
  std::ostringstream o;
  o.precision(digits);
  o << v;
  return o.str();
}

// one line per method that took gradients: how its adjoint formed the step Jacobians
void gradientRoutes(std::ostream& md, const std::vector<ReachResult>& results) {
  bool any = false;
  for (const ReachResult& r : results) {
    if (r.gradient_route.empty()) continue;
    md << (any ? "" : "\n") << "- " << r.method << " step Jacobians: " << r.gradient_route << "\n";
    any = true;
  }
}

// the converged parameters, one column per method (after the table's heading line)
void parameterTable(std::ostream& md, const std::vector<std::string>& names, const std::vector<ReachResult>& results) {
  for (const ReachResult& r : results) md << " " << r.method << " |";
  md << "\n|---|";
  for (size_t k = 0; k < results.size(); ++k) md << "---|";
  md << "\n";
  for (size_t i = 0; i < names.size(); ++i) {
    md << "| " << names[i] << " |";
    for (const ReachResult& r : results) md << " " << fmt(r.torques[static_cast<Eigen::Index>(i)], 10) << " |";
    md << "\n";
  }
}

std::string vec3(const Vec3& v) { return fmt(v[0]) + ", " + fmt(v[1]) + ", " + fmt(v[2]); }

}  // namespace

std::string writeReachReport(const std::string& dir, const ReachSetup& setup, const std::vector<ReachResult>& results,
                             const std::string& command_line) {
  namespace fs = std::filesystem;
  const fs::path target(dir);
  const fs::path tmp = target.parent_path() / (target.filename().string() + ".tmp-" + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(tmp, ec);
  if (!fs::create_directories(tmp, ec) && ec) throw std::runtime_error(tmp.string() + ": " + ec.message());
  const ReachOptions& o = setup.options;

  // per method: one row per objective evaluation
  for (const ReachResult& r : results) {
    std::ostringstream c;
    c.precision(12);
    c << "evaluation,simulations,step_evaluations,seconds,objective,best_objective,error_m\n";
    for (size_t i = 0; i < r.evaluations.size(); ++i) {
      const ReachEvaluation& e = r.evaluations[i];
      c << i + 1 << "," << e.simulations << "," << e.step_evaluations << "," << e.seconds << "," << e.objective << ","
        << e.best_objective << "," << e.error << "\n";
    }
    osim::writeFileAtomic((tmp / (r.method + "_iterations.csv")).string(), c.str());
  }

  // the best objective so far against simulations, every method on one log-scale panel
  PlotFigure fig;
  fig.title = (isTrack(o) ? "tracking task: " : "reaching task: ") + setup.gradient.model.description.name;
  PlotPanel panel;
  panel.title = "best objective so far";
  panel.xlabel = "simulations (forward runs)";
  panel.ylabel = "J";
  panel.log_y = true;
  for (const ReachResult& r : results) {
    std::vector<double> x, y;
    for (const ReachEvaluation& e : r.evaluations) {
      x.push_back(static_cast<double>(e.simulations));
      y.push_back(e.best_objective);
    }
    panel.lines.push_back(makePlotLine(r.method, x, y, "linespoints"));
  }
  fig.panels.push_back(panel);
  std::string plot_status, plot_file;
  const GnuplotInfo gp = findGnuplot();
  if (!gp.available) {
    plot_status = "plot skipped: " + gp.why_not;
  } else {
    const PlotOutcome out = renderPlot(gp, PlotFormat::Auto, fig, (tmp / "objective").string());
    if (out.ok) {
      plot_file = fs::path(out.file).filename().string();
      plot_status = "plot: " + plot_file;
    } else {
      plot_status = "plot failed: " + out.error;
    }
  }

  // excitation drive: the best run's hand path, excitations and tendon forces (and the lumped replay)
  const bool excite = o.drive == "excitations";
  ReachReplay replay;
  std::string replay_plot, replay_status;
  const ReachResult* best = nullptr;
  for (const ReachResult& r : results)
    if (!best || r.objective < best->objective) best = &r;
  if (excite && best) {
    replay = replayReach(setup, best->torques);
    std::ostringstream c;
    c.precision(10);
    c << "time,hand_x,hand_y,hand_z";
    if (!replay.lumped_hand.empty()) c << ",lumped_hand_x,lumped_hand_y,lumped_hand_z";
    for (const auto& m : replay.muscles) c << ",excitation_" << m;
    for (const auto& m : replay.muscles) c << ",tendon_force_" << m;
    c << "\n";
    for (size_t j = 0; j < replay.t.size(); ++j) {
      c << replay.t[j] << "," << replay.hand[j][0] << "," << replay.hand[j][1] << "," << replay.hand[j][2];
      if (!replay.lumped_hand.empty())
        c << "," << replay.lumped_hand[j][0] << "," << replay.lumped_hand[j][1] << "," << replay.lumped_hand[j][2];
      for (const auto& e : replay.excitation) c << "," << e[j];
      for (const auto& f : replay.tendon_force) c << "," << f[j];
      c << "\n";
    }
    osim::writeFileAtomic((tmp / "best_run.csv").string(), c.str());
    PlotFigure rf;
    rf.title = "excitation-driven reach (" + best->method + "): " + setup.gradient.model.description.name;
    PlotPanel path;
    path.title = "hand path (ground x-y)";
    path.xlabel = "x (m)";
    path.ylabel = "y (m)";
    auto xy = [](const std::vector<Vec3>& v, int i) {
      std::vector<double> out;
      for (const Vec3& p : v) out.push_back(p[i]);
      return out;
    };
    path.lines.push_back(makePlotLine(setup.gradient.model.muscle_mass > 0.0 ? "inertial" : "lumped",
                                      xy(replay.hand, 0), xy(replay.hand, 1)));
    if (!replay.lumped_hand.empty())
      path.lines.push_back(makePlotLine("same excitations, lumped", xy(replay.lumped_hand, 0), xy(replay.lumped_hand, 1)));
    path.lines.push_back(makePlotLine("target", {o.target[0]}, {o.target[1]}, "points"));
    PlotPanel ex;
    ex.title = "excitations";
    ex.xlabel = "t (s)";
    ex.ylabel = "u";
    PlotPanel fo;
    fo.title = "tendon forces";
    fo.xlabel = "t (s)";
    fo.ylabel = "N";
    for (size_t m = 0; m < replay.muscles.size(); ++m) {
      ex.lines.push_back(makePlotLine(replay.muscles[m], replay.t, replay.excitation[m]));
      fo.lines.push_back(makePlotLine(replay.muscles[m], replay.t, replay.tendon_force[m]));
    }
    rf.panels = {path, ex, fo};
    const GnuplotInfo gp2 = findGnuplot();
    if (!gp2.available) {
      replay_status = "plot skipped: " + gp2.why_not;
    } else {
      const PlotOutcome out = renderPlot(gp2, PlotFormat::Auto, rf, (tmp / "best_run").string());
      if (out.ok) replay_plot = fs::path(out.file).filename().string();
      else replay_status = "plot failed: " + out.error;
    }
  }

  // track: the tracked coordinates of the best run against the motion
  const bool track = isTrack(o);
  TrackReplay tracked;
  std::string track_plot, track_status;
  if (track && best && !setup.gradient.objective.coordinate_tracks.empty()) {
    tracked = replayTrack(setup, best->torques);
    std::ostringstream c;
    c.precision(12);
    c << "time";
    for (const auto& n : tracked.coordinates) c << "," << n << "," << n << "_motion";
    c << "\n";
    for (size_t j = 0; j < tracked.t.size(); ++j) {
      c << tracked.t[j];
      for (size_t m = 0; m < tracked.coordinates.size(); ++m) c << "," << tracked.simulated[m][j] << "," << tracked.target[m][j];
      c << "\n";
    }
    osim::writeFileAtomic((tmp / "best_run.csv").string(), c.str());
    PlotFigure tf;
    tf.title = "tracked coordinates (" + best->method + "): " + setup.gradient.model.description.name;
    for (size_t m = 0; m < tracked.coordinates.size(); ++m) {
      PlotPanel pn;
      pn.title = tracked.coordinates[m];
      pn.xlabel = "t (s)";
      pn.ylabel = "q (rad or m)";
      pn.lines.push_back(makePlotLine("simulated", tracked.t, tracked.simulated[m]));
      PlotLine target = makePlotLine("motion", tracked.t, tracked.target[m]);
      target.dash_type = 2;
      pn.lines.push_back(target);
      tf.panels.push_back(pn);
    }
    const GnuplotInfo gp3 = findGnuplot();
    if (!gp3.available) {
      track_status = "plot skipped: " + gp3.why_not;
    } else {
      const PlotOutcome out = renderPlot(gp3, PlotFormat::Auto, tf, (tmp / "tracking").string());
      if (out.ok) track_plot = fs::path(out.file).filename().string();
      else track_status = "plot failed: " + out.error;
    }
  }

  std::ostringstream md;
  if (track) {
    md << "# Tracking task: " << setup.gradient.model.description.name << "\n\n";
    md << "Command: `" << command_line << "`\n\n";
    md << "Generalized forces on " << setup.gradient.param_names.size() << " parameter(s) from zero; objective";
    if (!o.motion.empty()) md << " `coords:" << o.motion << "`";
    if (!o.objective.empty()) md << (o.motion.empty() ? "" : " +") << " `" << o.objective << "`";
    if (o.rest_weight > 0.0) md << " + `" << fmt(o.rest_weight) << "/2 |qdot|^2`";
    md << " (docs/gradients.md §3) over " << fmt(o.duration) << " s (" << setup.gradient.problem.integrator << ", dt "
       << fmt(o.dt) << " s, " << setup.gradient.model.muscle_mass << " kg of muscle mass in mass points), from the "
       << "motion's pose at the start.\n\n";
    md << "- error: sqrt(2 J / duration), the root-mean-square tracking error (rad or m, summed over the tracked "
          "coordinates) for a unit-weight coords: term alone\n";
    md << "- stop: objective <= " << fmt(stopObjective(o)) << ", a method's own convergence test, or "
       << o.max_simulations << " simulations; reached means error <= " << fmt(o.tolerance) << "\n\n";
    md << "| method | simulations (diverged) | step evaluations | wall time (s) | final objective | final error | reached | stop |\n";
    md << "|---|---|---|---|---|---|---|---|\n";
    for (const ReachResult& r : results)
      md << "| " << r.method << " | " << r.simulations << " (" << r.failed_simulations << ") | " << r.step_evaluations
         << " | " << fmt(r.seconds, 4) << " | " << fmt(r.objective) << " | " << fmt(r.error) << " | "
         << (r.reached ? "yes" : "no") << " | " << r.stop << " |\n";
    gradientRoutes(md, results);
    md << "\n## Converged parameters (N m or N)\n\n| parameter |";
    parameterTable(md, setup.gradient.param_names, results);
    if (!tracked.coordinates.empty()) {
      md << "\n## Best run (" << best->method << ")\n\n- RMS tracking error over the run " << fmt(tracked.rms)
         << "\n- [best_run.csv](best_run.csv): time, each tracked coordinate and the motion's value\n";
      if (!track_plot.empty()) md << "\n![tracked against simulated coordinates](" << track_plot << ")\n";
      else md << "\n(" << track_status << ")\n";
    }
  } else {
    md << "# Reaching task: " << setup.gradient.model.description.name << "\n\n";
    md << "Command: `" << command_line << "`\n\n";
    if (excite)
      md << "Muscle excitations, " << o.nodes << " piecewise-linear node(s) per muscle (" << setup.gradient.param_names.size()
         << " parameters) from " << fmt(o.initial_excitation)
         << ", within each muscle's [min_control, max_control]; Hill-type muscles with activation and fibre states; "
            "objective `1/2 |p - target|^2";
    else
      md << "Constant generalized forces on " << setup.gradient.param_names.size()
         << " coordinates from zero; objective `1/2 |p - target|^2";
    if (excite && o.excitation_weight > 0.0) md << " + " << fmt(o.excitation_weight) << " int |u|^2 dt";
    if (o.rest_weight > 0.0) md << " + " << fmt(o.rest_weight) << "/2 |qdot|^2";
    md << "` at t = " << fmt(o.duration) << " s (" << setup.gradient.problem.integrator << ", dt " << fmt(o.dt)
       << " s, " << setup.gradient.model.muscle_mass << " kg of muscle mass in mass points).\n\n";
    md << "- point " << vec3(o.point) << " m of body `" << o.body << "`, at the start " << vec3(setup.start_point)
       << " m, target " << vec3(o.target) << " m (distance " << fmt((o.target - setup.start_point).norm()) << " m)\n";
    md << "- stop: objective <= " << fmt(stopObjective(o))
       << ", a method's own convergence test, or " << o.max_simulations << " simulations; reached means error <= "
       << fmt(o.tolerance) << " m\n\n";
    md << "| method | simulations (diverged) | step evaluations | wall time (s) | final objective | final error (m) | final |qdot| (rad/s) | reached | stop |\n";
    md << "|---|---|---|---|---|---|---|---|---|\n";
    for (const ReachResult& r : results)
      md << "| " << r.method << " | " << r.simulations << " (" << r.failed_simulations << ") | " << r.step_evaluations << " | " << fmt(r.seconds, 4) << " | "
         << fmt(r.objective) << " | " << fmt(r.error) << " | " << fmt(r.final_speed) << " | " << (r.reached ? "yes" : "no")
         << " | " << r.stop << " |\n";
    md << "\nOne simulation is one forward run; an L-BFGS evaluation also runs the adjoint sweep, whose cost is in the "
          "step evaluations (docs/gradients.md §5).\n";
    gradientRoutes(md, results);
    md << "\n## Converged parameters" << (excite ? "" : " (N m)") << "\n\n| parameter |";
    parameterTable(md, setup.gradient.param_names, results);
    if (excite && best) {
      md << "\n## Best run (" << best->method << ")\n\n";
      md << "- final hand error " << fmt(best->error) << " m";
      if (replay.lumped_error >= 0.0)
        md << "; the same excitations on the lumped model (no muscle mass): " << fmt(replay.lumped_error) << " m";
      md << "\n- [best_run.csv](best_run.csv): time, hand point, excitations and tendon forces per step\n";
      if (!replay_plot.empty()) md << "\n![hand path, excitations, tendon forces](" << replay_plot << ")\n";
      else md << "\n(" << replay_status << ")\n";
    }
  }
  md << "\n## Objective per evaluation\n\n";
  for (const ReachResult& r : results) md << "- [" << r.method << "_iterations.csv](" << r.method << "_iterations.csv)\n";
  if (!plot_file.empty()) md << "\n![objective against simulations](" << plot_file << ")\n";
  else md << "\n(" << plot_status << ")\n";
  osim::writeFileAtomic((tmp / "report.md").string(), md.str());

  // swap the finished folder into place
  const fs::path old = target.parent_path() / (target.filename().string() + ".old-" + std::to_string(::getpid()));
  const bool had = fs::exists(target);
  if (had) {
    fs::rename(target, old, ec);
    if (ec) throw std::runtime_error(target.string() + ": " + ec.message());
  }
  fs::rename(tmp, target, ec);
  if (ec) throw std::runtime_error(target.string() + ": " + ec.message());
  if (had) fs::remove_all(old, ec);
  return plot_status;
}

}  // namespace redmax::validation
