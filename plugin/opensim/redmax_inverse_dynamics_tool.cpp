#include "plugin/opensim/redmax_inverse_dynamics_tool.hpp"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include <OpenSim/Common/ComponentPath.h>
#include <OpenSim/Common/Constant.h>
#include <OpenSim/Common/GCVSplineSet.h>
#include <OpenSim/Common/IO.h>
#include <OpenSim/Common/Storage.h>
#include <OpenSim/Simulation/InverseDynamicsSolver.h>
#include <OpenSim/Simulation/Model/Model.h>
#include <OpenSim/Simulation/SimulationUtilities.h>

#include "converter/error.hpp"
#include "converter/osim_reader.hpp"
#include "plugin/opensim/matter_muscle_inertia.hpp"

namespace redmax::opensim {

namespace {

namespace fs = std::filesystem;

// a value or derivative of one coordinate function, evaluated as OpenSim's FunctionSet does
double evaluateFunction(const OpenSim::Function& f, int order, double t) {
  const SimTK::Vector arg(1, t);
  if (order == 0) return f.calcValue(arg);
  return f.calcDerivative(std::vector<int>(static_cast<size_t>(order), 0), arg);
}

// "FILE: message" as an OpenSim exception (opensim-cmd prints what() and exits 1)
[[noreturn]] void fail(const std::string& file, const std::string& message) {
  throw OpenSim::Exception((file.empty() ? std::string() : file + ": ") + message);
}

// the setup's folder ("" = the current directory)
std::string setupFolder(const std::string& document) {
  if (document.empty()) return "";
  return fs::absolute(fs::path(document)).parent_path().string();
}

// a path from the setup resolved against `base` (absolute paths stay as they are)
std::string resolveAgainst(const std::string& base, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute() || base.empty()) return path;
  return (fs::path(base) / path).lexically_normal().string();
}

bool unassigned(const std::string& s) { return s.empty() || s == "Unassigned"; }

}  // namespace

RedmaxInverseDynamicsTool::RedmaxInverseDynamicsTool() { constructProperties(); }

RedmaxInverseDynamicsTool::RedmaxInverseDynamicsTool(const std::string& setup_file)
    : OpenSim::InverseDynamicsTool(setup_file, false) {
  constructProperties();
  updateFromXMLDocument();
}

void RedmaxInverseDynamicsTool::constructProperties() {
  constructProperty_muscle_mass("none");
  constructProperty_muscles("all");
  constructProperty_mass_points(20);
  constructProperty_specific_tension(osim::kDefaultSpecificTension);
  constructProperty_muscle_density(osim::kDefaultMuscleDensity);
  constructProperty_transfer_body("");
  constructProperty_transfer_fraction(0.0);
  constructProperty_full_precision(false);
}

osim::MuscleMassOptions RedmaxInverseDynamicsTool::muscleMassOptions() const {
  osim::MuscleMassOptions o;
  const std::string& source = get_muscle_mass();
  if (source != "none" && source != "physiological" && source != "transfer")
    throw std::invalid_argument("muscle_mass must be none, physiological or transfer, got '" + source + "'");
  o.source = osim::parseMuscleMassSource(source);
  o.muscles = get_muscles();
  o.mass_points = get_mass_points();
  o.specific_tension = get_specific_tension();
  o.density = get_muscle_density();
  o.transfer_body = get_transfer_body();
  o.transfer_fraction = get_transfer_fraction();
  if (o.mass_points < 1) throw std::invalid_argument("mass_points must be >= 1, got " + std::to_string(o.mass_points));
  if (!(o.specific_tension > 0.0) || !std::isfinite(o.specific_tension))
    throw std::invalid_argument("specific_tension must be a positive number of Pa");
  if (!(o.density > 0.0) || !std::isfinite(o.density))
    throw std::invalid_argument("muscle_density must be a positive number of kg/m^3");
  if (o.source == osim::MuscleMassOptions::Source::Transfer) {
    if (o.transfer_body.empty()) throw std::invalid_argument("muscle_mass transfer needs transfer_body");
    if (!(o.transfer_fraction >= 0.0 && o.transfer_fraction < 1.0))
      throw std::invalid_argument("transfer_fraction must be in [0, 1)");
  }
  return o;
}

