#include "validation/forward/forward_tool.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "converter/build/force_terms.hpp"
#include "converter/external_loads.hpp"
#include "converter/build/functions_to_core.hpp"
#include "converter/coordinates_file.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/sampled_loads.hpp"
#include "core/dynamics/controller.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/muscles/hill/muscle_model.hpp"

namespace redmax::validation {

namespace {
namespace fs = std::filesystem;

// the muscle model of every muscle of the model (null: none)
std::vector<std::shared_ptr<const hill::MuscleModel>> muscleModelsOf(const MusculoskeletalModel& model) {
  std::vector<std::shared_ptr<const hill::MuscleModel>> models = model.muscleModels();
  models.resize(model.muscles().size());
  return models;
}

}  // namespace

namespace {
void addResolved(System& sys, const osim::ResolvedController& r) {
  if (r.entries.empty()) return;
  std::vector<PrescribedControls::Entry> entries;
  for (const auto& e : r.entries) entries.push_back({e.actuator, e.function});
  sys.addController(std::make_shared<PrescribedControls>(r.name, entries));
}
}  // namespace

void addControlsFile(System& sys, const std::string& file, std::vector<std::string>& warnings,
                     const std::vector<std::string>& actuator_list) {
  addResolved(sys, osim::resolveControlsFile(file, sys.controlNames(), warnings, actuator_list));
}

void addSetupControllers(System& sys, const osim::ForwardSetup& setup, std::vector<std::string>& warnings) {
  std::vector<osim::ControllerSetupDesc> controls;  // CorrectionControllers are force terms (below)
  for (const osim::ControllerSetupDesc& c : setup.controllers)
    if (c.type != "CorrectionController") controls.push_back(c);
  for (const osim::ResolvedController& r :
       osim::resolveSetupControllers(controls, setup.source_file, sys.controlNames(), warnings))
    addResolved(sys, r);
}

namespace {

// OpenSim's CorrectionController: a CoordinateActuator `<coord>_corrector` of optimal force 1 on every
// coordinate that is not constrained (locked, prescribed, a coupler's dependent), driven by
// -(kp (q - q_d(t)) + kv (u - u_d(t))), q_d and u_d the tool's states_file at t as
// Storage::getDataAtTime gives them (linear between rows and from the last two rows beyond the end;
// 0 before the first row)
class CorrectionTerm final : public ForceTerm {
 public:
  struct Coordinate {
    int q = -1;
    std::vector<double> value, speed;
  };
  CorrectionTerm(double kp, double kv, std::vector<double> time, std::vector<Coordinate> coordinates)
      : kp_(kp), kv_(kv), time_(std::move(time)), coordinates_(std::move(coordinates)) {}
  std::string name() const override { return "correction_controller"; }
  bool addsMass() const override { return false; }
  void addForce(const Model&, const State& s, const TermContext&, VecX& f) const override {
    const int n = static_cast<int>(time_.size());
    if (n == 0 || s.t < time_.front()) {
      for (const Coordinate& c : coordinates_) f[c.q] -= kp_ * s.q[c.q] + kv_ * s.qdot[c.q];
      return;
    }
    int i2 = static_cast<int>(std::upper_bound(time_.begin(), time_.end(), s.t) - time_.begin());
    if (i2 >= n) i2 = n - 1;
    const int i1 = std::max(i2 - 1, 0);
    const double dt = time_[i2] - time_[i1];
    const double w = dt > 0.0 ? (s.t - time_[i1]) / dt : 0.0;
    for (const Coordinate& c : coordinates_) {
      const double qd = c.value[i1] + w * (c.value[i2] - c.value[i1]);
      const double ud = c.speed[i1] + w * (c.speed[i2] - c.speed[i1]);
      f[c.q] -= kp_ * (s.q[c.q] - qd) + kv_ * (s.qdot[c.q] - ud);
    }
  }

