#include "validation/simulate/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "converter/coordinates_file.hpp"
#include "converter/osim_reader.hpp"
#include "validation/simulate/spec_parse.hpp"
#include "core/dynamics/body_loads.hpp"
#include "core/dynamics/contact_force_terms.hpp"
#include "core/dynamics/skeleton_dynamics.hpp"

namespace redmax::validation {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

// strict number parse: the whole text must be a finite number
bool parseNumber(const std::string& text, double& v) {
  try {
    size_t used = 0;
    v = std::stod(text, &used);
    return used == text.size() && std::isfinite(v);
  } catch (const std::exception&) {
    return false;
  }
}

bool parseVec3(const std::string& text, Vec3& v) {
  const auto parts = split(text, ',');
  if (parts.size() != 3) return false;
  for (int k = 0; k < 3; ++k)
    if (!parseNumber(parts[k], v[k])) return false;
  return true;
}

namespace {

bool isAdaptive(const std::string& name) { return name == "rk45" || name == "cvode"; }

// the skeleton coordinate behind system coordinate k (with a coordinate map, only independents)
int skeletonIndex(const System& sys, int k) {
  if (sys.coordinateMap()) return sys.coordinateMap()->independent()[k];
  return k;
}

// rewrite "q[k]" / "qdot[k]" in an integrator's message so that it names the coordinate
std::string nameCoordinates(const SimulationModel& m, const std::string& what) {
  static const std::regex re(R"((qdot|q)\[(\d+)\])");
  std::string out;
  auto begin = std::sregex_iterator(what.begin(), what.end(), re);
  size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    const std::smatch& mt = *it;
    out += what.substr(last, mt.position() - last);
    const int k = std::stoi(mt[2].str());
    out += mt.str();
    if (k >= 0 && k < m.system->ndof()) {
      const int i = skeletonIndex(*m.system, k);
      if (i < static_cast<int>(m.coordinate_names.size()))
        out += std::string(" (") + (mt[1].str() == "q" ? "value" : "speed") + " of coordinate '" +
               m.coordinate_names[i] + "')";
    }
    last = mt.position() + mt.length();
  }
  out += what.substr(last);
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// impulses

ImpulseSpec parseImpulse(const std::string& text) {
  // TARGET may itself hold a comma list after '@' but never a ':'
  const auto parts = split(text, ':');
  auto bad = [&](const std::string& why) {
    return std::invalid_argument("--impulse '" + text + "': " + why +
                                 " (expected BODY|MARKER|BODY@X,Y,Z:FX,FY,FZ:DURATION)");
  };
  if (parts.size() != 3) throw bad("needs three ':'-separated parts");
  ImpulseSpec s;
  s.target = parts[0];
  if (s.target.empty()) throw bad("no body or marker");
  if (!parseVec3(parts[1], s.force_w)) throw bad("the force must be three numbers FX,FY,FZ in N");
  if (!parseNumber(parts[2], s.duration) || !(s.duration > 0.0))
    throw bad("the duration must be a positive number of seconds");
  return s;
}

bool ImpulseLoads::active(double t) const {
  for (const Load& l : loads_)
    if (t < l.t_end - 1e-12) return true;
  return false;
}

void ImpulseLoads::addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const {
  // the switch-off is a step in time; 1e-12 s of slack keeps a step that starts at t_end (up to
  // round-off in t) out of the impulse
  BodyLoads on;
  for (const Load& l : loads_)
    if (s.t < l.t_end - 1e-12) on.point_forces.push_back({l.body, l.point_i, l.force_w});
  if (!on.point_forces.empty()) on.addForce(model, s, ctx, f);
}

// ---------------------------------------------------------------------------------------------
// model

SimulationModel loadSimulationModel(const std::string& osim_path, const SimulationModelOptions& options) {
  return makeSimulationModel(osim::readOsimModel(osim_path), options);
}

SimulationModel makeSimulationModel(const osim::ModelDescription& d, const SimulationModelOptions& options) {
  SimulationModel m;
  const bool explicit_mass = !options.explicit_masses.empty();
  if (explicit_mass && options.muscle_mass.source != osim::MuscleMassOptions::Source::None)
    throw std::invalid_argument("--muscle-mass-kg excludes a --muscle-mass source other than none");
  if (options.muscle_mass.source != osim::MuscleMassOptions::Source::None) {
    // mass moves from the bodies into the muscles (converter/build/muscle_mass.hpp); top:K ranks at
    // the default pose
    osim::MuscleMassModel mm = osim::applyMuscleMass(d, options.build, options.muscle_mass);
    m.description = std::move(mm.description);
    m.build = std::move(mm.build);
    m.mass_summary = osim::describeMuscleMass(mm.plan);
  } else {
    m.description = d;
    m.build = osim::buildCoreModel(m.description, options.build);
  }
  // gravity and explicit masses are edits of the built model
  MusculoskeletalModelBuilder edit(m.build.model);
  if (options.gravity) edit.skeleton().setGravity(*options.gravity);
  edit.settings().muscle_term.quadratic_velocity = options.quadratic_velocity;
  const std::vector<Muscle>& built = m.build.model.muscles();

  // explicit masses: added to the muscles, no body gives any
  std::vector<double> masses(built.size(), 0.0);
  std::vector<std::string> placement_notes(built.size());
  if (explicit_mass) {
    if (options.muscle_mass.mass_points < 1)
      throw std::invalid_argument("--mass-points must be at least 1");
    for (const auto& [name, kg] : options.explicit_masses) {
      const int found = m.build.model.findMuscle(name);
      if (found < 0) throw std::invalid_argument("--muscle-mass-kg: the model has no muscle '" + name + "'");
      if (!(kg >= 0.0) || !std::isfinite(kg))
        throw std::invalid_argument("--muscle-mass-kg: mass of '" + name + "' must be a finite number >= 0");
      masses[found] = kg;
    }
    MassPointOptions mp;
    mp.count = options.muscle_mass.mass_points;
    mp.region = options.muscle_mass.region;
    // wrapping (Type III) muscles take their points here when wrap mass is on (addMusclePointMasses
    // refuses them); validateMuscle names the reason when the shape is not supported
    std::vector<double> plain = masses;
    for (size_t k = 0; k < built.size(); ++k) {
      if (pathType(built[k].path) != PathType::III || !(masses[k] > 0.0)) continue;
      if (!options.muscle_mass.wrap_mass)
        throw std::invalid_argument("--muscle-mass-kg: muscle '" + built[k].name +
                                    "' wraps (Type III) and wrap mass is off (--wrap lumped)");
      plain[k] = 0.0;
    }
    const std::vector<Muscle> with = osim::addMusclePointMasses(built, plain, mp);
    for (size_t k = 0; k < with.size(); ++k) {
      Muscle& mu = edit.muscle(static_cast<int>(k));
      mu = with[k];
      if (plain[k] == masses[k]) continue;
      mu.wrap = options.muscle_mass.wrap;
      mu.mass_points = makeMassPoints(masses[k], mu.optimal_fiber_length, mu.tendon_slack_length, mp);
      validateMuscle(m.build.model, mu);
    }
    // fibre-following placement where asked (a muscle that cannot stays uniform, said below)
    for (size_t k = 0; k < built.size(); ++k) {
      if (!(masses[k] > 0.0)) continue;
      const auto& mms = m.build.model.muscleModels();
      const std::string why = osim::placeMassPoints(m.build.model.skeleton(), options.muscle_mass,
                                                    k < mms.size() ? mms[k] : nullptr, edit.muscle(static_cast<int>(k)));
      if (!why.empty()) placement_notes[k] = ", uniform placement (" + why + ")";
    }
  }
  m.build.model = edit.finalize();
  const std::vector<Muscle>& muscles = m.build.model.muscles();
  if (explicit_mass) {
    std::ostringstream os;
    for (size_t k = 0; k < muscles.size(); ++k) {
      if (masses[k] <= 0.0) continue;
      os << "  muscle " << muscles[k].name << ": " << masses[k] << " kg on " << muscles[k].mass_points.size()
         << " points (added; no body gives mass)"
         << (pathType(muscles[k].path) == PathType::III
                 ? std::string(", wrapping, wrap model ") + osim::toString(muscles[k].wrap.model)
                 : std::string())
         << (muscles[k].fibre.enabled() ? ", fibre-following" : "") << placement_notes[k] << "\n";
      m.added_mass += masses[k];
    }
    m.mass_summary = os.str();
  }
  m.muscle_mass = m.build.model.muscleMass();

  m.system = std::make_shared<System>(m.build.makeSystem());
  if (m.muscle_mass > 0.0) {
    auto term = std::make_shared<MuscleTerm>(m.system->model(), muscles, m.build.model.settings().muscle_term);
    m.muscle_term = term;
    m.system->addTerm(term);
  }

  // impulses: body, marker or BODY@x,y,z
  if (!options.impulses.empty()) {
    std::vector<ImpulseLoads::Load> loads;
    for (const ImpulseSpec& spec : options.impulses) {
      ImpulseLoads::Load l;
      l.force_w = spec.force_w;
      l.t_end = spec.duration;
      std::string body = spec.target;
      const size_t at = spec.target.find('@');
      if (at != std::string::npos) {
        body = spec.target.substr(0, at);
        if (!parseVec3(spec.target.substr(at + 1), l.point_i))
          throw std::invalid_argument("--impulse: point of '" + spec.target + "' must be X,Y,Z in m");
      }
      const int b = d.findBody(body);
      l.body = b >= 0 && b < static_cast<int>(m.build.body_index.size()) ? m.build.body_index[b] : -1;
      if (b < 0 && at == std::string::npos) {
        const CoreMarker cm = findCoreMarker(m, body);
        l.body = cm.body;
        l.point_i = cm.point;
      }
      if (l.body < 0)
        throw std::invalid_argument("--impulse: '" + body + "' is not a moving body or a marker of the model");
      loads.push_back(l);
    }
    auto term = std::make_shared<ImpulseLoads>(std::move(loads));
    m.impulses = term;
    m.system->addTerm(term);
  }

  // output labels: OpenSim's absolute state paths
  const Model& model = m.system->model();
  m.coordinate_names.resize(model.nr());
  m.q_labels.resize(model.nr());
  m.u_labels.resize(model.nr());
  for (int i = 0; i < model.nr(); ++i) {
    m.coordinate_names[i] = model.coordinates()[i].name;
    m.q_labels[i] = model.coordinates()[i].name + "/value";
    m.u_labels[i] = model.coordinates()[i].name + "/speed";
  }
  for (size_t k = 0; k < d.coordinates.size(); ++k) {
    const int i = k < m.build.coordinate_index.size() ? m.build.coordinate_index[k] : -1;
    if (i < 0) continue;
    const auto& c = d.coordinates[k];
    const std::string joint = c.joint_index >= 0 ? d.joints[c.joint_index].name : c.joint;
    const std::string path = "/jointset/" + joint + "/" + c.name;
    m.coordinate_names[i] = c.name;
    m.q_labels[i] = path + "/value";
    m.u_labels[i] = path + "/speed";
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// initial states

namespace {
State finishInitialState(const SimulationModel& m, State s_r) {
  const System& sys = *m.system;
  State s = sys.reduceState(s_r);
  s.t = s_r.t;
  // the force terms' own states (muscles: docs/forward.md) at their defaults
  if (s.z.size() != sys.numStates()) s.z = sys.defaultState().z;
  if (sys.numConstraintRows() > 0) {
    DynamicsWorkspace ws(sys.model());
    sys.projectPositions(s, ws);
    sys.projectVelocities(s, ws);
  }
  return s;
}

State defaultSkeletonState(const SimulationModel& m) {
  const Model& model = m.system->model();
  State s;
  s.t = 0.0;
  s.q = model.defaultQ();
  s.qdot = VecX::Zero(model.nr());
  for (size_t k = 0; k < m.description.coordinates.size(); ++k) {
    const int i = k < m.build.coordinate_index.size() ? m.build.coordinate_index[k] : -1;
    if (i >= 0) s.qdot[i] = m.description.coordinates[k].default_speed_value;
  }
  return s;
}
}  // namespace

CoreMarker findCoreMarker(const SimulationModel& m, const std::string& name) {
  CoreMarker out;
  const osim::ModelDescription& d = m.description;
  for (const osim::MarkerDesc& mk : d.markers) {
    if (mk.name != name) continue;
    out.mk = &mk;
    const int db = d.findBody(mk.body);
    out.body = db >= 0 && db < static_cast<int>(m.build.body_index.size()) ? m.build.body_index[db] : -1;
    out.point = transformPoint(mk.X_body_frame, mk.location);
    break;
  }
  return out;
}

State defaultInitialState(const SimulationModel& m) { return finishInitialState(m, defaultSkeletonState(m)); }

State initialStateFromStorage(const SimulationModel& m, const osim::Storage& table, const std::string& file,
                              double time) {
  if (table.numRows() == 0) throw osim::ConvertError(file, 0, "the table has no rows");
  int row = 0;
  if (std::isnan(time)) {
    for (int r = 0; r < table.numRows(); ++r)
      if (std::abs(table.time[r]) <= 1e-9) {
        row = r;
        break;
      }
  } else {
    row = -1;
    for (int r = 0; r < table.numRows(); ++r)
      if (std::abs(table.time[r] - time) <= 1e-9) row = r;
    if (row < 0) {
      std::ostringstream os;
      os << "no row at t = " << time << " (rows span " << table.time.front() << " to " << table.time.back() << ")";
      throw osim::ConvertError(file, 0, os.str());
    }
  }
  State s = defaultSkeletonState(m);
  s.t = table.time[row];
  int matched = 0;
  for (size_t k = 0; k < m.description.coordinates.size(); ++k) {
    const int i = k < m.build.coordinate_index.size() ? m.build.coordinate_index[k] : -1;
    if (i < 0) continue;
    const auto& c = m.description.coordinates[k];
    // one label rule and degree constant for every coordinates reader (converter/coordinates_file.hpp)
    const double scale = osim::coordinateScale(table, c);
    const int col = osim::findCoordinateColumn(table, c);
    if (col >= 0) {
      s.q[i] = scale * table.data(row, col);
      ++matched;
    }
    const int ucol = osim::findSpeedColumn(table, c);
    if (ucol >= 0) {
      s.qdot[i] = scale * table.data(row, ucol);
      ++matched;
    }
  }
  if (matched == 0)
    throw osim::ConvertError(file, 0,
                             "no column names a coordinate of the model (expected names such as '" +
                                 (m.q_labels.empty() ? std::string("?") : m.q_labels[0]) + "' or '" +
                                 (m.coordinate_names.empty() ? std::string("?") : m.coordinate_names[0]) + "')");
  if (!s.q.allFinite() || !s.qdot.allFinite())
    throw osim::ConvertError(file, 0, "the initial row holds a non-finite value");
  return finishInitialState(m, s);
}

// ---------------------------------------------------------------------------------------------
// simulation

std::pair<double, double> calcEnergies(const SimulationModel& m, const State& s) {
  DynamicsWorkspace ws(m.system->model());
  return {m.system->kineticEnergy(s, ws), m.system->potentialEnergy(s, ws)};
}

SimulationResult makeStatesResult(const SimulationModel& m) {
  SimulationResult res;
  res.states.name = "redmax simulate states";
  res.states.version = 1;
  res.states.in_degrees = false;
  res.states.labels = m.q_labels;
  res.states.labels.insert(res.states.labels.end(), m.u_labels.begin(), m.u_labels.end());
  for (const char* e : {"kinetic_energy", "potential_energy", "total_energy"}) res.states.labels.push_back(e);
  if (m.system)
    for (const std::string& n : m.system->stateNames()) res.states.labels.push_back(n);
  return res;
}

SimulationResult simulate(const SimulationModel& m, const State& initial, const SimulateOptions& options) {
  const System& sys = *m.system;
  if (!(options.duration > 0.0) || !std::isfinite(options.duration))
    throw std::invalid_argument("the duration must be a positive number of seconds");
  if (!(options.output_dt >= 0.0) || !std::isfinite(options.output_dt))
    throw std::invalid_argument("the output interval must be a positive number of seconds");
  const bool adaptive = isAdaptive(options.integrator);
  auto integ = makeIntegrator(options.integrator, options.integrator_options);  // validates the name
  const double dt = options.integrator_options.dt;

  // output times: t0 + k h_out, the last one t0 + duration
  double h_out = options.output_dt > 0.0 ? options.output_dt : (!adaptive && dt > 0.01 ? dt : 0.01);
  if (!adaptive) h_out = std::max(1.0, std::round(h_out / dt)) * dt;
  const double t0 = initial.t, t1 = t0 + options.duration;
  const long n_rows = std::max(1L, static_cast<long>(std::ceil(options.duration / h_out - 1e-9)));
  if (n_rows > 50'000'000) throw std::invalid_argument("more than 5e7 output rows: raise the output interval");
  struct Target {
    double t;
    bool row;    // an output row
    bool brk;    // an impulse switches off here
  };
  std::vector<Target> targets;
  for (long k = 1; k < n_rows; ++k) targets.push_back({t0 + k * h_out, true, false});
  targets.push_back({t1, true, false});
  // impulse switch-offs inside the run are breakpoints
  if (m.impulses) {
    for (const auto& l : m.impulses->loads()) {
      if (!(l.t_end > t0 && l.t_end < t1)) continue;
      bool on_row = false;
      for (auto& tg : targets)
        if (std::abs(tg.t - l.t_end) <= 1e-12 * std::max(1.0, std::abs(l.t_end))) on_row = tg.brk = true;
      if (!on_row) targets.push_back({l.t_end, false, true});
    }
  }
  std::sort(targets.begin(), targets.end(), [](const Target& a, const Target& b) { return a.t < b.t; });

  SimulationResult res = makeStatesResult(m);
  DynamicsWorkspace ws(sys.model());
  StateRecorder recorder(res);
  // the contact terms, watched at every row (docs/contact.md)
  std::vector<const ContactForceTerm*> contact_terms;
  for (const auto& t : sys.terms())
    if (auto c = dynamic_cast<const ContactForceTerm*>(t.get())) contact_terms.push_back(c);
  SkeletonWorkspace contact_sk(sys.model());
  std::vector<ContactReport> reports;
  MatX contact_M;
  Eigen::LDLT<MatX> contact_ldlt;
  bool contact_factored = false;  // contact_ldlt holds this row's M
  MatX contact_J(3, sys.model().nr());
  // the effective mass of a contact along its normal, 1 / (w^T M^-1 w) with w = (J_2 - J_1)^T n
  // (the skeleton's mass matrix: mass points only add mass, so the frequency is not underestimated)
  auto effective_mass = [&](const ContactReport& r) {
    const Model& model = sys.model();
    VecX w = VecX::Zero(model.nr());
    for (const auto& [body, sign] : {std::pair{r.body2, 1.0}, std::pair{r.body1, -1.0}}) {
      if (body < 0) continue;
      const Mat4& E = contact_sk.E_wi[body];
      const Vec3 x_i = E.topLeftCorner<3, 3>().transpose() * (r.point_w - E.topRightCorner<3, 1>());
      pointJacobian(model, contact_sk, body, x_i, contact_J);
      w += sign * contact_J.transpose() * r.normal_w;
    }
    if (!contact_factored) {  // once per row, whatever the number of contacts
      if (contact_M.rows() != model.nr()) contact_M.resize(model.nr(), model.nr());
      calcSkeletonMass(model, contact_sk, contact_M);
      contact_ldlt.compute(contact_M);
      contact_factored = true;
    }
    const double inv = w.dot(contact_ldlt.solve(w));
    return inv > 0.0 ? 1.0 / inv : 0.0;
  };

  // false (failed set) when a contact went deeper than its sphere's radius
  auto watch_contacts = [&](const State& s_r) -> bool {
    if (contact_terms.empty()) return true;
    calcKinematics(sys.model(), s_r, contact_sk);
    contact_factored = false;
    auto fail = [&](const std::string& why) {
      res.failed = true;
      res.failure = why;
      res.failure_time = s_r.t;
      return false;
    };
    reports.clear();
    for (const ContactForceTerm* c : contact_terms) c->contacts(contact_sk, reports);
    ContactStats& cs = res.contacts;
    cs.contacts = static_cast<int>(reports.size());
    cs.active_final = 0;
    Vec3 net = Vec3::Zero();
    for (const ContactReport& r : reports) {
      if (!r.active) continue;
      ++cs.active_final;
      net += r.force_w;
      if (r.penetration > cs.max_penetration) {
        cs.max_penetration = r.penetration;
        cs.deepest = r.name;
        cs.deepest_time = s_r.t;
      }
      // a fixed step too long for the contact's oscillation throws the body off: the explicit
      // stability limit is omega h = 2, but impacts gain energy well before it (docs/contact.md
      // §3: omega h = 1.24 quadrupled a ball's energy in 2 s), so h < 1 / omega is asked
      if (!adaptive && r.stiffness > 0.0) {
        const double m_eff = effective_mass(r);
        const double omega = m_eff > 0.0 ? std::sqrt(r.stiffness / m_eff) : 0.0;
        if (omega * dt > 1.0) {
          std::ostringstream os;
          os << "contact '" << r.name << "' at t = " << s_r.t << ": the step h = " << dt
             << " s is too large for the contact's stiffness (" << r.stiffness << " N/m at penetration "
             << r.penetration << " m, effective mass " << m_eff << " kg: omega = " << omega
             << " rad/s needs h < 1 / omega = " << 1.0 / omega << " s; use a smaller --dt, or rk45)";
          return fail(os.str());
        }
      }
      if (r.radius > 0.0 && r.penetration > r.radius) {
        std::ostringstream os;
        os << "contact '" << r.name << "' penetrates " << r.penetration << " m, deeper than the sphere's radius "
           << r.radius << " m, at t = " << s_r.t << ": the step is too large for the contact's stiffness"
           << (adaptive ? " (lower --max-step or the tolerances)" : " (use a smaller --dt, or rk45)");
        return fail(os.str());
      }
    }
    cs.active_max = std::max(cs.active_max, cs.active_final);
    if (net.norm() > cs.max_force) {
      cs.max_force = net.norm();
      cs.max_force_up = net.y();
      cs.max_force_time = s_r.t;
    }
    return true;
  };

  auto record = [&](const State& s) -> bool {
    const double K = sys.kineticEnergy(s, ws), V = sys.potentialEnergy(s, ws);
    const State s_r = sys.expandState(s);
    if (!recorder.add(s.t, s_r.q, s_r.qdot, K, V, "", s.z)) return false;
    if (!watch_contacts(s_r)) return false;
    if (options.check) {
      const std::string why = options.check(s, K, V);
      if (!why.empty()) {
        res.failed = true;
        res.failure = why;
        res.failure_time = s.t;
        return false;
      }
    }
    return true;
  };

  auto add_stats = [&](const IntegratorStats& st) {
    res.stats.steps += st.steps;
    res.stats.rhs_evals += st.rhs_evals;
    res.stats.jacobian_evals += st.jacobian_evals;
    res.stats.reparameterizations += st.reparameterizations;
    res.stats.failed_steps += st.failed_steps;
    res.stats.unilateral_steps += st.unilateral_steps;
    res.stats.qp_iterations += st.qp_iterations;
    res.stats.qp_solves += st.qp_solves;
    res.stats.contact_rows += st.contact_rows;
    res.stats.max_contacts = std::max(res.stats.max_contacts, st.max_contacts);
    res.stats.max_penetration = std::max(res.stats.max_penetration, st.max_penetration);
    res.stats.friction_unconverged += st.friction_unconverged;
    res.stats.event_impacts += st.event_impacts;
    res.stats.event_releases += st.event_releases;
    res.stats.event_slips += st.event_slips;
    res.stats.event_sticks += st.event_sticks;
  };

  // the network wrap model's counts live in the workspaces: the integrator's and the energies'
  auto take_counts = [&] {
    if (!options.wrap_fallbacks) return;
    if (DynamicsWorkspace* iw = integ->lastWorkspace()) takeWrapFallbackCounts(sys, *iw, *options.wrap_fallbacks);
    takeWrapFallbackCounts(sys, ws, *options.wrap_fallbacks);
  };

  const auto start = std::chrono::steady_clock::now();
  State s = initial;
  checkAdvanceArguments(sys, s, t1, "simulate");
  bool ok = record(s);
  bool restart = false;
  for (size_t k = 0; ok && k < targets.size(); ++k) {
    if (restart) {
      // a new adaptive integrator after a breakpoint: no dense output across the switch
      add_stats(integ->stats());
      integ = makeIntegrator(options.integrator, options.integrator_options);
      restart = false;
    }
    try {
      integ->advance(sys, s, targets[k].t);
    } catch (const SimulationError& e) {
      res.failed = true;
      res.failure = nameCoordinates(m, e.what());
      res.failure_time = e.time;
      res.failure_step = e.step;
      break;
    }
    restart = adaptive && targets[k].brk;
    take_counts();  // before a restart drops the integrator's workspace
    if (!targets[k].row) continue;
    ok = record(s);
    if (options.on_row) options.on_row(s.t);
  }
  take_counts();
  add_stats(integ->stats());
  if (res.failed && res.failure_step == 0.0) res.failure_step = adaptive ? 0.0 : dt;
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  res.final_state = s;
  recorder.finish();
  return res;
}

bool StateRecorder::add(double t, const VecX& q, const VecX& qdot, double K, double V, const std::string& where,
                        const VecX& z) {
  VecX row(q.size() + qdot.size() + 3 + z.size());
  row.head(q.size() + qdot.size() + 3) << q, qdot, K, V, K + V;
  if (z.size() > 0) row.tail(z.size()) = z;
  if (!row.allFinite()) {
    std::ostringstream os;
    os << "non-finite state or energy at t = " << t << " s" << where;
    res_.failed = true;
    res_.failure = os.str();
    res_.failure_time = t;
    return false;
  }
  if (rows_.empty()) res_.energy_initial = K + V;
  res_.energy_final = K + V;
  max_ke_ = std::max(max_ke_, K);
  res_.energy_drift_abs = std::max(res_.energy_drift_abs, std::abs(K + V - res_.energy_initial));
  res_.states.time.push_back(t);
  rows_.push_back(std::move(row));
  return true;
}

void StateRecorder::finish() {
  const double scale = std::max(std::abs(res_.energy_initial), max_ke_);
  res_.energy_drift_rel = scale > 0.0 ? res_.energy_drift_abs / scale : 0.0;
  res_.states.data.resize(static_cast<Eigen::Index>(rows_.size()), static_cast<Eigen::Index>(res_.states.labels.size()));
  for (size_t r = 0; r < rows_.size(); ++r) res_.states.data.row(static_cast<Eigen::Index>(r)) = rows_[r].transpose();
}

}  // namespace redmax::validation