bool RedmaxInverseDynamicsTool::run() {
  const std::string setup = getDocumentFileName();
  const std::string where = setup.empty() ? getName() : setup;
  osim::MuscleMassOptions options;
  try {
    options = muscleMassOptions();
  } catch (const std::invalid_argument& e) {
    fail(where, e.what());
  }
  const bool with_mass = options.source != osim::MuscleMassOptions::Source::None;
  if (_jointsForReportingBodyForces.getSize() > 0)
    OpenSim::log_warn("RedmaxInverseDynamicsTool: joints_to_report_body_forces is not supported; no body forces are written");

  // paths relative to the setup file's folder (docs/opensim_compatibility.md §7), for every file
  const std::string base = setupFolder(setup);
  const std::string model_file = resolveAgainst(base, _modelFileName);
  const std::string coordinates_file = resolveAgainst(base, _coordinatesFileName);
  if (unassigned(_modelFileName)) fail(where, "no model_file");
  if (unassigned(_coordinatesFileName)) fail(where, "no coordinates_file");
  std::string results_dir = get_results_directory();
  if (results_dir.empty()) results_dir = ".";
  results_dir = resolveAgainst(base, results_dir);
  const std::string out_name = unassigned(_outputGenForceFileName) ? "inverse_dynamics.sto" : _outputGenForceFileName;
  output_path_ = fs::path(out_name).is_absolute() ? out_name : (fs::path(results_dir.empty() ? "." : results_dir) / out_name).string();
  // OpenSim reads the external loads' data relative to the working directory: the setup folder
  OpenSim::IO::CwdChanger cwd = base.empty() ? OpenSim::IO::CwdChanger::noop() : OpenSim::IO::CwdChanger::changeTo(base);

  std::unique_ptr<OpenSim::Model> model;
  try {
    model = std::make_unique<OpenSim::Model>(model_file);
  } catch (const std::exception& e) {
    fail(model_file, std::string("cannot read the model: ") + e.what());
  }
  model->finalizeFromProperties();
  try {
    createExternalLoads(_externalLoadsFileName, *model);
  } catch (const std::exception& e) {
    fail(_externalLoadsFileName, std::string("cannot read the external loads: ") + e.what());
  }
  SimTK::State* s = &model->initSystem();

  // the coordinates, processed as OpenSim's InverseDynamicsTool processes them (§7 steps 2-5)
  std::unique_ptr<OpenSim::Storage> coords;
  try {
    coords = std::make_unique<OpenSim::Storage>(coordinates_file);
  } catch (const std::exception& e) {
    fail(coordinates_file, std::string("cannot read the coordinates: ") + e.what());
  }
  if (coords->getSize() == 0) fail(coordinates_file, "the coordinates file has no rows");
  if (_lowpassCutoffFrequency >= 0) {
    coords->pad(coords->getSize() / 2);
    coords->lowpassIIR(_lowpassCutoffFrequency);
  }
  if (coords->isInDegrees()) model->getSimbodyEngine().convertDegreesToRadians(*coords);
  OpenSim::GCVSplineSet splines(5, coords.get());

  // q and u slots -> coordinates, from the state variable names /.../<coordinate>/value|speed
  auto mapSlots = [&](const SimTK::State& st, std::vector<int>& coord_of_q, std::vector<int>& coord_of_u,
                      std::vector<const OpenSim::Coordinate*>& tree_coords) {
    tree_coords.clear();
    for (const auto& c : model->getCoordinatesInMultibodyTreeOrder()) tree_coords.push_back(c.get());
    const int nq = st.getNQ(), nu = st.getNU();
    coord_of_q.assign(static_cast<size_t>(nq), -1);
    coord_of_u.assign(static_cast<size_t>(nu), -1);
    for (const auto& [name, index] : OpenSim::createSystemYIndexMap(*model)) {
      if (index >= nq + nu) continue;
      const OpenSim::ComponentPath path(name);
      const std::string last = path.getComponentName();
      const std::string coord = path.getSubcomponentNameAtLevel(path.getNumPathLevels() - 2);
      for (int i = 0; i < static_cast<int>(tree_coords.size()); ++i) {
        if (tree_coords[i]->getName() != coord) continue;
        if (last == "value") coord_of_q[index] = i;
        if (last == "speed") coord_of_u[index - nq] = i;
        break;
      }
    }
  };
  std::vector<int> coord_of_q, coord_of_u;
  std::vector<const OpenSim::Coordinate*> tree_coords;
  mapSlots(*s, coord_of_q, coord_of_u, tree_coords);

  // one function per coordinate (tree order): its spline by exact name, else its default value
  std::vector<std::unique_ptr<OpenSim::Function>> constants;
  std::vector<const OpenSim::Function*> coord_fn(tree_coords.size(), nullptr);
  for (size_t i = 0; i < tree_coords.size(); ++i) {
    const std::string& name = tree_coords[i]->getName();
    if (splines.contains(name)) {
      coord_fn[i] = &splines.get(name);
    } else {
      constants.push_back(std::make_unique<OpenSim::Constant>(tree_coords[i]->getDefaultValue()));
      coord_fn[i] = constants.back().get();
      OpenSim::log_info("RedmaxInverseDynamicsTool: coordinate file does not contain coordinate '{}'. Assuming default value.", name);
    }
  }

  // output frames: findIndex(start) .. findIndex(end) of the processed rows (§7 step 7)
  const double first_time = coords->getFirstTime(), last_time = coords->getLastTime();
  const double start_time = std::max(first_time, _timeRange[0]);
  const double final_time = std::min(last_time, _timeRange[1]);
  const int start_index = coords->findIndex(start_time), final_index = coords->findIndex(final_time);
  std::vector<double> times;
  for (int i = start_index; i <= final_index; ++i) times.push_back(coords->getStateVector(i)->getTime());

  // muscle mass: redmax's plan on the same file; the bodies' new mass properties go into the
  // OpenSim model, whose system is then rebuilt
  std::unique_ptr<osim::MuscleMassModel> mass;
  plan_ = osim::MuscleMassPlan();
  if (with_mass) {
    try {
      const osim::ModelDescription description = osim::readOsimModel(model_file);
      osim::BuildOptions bo;
      bo.simbody_compat = true;
      bo.constraints = false;
      bo.muscles = true;  // they carry the mass; the model is built once and then edited
      osim::BuildResult built = osim::buildCoreModel(description, bo);
      // top:K ranks over the output frames: q of each frame in the core's q order
      std::vector<VecX> samples;
      if (options.muscles.rfind("top:", 0) == 0) {
        const Model& order = built.model.skeleton();
        for (double t : times) {
          VecX q(order.nr());
          for (int k = 0; k < order.nr(); ++k) {
            const std::string& name = order.coordinates()[k].name;
            q[k] = splines.contains(name) ? evaluateFunction(splines.get(name), 0, t)
                                          : order.coordinates()[k].default_value;
          }
          samples.push_back(q);
        }
      }
      mass = std::make_unique<osim::MuscleMassModel>(
          osim::addMuscleMass(description, std::move(built), options, samples));
    } catch (const osim::ConvertError& e) {
      throw OpenSim::Exception(std::string("muscle mass: ") + e.what());
    } catch (const std::exception& e) {
      fail(model_file, std::string("muscle mass: ") + e.what());
    }
    plan_ = mass->plan;
    for (const osim::BodyMassChange& b : plan_.bodies) {
      if (!model->getBodySet().contains(b.name)) fail(model_file, "muscle mass: no body '" + b.name + "' in the OpenSim model");
      OpenSim::Body& body = model->updBodySet().get(b.name);
      const Mat3& I = b.inertia_after;
      body.setMass(b.mass_after);
      body.setMassCenter(SimTK::Vec3(b.com_after.x(), b.com_after.y(), b.com_after.z()));
      body.setInertia(SimTK::Inertia(SimTK::Vec3(I(0, 0), I(1, 1), I(2, 2)), SimTK::Vec3(I(0, 1), I(0, 2), I(1, 2))));
    }
    OpenSim::log_info("RedmaxInverseDynamicsTool: muscle mass {}:\n{}", osim::toString(options.source),
                      osim::describeMuscleMass(plan_));
    s = &model->initSystem();
    mapSlots(*s, coord_of_q, coord_of_u, tree_coords);
  }

  // u slot -> coordinate function (the solver puts s'(t) in u and s''(t) in udot, §7 step 7)
  const int nq = s->getNQ(), nu = s->getNU();
  for (int j = 0; j < nu; ++j)
    if (coord_of_u[j] < 0) fail(model_file, "generalized speed " + std::to_string(j) + " belongs to no coordinate");
  disableModelForces(*model, *s, _excludedForces);

  // the mass points on OpenSim's own Simbody system
  std::unique_ptr<MatterMuscleInertia> inertia;
  if (with_mass) {
    const Model& core = mass->build.model;
    MatterMap map;
    map.mobod_of_body.resize(static_cast<size_t>(core.nb()));
    for (int b = 0; b < core.nb(); ++b)
      if (model->getBodySet().contains(core.bodies()[b].name))
        map.mobod_of_body[b] = model->getBodySet().get(core.bodies()[b].name).getMobilizedBodyIndex();
    map.q_of_coordinate.assign(static_cast<size_t>(core.nr()), -1);
    const SimTK::SimbodyMatterSubsystem& matter = model->getMatterSubsystem();
    for (int k = 0; k < core.nr(); ++k) {
      const std::string& name = core.coordinates()[k].name;
      if (!model->getCoordinateSet().contains(name)) continue;
      const OpenSim::Coordinate& c = model->getCoordinateSet().get(name);
      map.q_of_coordinate[k] = matter.getMobilizedBody(c.getBodyIndex()).getFirstQIndex(*s) + c.getMobilizerQIndex();
    }
    const SimTK::Vec3 g = model->getGravity();
    try {
      inertia = std::make_unique<MatterMuscleInertia>(matter, std::move(map), core, mass->build.model.muscles(),
                                                      Vec3(g[0], g[1], g[2]));
    } catch (const std::exception& e) {
      fail(model_file, std::string("muscle mass: ") + e.what());
    }
    OpenSim::log_info("RedmaxInverseDynamicsTool: {} muscles carry {:.6g} kg in mass points",
                      inertia->numMassiveMuscles(), inertia->totalMass());
  }

  // solve every frame: OpenSim's residual plus the mass points' generalized forces
  OpenSim::InverseDynamicsSolver solver(*model);
  result_ = osim::Storage();
  result_.name = "Inverse Dynamics Generalized Forces";
  result_.version = 1;
  result_.in_degrees = false;
  for (const OpenSim::Coordinate* c : tree_coords)
    result_.labels.push_back(c->getName() + (c->getMotionType() == OpenSim::Coordinate::Rotational ? "_moment" : "_force"));
  const int nt = static_cast<int>(times.size());
  const int ncol = static_cast<int>(result_.labels.size());
  if (ncol != nu) fail(model_file, "the model has " + std::to_string(nu) + " generalized speeds but " +
                                       std::to_string(ncol) + " coordinates; not supported");
  result_.time = times;
  result_.data.resize(nt, ncol);
  SimTK::Vector udot(nu), f_u;
  for (int i = 0; i < nt; ++i) {
    const double t = times[i];
    SimTK::State& st = *s;
    st.updTime() = t;
    SimTK::Vector& q = st.updQ();
    SimTK::Vector& u = st.updU();
    for (int j = 0; j < nq; ++j) q[j] = coord_of_q[j] >= 0 ? evaluateFunction(*coord_fn[coord_of_q[j]], 0, t) : 0.0;
    for (int j = 0; j < nu; ++j) {
      u[j] = evaluateFunction(*coord_fn[coord_of_u[j]], 1, t);
      udot[j] = evaluateFunction(*coord_fn[coord_of_u[j]], 2, t);
    }
    SimTK::Vector tau = solver.solve(st, udot);
    if (inertia) {
      try {
        inertia->calcGeneralizedForces(st, udot, f_u);
      } catch (const std::exception& e) {
        std::ostringstream os;
        os << "muscle mass at t = " << t << ": " << e.what();
        fail(coordinates_file, os.str());
      }
      tau += f_u;
    }
    for (int j = 0; j < ncol; ++j) {
      if (!std::isfinite(tau[j])) {
        std::ostringstream os;
        os << "non-finite generalized force " << result_.labels[j] << " at t = " << t;
        fail(coordinates_file, os.str());
      }
      result_.data(i, j) = tau[j];
    }
  }
  // the loads belong to this run's model, which goes away with it
  _modelExternalLoads.release();

  // written as `redmax id` writes it, atomically; OpenSim creates the results directory
  osim::StorageWriteOptions wo;
  if (get_full_precision()) {
    wo.scientific = true;
    wo.decimals = 16;
  }
  try {
    const fs::path parent = fs::path(output_path_).parent_path();
    std::error_code ec;
    if (!parent.empty()) fs::create_directories(parent, ec);
    osim::writeStorage(output_path_, result_, wo);
  } catch (const osim::ConvertError& e) {
    throw OpenSim::Exception(e.what());
  }
  OpenSim::log_info("RedmaxInverseDynamicsTool: {} frames, {} coordinates -> {}", nt, ncol, output_path_);
  return true;
}

}  // namespace redmax::opensim