 private:
  double kp_, kv_;
  std::vector<double> time_;
  std::vector<Coordinate> coordinates_;
};

// `states`: the tool's states_file, read (absent when the setup names none)
void addCorrectionControllers(System& sys, const SimulationModel& m, const osim::ForwardSetup& setup,
                              const std::optional<osim::Storage>& states, std::vector<std::string>& warnings) {
  for (const osim::ControllerSetupDesc& c : setup.controllers) {
    if (c.type != "CorrectionController" || c.disabled) continue;
    if (!states)
      throw osim::ConvertError(setup.source_file, c.line,
                               "CorrectionController '" + c.name + "' corrects toward the tool's states_file, "
                               "and the setup names none");
    const osim::Storage& table = *states;
    const osim::ModelDescription& d = m.description;
    std::set<std::string> dependent;  // a coupler's dependent coordinate is constrained
    for (const osim::ConstraintDesc& k : d.constraints)
      if (k.kind == osim::ConstraintKind::CoordinateCoupler && k.enforced) dependent.insert(k.dependent_coordinate);
    std::vector<CorrectionTerm::Coordinate> coords;
    std::vector<std::string> missing;
    for (size_t k = 0; k < d.coordinates.size(); ++k) {
      const osim::CoordinateDesc& cd = d.coordinates[k];
      const int q = k < m.build.coordinate_index.size() ? m.build.coordinate_index[k] : -1;
      if (q < 0 || cd.locked || cd.prescribed || dependent.count(cd.name)) continue;
      const int vc = osim::findCoordinateColumn(table, cd), uc = osim::findSpeedColumn(table, cd);
      if (vc < 0 || uc < 0) {
        missing.push_back(cd.name);
        continue;
      }
      const double scale = osim::coordinateScale(table, cd);
      CorrectionTerm::Coordinate c{q, {}, {}};
      for (int r = 0; r < table.numRows(); ++r) {
        c.value.push_back(scale * table.data(r, vc));
        c.speed.push_back(scale * table.data(r, uc));
      }
      coords.push_back(std::move(c));
    }
    if (!missing.empty()) {
      std::string names;
      for (const std::string& n : missing) names += (names.empty() ? "" : ", ") + n;
      warnings.push_back(setup.source_file + ":" + std::to_string(c.line) + ": CorrectionController '" + c.name +
                         "': " + setup.states_file + " has no value or speed column for " + names +
                         "; those coordinates are not corrected");
    }
    sys.addTerm(std::make_shared<CorrectionTerm>(c.kp, c.kv, table.time, std::move(coords)));
  }
}

}  // namespace

namespace {

// contact geometry that no applied contact force uses, and geometry redmax does not model
void listUnusedContactGeometry(const osim::ModelDescription& d, const std::function<bool(const osim::ForceDesc&)>& applied,
                               std::vector<std::string>& not_applied) {
  std::set<std::string> used;
  for (const osim::ForceDesc& f : d.forces)
    if (f.modelled && applied(f))
      for (const osim::ContactParametersDesc& cp : f.contact_parameters) used.insert(cp.geometry.begin(), cp.geometry.end());
  for (const osim::ContactGeometryDesc& g : d.contact_geometry) {
    const std::string where = d.source_file + ":" + std::to_string(g.line) + ": " + g.class_name + " '" + g.name + "'";
    if (!g.modelled)
      not_applied.push_back(where + ": this contact geometry is not modelled; ignored");
    else if (!used.count(g.name))
      not_applied.push_back(where + ": no applied contact force uses it; it touches nothing");
  }
}

// forces of classes redmax does not model
void listUnmodelledForces(const osim::ModelDescription& d, const std::function<bool(const osim::ForceDesc&)>& include,
                          std::vector<std::string>& not_applied) {
  for (const osim::ForceDesc& f : d.forces)
    if (include(f) && !f.modelled)
      not_applied.push_back(f.class_name + " '" + f.name + "' is not modelled in forward simulation; ignored");
}

bool isContactForce(const osim::ForceDesc& f) {
  return f.class_name == "HuntCrossleyForce" || f.class_name == "SmoothSphereHalfSpaceForce";
}

bool isActuator(const osim::ForceDesc& f) {
  return f.class_name == "CoordinateActuator" || f.class_name == "PointActuator" || f.class_name == "TorqueActuator" ||
         f.class_name == "ActivationCoordinateActuator" || f.class_name == "BodyActuator" ||
         f.class_name == "PointToPointActuator";
}

}  // namespace

void addActuatorTerms(SimulationModel& m, std::vector<std::string>& warnings, bool model_forces,
                      std::vector<std::string>* not_applied, bool hard_contact) {
  std::vector<std::string>& missing = not_applied ? *not_applied : warnings;
  auto sys = std::make_shared<System>(*m.system);
  const MusculoskeletalModel& model = m.build.model;
  auto models = muscleModelsOf(model);
  bool any = false;
  for (size_t k = 0; k < models.size(); ++k) {
    // without the model's own forces (replace_force_set) only the muscles of force_set_files pull
    const int src = k < m.build.muscle_source.size() ? m.build.muscle_source[k] : -1;
    const bool from_file = src >= 0 && !m.description.muscles[static_cast<size_t>(src)].source_file.empty();
    if (!model_forces && !from_file) {
      models[k] = nullptr;
      continue;
    }
    if (models[k]) {
      any = true;
      continue;
    }
    const std::string cls = k < model.muscleClasses().size() ? model.muscleClasses()[k] : "";
    missing.push_back("muscle '" + model.muscles()[k].name + "' (" + (cls.empty() ? "unknown class" : cls) +
                      "): no force model, it exerts no force");
  }
  if (any) sys->addTerm(std::make_shared<MuscleForceTerm>(model.skeleton(), model.muscles(), models));
  // the actuators, passive forces and contacts (converter/build/force_terms.hpp); other classes are named
  // (hard_contact: the contact forces' geometry becomes hard contacts instead, addHardConstraints)
  auto include = [&](const osim::ForceDesc& f) {
    return f.applies_force && (model_forces || !f.source_file.empty()) && !(hard_contact && isContactForce(f));
  };
  const osim::ForceTermSet terms = osim::buildForceTerms(m.description, m.build, warnings, include);
  for (const auto& t : terms.actuatorTerms()) sys->addTerm(t);
  for (const auto& t : terms.passiveTerms()) sys->addTerm(t);
  listUnmodelledForces(m.description, include, missing);
  if (!hard_contact) listUnusedContactGeometry(m.description, include, missing);
  // fibre-following mass points read their muscle's states (core/dynamics/muscle_term.hpp)
  for (std::string& note : bindMuscleStates(*sys)) warnings.push_back(std::move(note));
  for (const auto& t : sys->terms())
    if (auto mt = std::dynamic_pointer_cast<const MuscleTerm>(t)) m.muscle_term = mt;
  m.system = sys;
}

std::string strictRefusal(const std::vector<std::string>& not_applied) {
  std::string msg = "--strict: " + std::to_string(not_applied.size()) +
                    (not_applied.size() == 1 ? " force or geometry is" : " forces or geometries are") +
                    " not applied:";
  for (const std::string& w : not_applied) msg += "\n  " + w;
  return msg;
}

void addPassiveTerms(SimulationModel& m, std::vector<std::string>& warnings, std::vector<std::string>& not_applied,
                     PassiveForces which, bool hard_contact, const std::string& controls_hint,
                     const std::vector<std::string>& pulling) {
  const bool apply = which != PassiveForces::None;
  const osim::ModelDescription& d = m.description;
  // muscles and actuators need controls: named in one line each, every name given
  auto listNames = [&](const std::vector<std::string>& names, const std::string& what) {
    if (names.empty()) return;
    std::string line = std::to_string(names.size()) + " " + what + ":";
    for (size_t k = 0; k < names.size(); ++k) line += (k ? ", " : " ") + names[k];
    not_applied.push_back(line);
  };
  std::vector<std::string> muscles, actuators;
  for (const osim::PathForceDesc& p : d.muscles)
    if (p.applies_force && std::find(pulling.begin(), pulling.end(), p.name) == pulling.end())
      muscles.push_back(p.name + " (" + p.class_name + ")");
  for (const osim::ForceDesc& f : d.forces)
    if (f.applies_force && isActuator(f)) actuators.push_back(f.name + " (" + f.class_name + ")");
  listNames(muscles, apply ? "path forces exert no force without " + controls_hint + " (their mass, if any, stays)"
                           : "path forces exert no force with this engine");
  listNames(actuators, apply ? "actuators apply nothing without " + controls_hint : "actuators apply nothing with this engine");
  auto passive = [&](const osim::ForceDesc& f) {
    return f.applies_force && !isActuator(f) && !(hard_contact && isContactForce(f)) &&
           (which != PassiveForces::ContactOnly || isContactForce(f));
  };
  if (which == PassiveForces::ContactOnly) {
    // the forces the engine leaves out, named
    std::vector<std::string> forces;
    for (const osim::ForceDesc& f : d.forces)
      if (f.applies_force && !isActuator(f) && !isContactForce(f)) forces.push_back(f.name + " (" + f.class_name + ")");
    listNames(forces, "forces are not applied with this engine (it applies the contact forces only)");
  }
  if (!apply) {
    std::vector<std::string> forces;
    for (const osim::ForceDesc& f : d.forces)
      if (passive(f)) forces.push_back(f.name + " (" + f.class_name + ")");
    listNames(forces, "forces are not applied with this engine");
    for (const osim::ContactGeometryDesc& g : d.contact_geometry)
      not_applied.push_back(d.source_file + ":" + std::to_string(g.line) + ": " + g.class_name + " '" + g.name +
                            "' is not applied with this engine");
    return;
  }
  const osim::ForceTermSet terms = osim::buildForceTerms(d, m.build, warnings, passive);
  if (!terms.passiveTerms().empty()) {
    auto sys = std::make_shared<System>(*m.system);
    for (const auto& t : terms.passiveTerms()) sys->addTerm(t);
    m.system = sys;
  }
  listUnmodelledForces(d, passive, not_applied);
  if (!hard_contact) listUnusedContactGeometry(d, passive, not_applied);
}

HardConstraintSummary addHardConstraints(SimulationModel& m, const HardConstraintOptions& o,
                                         std::vector<std::string>& not_applied) {
  const osim::ModelDescription& d = m.description;
  const Model& core = m.system->model();
  HardConstraintSummary out;
  std::vector<JointLimit> limits;
  if (!o.joint_limits.empty()) {
    for (const osim::CoordinateDesc& c : d.coordinates) {
      if (o.joint_limits == "clamped" && !c.clamped) continue;
      if (c.locked || c.prescribed) continue;
      const int k = core.findCoordinate(c.name);
      if (k < 0) {
        not_applied.push_back(d.source_file + ":" + std::to_string(c.line) + ": coordinate '" + c.name +
                              "' has no coordinate of its own in the core; its range is not enforced");
        continue;
      }
      limits.push_back({c.name, k, c.range_min, c.range_max, o.limit_restitution});
      if (!(c.default_value >= c.range_min && c.default_value <= c.range_max))
        throw ModelError("coordinate " + c.name + ": default value " + std::to_string(c.default_value) +
                         " lies outside its range [" + std::to_string(c.range_min) + ", " +
                         std::to_string(c.range_max) + "] that --joint-limits enforces");
    }
  }
  std::vector<CollisionGeometry> geo;
  std::vector<CollisionPair> pairs;
  if (o.contact) {
    std::map<std::string, int> index;  // geometry name -> geo
    std::set<std::string> used;
    for (const osim::ContactGeometryDesc& g : d.contact_geometry) {
      const std::string where = d.source_file + ":" + std::to_string(g.line) + ": " + g.class_name + " '" + g.name + "'";
      if (g.class_name != "ContactSphere" && g.class_name != "ContactHalfSpace") {
        not_applied.push_back(where + ": only ContactSphere and ContactHalfSpace can be hard contacts; ignored");
        continue;
      }
      CollisionGeometry c;
      c.name = g.name;
      c.shape = g.class_name == "ContactSphere" ? CollisionShape::Sphere : CollisionShape::HalfSpace;
      c.body = g.body == d.ground_name ? -1 : core.findBody(g.body);
      if (g.body != d.ground_name && c.body < 0) {
        not_applied.push_back(where + ": its body '" + g.body + "' is not in the core model; ignored");
        continue;
      }
      c.X_body = g.X_body;
      c.radius = g.radius;
      index[g.name] = static_cast<int>(geo.size());
      geo.push_back(c);
    }
    auto harmonic = [](double a, double b) { return a + b > 0.0 ? 2.0 * a * b / (a + b) : 0.0; };
    auto addPair = [&](int i, int j, double mu) {
      const CollisionGeometry &a = geo[i], &b = geo[j];
      const bool hs = (a.shape == CollisionShape::HalfSpace) != (b.shape == CollisionShape::HalfSpace);
      const bool ss = a.shape == CollisionShape::Sphere && b.shape == CollisionShape::Sphere;
      if (!(hs || ss) || a.body == b.body) return;
      pairs.push_back({i, j, o.contact_friction >= 0.0 ? o.contact_friction : mu, o.contact_restitution});
      used.insert(a.name);
      used.insert(b.name);
    };
    for (const osim::ForceDesc& f : d.forces) {
      if (!f.applies_force || !isContactForce(f)) continue;
      if (f.class_name == "SmoothSphereHalfSpaceForce") {
        auto i = index.find(f.half_space), j = index.find(f.sphere);
        if (i != index.end() && j != index.end())
          addPair(i->second, j->second, f.contact_parameters.empty() ? 0.0 : f.contact_parameters[0].dynamic_friction);
        continue;
      }
      std::vector<std::pair<int, double>> members;  // geometry, its dynamic friction
      for (const osim::ContactParametersDesc& cp : f.contact_parameters)
        for (const std::string& name : cp.geometry) {
          auto it = index.find(name);
          if (it != index.end()) members.emplace_back(it->second, cp.dynamic_friction);
        }
      for (size_t a = 0; a < members.size(); ++a)
        for (size_t b = a + 1; b < members.size(); ++b)
          addPair(members[a].first, members[b].first, harmonic(members[a].second, members[b].second));
    }
    for (const osim::ContactGeometryDesc& g : d.contact_geometry)
      if (index.count(g.name) && !used.count(g.name))
        not_applied.push_back(d.source_file + ":" + std::to_string(g.line) + ": " + g.class_name + " '" + g.name +
                              "': no contact force pairs it with another geometry; it touches nothing");
  }
  out.limits = static_cast<int>(limits.size());
  out.pairs = static_cast<int>(pairs.size());
  if (limits.empty() && pairs.empty()) return out;
  auto sys = std::make_shared<System>(*m.system);
  sys->setUnilateral(std::make_shared<UnilateralConstraints>(core, geo, pairs, limits));
  m.system = sys;
  return out;
}

State forwardInitialState(const SimulationModel& m, const osim::Storage& table, const std::string& file, double time) {
  if (table.numRows() == 0) throw osim::ConvertError(file, 0, "the states table has no rows");
  // the closest earlier row (OpenSim's ForwardTool: no interpolation)
  int row = 0;
  for (int r = 0; r < table.numRows(); ++r)
    if (table.time[r] <= time + 1e-12) row = r;
  osim::Storage one = table;
  one.time = {table.time[row]};
  one.data = table.data.row(row);
  State s = initialStateFromStorage(m, one, file);
  readAuxiliaryStates(*m.system, table, row, file, s);
  s.t = time;
  return s;
}

void readAuxiliaryStates(const System& sys, const osim::Storage& table, int row, const std::string& file, State& s) {
  if (s.z.size() != sys.numStates()) s.z = sys.defaultState().z;
  if (row < 0 || row >= table.numRows()) return;
  const std::vector<std::string> names = sys.stateNames();
  for (size_t k = 0; k < names.size(); ++k) {
    // /forceset/M/S, or OpenSim 3's M.S
    int col = table.findColumn(names[k]);
    if (col < 0 && names[k].rfind("/forceset/", 0) == 0) {
      const std::string rest = names[k].substr(10);
      const auto slash = rest.find('/');
      if (slash != std::string::npos) col = table.findColumn(rest.substr(0, slash) + "." + rest.substr(slash + 1));
    }
    if (col < 0) continue;
    const double v = table.data(row, col);
    if (!std::isfinite(v)) throw osim::ConvertError(file, 0, "state '" + names[k] + "' is not finite");
    s.z[static_cast<int>(k)] = v;
  }
}

ForwardResult runForward(const SimulationModel& m, const State& initial, const std::vector<double>& times,
                         const std::string& integrator, const IntegratorOptions& options, long max_total_steps) {
  const System& sys = *m.system;
  ForwardResult res;
  const std::vector<std::string> z_names = sys.stateNames();
  res.states.name = "states";
  res.states.labels = m.q_labels;
  res.states.labels.insert(res.states.labels.end(), m.u_labels.begin(), m.u_labels.end());
  res.states.labels.insert(res.states.labels.end(), z_names.begin(), z_names.end());
  res.controls.name = "controls";
  res.controls.labels = sys.controlNames();
  std::vector<VecX> rows, crow;
  std::vector<double> t_rows;
  DynamicsWorkspace ws(sys);
  auto record = [&](const State& s) {
    const State e = sys.expandState(s);
    VecX r(e.q.size() + e.qdot.size() + s.z.size());
    r.head(e.q.size()) = e.q;
    r.segment(e.q.size(), e.qdot.size()) = e.qdot;
    if (s.z.size() > 0) r.tail(s.z.size()) = s.z;
    rows.push_back(r);
    t_rows.push_back(s.t);
    if (sys.numControls() > 0) {
      sys.calcMassAndForce(s, ws);
      crow.push_back(ws.controls);
    } else {
      crow.push_back(VecX());
    }
  };
  IntegratorOptions opt = options;
  auto integ = makeIntegrator(integrator, opt);
  State s = initial;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    for (double t : times) {
      if (t < s.t) continue;
      if (t > s.t) integ->advance(sys, s, t);
      record(s);
      if (max_total_steps > 0 && integ->stats().steps > max_total_steps) {
        std::ostringstream os;
        os << integrator << ": more than maximum_number_of_integrator_steps = " << max_total_steps
           << " steps by t = " << s.t;
        throw SimulationError(os.str(), s.t, 0.0);
      }
    }
  } catch (const SimulationError& e) {
    res.failed = true;
    res.failure = e.what();
  }
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  res.stats = integ->stats();
  const int nrow = static_cast<int>(rows.size());
  res.states.time = t_rows;
  res.states.data.resize(nrow, static_cast<int>(res.states.labels.size()));
  res.controls.time = t_rows;
  res.controls.data.resize(nrow, static_cast<int>(res.controls.labels.size()));
  for (int r = 0; r < nrow; ++r) {
    res.states.data.row(r) = rows[r].transpose();
    if (crow[r].size() == res.controls.data.cols()) res.controls.data.row(r) = crow[r].transpose();
  }
  return res;
}

