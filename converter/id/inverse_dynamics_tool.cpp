#include "converter/id/inverse_dynamics_tool.hpp"

#include "converter/detail/xml_util.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "converter/coordinates_file.hpp"
#include "converter/osim_reader.hpp"
#include "converter/signal/signal_error.hpp"

namespace redmax::osim {

namespace {

std::string quoted(const std::string& s) { return "'" + s + "'"; }

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

using detail::joinNames;

}  // namespace

// ---------------------------------------------------------------------------------------------
IdToolConfig resolveIdSettings(const IdToolSettings& s) {
  IdToolConfig c;
  c.opensim_compat = s.opensim_compat;
  c.muscle_mass = s.muscle_mass;
  if (!s.setup_file.empty()) {
    const InverseDynamicsSetup setup = readInverseDynamicsSetup(s.setup_file);
    c.setup_file = s.setup_file;
    c.model_file = setup.model_file;
    c.coordinates_file = setup.coordinates_file;
    c.external_loads_file = setup.external_loads_file;
    c.loads_working_dir = setup.directory;
    c.output_file = setup.output_gen_force_file;
    c.lowpass_cutoff_hz = setup.lowpass_cutoff_frequency_for_coordinates;
    c.t0 = setup.time_start;
    c.t1 = setup.time_end;
    c.forces_to_exclude = setup.forces_to_exclude;
    c.warnings = setup.warnings;
    if (!setup.joints_to_report_body_forces.empty())
      c.warnings.push_back("joints_to_report_body_forces is not supported: no body forces are written");
  } else {
    // redmax computes no muscle forces, so the flag-only default excludes them
    c.forces_to_exclude = {"Muscles"};
  }
  // flags override the setup
  if (s.model_file) c.model_file = *s.model_file;
  if (s.coordinates_file) c.coordinates_file = *s.coordinates_file;
  if (s.external_loads_file) c.external_loads_file = *s.external_loads_file;
  if (s.output_file) c.output_file = *s.output_file;
  if (s.lowpass_cutoff_hz) c.lowpass_cutoff_hz = *s.lowpass_cutoff_hz;
  if (s.t0) c.t0 = *s.t0;
  if (s.t1) c.t1 = *s.t1;
  if (s.forces_to_exclude) c.forces_to_exclude = *s.forces_to_exclude;

  const std::string where = c.setup_file;
  if (c.model_file.empty())
    throw ConvertError(where, 0, "no model file: give --model or a setup file with <model_file>");
  if (c.coordinates_file.empty())
    throw ConvertError(where, 0,
                       "no coordinates file: give --coordinates or a setup file with <coordinates_file>");
  if (std::isnan(c.lowpass_cutoff_hz) || std::isinf(c.lowpass_cutoff_hz))
    throw ConvertError(where, 0, "the low-pass cutoff must be a finite number of Hz (< 0: no filter)");
  if (std::isnan(c.t0) || std::isnan(c.t1) || c.t0 > c.t1) {
    std::ostringstream os;
    os << "the time range [" << c.t0 << ", " << c.t1 << "] is empty or not a number";
    throw ConvertError(where, 0, os.str());
  }
  return c;
}

// ---------------------------------------------------------------------------------------------
IdEngineOptions idEngineOptions(const ModelDescription& d, const BuildResult& build, bool opensim_compat) {
  IdEngineOptions o;
  // OpenSim's u for Ball/Free/Ellipsoid joints: the data's rates read as angular velocity in F
  o.rates_as_u.assign(build.model.skeleton().nb(), false);
  if (opensim_compat) {
    for (const JointDesc& j : d.joints) {
      if (j.kind != JointKind::Ball && j.kind != JointKind::Free && j.kind != JointKind::Ellipsoid &&
          j.kind != JointKind::Scapulothoracic)
        continue;
      if (j.coordinates.empty()) continue;
      const int k = build.coordinate_index[j.coordinates.front()];
      o.rates_as_u[build.model.skeleton().coordinates()[k].joint] = true;
    }
  }
  return o;
}

std::vector<std::string> idOutputLabels(const ModelDescription& d, const Model& model) {
  std::vector<std::string> labels;
  for (const Coordinate& c : model.coordinates()) {
    const int ci = d.findCoordinate(c.name);
    const bool rot = ci >= 0 && d.coordinates[ci].motion_type == MotionType::Rotational;
    labels.push_back(c.name + (rot ? "_moment" : "_force"));
  }
  return labels;
}

InverseDynamicsTool::InverseDynamicsTool(IdToolConfig config) : config_(std::move(config)) {
  warnings_ = config_.warnings;
  description_ = readOsimModel(config_.model_file, config_.muscle_class);

  // the model as OpenSim's ID sees it: no constraints (calcResidualForceIgnoringConstraints), no
  // muscles (redmax models no muscle forces; see checkForces) unless they take mass: then the
  // muscles are built here, once, and applyMuscleMassOptions edits this model
  BuildOptions bo;
  bo.simbody_compat = config_.opensim_compat;
  bo.constraints = false;
  bo.muscles = config_.muscle_mass.source != MuscleMassOptions::Source::None;
  try {
    build_ = std::make_unique<BuildResult>(buildCoreModel(description_, bo));
  } catch (const ConvertError&) {
    throw;
  } catch (const std::exception& e) {
    throw ConvertError(config_.model_file, 0, std::string("the core cannot build this model: ") + e.what());
  }
  for (const auto& w : build_->warnings) warnings_.push_back(w);
  for (size_t ci = 0; ci < description_.coordinates.size(); ++ci) {
    if (build_->coordinate_index[ci] >= 0) continue;
    const CoordinateDesc& c = description_.coordinates[ci];
    const JointDesc* j = c.joint_index >= 0 ? &description_.joints[c.joint_index] : nullptr;
    throw ConvertError(config_.model_file, j ? j->line : c.line,
                       "coordinate " + quoted(c.name) + (j ? " of " + j->type + " " + quoted(j->name) : "") +
                           " is not modelled by the core, so its generalized force cannot be computed");
  }

  engine_options_ = idEngineOptions(description_, *build_, config_.opensim_compat);

  checkForces();
  prepareCoordinates();
  applyMuscleMassOptions();
  prepareLoads();
}

// the model with muscle mass is an edit of the built one (bodies' mass properties, the muscles'
// mass points), so its q order, coordinates and body indices stay and so do the coordinate sources
void InverseDynamicsTool::applyMuscleMassOptions() {
  muscle_mass_plan_.options = config_.muscle_mass;
  if (config_.muscle_mass.source == MuscleMassOptions::Source::None) {
    mass_description_ = description_;
    return;
  }
  std::vector<VecX> samples;
  VecX q, v, vdot;
  std::vector<IdLoadSample> no_loads;
  for (int k = 0; k < numFrames(); ++k) {
    calcInputs(frameTime(k), q, v, vdot, no_loads);
    samples.push_back(q);
  }
  MuscleMassModel mm;
  try {
    mm = addMuscleMass(description_, *build_, config_.muscle_mass, samples);
  } catch (const ConvertError&) {
    throw;
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw ConvertError(config_.model_file, 0, std::string("muscle mass: ") + e.what());
  }
  build_ = std::make_unique<BuildResult>(std::move(mm.build));
  muscle_mass_plan_ = std::move(mm.plan);
  mass_description_ = std::move(mm.description);
}

// forces_to_exclude as OpenSim applies it (§7 step 7), and the forces it leaves that redmax lacks
void InverseDynamicsTool::checkForces() {
  const auto& excl = config_.forces_to_exclude;
  auto excluded = [&](const std::string& name, bool is_actuator, bool is_muscle) {
    for (const std::string& e : excl) {
      const std::string l = lower(e);
      if (l == "all") return true;
      if (l == "actuators" && is_actuator) return true;
      if (l == "muscles" && is_muscle) return true;
      for (const ForceGroupDesc& g : description_.force_groups)
        if (g.name == e && std::find(g.members.begin(), g.members.end(), name) != g.members.end())
          return true;
      if (e == name) return true;
    }
    return false;
  };
  std::vector<std::string> muscles;
  for (const PathForceDesc& m : description_.muscles) {
    if (!m.applies_force) continue;
    const bool actuator = m.is_muscle || m.class_name.find("Actuator") != std::string::npos;
    if (excluded(m.name, actuator, m.is_muscle)) continue;
    // an actuator without a controller has zero control, hence zero force
    if (!m.is_muscle && actuator) continue;
    (m.is_muscle ? muscles : unmodelled_forces_).push_back(m.name + " (" + m.class_name + ")");
  }
  for (const ForceDesc& f : description_.forces) {
    if (!f.applies_force) continue;
    const bool actuator = f.class_name.find("Actuator") != std::string::npos;
    if (excluded(f.name, actuator, false) || actuator) continue;
    unmodelled_forces_.push_back(f.name + " (" + f.class_name + ")");
  }
  if (!muscles.empty()) {
    warnings_.push_back(std::to_string(muscles.size()) +
                        " muscles are not in forces_to_exclude: OpenSim would apply their forces at "
                        "default muscle states; redmax leaves them out (" + joinNames(muscles, 6) + ")");
    unmodelled_forces_.insert(unmodelled_forces_.end(), muscles.begin(), muscles.end());
  }
  const size_t others = unmodelled_forces_.size() - muscles.size();
  if (others > 0) {
    std::vector<std::string> list(unmodelled_forces_.begin(),
                                  unmodelled_forces_.begin() + static_cast<long>(others));
    warnings_.push_back("OpenSim would also apply these forces, which redmax does not model (add "
                        "them to forces_to_exclude to silence this): " + joinNames(list));
  }
}

void InverseDynamicsTool::prepareCoordinates() {
  const std::string& file = config_.coordinates_file;
  coordinates_ = config_.coordinates_table ? *config_.coordinates_table : readStorage(file);
  for (const auto& w : coordinates_.warnings) warnings_.push_back(file + ": " + w);
  if (coordinates_.numRows() == 0) throw ConvertError(file, 0, "the coordinates file has no rows");

  // q functions by exact column name (§7 step 6, converter/coordinates_file.hpp); every other
  // column is carried and ignored
  const Model& m = model();
  const CoordinateColumns columns =
      matchCoordinateColumns(coordinates_, description_.coordinates, CoordinateLabels::ExactName);
  std::vector<int> used;
  std::vector<double> scale;
  std::vector<std::string> missing;
  sources_.resize(static_cast<size_t>(m.nr()));
  for (int k = 0; k < m.nr(); ++k) {
    IdCoordinateSource& s = sources_[k];
    s.name = m.coordinates()[k].name;
    s.constant = m.coordinates()[k].default_value;
    const int ci = description_.findCoordinate(s.name);
    s.data_column = ci >= 0 ? columns.value_column[ci] : coordinates_.findColumn(s.name);
    if (s.data_column < 0) {
      missing.push_back(s.name);
      continue;
    }
    // deg -> rad only for Rotational coordinates (§3.4, §7 step 4)
    s.converted = ci >= 0 && columns.scale[ci] != 1.0;
    s.spline = static_cast<int>(used.size());
    used.push_back(s.data_column);
    scale.push_back(s.converted ? columns.scale[ci] : 1.0);
  }
  // columns whose path names a coordinate are not matched (OpenSim matches exact names only)
  const std::vector<std::string>& path_labels = columns.unused_path_labels;
  // OpenSim would solve with every coordinate at its default; that is almost surely not what the
  // user meant, so it is an input error here
  if (used.empty())
    throw ConvertError(file, coordinates_.label_line, "none of the model's " + std::to_string(m.nr()) +
                                    " coordinates is a column of this file (columns: " +
                                    joinNames(coordinates_.labels) + ")" +
                                    (path_labels.empty() ? std::string()
                                                         : "; columns are matched by exact coordinate "
                                                           "name, as OpenSim's ID does, not by path"));
  if (!missing.empty())
    warnings_.push_back("coordinates not in " + file + " are held at their default values (qdot = "
                        "qddot = 0), as OpenSim does: " + joinNames(missing));
  if (!path_labels.empty())
    warnings_.push_back("columns labelled with a path are not used for q (OpenSim matches exact "
                        "coordinate names): " + joinNames(path_labels));

  MatX cols(coordinates_.numRows(), static_cast<Eigen::Index>(used.size()));
  for (size_t c = 0; c < used.size(); ++c) cols.col(static_cast<Eigen::Index>(c)) = coordinates_.data.col(used[c]);
  signal::CoordinateProcessingOptions opt;
  opt.lowpass_cutoff_hz = config_.lowpass_cutoff_hz;
  opt.column_scale = scale;
  try {
    processed_ = signal::processCoordinates(coordinates_.time, cols, opt);
    window_ = processed_.selectWindow(config_.t0, config_.t1);
  } catch (const signal::SignalError& e) {
    throw ConvertError(file, 0, e.what());
  }
  for (const auto& n : processed_.notes) warnings_.push_back(file + ": " + n);
  if (config_.t0 > processed_.time.back() || config_.t1 < processed_.time.front()) {
    std::ostringstream os;
    os << "the time range [" << config_.t0 << ", " << config_.t1 << "] lies outside the data ["
       << processed_.time.front() << ", " << processed_.time.back() << "]; OpenSim solves the "
       << "nearest row only";
    warnings_.push_back(os.str());
  }
}

void InverseDynamicsTool::prepareLoads() {
  if (config_.external_loads_file.empty()) return;
  ExternalLoads el = readExternalLoads(config_.external_loads_file, config_.loads_working_dir);
  checkExternalLoads(el, description_);
  for (const auto& w : el.warnings) warnings_.push_back(config_.external_loads_file + ": " + w);

  loads_ = makeLoadSources(el, description_, build_->body_index, warnings_);
  const Storage& data = el.data;
  // (accumulated resampling times may step a rounding error outside, e.g. -5e-7 s in set F)
  constexpr double kSlack = 1e-6;
  if (!data.time.empty() && numFrames() > 0 &&
      (frameTime(0) < data.time.front() - kSlack || frameTime(numFrames() - 1) > data.time.back() + kSlack))
    warnings_.push_back("the output times extend beyond the external-load data (" + el.datafile_path +
                        "); the loads are extrapolated as OpenSim extrapolates them");
}

// ---------------------------------------------------------------------------------------------
std::vector<std::string> InverseDynamicsTool::outputLabels() const { return idOutputLabels(description_, model()); }

void InverseDynamicsTool::calcInputs(double t, VecX& q, VecX& v, VecX& vdot,
                                     std::vector<IdLoadSample>& loads) const {
  const int nr = model().nr();
  q.resize(nr);
  v.resize(nr);
  vdot.resize(nr);
  double d[3];
  for (int k = 0; k < nr; ++k) {
    const IdCoordinateSource& s = sources_[k];
    if (s.spline < 0) {
      q[k] = s.constant;
      v[k] = vdot[k] = 0.0;
      continue;
    }
    processed_.splines[s.spline].calcDerivatives(t, d);
    q[k] = d[0];
    v[k] = d[1];
    vdot[k] = d[2];
  }
  sampleLoads(loads_, t, loads);
}

Storage InverseDynamicsTool::run(IdEngine& engine, const std::function<void(int, int)>& progress) const {
  Storage out;
  out.name = kIdStorageName;
  out.version = 1;
  out.in_degrees = false;
  out.labels = outputLabels();
  const int n = numFrames(), nr = model().nr();
  out.time.resize(static_cast<size_t>(n));
  out.data.resize(n, nr);
  VecX q, v, vdot, tau;
  std::vector<IdLoadSample> loads;
  for (int k = 0; k < n; ++k) {
    const double t = frameTime(k);
    calcInputs(t, q, v, vdot, loads);
    engine.calcGeneralizedForces(t, q, v, vdot, loads, tau);
    if (!tau.allFinite()) {
      int bad = 0;
      while (bad < nr && std::isfinite(tau[bad])) ++bad;
      std::ostringstream os;
      os << engine.name() << " engine: non-finite generalized force " << out.labels[bad]
         << " at t = " << t;
      throw IdEngineError(os.str());
    }
    out.time[k] = t;
    out.data.row(k) = tau.transpose();
    if (progress) progress(k + 1, n);
  }
  return out;
}

}  // namespace redmax::osim
