// OpenSim's AnalyzeTool + StaticOptimization (docs/analyze.md): setup, force set, frames, the
// per-frame program and OpenSim's output files.
#include "converter/analyze/analyze_tool.hpp"

#include "core/dynamics/muscle_force_term.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "converter/analyze/states_file.hpp"
#include "converter/analyze/static_optimization.hpp"
#include "converter/atomic_file.hpp"
#include "converter/build/build_core_model.hpp"
#include "converter/build/force_terms.hpp"
#include "converter/osim_reader.hpp"
#include "converter/detail/controller_set.hpp"
#include "converter/detail/xml_util.hpp"
#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/id_setup.hpp"
#include "core/muscles/hill/factory.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/muscle_workspace.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::osim {
namespace fs = std::filesystem;
using namespace detail;

namespace {

// OpenSim's Analysis classes (osimAnalyses, osimSimulation, osimTools): known by name, so that an
// analysis redmax does not run is listed as such and anything else is a typo
const std::set<std::string>& openSimAnalysisClasses() {
  static const std::set<std::string> s = {
      "Actuation",        "BodyKinematics", "ForceReporter",    "InducedAccelerations",
      "JointReaction",    "Kinematics",     "MuscleAnalysis",   "OutputReporter",
      "PointKinematics",  "ProbeReporter",  "StatesReporter",   "StaticOptimization",
      "IMUDataReporter",  "ControlReporter"};
  return s;
}



bool isCoordinateActuator(const std::string& cls) {
  return cls == "CoordinateActuator" || cls == "ActivationCoordinateActuator";
}

// the actuator named `name` of a PointActuatorTerm / TorqueActuatorTerm (null: none)
template <class Term>
const typename Term::Actuator* findByName(const std::shared_ptr<const Term>& term, const std::string& name) {
  if (!term) return nullptr;
  for (const auto& a : term->actuators())
    if (a.name == name) return &a;
  return nullptr;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// setup

AnalyzeSetup readAnalyzeSetup(const std::string& path) {
  XmlDocument doc(path);
  const XMLElement* el = toolRoot(doc, "AnalyzeTool");
  AnalyzeSetup s;
  s.source_file = path;
  s.name = attribute(el, "name");
  s.directory = folderOf(path);
  auto file = [&](const char* tag) { return resolveRelativeTo(s.directory, childText(el, tag)); };
  s.model_file = file("model_file");
  s.coordinates_file = file("coordinates_file");
  s.states_file = file("states_file");
  s.speeds_file = file("speeds_file");
  s.external_loads_file = file("external_loads_file");
  const std::string rd = childText(el, "results_directory");
  s.results_directory = rd.empty() ? s.directory : resolveRelativeTo(s.directory, rd);
  for (const std::string& f : splitWords(childText(el, "force_set_files")))
    s.force_set_files.push_back(resolveRelativeTo(s.directory, f));
  s.replace_force_set = childBool(doc, el, "replace_force_set", false);
  s.initial_time = childDouble(doc, el, "initial_time", 0.0);
  s.final_time = childDouble(doc, el, "final_time", 1.0);
  if (!(s.initial_time <= s.final_time))
    doc.fail(firstChild(el, "final_time"), "final_time is before initial_time");
  s.lowpass_cutoff_frequency_for_coordinates =
      childDouble(doc, el, "lowpass_cutoff_frequency_for_coordinates", -1.0);
  s.solve_for_equilibrium_for_auxiliary_states =
      childBool(doc, el, "solve_for_equilibrium_for_auxiliary_states", false);
  if (const XMLElement* p = firstChild(el, "output_precision"); p && !textOf(p).empty())
    s.output_precision = parseInt(doc, p);
  if (s.output_precision < 1 || s.output_precision > 30)
    doc.fail(firstChild(el, "output_precision"), "output_precision must be in [1, 30]");

  s.controllers = readControllerSet(doc, el, s.directory);
  s.controls_file = readToolControlsFile(doc, el, s.directory, s.warnings);

  const XMLElement* set = firstChild(el, "AnalysisSet");
  for (const XMLElement* a : childElements(set ? firstChild(set, "objects") : nullptr)) {
    AnalysisEntry e;
    e.class_name = a->Name();
    e.name = attribute(a, "name");
    if (e.name.empty()) e.name = e.class_name;
    e.line = lineOf(a);
    e.on = childBool(doc, a, "on", true);
    if (!openSimAnalysisClasses().count(e.class_name))
      doc.fail(a, "unknown analysis <" + e.class_name + "> in the AnalysisSet (OpenSim has no such class)");
    if (e.class_name == "StaticOptimization" && e.on) {
      StaticOptimizationSettings& so = s.static_optimization;
      if (so.present) doc.fail(a, "a second StaticOptimization that is on: redmax runs one");
      so.present = true;
      so.name = e.name;
      so.line = e.line;
      so.start_time = childDouble(doc, a, "start_time", 0.0);
      so.end_time = childDouble(doc, a, "end_time", 0.0);
      if (const XMLElement* c = firstChild(a, "step_interval"); c && !textOf(c).empty())
        so.step_interval = parseInt(doc, c);
      if (so.step_interval < 1) doc.fail(firstChild(a, "step_interval"), "step_interval must be >= 1");
      so.activation_exponent = childDouble(doc, a, "activation_exponent", 2.0);
      if (!(so.activation_exponent > 1.0))
        doc.fail(firstChild(a, "activation_exponent"),
                 "activation_exponent must be > 1 (the objective sum |x|^p is then strictly convex)");
      so.use_muscle_physiology = childBool(doc, a, "use_muscle_physiology", true);
      so.optimizer_convergence_criterion = childDouble(doc, a, "optimizer_convergence_criterion", 1e-4);
      if (!(so.optimizer_convergence_criterion > 0))
        doc.fail(firstChild(a, "optimizer_convergence_criterion"), "optimizer_convergence_criterion must be > 0");
      if (const XMLElement* c = firstChild(a, "optimizer_max_iterations"); c && !textOf(c).empty())
        so.optimizer_max_iterations = parseInt(doc, c);
      if (so.optimizer_max_iterations < 1)
        doc.fail(firstChild(a, "optimizer_max_iterations"), "optimizer_max_iterations must be >= 1");
      so.use_model_force_set = childBool(doc, a, "use_model_force_set", true);
    }
    if ((e.class_name == "MuscleAnalysis" || e.class_name == "Actuation") && e.on) {
      const bool ma = e.class_name == "MuscleAnalysis";
      if (ma ? s.muscle_analysis.present : s.actuation.present)
        doc.fail(a, "a second " + e.class_name + " that is on: redmax runs one");
      int step = 1;
      if (const XMLElement* c = firstChild(a, "step_interval"); c && !textOf(c).empty()) step = parseInt(doc, c);
      if (step < 1) doc.fail(firstChild(a, "step_interval"), "step_interval must be >= 1");
      if (ma) {
        MuscleAnalysisSettings& m = s.muscle_analysis;
        m.present = true;
        m.name = e.name;
        m.line = e.line;
        m.step_interval = step;
        if (const XMLElement* c = firstChild(a, "muscle_list"); c && !textOf(c).empty())
          m.muscle_list = splitWords(textOf(c));
        if (const XMLElement* c = firstChild(a, "moment_arm_coordinate_list"); c && !textOf(c).empty())
          m.coordinate_list = splitWords(textOf(c));
        m.compute_moments = childBool(doc, a, "compute_moments", true);
      } else {
        s.actuation = {true, e.name, step, e.line};
      }
    }
    s.analyses.push_back(e);
  }
  if (s.analyses.empty()) doc.fail(set ? set : el, "the AnalysisSet has no analyses (OpenSim refuses to run)");
  if (!s.speeds_file.empty())
    s.warnings.push_back("speeds_file is not read: speeds are the derivatives of the coordinates' splines");
  return s;
}

// ---------------------------------------------------------------------------------------------
// the tool

namespace {

struct Actuator {
  std::string name;
  int muscle = -1;      ///< index into the geometry model's muscles, or -1
  int coordinate = -1;  ///< core coordinate of a CoordinateActuator
  int point = -1, torque = -1;  ///< index in ForceTermSet's PointActuatorTerm / TorqueActuatorTerm
  double optimal_force = 1.0;
  double lower = 0.0, upper = 1.0;
};

// a CoordinateActuator, PointActuator or TorqueActuator of the force set; term: (0 coordinate,
// 1 point, 2 torque; index in that term), or (3, core coordinate) of an ActivationCoordinateActuator
Actuator forceSetActuator(const ForceDesc& f, std::pair<int, int> term, const ForceTermSet& set) {
  Actuator a;
  a.name = f.name;
  if (term.first == 0) a.coordinate = set.coordinate_actuators->actuators()[static_cast<size_t>(term.second)].coordinate;
  if (term.first == 3) a.coordinate = term.second;  // the core coordinate itself
  if (term.first == 1) a.point = term.second;
  if (term.first == 2) a.torque = term.second;
  a.optimal_force = f.optimal_force;
  a.lower = f.min_control;
  a.upper = f.max_control;
  return a;
}

}  // namespace

struct AnalyzeTool::Impl {
  std::unique_ptr<InverseDynamicsTool> id;
  std::unique_ptr<CoreIdEngine> engine;
  MusculoskeletalModel geometry;  ///< the muscles' paths and force models (massless)
  std::vector<Actuator> actuators;
  std::vector<int> rows;                        ///< core coordinates the program constrains
  std::vector<signal::NaturalSpline> u_splines;  ///< per core coordinate (empty: no data)
  std::vector<MuscleKinematics> mk;             ///< columns each muscle's path depends on
  std::unique_ptr<MuscleForceTerm> force_term;  ///< the muscles with a force model, as forward applies them
  ForceTermSet forces;  ///< the force set's actuators (columns) and passive forces (moved into b)
  std::unique_ptr<AnalyzeStatesFile> states;    ///< the states_file, when the setup gives one
  std::vector<int> coordinate_desc;             ///< per core coordinate: its description index (-1: none)
  std::vector<int> muscle_source;               ///< per geometry muscle: its description index
  std::vector<int> coordinate_index;            ///< per description coordinate: its core index (-1: none)
  MuscleAnalysisColumns ma_columns;             ///< MuscleAnalysis's muscles and coordinates
  std::vector<ActuationColumn> act_columns;     ///< Actuation's actuators
  // controls (AbstractTool's ControllerSet): per actuator of the force set, by name
  std::vector<std::string> control_names;
  std::vector<ResolvedController> controllers;
  std::vector<int> muscle_control;              ///< per geometry muscle: its control, or -1
  std::unique_ptr<BuildResult> constrained;     ///< the model's constraints for MuscleAnalysis's moment arms

  // the controls at time t (ControllerSet: every controller adds from zero)
  VecX controlsAt(double t) const {
    VecX u = VecX::Zero(static_cast<Eigen::Index>(control_names.size()));
    VecJ x(1);
    x[0] = t;
    for (const ResolvedController& c : controllers)
      for (const auto& e : c.entries) u[e.actuator] += e.function->value(x);
    return u;
  }
};

AnalyzeTool::~AnalyzeTool() = default;

AnalyzeTool::AnalyzeTool(AnalyzeToolSettings settings) : settings_(std::move(settings)) {
  setup_ = readAnalyzeSetup(settings_.setup_file);
  warnings_ = setup_.warnings;
  const std::string& where = settings_.setup_file;
  out_dir_ = settings_.out_dir ? *settings_.out_dir : setup_.results_directory;
  for (const AnalysisEntry& a : setup_.analyses)
    if (a.on && a.class_name != "StaticOptimization" && a.class_name != "MuscleAnalysis" &&
        a.class_name != "Actuation")
      unsupported_.push_back(a.name + " (" + a.class_name + ")");
  const StaticOptimizationSettings& so = setup_.static_optimization;
  if (!so.present && !runsMuscleAnalyses())
    throw ConvertError(where, 0,
                       "no analysis redmax runs is on (redmax runs StaticOptimization, MuscleAnalysis, Actuation" +
                           (unsupported_.empty() ? std::string(")")
                                                 : "; not supported: " + joinNames(unsupported_) + ")"));
  if (setup_.model_file.empty()) throw ConvertError(where, 0, "the setup names no model_file");
  if (setup_.states_file.empty() && setup_.coordinates_file.empty())
    throw ConvertError(where, 0, "the setup names neither a states_file nor a coordinates_file");

  impl_ = std::make_unique<Impl>();
  Impl& I = *impl_;
  IdToolConfig cfg;
  cfg.setup_file = where;
  cfg.model_file = setup_.model_file;
  cfg.coordinates_file = setup_.coordinates_file;
  if (!setup_.states_file.empty()) {
    // AnalyzeTool::loadStatesFromFile: the states file wins, unfiltered
    I.states = std::make_unique<AnalyzeStatesFile>(setup_.states_file);
    if (!setup_.coordinates_file.empty())
      warnings_.push_back("coordinates_file is ignored since states_file is also set (as OpenSim does)");
    cfg.coordinates_file = setup_.states_file;
    cfg.coordinates_table = I.states->coordinatesTable();
  }
  cfg.external_loads_file = setup_.external_loads_file;
  cfg.loads_working_dir = setup_.directory;
  cfg.lowpass_cutoff_hz = I.states ? -1.0 : setup_.lowpass_cutoff_frequency_for_coordinates;
  cfg.t0 = setup_.initial_time;
  cfg.t1 = setup_.final_time;
  cfg.opensim_compat = true;
  cfg.muscle_mass = settings_.muscle_mass;
  if (settings_.muscle_class) {
    const auto& known = hill::muscleModelClasses();
    if (std::find(known.begin(), known.end(), *settings_.muscle_class) == known.end())
      throw ConvertError(where, 0, "--muscle-class " + *settings_.muscle_class + ": redmax has no such muscle model");
    cfg.muscle_class = *settings_.muscle_class;
  }
  // the actuators are the program's unknowns; every other force is what ID leaves to them. The
  // passive forces redmax models (converter/build/force_terms.hpp) are applied below, so ID
  // leaves them out instead of naming them as unmodelled.
  cfg.forces_to_exclude = {"Actuators"};
  ModelDescription with_files = readOsimModel(setup_.model_file, cfg.muscle_class);
  const size_t nw = with_files.warnings.size();
  for (const std::string& file : setup_.force_set_files)
    appendForceSetFile(with_files, file, setup_.replace_force_set);
  warnings_.insert(warnings_.end(), with_files.warnings.begin() + static_cast<std::ptrdiff_t>(nw),
                   with_files.warnings.end());
  for (const ForceDesc& f : with_files.forces)
    if (f.modelled && f.class_name.find("Actuator") == std::string::npos) cfg.forces_to_exclude.push_back(f.name);
  I.id = std::make_unique<InverseDynamicsTool>(cfg);
  for (const auto& w : I.id->warnings()) warnings_.push_back(w);
  I.engine = std::make_unique<CoreIdEngine>(I.id->musculoskeletalModel(), I.id->engineOptions());
  if (std::find(I.id->engineOptions().rates_as_u.begin(), I.id->engineOptions().rates_as_u.end(), true) !=
      I.id->engineOptions().rates_as_u.end())
    warnings_.push_back("Ball/Free/Ellipsoid joints: muscle moment arms are taken per coordinate rate, "
                        "not per Simbody speed");

  // the muscles' paths and force models (read as --muscle-class when given)
  const ModelDescription& d = I.id->description();
  BuildOptions bo;
  bo.simbody_compat = true;
  bo.constraints = false;
  bo.muscles = true;
  BuildResult built = buildCoreModel(d, bo);
  // the model's forces (all dropped with replace_force_set) and those of force_set_files, with
  // the ID tool's model (muscle class) and the files' entries after them, as OpenSim appends them
  ModelDescription dd = d;
  if (setup_.replace_force_set)
    for (ForceDesc& f : dd.forces) f.applies_force = false;
  for (size_t k = 0; k < with_files.forces.size(); ++k)
    if (!with_files.forces[k].source_file.empty()) dd.forces.push_back(with_files.forces[k]);
  for (const PathForceDesc& m : with_files.muscles)
    if (!m.source_file.empty() && m.applies_force)
      throw ConvertError(m.source_file, m.line, m.class_name + " '" + m.name +
                                                    "': muscles in force_set_files are not supported by redmax's analyze");
  I.forces = buildForceTerms(dd, built, warnings_);
  // (the model's own unmodelled forces are named by the ID tool's warnings)
  for (const ForceDesc& f : dd.forces)
    if (f.applies_force && !f.modelled && !f.source_file.empty() && f.class_name.find("Actuator") == std::string::npos)
      warnings_.push_back(f.source_file + ":" + std::to_string(f.line) + ": " + f.class_name + " '" + f.name +
                          "': OpenSim applies it, redmax does not model it");
  // ForceDesc index -> (kind, index in its actuator term)
  std::map<int, std::pair<int, int>> term_of;
  for (size_t k = 0; k < I.forces.coordinate_actuator_source.size(); ++k)
    term_of[I.forces.coordinate_actuator_source[k]] = {0, static_cast<int>(k)};
  for (size_t k = 0; k < I.forces.point_actuator_source.size(); ++k)
    term_of[I.forces.point_actuator_source[k]] = {1, static_cast<int>(k)};
  for (size_t k = 0; k < I.forces.torque_actuator_source.size(); ++k)
    term_of[I.forces.torque_actuator_source[k]] = {2, static_cast<int>(k)};
  for (size_t i = 0; i < dd.forces.size(); ++i) {
    // ActivationCoordinateActuator: its actuation is overridden, so it is a CoordinateActuator here
    const ForceDesc& f = dd.forces[i];
    if (f.class_name != "ActivationCoordinateActuator" || !f.applies_force) continue;
    const int ci = d.findCoordinate(f.coordinate);
    const int k = ci >= 0 ? built.coordinate_index[ci] : -1;
    if (k < 0)
      throw ConvertError(f.source_file.empty() ? setup_.model_file : f.source_file, f.line,
                         f.class_name + " '" + f.name + "': no coordinate '" + f.coordinate + "'");
    term_of[static_cast<int>(i)] = {3, k};
  }
  I.geometry = std::move(built.model);
  const Model& skel = I.id->model();
  for (int k = 0; k < skel.nr(); ++k) I.coordinate_desc.push_back(d.findCoordinate(skel.coordinates()[k].name));
  I.muscle_source = built.muscle_source;
  I.coordinate_index = built.coordinate_index;
  if (I.states) I.states->bind(d, skel, I.coordinate_desc, I.geometry, warnings_);
  I.mk.resize(I.geometry.muscles().size());
  for (size_t m = 0; m < I.mk.size(); ++m) initMuscleKinematics(skel, I.geometry.muscles()[m], I.mk[m]);
  I.force_term = std::make_unique<MuscleForceTerm>(skel, I.geometry.muscles(), I.geometry.muscleModels());
  if (runsMuscleAnalyses()) prepareMuscleAnalyses();
  if (so.present && (!setup_.controllers.empty() || !setup_.controls_file.empty()))
    warnings_.push_back(so.name + ": the setup's controllers are not used: static optimization overrides the "
                                  "actuators' controls (as OpenSim's StaticOptimizationTarget does)");
  if (!so.present) return;

  // the force set in OpenSim's order (the model's in file order, then force_set_files), those
  // with appliesForce false removed
  std::vector<Actuator>& acts = I.actuators;
  if (!so.use_model_force_set) {
    // CoordinateActuator::CreateForceSetOfCoordinateActuatorsForModel(s, model, 1, false)
    for (int k = 0; k < skel.nr(); ++k) {
      const int ci = d.findCoordinate(skel.coordinates()[k].name);
      if (ci >= 0 && (d.coordinates[ci].locked || d.coordinates[ci].prescribed)) continue;
      Actuator a;
      a.name = skel.coordinates()[k].name + "_actuator";
      a.coordinate = k;
      a.lower = -std::numeric_limits<double>::infinity();
      a.upper = std::numeric_limits<double>::infinity();
      acts.push_back(a);
    }
  } else {
    std::vector<std::pair<int, Actuator>> model_acts;
    if (!setup_.replace_force_set) {
      for (size_t m = 0; m < built.muscle_source.size(); ++m) {
        const PathForceDesc& pf = d.muscles[built.muscle_source[m]];
        if (!pf.applies_force) continue;
        if (!pf.is_muscle) {
          if (pf.class_name.find("Actuator") != std::string::npos)
            throw ConvertError(setup_.model_file, pf.line,
                               pf.class_name + " '" + pf.name + "' is not modelled by redmax's static optimization");
          continue;  // a PathSpring and the like: not an actuator (ID reports it unmodelled)
        }
        const auto& model = I.geometry.muscleModels()[m];
        if (!model)
          throw ConvertError(setup_.model_file, pf.line,
                             "muscle '" + pf.name + "' (" + I.geometry.muscleClasses()[m] +
                                 "): redmax has no force model for this class");
        Actuator a;
        a.name = pf.name;
        a.muscle = static_cast<int>(m);
        a.optimal_force = pf.max_isometric_force;
        a.lower = model->minControl();
        a.upper = model->maxControl();
        model_acts.emplace_back(pf.line, a);
      }
      for (size_t i = 0; i < dd.forces.size(); ++i) {
        const ForceDesc& f = dd.forces[i];
        if (!f.applies_force || !f.source_file.empty()) continue;
        if (auto it = term_of.find(static_cast<int>(i)); it != term_of.end()) {
          model_acts.emplace_back(f.line, forceSetActuator(f, it->second, I.forces));
        } else if (f.class_name.find("Actuator") != std::string::npos) {
          throw ConvertError(setup_.model_file, f.line,
                             f.class_name + " '" + f.name + "' is not modelled by redmax's static optimization");
        }
      }
      std::stable_sort(model_acts.begin(), model_acts.end(),
                       [](const auto& x, const auto& y) { return x.first < y.first; });
      for (auto& [line, a] : model_acts) acts.push_back(a);
    }
    // force_set_files, in file order
    for (size_t i = 0; i < dd.forces.size(); ++i) {
      const ForceDesc& f = dd.forces[i];
      if (!f.applies_force || f.source_file.empty()) continue;
      if (auto it = term_of.find(static_cast<int>(i)); it != term_of.end())
        acts.push_back(forceSetActuator(f, it->second, I.forces));
      else if (f.class_name.find("Actuator") != std::string::npos)
        throw ConvertError(f.source_file, f.line,
                           f.class_name + " '" + f.name + "' is not modelled by redmax's static optimization");
    }
  }
  if (acts.empty()) throw ConvertError(setup_.model_file, 0, "static optimization: the force set has no actuators");
  for (const Actuator& a : acts)
    if (!(a.lower <= a.upper) || std::isnan(a.optimal_force))
      throw ConvertError(setup_.model_file, 0,
                         "actuator '" + a.name + "': min_control " + std::to_string(a.lower) +
                             " is above max_control " + std::to_string(a.upper) + " (infeasible bounds)");

  // rows: the coordinates that are not locked or prescribed (OpenSim's isConstrained)
  const auto& sources = I.id->coordinateSources();
  std::vector<std::string> missing;
  for (int k = 0; k < skel.nr(); ++k) {
    const int ci = d.findCoordinate(skel.coordinates()[k].name);
    if (ci >= 0 && (d.coordinates[ci].locked || d.coordinates[ci].prescribed)) continue;
    I.rows.push_back(k);
    if (sources[k].spline < 0) missing.push_back(skel.coordinates()[k].name);
  }
  if (!missing.empty())
    throw ConvertError(I.id->config().coordinates_file, I.id->coordinatesData().label_line,
                       "no column for coordinate(s) " + joinNames(missing) +
                           ", which static optimization must drive (OpenSim would use 0)");
  if (static_cast<int>(acts.size()) < static_cast<int>(I.rows.size()))
    throw ConvertError(setup_.model_file, 0,
                       "StaticOptimization: over-constrained system: " + std::to_string(acts.size()) +
                           " actuators for " + std::to_string(I.rows.size()) + " degrees of freedom");

  // StaticOptimization::begin: GCVSplineSet(5, states store) over every processed row, and its
  // first derivative: the target accelerations
  const auto& P = I.id->processed();
  I.u_splines.resize(static_cast<size_t>(skel.nr()));
  std::vector<double> u(P.time.size());
  for (int k = 0; k < skel.nr(); ++k) {
    if (sources[k].spline < 0) continue;
    const auto& s = P.splines[static_cast<size_t>(sources[k].spline)];
    for (size_t r = 0; r < P.time.size(); ++r) u[r] = s.calcDerivative(1, P.time[r]);
    if (I.states) u = I.states->speedColumn(k);  // the states' own u
    I.u_splines[static_cast<size_t>(k)] = signal::NaturalSpline(5, P.time, u);
  }
}

double AnalyzeTool::muscleMass() const { return impl_->engine->muscleMass(); }

std::string AnalyzeTool::muscleMassSummary() const { return describeMuscleMass(impl_->id->muscleMassPlan()); }

StaticOptimizationRun AnalyzeTool::runStaticOptimization() const {
  if (!runsStaticOptimization()) return {};
  const Impl& I = *impl_;
  const StaticOptimizationSettings& so = setup_.static_optimization;
  const Model& skel = I.id->model();
  const int nr = skel.nr(), na = static_cast<int>(I.actuators.size());
  const int nrow = static_cast<int>(I.rows.size());
  StaticOptimizationRun run;
  for (const Actuator& a : I.actuators) {
    run.actuators.push_back(a.name);
    run.is_muscle.push_back(a.muscle >= 0);
  }
  std::vector<int> row_of(static_cast<size_t>(nr), -1);
  for (int r = 0; r < nrow; ++r) row_of[static_cast<size_t>(I.rows[r])] = r;

  // which muscles' paths each coordinate moves
  const auto& muscles = I.geometry.muscles();
  const int nm = static_cast<int>(muscles.size());
  std::vector<char> muscle_used(static_cast<size_t>(nm), 0);
  for (const Actuator& a : I.actuators)
    if (a.muscle >= 0) muscle_used[static_cast<size_t>(a.muscle)] = 1;
  // muscles whose dl/dq only the central differences below give (the rest: MuscleForceTerm)
  std::vector<char> by_differences(muscle_used);
  for (int m = 0; m < nm; ++m)
    if (I.geometry.muscleModels()[static_cast<size_t>(m)]) by_differences[static_cast<size_t>(m)] = 0;

  CoreIdWorkspace ws(I.engine->system());
  const signal::TimeWindow& w = I.id->window();
  const auto& P = I.id->processed();
  VecX q, v, vdot, tau, qh;
  std::vector<IdLoadSample> loads;
  std::vector<Mat4> E;
  VecX length(nm), speed(nm);
  MatX dl(nm, nr);
  VecX prev, dl_row, column;
  SkeletonWorkspace sk(skel);
  StaticOptimizationOptions opt;
  opt.convergence_tolerance = std::min(so.optimizer_convergence_criterion, 1e-8);
  opt.max_iterations = so.optimizer_max_iterations;
  constexpr double h = 1e-6;  // central differences of the path lengths (rad or m)

  for (int i = w.first_row; i <= w.last_row; ++i) {
    if (i != w.first_row && i != w.last_row && i % so.step_interval != 0) continue;
    StaticOptimizationFrame fr;
    fr.time = P.time[static_cast<size_t>(i)];
    fr.activation = VecX::Constant(na, std::numeric_limits<double>::quiet_NaN());
    fr.force = fr.activation;
    try {
      I.id->calcInputs(fr.time, q, v, vdot, loads);
      if (I.states) I.states->stateAt(i, q, q, v);
      for (int k = 0; k < nr; ++k)
        vdot[k] = I.u_splines[static_cast<size_t>(k)].size() > 0
                      ? I.u_splines[static_cast<size_t>(k)].calcDerivative(1, fr.time)
                      : 0.0;
      I.engine->calcGeneralizedForces(fr.time, q, v, vdot, loads, tau, ws);

      // path lengths, -moment arms dl/dq and lengthening speeds
      calcBodyPoses(skel, q, E);
      for (int m = 0; m < nm; ++m)
        if (muscle_used[static_cast<size_t>(m)]) length[m] = calcPathLength(skel, muscles[m].path, q, E);
      dl.setZero();
      for (int k = 0; k < nr; ++k) {
        bool any = false;
        for (int m = 0; m < nm && !any; ++m)
          any = by_differences[static_cast<size_t>(m)] && I.mk[static_cast<size_t>(m)].col_of[static_cast<size_t>(k)] >= 0;
        if (!any) continue;
        qh = q;
        qh[k] = q[k] + h;
        calcBodyPoses(skel, qh, E);
        VecX lp(nm);
        for (int m = 0; m < nm; ++m)
          if (by_differences[static_cast<size_t>(m)] && I.mk[static_cast<size_t>(m)].col_of[static_cast<size_t>(k)] >= 0)
            lp[m] = calcPathLength(skel, muscles[m].path, qh, E);
        qh[k] = q[k] - h;
        calcBodyPoses(skel, qh, E);
        for (int m = 0; m < nm; ++m)
          if (by_differences[static_cast<size_t>(m)] && I.mk[static_cast<size_t>(m)].col_of[static_cast<size_t>(k)] >= 0)
            dl(m, k) = (lp[m] - calcPathLength(skel, muscles[m].path, qh, E)) / (2 * h);
      }
      // muscles with a force model: the generalized force per unit tension as the forward
      // simulation applies it (MuscleForceTerm: OpenSim's straight segments with wrap tangent
      // points held in their surface's body), so both tools use one moment arm
      State st;
      st.t = fr.time;
      st.q = q;
      st.qdot = v;
      calcKinematics(skel, st, sk);
      if (I.force_term) {
        for (int m = 0, k = 0; m < nm; ++m) {
          if (!I.geometry.muscleModels()[m]) continue;
          if (muscle_used[static_cast<size_t>(m)]) {
            double len = 0.0, spd = 0.0;
            I.force_term->calcPath(skel, st, sk, k, len, spd, dl_row);
            dl.row(m) = dl_row.transpose();
          }
          ++k;
        }
      }
      speed = dl * v;

      StaticOptimizationProblem pb;
      pb.A = MatX::Zero(nrow, na);
      pb.b.resize(nrow);
      // the passive forces (CoordinateLimitForce, springs) act at (q, u) whatever the controls:
      // OpenSim's StaticOptimizationTarget sees them in the accelerations at zero actuation, so
      // the actuators supply what they leave (b = tau - f_passive)
      VecX f_passive = VecX::Zero(nr);
      for (const auto& term : I.forces.passiveTerms()) term->addForce(skel, st, TermContext(sk), f_passive);
      for (int r = 0; r < nrow; ++r) pb.b[r] = tau[I.rows[r]] - f_passive[I.rows[r]];
      pb.lower.resize(na);
      pb.upper.resize(na);
      VecX fopt(na);
      for (int j = 0; j < na; ++j) {
        const Actuator& a = I.actuators[static_cast<size_t>(j)];
        pb.lower[j] = a.lower;
        pb.upper[j] = a.upper;
        if (a.muscle >= 0) {
          fopt[j] = so.use_muscle_physiology
                        ? I.geometry.muscleModels()[a.muscle]->inextensibleTendonActiveFiberForce(
                              {length[a.muscle], speed[a.muscle], 0.0}, 1.0)
                        : a.optimal_force;
          for (int r = 0; r < nrow; ++r) pb.A(r, j) = -fopt[j] * dl(a.muscle, I.rows[r]);
        } else if (a.point >= 0 || a.torque >= 0) {
          // a residual: its generalized force at the optimal force, through the body Jacobians
          fopt[j] = a.optimal_force;
          column.setZero(nr);
          if (a.point >= 0) I.forces.point_actuators->addActuation(skel, sk, a.point, fopt[j], column);
          else I.forces.torque_actuators->addActuation(skel, sk, a.torque, fopt[j], column);
          for (int r = 0; r < nrow; ++r) pb.A(r, j) = column[I.rows[r]];
        } else {
          fopt[j] = a.optimal_force;
          if (row_of[static_cast<size_t>(a.coordinate)] >= 0) pb.A(row_of[static_cast<size_t>(a.coordinate)], j) = fopt[j];
        }
      }
      pb.exponent = so.activation_exponent;
      // warm start from the previous frame's optimum (the first frame: zero, as OpenSim starts)
      pb.x0 = prev.size() == na ? prev : VecX::Zero(na);
      for (int j = 0; j < na; ++j) pb.x0[j] = std::clamp(pb.x0[j], pb.lower[j], pb.upper[j]);
      const StaticOptimizationResult res = solveStaticOptimization(pb, opt);
      fr.iterations = res.iterations;
      fr.constraint_violation = res.constraint_violation;
      fr.converged = res.converged;
      fr.status = res.status;
      if (res.converged) {
        fr.activation = res.x;
        fr.force = res.x.cwiseProduct(fopt);
        prev = res.x;
      }
    } catch (const std::exception& e) {
      fr.converged = false;
      fr.status = e.what();
    }
    if (!fr.converged) ++run.failed;
    run.frames.push_back(std::move(fr));
  }
  return run;
}

std::vector<std::string> AnalyzeTool::writeStaticOptimization(const StaticOptimizationRun& run) const {
  const std::string stem = setup_.name + "_" + setup_.static_optimization.name;
  Storage act, force;
  act.name = force.name = "Static Optimization";
  act.version = force.version = 1;
  act.labels = force.labels = run.actuators;
  const auto nf = static_cast<Eigen::Index>(run.frames.size());
  const auto na = static_cast<Eigen::Index>(run.actuators.size());
  act.data.resize(nf, na);
  force.data.resize(nf, na);
  std::string failed;
  for (Eigen::Index r = 0; r < nf; ++r) {
    const StaticOptimizationFrame& f = run.frames[static_cast<size_t>(r)];
    act.time.push_back(f.time);
    force.time.push_back(f.time);
    act.data.row(r) = f.activation.transpose();
    force.data.row(r) = f.force.transpose();
    if (!f.converged) {
      std::ostringstream os;
      os.precision(10);
      os << "failed frame t = " << f.time << ": " << f.status << " (its row is nan)\n";
      failed += os.str();
    }
  }
  StorageWriteOptions wo;
  wo.decimals = setup_.output_precision;
  wo.description = "This file contains static optimization results.\n" + failed + "\n";
  // a folder that cannot be made shows up as the write's error, with the file named
  std::error_code ec;
  fs::create_directories(out_dir_, ec);
  const std::string a_path = (fs::path(out_dir_) / (stem + "_activation.sto")).string();
  const std::string f_path = (fs::path(out_dir_) / (stem + "_force.sto")).string();
  writeStorage(a_path, act, wo);
  writeStorage(f_path, force, wo);
  return {a_path, f_path};
}

// ---------------------------------------------------------------------------------------------
// MuscleAnalysis and Actuation

void AnalyzeTool::prepareMuscleAnalyses() {
  Impl& I = *impl_;
  const ModelDescription& d = I.id->description();
  std::vector<int> geometry_of(d.muscles.size(), -1);
  for (size_t m = 0; m < I.muscle_source.size(); ++m) geometry_of[static_cast<size_t>(I.muscle_source[m])] = static_cast<int>(m);
  // replace_force_set takes the model's forces away, muscles included (AbstractTool::updateModelForces)
  const bool model_forces = !setup_.replace_force_set;

  // the controls: one per actuator of the force set, by name (the model's, then force_set_files)
  std::map<std::string, int> control_of;
  auto addControl = [&](const std::string& name) {
    if (control_of.count(name)) return control_of[name];
    I.control_names.push_back(name);
    return control_of[name] = static_cast<int>(I.control_names.size()) - 1;
  };
  I.muscle_control.assign(I.geometry.muscles().size(), -1);
  ModelDescription files = d;
  files.forces.clear();
  for (const std::string& file : setup_.force_set_files) appendForceSetFile(files, file, setup_.replace_force_set);
  if (model_forces) {
    for (size_t k = 0; k < d.muscles.size(); ++k) {
      const PathForceDesc& pf = d.muscles[k];
      if (pf.applies_force && (pf.is_muscle || pf.class_name.find("Actuator") != std::string::npos) && geometry_of[k] >= 0)
        I.muscle_control[static_cast<size_t>(geometry_of[k])] = addControl(pf.name);
    }
    for (const ForceDesc& f : d.forces)
      if (f.applies_force && f.class_name.find("Actuator") != std::string::npos) addControl(f.name);
  }
  for (const ForceDesc& f : files.forces)
    if (f.applies_force && f.class_name.find("Actuator") != std::string::npos) addControl(f.name);
  I.controllers = resolveSetupControllers(setup_.controllers, setup_.source_file, I.control_names, warnings_);
  if (!setup_.controls_file.empty())
    I.controllers.push_back(resolveControlsFile(setup_.controls_file, I.control_names, warnings_));

  if (const MuscleAnalysisSettings& ma = setup_.muscle_analysis; ma.present) {
    MuscleAnalysisColumns& c = I.ma_columns;
    std::vector<int> muscles;  // the force set's Muscles, file order
    if (model_forces)
      for (size_t k = 0; k < d.muscles.size(); ++k)
        if (d.muscles[k].is_muscle && geometry_of[k] >= 0) muscles.push_back(geometry_of[k]);
    const bool all = ma.muscle_list.size() == 1 && ma.muscle_list[0] == "all";
    std::vector<std::string> absent, no_model;
    if (all) {
      c.muscle_index = muscles;
    } else {
      for (const std::string& name : ma.muscle_list) {
        int found = -1;
        for (int m : muscles)
          if (I.geometry.muscles()[static_cast<size_t>(m)].name == name) found = m;
        if (found >= 0) c.muscle_index.push_back(found);
        else absent.push_back(name);
      }
    }
    for (int m : c.muscle_index) {
      c.muscles.push_back(I.geometry.muscles()[static_cast<size_t>(m)].name);
      const auto& model = I.geometry.muscleModels()[static_cast<size_t>(m)];
      c.classes.push_back(model ? model->className() : std::string());
      if (!model) no_model.push_back(c.muscles.back());
    }
    if (!absent.empty())
      warnings_.push_back(ma.name + ": muscle_list names no muscle of the force set: " + joinNames(absent) +
                          " (dropped, as OpenSim drops them)");
    if (!no_model.empty())
      warnings_.push_back(ma.name + ": no force model for " + joinNames(no_model) +
                          ": lengths and moment arms only, the other quantities nan");
    if (ma.compute_moments) {
      if (!ma.coordinate_list.empty() && toLower(ma.coordinate_list[0]) == "all") {
        for (size_t ci = 0; ci < d.coordinates.size(); ++ci)
          if (I.coordinate_index[ci] >= 0) {
            c.coordinates.push_back(d.coordinates[ci].name);
            c.coordinate_index.push_back(I.coordinate_index[ci]);
          }
      } else {
        std::vector<std::string> unknown;
        for (const std::string& name : ma.coordinate_list) {
          const int ci = d.findCoordinate(name);
          const int k = ci >= 0 ? I.coordinate_index[static_cast<size_t>(ci)] : -1;
          if (k < 0) {
            unknown.push_back(name);
            continue;
          }
          c.coordinates.push_back(name);
          c.coordinate_index.push_back(k);
        }
        if (!unknown.empty())
          warnings_.push_back(ma.name + ": moment_arm_coordinate_list: coordinate(s) " + joinNames(unknown) +
                              " not part of the model (dropped, as OpenSim drops them)");
      }
      if (!d.constraints.empty()) {
        // OpenSim's MomentArmSolver moves the coordinates the constraints couple (coupler,
        // weld, point constraints; locked and prescribed coordinates are not constraints here)
        BuildOptions cb;
        cb.simbody_compat = true;
        cb.couplers = CouplerHandling::Constraint;
        cb.locked_coordinates = false;
        cb.prescribed_coordinates = false;
        cb.muscles = false;
        I.constrained = std::make_unique<BuildResult>(buildCoreModel(d, cb));
        const Model& cs = I.constrained->model.skeleton();
        bool same = cs.nr() == I.id->model().nr();
        for (int k = 0; same && k < cs.nr(); ++k)
          same = cs.coordinates()[k].name == I.id->model().coordinates()[k].name;
        if (!same || I.constrained->model.constraints().empty()) {
          if (!same)
            warnings_.push_back(ma.name + ": moment arms are -dl/dq per coordinate: the constrained model's "
                                          "coordinates differ from the tool's");
          I.constrained.reset();
        }
      }
    }
  }

  if (setup_.actuation.present) {
    std::vector<std::pair<int, ActuationColumn>> model_acts;
    std::vector<std::string> unmodelled;
    // an actuator of the force set as an Actuation column; others (springs, limits) are not actuators
    auto actuationColumn = [&](const ForceDesc& f) -> std::optional<ActuationColumn> {
      if (!f.applies_force || f.class_name.find("Actuator") == std::string::npos) return std::nullopt;
      ActuationColumn a;
      a.name = f.name;
      a.control = control_of.count(f.name) ? control_of[f.name] : -1;
      a.optimal_force = f.optimal_force;
      if (isCoordinateActuator(f.class_name)) {
        const int ci = d.findCoordinate(f.coordinate);
        a.coordinate = ci >= 0 ? I.coordinate_index[static_cast<size_t>(ci)] : -1;
        if (a.coordinate < 0 && !f.source_file.empty())
          throw ConvertError(f.source_file, f.line, f.class_name + " '" + f.name +
                                                        "': the model has no coordinate '" + f.coordinate + "'");
      } else if (const auto* pa = findByName(I.forces.point_actuators, f.name);
                 pa && f.class_name == "PointActuator") {
        a.rigid = ActuationColumn::Rigid::Point;
        a.body_a = pa->body;
        a.vector = pa->point;  // as written: OpenSim's calcSpeed reads it as a body station
      } else if (const auto* ta = findByName(I.forces.torque_actuators, f.name);
                 ta && f.class_name == "TorqueActuator") {
        a.rigid = ActuationColumn::Rigid::Torque;
        a.body_a = ta->body_a;
        a.body_b = ta->body_b;
        a.vector = ta->axis;
      } else {
        unmodelled.push_back(f.name + " (" + f.class_name + ")");
      }
      return a;
    };
    if (model_forces) {
      for (size_t k = 0; k < d.muscles.size(); ++k) {
        const PathForceDesc& pf = d.muscles[k];
        if (!pf.applies_force || !(pf.is_muscle || pf.class_name.find("Actuator") != std::string::npos)) continue;
        ActuationColumn a;
        a.name = pf.name;
        a.path = geometry_of[k];
        a.muscle = pf.is_muscle;
        a.control = control_of.count(pf.name) ? control_of[pf.name] : -1;
        a.optimal_force = pf.optimal_force;
        model_acts.emplace_back(pf.line, a);
      }
      for (const ForceDesc& f : d.forces)
        if (auto a = actuationColumn(f)) model_acts.emplace_back(f.line, *a);
      std::stable_sort(model_acts.begin(), model_acts.end(),
                       [](const auto& x, const auto& y) { return x.first < y.first; });
    }
    for (auto& [line, a] : model_acts) I.act_columns.push_back(a);
    // force_set_files, read by the same reader the force set of static optimization uses
    for (const ForceDesc& f : files.forces)
      if (auto a = actuationColumn(f)) I.act_columns.push_back(*a);
    if (!unmodelled.empty())
      warnings_.push_back(setup_.actuation.name + ": speed and power nan for " + joinNames(unmodelled) +
                          ": redmax does not model these actuators' speeds");
    if (I.act_columns.empty())
      warnings_.push_back(setup_.actuation.name + ": the force set has no actuators (OpenSim cancels the analysis)");
  }
}

MuscleAnalysisRun AnalyzeTool::runMuscleAnalyses() const {
  const Impl& I = *impl_;
  MuscleAnalysisRun run;
  run.columns = I.ma_columns;
  run.actuators = I.act_columns;
  if (!runsMuscleAnalyses()) return run;
  const MuscleFrameEvaluator eval(I.id->model(), I.geometry);
  const signal::TimeWindow& w = I.id->window();
  const auto& P = I.id->processed();
  const int ma_step = setup_.muscle_analysis.step_interval, act_step = setup_.actuation.step_interval;
  VecX q, v, vdot;
  std::vector<IdLoadSample> loads;
  SkeletonWorkspace sk(I.id->model());
  for (int i = w.first_row; i <= w.last_row; ++i) {
    // Analysis::proceed: begin (first row), end (last row) and every step_interval-th step
    const bool ends = i == w.first_row || i == w.last_row;
    const bool ma = setup_.muscle_analysis.present && (ends || i % ma_step == 0);
    const bool act = setup_.actuation.present && (ends || i % act_step == 0);
    if (!ma && !act) continue;
    MuscleFrameInput in;
    in.time = P.time[static_cast<size_t>(i)];
    I.id->calcInputs(in.time, q, v, vdot, loads);
    if (I.states) {
      I.states->stateAt(i, q, q, v);
      in.z_given = I.states->muscleStatesAt(i);
    }
    in.q = q;
    in.u = v;
    in.controls = I.controlsAt(in.time);
    if (!I.controllers.empty()) {
      // the muscles' excitations from the controllers (controls start at 0, as OpenSim's)
      in.excitation = VecX::Zero(static_cast<Eigen::Index>(I.muscle_control.size()));
      for (size_t m = 0; m < I.muscle_control.size(); ++m)
        if (I.muscle_control[m] >= 0) in.excitation[static_cast<Eigen::Index>(m)] = in.controls[I.muscle_control[m]];
    }
    run.frames.push_back(eval.evaluate(in, setup_.solve_for_equilibrium_for_auxiliary_states));
    if (ma && I.constrained)
      run.frames.back().coupling = constraintCoupling(I.constrained->model.skeleton(), I.constrained->model.constraints(),
                                                      q, I.ma_columns.coordinate_index);
    if (act) {
      State st;
      st.t = in.time;
      st.q = q;
      st.qdot = v;
      calcKinematics(I.id->model(), st, sk);
      run.frames.back().actuator_speed = actuatorSpeeds(I.act_columns, sk);
    }
    run.muscle_analysis.push_back(ma);
    run.actuation.push_back(act);
    for (const std::string& f : run.frames.back().failures) {
      std::ostringstream os;
      os.precision(10);
      os << "t = " << in.time << ": " << f;
      run.failures.push_back(os.str());
    }
  }
  return run;
}

std::vector<std::string> AnalyzeTool::writeMuscleAnalyses(const MuscleAnalysisRun& run) const {
  // every table is made before any file is written, so a failure leaves no partial set behind
  std::vector<std::pair<std::string, std::string>> files;  // path, contents
  StorageWriteOptions wo;
  wo.decimals = setup_.output_precision;
  auto add = [&](const std::string& stem, const std::vector<Storage>& tables, const std::vector<std::string>& suffixes,
                 const std::string& description) {
    wo.description = description;
    for (size_t k = 0; k < tables.size(); ++k)
      files.emplace_back((fs::path(out_dir_) / (setup_.name + "_" + stem + "_" + suffixes[k] + ".sto")).string(),
                         formatStorage(tables[k], wo));
  };
  auto recorded = [&](const std::vector<char>& mask) {
    std::vector<const MuscleFrame*> f;
    for (size_t k = 0; k < run.frames.size(); ++k)
      if (mask[k]) f.push_back(&run.frames[k]);
    return f;
  };
  if (setup_.muscle_analysis.present) {
    const auto tables = muscleAnalysisTables(setup_.muscle_analysis, run.columns, recorded(run.muscle_analysis));
    std::vector<std::string> names;
    for (const Storage& t : tables) names.push_back(t.name);
    add(setup_.muscle_analysis.name, tables, names, muscleAnalysisDescription());
  }
  if (setup_.actuation.present && !run.actuators.empty())
    add(setup_.actuation.name, actuationTables(run.actuators, recorded(run.actuation)), {"force", "speed", "power"},
        actuationDescription());
  std::error_code ec;
  fs::create_directories(out_dir_, ec);
  std::vector<std::string> paths;
  for (const auto& [path, text] : files) {
    writeFileAtomic(path, text);
    paths.push_back(path);
  }
  return paths;
}

}  // namespace redmax::osim