namespace {
// the rules as one ProportionalController, names resolved against the system and the skeleton
void addFeedback(System& sys, const SimulationModel& m, const std::vector<FeedbackRule>& rules) {
  const std::vector<std::string> controls = sys.controlNames();
  std::vector<ProportionalController::Rule> out;
  for (const FeedbackRule& f : rules) {
    ProportionalController::Rule r;
    for (size_t k = 0; k < controls.size(); ++k)
      if (controls[k] == f.actuator) r.control = static_cast<int>(k);
    for (size_t k = 0; k < m.coordinate_names.size(); ++k)
      if (m.coordinate_names[k] == f.coordinate) r.coordinate = static_cast<int>(k);
    if (r.control < 0) throw std::invalid_argument("feedback: no actuator named '" + f.actuator + "'");
    if (r.coordinate < 0) throw std::invalid_argument("feedback: no coordinate named '" + f.coordinate + "'");
    if (!(f.min <= f.max)) throw std::invalid_argument("feedback for '" + f.actuator + "': min > max");
    r.target = f.target;
    r.kp = f.kp;
    r.kd = f.kd;
    r.bias = f.bias;
    r.min = f.min;
    r.max = f.max;
    out.push_back(r);
  }
  sys.addController(std::make_shared<ProportionalController>(std::move(out)));
}
}  // namespace

