#include "validation/gradient/gradient.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "converter/coordinates_file.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "converter/trc_file.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/muscles/path.hpp"
#include "validation/forward/forward_tool.hpp"
#include "validation/simulate/spec_parse.hpp"

namespace redmax::validation {
namespace {

std::invalid_argument bad(const std::string& flag, const std::string& item, const std::string& why) {
  return std::invalid_argument(flag + " '" + item + "': " + why);
}

int coordinateIndex(const SimulationModel& m, const std::string& flag, const std::string& item,
                    const std::string& name) {
  const int c = m.system->model().findCoordinate(name);
  if (c < 0) throw bad(flag, item, "no coordinate named '" + name + "'");
  return c;
}

// NAME[=V]: the name and, when given, the value
std::string nameAndValue(const std::string& flag, const std::string& text, const std::string& item, double& v,
                         bool& has_value) {
  const auto eq = text.find('=');
  has_value = eq != std::string::npos;
  if (has_value && !parseNumber(text.substr(eq + 1), v)) throw bad(flag, item, "the value after '=' must be a number");
  const std::string name = text.substr(0, eq);
  if (name.empty()) throw bad(flag, item, "no name");
  return name;
}

double explicitMass(const SimulationModelOptions& o, const std::string& muscle) {
  for (const auto& [name, kg] : o.explicit_masses)
    if (name == muscle) return kg;
  return -1.0;
}

}  // namespace

std::shared_ptr<System> withMuscleForces(const SimulationModel& m) {
  const MusculoskeletalModel& model = m.build.model;
  std::vector<std::shared_ptr<const hill::MuscleModel>> models = model.muscleModels();
  models.resize(model.muscles().size());
  auto sys = std::make_shared<System>(*m.system);
  if (std::none_of(models.begin(), models.end(), [](const auto& x) { return x != nullptr; })) return sys;
  sys->addTerm(std::make_shared<MuscleForceTerm>(model.skeleton(), model.muscles(), models));
  // fibre-following mass points read their muscle's states; the notes are about muscles that
  // cannot (their points stay uniform), which the mass summary already says
  (void)bindMuscleStates(*sys);
  return sys;
}

namespace {

// The gradient's model: what `redmax simulate` applies without controls - the ForceSet's passive
// forces and contacts (CoordinateLimitForce, springs, bushings, HuntCrossleyForce, ...) - and, with
// excitation parameters, the muscles' Hill-type forces. Actuators (no controllers here) and muscles
// without excitations are named in not_applied; mass-parameter runs rebuild it the same way.
SimulationModel makeGradientModel(const osim::ModelDescription& description, const SimulationModelOptions& options,
                                  bool hill, std::vector<std::string>& warnings,
                                  std::vector<std::string>& not_applied) {
  SimulationModel m = makeSimulationModel(description, options);
  std::vector<std::string> pulling;
  if (hill) {
    const MusculoskeletalModel& mm = m.build.model;
    for (size_t k = 0; k < mm.muscles().size(); ++k)
      if (k < mm.muscleModels().size() && mm.muscleModels()[k]) pulling.push_back(mm.muscles()[k].name);
  }
  addPassiveTerms(m, warnings, not_applied, PassiveForces::All, false, "excitation parameters (--params 'excitations:...')",
                  pulling);
  if (hill) m.system = withMuscleForces(m);
  return m;
}


// coords:FILE.mot[@C,...] with weight w: the coordinates of the model that the motion (or states)
// file has - all of them, or the named ones - tracked over the run (docs/gradients.md §3). The file
// is read as `redmax lengths` and `simulate --initial` read motions (osim::readStorage: OpenSim's
// inDegrees rule, Rotational coordinates of a degrees file converted; labels by name or state
// path), linear between its rows, which must cover the run.
void addCoordinateTracks(GradientSetup& g, const std::string& term_text, std::string spec, double w) {
  const std::string oflag = "--objective";
  std::vector<std::string> chosen;
  const auto at = spec.rfind('@');
  if (at != std::string::npos && spec.find('/', at) == std::string::npos) {
    chosen = split(spec.substr(at + 1), ',');
    spec = spec.substr(0, at);
    if (chosen.empty() || std::any_of(chosen.begin(), chosen.end(), [](const std::string& c) { return c.empty(); }))
      throw bad(oflag, term_text, "expected coordinate names after '@' (coords:FILE.mot@C1,C2)");
  }
  if (spec.empty()) throw bad(oflag, term_text, "expected coords:FILE.mot or coords:FILE.mot@C1,C2");
  const std::string& file = spec;
  const osim::Storage table = osim::readStorage(file);  // ConvertError names the file and line
  const auto& coords = g.model.description.coordinates;
  const auto& index = g.model.build.coordinate_index;
  const osim::CoordinateColumns cols = osim::matchCoordinateColumns(table, coords);
  std::vector<size_t> which;  // description coordinates tracked
  if (chosen.empty()) {
    for (size_t ci = 0; ci < coords.size(); ++ci)
      if (cols.value_column[ci] >= 0 && index[ci] >= 0) which.push_back(ci);
    if (which.empty()) throw bad(oflag, term_text, "'" + file + "' has no column for any coordinate of the model");
  } else {
    std::vector<std::string> unknown, absent;
    for (const std::string& name : chosen) {
      size_t ci = coords.size();
      for (size_t k = 0; k < coords.size(); ++k)
        if (coords[k].name == name && index[k] >= 0) ci = k;
      if (ci == coords.size()) unknown.push_back(name);
      else if (cols.value_column[ci] < 0) absent.push_back(name);
      else if (std::find(which.begin(), which.end(), ci) != which.end())
        throw bad(oflag, term_text, "coordinate '" + name + "' is named twice");
      else which.push_back(ci);
    }
    auto list = [](const std::vector<std::string>& v) {
      std::string s;
      for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
      return s;
    };
    if (!unknown.empty())
      throw bad(oflag, term_text, "the model has no coordinate named " + list(unknown));
    if (!absent.empty()) throw bad(oflag, term_text, "'" + file + "' has no column for " + list(absent));
  }
  // the rows from the last at or before the start to the first at or after the end
  const adjoint::Problem& pr = g.problem;
  const double t0 = pr.initial.t, t1 = pr.initial.t + pr.duration;
  const int rows = table.numRows();
  if (rows == 0 || table.time.front() > t0 + 1e-12 || table.time.back() < t1 - 1e-12)
    throw bad(oflag, term_text,
              "'" + file + "' does not cover the run [" + std::to_string(t0) + ", " + std::to_string(t1) + "] s" +
                  (rows ? " (its times are " + std::to_string(table.time.front()) + " to " +
                              std::to_string(table.time.back()) + " s)"
                        : std::string(" (no rows)")));
  int lo = 0, hi = rows - 1;
  while (lo + 1 < rows && table.time[lo + 1] <= t0 + 1e-12) ++lo;
  while (hi - 1 >= lo && table.time[hi - 1] >= t1 - 1e-12) --hi;
  for (int r = lo; r < hi; ++r)
    if (!(table.time[r + 1] > table.time[r]))
      throw bad(oflag, term_text, "'" + file + "': the times must increase (t = " + std::to_string(table.time[r + 1]) +
                                      " s follows " + std::to_string(table.time[r]) + " s)");
  for (size_t ci : which) {
    adjoint::Objective::CoordinateTrack ct;
    ct.coordinate = index[ci];
    ct.weight = w;
    const int col = cols.value_column[ci];
    for (int r = lo; r <= hi; ++r) {
      const double v = table.data(r, col) * cols.scale[ci];
      if (!std::isfinite(v))
        throw bad(oflag, term_text, "'" + file + "': coordinate '" + coords[ci].name + "' is not a number at t = " +
                                        std::to_string(table.time[r]) + " s, inside the run");
      ct.t.push_back(table.time[r]);
      ct.value.push_back(v);
    }
    g.objective.coordinate_tracks.push_back(std::move(ct));
  }
}

}  // namespace

GradientSetup makeGradientSetup(const std::string& osim_path, const SimulationModelOptions& options,
                                const std::string& integrator, double duration, double dt,
                                const std::string& params_spec, const std::string& objective_spec) {
  GradientSetup g;
  const auto description = std::make_shared<const osim::ModelDescription>(osim::readOsimModel(osim_path));
  // with excitation parameters the muscles pull (Hill-type, activation and fibre states in z)
  const bool hill = params_spec.find("excitations:") != std::string::npos;
  g.model = makeGradientModel(*description, options, hill, g.warnings, g.not_applied);
  adjoint::Problem& pr = g.problem;
  pr.integrator = integrator;
  pr.duration = duration;
  pr.dt = dt;
  pr.initial = defaultInitialState(g.model);
  const System& sys = *g.model.system;
  pr.initial.z = sys.defaultState().z;
  // the muscles' constant excitations: each one's min_control (the excitation parameters replace
  // them for the muscles they name); the terms' controls are the muscles' (no controllers here)
  const MuscleForceTerm* mft = nullptr;
  int mft_control = 0;
  if (hill) {
    int offset = 0;
    for (const auto& t : sys.terms()) {
      if (const auto* m = dynamic_cast<const MuscleForceTerm*>(t.get())) {
        mft = m;
        mft_control = offset;
      }
      offset += t->numControls();
    }
    if (!mft) throw std::invalid_argument("--params 'excitations:': the model has no muscle with a Hill-type force model");
    if (sys.numControls() != mft->numControls())
      throw std::invalid_argument("--params 'excitations:': the model's system has controls other than its muscles'");
    pr.controls = VecX::Zero(sys.numControls());
    for (size_t k = 0; k < mft->actuated().size(); ++k)
      pr.controls[mft_control + static_cast<Eigen::Index>(k)] = mft->actuated()[k].model->minControl();
    // the step Jacobians' difference step: the tendon's force bends on micrometres, so 6e-6 of a
    // coordinate gives 5e-6 of the gradient in truncation, 2e-7 gives 5e-10 (measured on
    // tug_of_war_step.osim, docs/gradients.md §5); a wrapping (Type III) path's dl/dq is itself a central
    // difference at 1e-7 rad, whose round-off a step that small amplifies, so they keep 6e-6
    bool wraps = false;
    for (const auto& a : mft->actuated()) wraps = wraps || pathType(a.muscle.path) == PathType::III;
    if (!wraps) pr.jacobian_step = 2e-7;
    // fibre lengths in equilibrium with the tendon at the default pose (OpenSim's
    // computeInitialFiberEquilibrium), activations at their defaults
    DynamicsWorkspace ws(sys);
    ws.controls = pr.controls;
    try {
      sys.equilibrateStates(pr.initial, ws);
    } catch (const hill::MuscleModelError& e) {
      throw ModelError(std::string("the muscles' initial fibre equilibrium: ") + e.what());
    }
  }

  // parameters, collected per kind and then stacked in the problem's order
  struct Value {
    std::string name;
    double v;
  };
  std::vector<Value> forces, excitations, q0, v0;
  std::vector<std::string> masses;
  const std::string pflag = "--params";
  if (params_spec.empty()) throw std::invalid_argument("--params: no parameters");
  for (const std::string& group : split(params_spec, ';')) {
    const auto colon = group.find(':');
    if (colon == std::string::npos)
      throw bad(pflag, group, "expected KIND:ITEM,... with KIND torques, excitations, q0, qdot0 or masses");
    const std::string kind = group.substr(0, colon);
    const std::string list = group.substr(colon + 1);
    if (list.empty()) throw bad(pflag, group, "no items");
    for (const std::string& item_text : split(list, ',')) {
      // messages name the item with its kind, e.g. 'torques:elbow'
      const std::string item = kind + ":" + item_text;
      double v = 0.0;
      bool has_value = false;
      if (kind == "torques") {
        std::string name = nameAndValue(pflag, item_text, item, v, has_value);
        int pieces = 1;
        auto shape = adjoint::ForceParameter::Shape::Pieces;
        const auto at = name.find('@');
        if (at != std::string::npos) {
          // C@K: K constant pieces; C@K~linear: K nodes of a piecewise-linear force; C@K~cubic: K
          // control points of a cubic B-spline
          std::string count = name.substr(at + 1);
          const auto tilde = count.find('~');
          if (tilde != std::string::npos) {
            const std::string how = count.substr(tilde + 1);
            if (how == "linear") shape = adjoint::ForceParameter::Shape::Linear;
            else if (how == "cubic") shape = adjoint::ForceParameter::Shape::Cubic;
            else throw bad(pflag, item, "after '~' expected linear or cubic (constant pieces: no '~')");
            count = count.substr(0, tilde);
          }
          double k = 0.0;
          if (!parseNumber(count, k) || k < 1.0 || k != static_cast<int>(k) || k > 100000)
            throw bad(pflag, item, "the piece count after '@' must be a whole number >= 1");
          pieces = static_cast<int>(k);
          if (shape == adjoint::ForceParameter::Shape::Cubic && pieces < 4)
            throw bad(pflag, item, "a cubic B-spline needs at least 4 control points (@4~cubic)");
          name = name.substr(0, at);
        }
        const int c = coordinateIndex(g.model, pflag, item, name);
        const char* what = shape == adjoint::ForceParameter::Shape::Pieces  ? " piece "
                           : shape == adjoint::ForceParameter::Shape::Linear ? " node "
                                                                             : " control point ";
        for (int k = 0; k < pieces; ++k) {
          pr.forces.push_back({c, k, pieces, shape});
          forces.push_back(
              {"torque " + name + (pieces > 1 ? what + std::to_string(k + 1) + "/" + std::to_string(pieces) : std::string()),
               v});
        }
      } else if (kind == "excitations") {
        std::string name = nameAndValue(pflag, item_text, item, v, has_value);
        int nodes = 1;
        const auto at = name.find('@');
        if (at != std::string::npos) {
          double k = 0.0;
          if (!parseNumber(name.substr(at + 1), k) || k < 1.0 || k != static_cast<int>(k) || k > 100000)
            throw bad(pflag, item, "the node count after '@' must be a whole number >= 1");
          nodes = static_cast<int>(k);
          name = name.substr(0, at);
        }
        int found = -1;
        for (size_t k = 0; k < mft->actuated().size(); ++k)
          if (mft->actuated()[k].muscle.name == name) found = static_cast<int>(k);
        if (found < 0) {
          const bool exists = g.model.build.model.findMuscle(name) >= 0;
          throw bad(pflag, item, exists ? "muscle '" + name + "' has no Hill-type force model to excite"
                                        : "no muscle named '" + name + "'");
        }
        for (const auto& e : pr.excitations)
          if (e.control == mft_control + found) throw bad(pflag, item, "muscle '" + name + "' is named twice");
        const hill::MuscleModel& mm = *mft->actuated()[static_cast<size_t>(found)].model;
        const double lo = mm.minControl(), hi = mm.maxControl();
        if (!has_value) v = std::clamp(0.1, lo, hi);
        if (!(v >= lo && v <= hi))
          throw bad(pflag, item, "the value must lie in the muscle's [min_control, max_control] = [" +
                                     std::to_string(lo) + ", " + std::to_string(hi) + "]");
        for (int k = 0; k < nodes; ++k) {
          pr.excitations.push_back({mft_control + found, k, nodes, lo, hi});
          excitations.push_back({"excitation " + name + (nodes > 1 ? " node " + std::to_string(k + 1) + "/" +
                                                                         std::to_string(nodes)
                                                                   : std::string()),
                                 v});
        }
      } else if (kind == "q0" || kind == "qdot0") {
        const std::string name = nameAndValue(pflag, item_text, item, v, has_value);
        const int c = coordinateIndex(g.model, pflag, item, name);
        if (kind == "q0") {
          pr.initial_q.push_back(c);
          q0.push_back({"q0 " + name, has_value ? v : pr.initial.q[c]});
        } else {
          pr.initial_qdot.push_back(c);
          v0.push_back({"qdot0 " + name, has_value ? v : pr.initial.qdot[c]});
        }
      } else if (kind == "masses") {
        if (item_text.find('=') != std::string::npos)
          throw bad(pflag, item, "a muscle's mass comes from --muscle-mass-kg NAME=KG, not from the SPEC");
        if (explicitMass(options, item_text) <= 0.0)
          throw bad(pflag, item, "needs a positive mass for it in --muscle-mass-kg " + item_text + "=KG");
        masses.push_back(item_text);
      } else {
        throw bad(pflag, group, "unknown kind '" + kind + "' (torques, excitations, q0, qdot0 or masses)");
      }
    }
  }
  const int np = static_cast<int>(forces.size() + excitations.size() + q0.size() + v0.size() + masses.size());
  g.p0.resize(np);
  int i = 0;
  for (const auto* list : {&forces, &excitations, &q0, &v0})
    for (const Value& v : *list) {
      g.param_names.push_back(v.name);
      g.p0[i++] = v.v;
    }
  for (const std::string& m : masses) {
    g.param_names.push_back("mass " + m);
    g.p0[i++] = explicitMass(options, m);
  }

  // the system, rebuilt for other muscle masses (the explicit masses of the named muscles replaced)
  pr.num_system_params = static_cast<int>(masses.size());
  pr.system_param_delta.resize(pr.num_system_params);
  // a mass steps by 1e-3 of itself (fourth-order differences of the step, core/adjoint)
  for (int j = 0; j < pr.num_system_params; ++j) pr.system_param_delta[j] = 1e-3 * g.p0[np - pr.num_system_params + j];
  const std::shared_ptr<const System> base = g.model.system;
  pr.make_system = [description, options, masses, base, hill](const VecX& sp) -> std::shared_ptr<const System> {
    if (sp.size() == 0) return base;
    SimulationModelOptions o = options;
    for (size_t j = 0; j < masses.size(); ++j)
      for (auto& [name, kg] : o.explicit_masses)
        if (name == masses[j]) kg = sp[static_cast<Eigen::Index>(j)];
    std::vector<std::string> warnings, not_applied;  // said once, for p0's model
    return makeGradientModel(*description, o, hill, warnings, not_applied).system;
  };

  // objective
  const std::string oflag = "--objective";
  if (objective_spec.empty()) throw std::invalid_argument("--objective: no terms");
  const Model& model = g.model.system->model();
  for (const std::string& term_text : split(objective_spec, ';')) {
    std::string term = term_text;
    double w = 1.0;
    const auto star = term.find('*');
    if (star != std::string::npos) {
      if (!parseNumber(term.substr(0, star), w) || w < 0.0)
        throw bad(oflag, term_text, "the weight before '*' must be a number >= 0");
      term = term.substr(star + 1);
    }
    if (term == "speed") {
      g.objective.speed_weight += w;
    } else if (term == "effort") {
      g.objective.effort_weight += w;
    } else if (term == "excitation") {
      if (pr.excitations.empty()) throw bad(oflag, term_text, "needs excitation parameters (--params 'excitations:...')");
      g.objective.excitation_weight += w;
    } else if (term.rfind("marker:", 0) == 0 || term.rfind("track:", 0) == 0) {
      // a marker of the model's MarkerSet: at the final time against a point, or over the run
      // against the same-named marker of a TRC file
      const bool track = term.rfind("track:", 0) == 0;
      const std::string spec = term.substr(track ? 6 : 7);
      const auto eq = spec.find('=');
      if (eq == std::string::npos || eq == 0)
        throw bad(oflag, term_text, track ? "expected track:MARKER=FILE.trc" : "expected marker:NAME=X,Y,Z");
      const std::string name = spec.substr(0, eq);
      const CoreMarker cm = findCoreMarker(g.model, name);
      if (!cm.mk) throw bad(oflag, term_text, "no marker named '" + name + "' in the model's MarkerSet");
      if (cm.body < 0) throw bad(oflag, term_text, "marker '" + name + "' is not on a moving body");
      const int body = cm.body;
      const Vec3 x_i = cm.point;
      if (!track) {
        adjoint::Objective::Point pt;
        pt.body = body;
        pt.x_i = x_i;
        if (!parseVec3(spec.substr(eq + 1), pt.target))
          throw bad(oflag, term_text, "the target must be three numbers X,Y,Z (m, ground)");
        pt.weight = w;
        g.objective.points.push_back(pt);
        continue;
      }
      const std::string file = spec.substr(eq + 1);
      const osim::MarkerTable trc = osim::readTrc(file);  // ConvertError names the file and line
      const int c = trc.findMarker(name);
      if (c < 0) throw bad(oflag, term_text, "'" + file + "' has no marker '" + name + "'");
      adjoint::Objective::Track tr;
      tr.body = body;
      tr.x_i = x_i;
      tr.weight = w;
      const double t0 = pr.initial.t, t1 = pr.initial.t + pr.duration;
      // the rows from the last at or before the start to the first at or after the end; a gap there
      // is refused (no interpolation across it)
      int lo = 0, hi = 0;
      trc.bracketRows(t0, t1, lo, hi);
      for (int r = lo; r <= hi; ++r) {
        if (!trc.present(r, c))
          throw bad(oflag, term_text, "marker '" + name + "' has a gap at t = " + std::to_string(trc.time[r]) +
                                          " s in '" + file + "', inside the run");
        tr.t.push_back(trc.time[r]);
        tr.target.push_back(trc.position(r, c));
      }
      if (tr.t.empty() || tr.t.front() > t0 + 1e-12 || tr.t.back() < t1 - 1e-12)
        throw bad(oflag, term_text, "'" + file + "' does not cover the run [" + std::to_string(t0) + ", " +
                                        std::to_string(t1) + "] s");
      g.objective.tracks.push_back(std::move(tr));
    } else if (term.rfind("coords:", 0) == 0) {
      addCoordinateTracks(g, term_text, term.substr(7), w);
    } else if (term.rfind("point:", 0) == 0) {
      const std::string body_spec = term.substr(6);
      const auto at = body_spec.find('@');
      const auto eq = body_spec.find('=');
      if (at == std::string::npos || eq == std::string::npos || eq < at)
        throw bad(oflag, term_text, "expected point:BODY@x,y,z=X,Y,Z");
      adjoint::Objective::Point pt;
      const std::string body = body_spec.substr(0, at);
      pt.body = model.findBody(body);
      if (pt.body < 0) throw bad(oflag, term_text, "no body named '" + body + "'");
      if (!parseVec3(body_spec.substr(at + 1, eq - at - 1), pt.x_i))
        throw bad(oflag, term_text, "the point must be three numbers x,y,z (m, body frame)");
      if (!parseVec3(body_spec.substr(eq + 1), pt.target))
        throw bad(oflag, term_text, "the target must be three numbers X,Y,Z (m, ground)");
      pt.weight = w;
      g.objective.points.push_back(pt);
    } else {
      throw bad(oflag, term_text,
                "unknown term (point:BODY@x,y,z=X,Y,Z, marker:NAME=X,Y,Z, track:MARKER=FILE.trc, coords:FILE.mot[@C,...], "
                "speed, effort or excitation)");
    }
  }
  return g;
}

}  // namespace redmax::validation