ForwardTool::ForwardTool(ForwardToolSettings settings) : settings_(std::move(settings)) {
  setup_ = osim::readForwardSetup(settings_.setup_file);
  warnings_ = setup_.warnings;
  const std::string& sf = setup_.source_file;
  if (setup_.model_file.empty()) throw osim::ConvertError(sf, 0, "the setup names no model_file");
  if (!(settings_.report_interval > 0.0) || !std::isfinite(settings_.report_interval))
    throw std::invalid_argument("the report interval must be positive");
  SimulationModelOptions mo;
  mo.muscle_mass = settings_.muscle_mass;
  // the model, then force_set_files appended (OpenSim's ForwardTool::loadModel + updateModelForces);
  // replace_force_set drops the model's own forces
  osim::ModelDescription d = osim::readOsimModel(setup_.model_file);
  if (setup_.replace_force_set)
    for (osim::ForceDesc& f : d.forces) f.applies_force = false;
  const size_t nw = d.warnings.size();
  for (const std::string& file : setup_.force_set_files)
    osim::appendForceSetFile(d, file, setup_.replace_force_set);
  warnings_.insert(warnings_.end(), d.warnings.begin() + static_cast<std::ptrdiff_t>(nw), d.warnings.end());
  for (const osim::UnsupportedItem& u : d.unsupported)
    if (u.what.rfind("force ", 0) == 0)  // the model's (force_set_files entries name their file)
      warnings_.push_back(setup_.model_file + ":" + std::to_string(u.line) + ": " + u.what + "; ignored");
    else if (u.what.find(": force '") != std::string::npos)
      warnings_.push_back(u.what + "; ignored");
  model_ = makeSimulationModel(d, mo);
  for (const std::string& w : model_.build.warnings) warnings_.push_back(w);
  if (!settings_.muscle_class.empty()) {
    // OpenSim's Object::renameType on every muscle: the models follow the class
    MusculoskeletalModelBuilder b(model_.build.model);
    b.overrideMuscleClass(settings_.muscle_class);
    model_.build.model = b.finalize();
  }
  // replace_force_set: only the forces of force_set_files act (OpenSim)
  addActuatorTerms(model_, warnings_, !setup_.replace_force_set, &not_applied_);
  if (settings_.strict && !not_applied_.empty()) throw std::invalid_argument(strictRefusal(not_applied_));
  if (!setup_.external_loads_file.empty()) {
    // OpenSim's ExternalLoads, the data looked up from the setup's folder first (as the ID tool)
    osim::ExternalLoads el = osim::readExternalLoads(setup_.external_loads_file, setup_.directory);
    osim::checkExternalLoads(el, model_.description);
    for (const auto& w : el.warnings) warnings_.push_back(setup_.external_loads_file + ": " + w);
    auto sources = std::make_shared<const std::vector<osim::LoadSource>>(
        osim::makeLoadSources(el, model_.description, model_.build.body_index, warnings_));
    if (!sources->empty()) {
      auto sys = std::make_shared<System>(*model_.system);
      sys->addTerm(std::make_shared<SampledLoadsTerm>(
          [sources](double t, std::vector<IdLoadSample>& loads) { osim::sampleLoads(*sources, t, loads); }));
      model_.system = sys;
    }
  }
  System& sys = *model_.system;
  addSetupControllers(sys, setup_, warnings_);
  std::optional<osim::Storage> states;
  if (!setup_.states_file.empty()) states = osim::readStorage(setup_.states_file);
  addCorrectionControllers(sys, model_, setup_, states, warnings_);
  if (!setup_.controls_file.empty()) addControlsFile(sys, setup_.controls_file, warnings_);
  if (!settings_.feedback.empty()) addFeedback(sys, model_, settings_.feedback);
  // initial state
  initial_ = defaultInitialState(model_);
  initial_.z = sys.defaultState().z;
  initial_.t = setup_.initial_time;
  if (states) initial_ = forwardInitialState(model_, *states, setup_.states_file, setup_.initial_time);
  if (setup_.solve_for_equilibrium) {
    DynamicsWorkspace ws(sys);
    sys.equilibrateStates(initial_, ws);
  }
  for (const double t : settings_.output_times)
    if (!std::isfinite(t)) throw std::invalid_argument("non-finite output time");
}

std::string ForwardTool::resultsDirectory() const {
  return settings_.out_dir ? *settings_.out_dir : setup_.results_directory;
}
std::string ForwardTool::statesPath() const {
  return (fs::path(resultsDirectory()) / (setup_.name + "_states.sto")).string();
}
std::string ForwardTool::controlsPath() const {
  return (fs::path(resultsDirectory()) / (setup_.name + "_controls.sto")).string();
}
std::string ForwardTool::viewPath() const {
  return (fs::path(resultsDirectory()) / (setup_.name + "_view")).string();
}

ForwardResult ForwardTool::run() const {
  const double t0 = setup_.initial_time, t1 = setup_.final_time;
  std::vector<double> times;
  if (!settings_.output_times.empty()) {
    for (double t : settings_.output_times)
      if (t >= t0 - 1e-12 && t <= t1 + 1e-12) times.push_back(std::clamp(t, t0, t1));
    std::sort(times.begin(), times.end());
  } else {
    const long n = std::max(1L, std::lround(std::ceil((t1 - t0) / settings_.report_interval - 1e-9)));
    for (long k = 0; k <= n; ++k) times.push_back(k == n ? t1 : t0 + k * settings_.report_interval);
  }
  IntegratorOptions opt;
  const double tol = settings_.tolerance ? *settings_.tolerance : setup_.integrator_error_tolerance;
  opt.rtol = tol;
  opt.atol = tol;
  opt.max_step = setup_.maximum_integrator_step_size;
  opt.dt = std::min(1e-3, setup_.maximum_integrator_step_size);
  ForwardResult r = runForward(model_, initial_, times, settings_.integrator, opt, setup_.maximum_number_of_integrator_steps);
  r.states.name = setup_.name + "_states";
  r.controls.name = setup_.name + "_controls";
  return r;
}

view::ViewSummary ForwardTool::write(const ForwardResult& r) const {
  const std::string dir = resultsDirectory();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw osim::ConvertError(dir, 0, "cannot create the results directory: " + ec.message());
  osim::StorageWriteOptions o;
  o.decimals = std::max(8, setup_.output_precision);
  o.scientific = true;
  o.description = "redmax forward: states of " + setup_.source_file;
  osim::writeStorage(statesPath(), r.states, o);
  o.description = "redmax forward: controls of " + setup_.source_file;
  osim::writeStorage(controlsPath(), r.controls, o);
  if (settings_.view.index_html.empty()) return {};
  view::ViewInput in;
  // the model as written: model_.description has the muscle mass moved already, writeView moves it
  in.description = osim::readOsimModel(setup_.model_file);
  in.motion_file = statesPath();
  in.motion = r.states;
  in.mass = settings_.muscle_mass;
  return view::writeView(in, settings_.view, viewPath());
}

}  // namespace redmax::validation
