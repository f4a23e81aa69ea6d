#include "validation/simulate/prescribe_motion.hpp"

#include <algorithm>
#include <set>
#include <sstream>
#include <stdexcept>

#include "converter/coordinates_file.hpp"
#include "converter/error.hpp"
#include "converter/signal/coordinate_pipeline.hpp"
#include "core/dynamics/constraints/constraint_function.hpp"
#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "validation/simulate/prescribe_markers.hpp"

namespace redmax::validation {

struct MotionPrescription::Splines {
  signal::ProcessedCoordinates processed;  // one spline per prescribed coordinate, q order
};

void MotionPrescription::values(double t, VecX& q, VecX& qdot) const {
  const int n = static_cast<int>(q_index.size());
  q.resize(n);
  qdot.resize(n);
  double d[2];
  for (int k = 0; k < n; ++k) {
    splines->processed.splines[k].calcDerivatives(t, d);
    q[k] = d[0];
    qdot[k] = d[1];
  }
}

MotionPrescription prescribeMotion(SimulationModel& m, const osim::Storage& motion, const std::string& file,
                                   const MotionPrescriptionOptions& options) {
  const osim::ModelDescription& d = m.description;
  const int line = motion.label_line;
  auto fail = [&](const std::string& what) { throw osim::ConvertError(file, line, what); };
  if (motion.numRows() == 0) fail("the motion has no rows");

  // coordinates the model already moves by a constraint cannot take a second prescription
  std::set<std::string> constrained;
  for (const auto& c : d.coordinates)
    if (c.locked || c.prescribed) constrained.insert(c.name);
  for (const auto& c : d.constraints)
    if (c.enforced && !c.dependent_coordinate.empty()) constrained.insert(c.dependent_coordinate);

  std::vector<int> chosen;  // description indices
  if (options.coordinates.empty()) {
    for (size_t k = 0; k < d.coordinates.size(); ++k)
      if (osim::findCoordinateColumn(motion, d.coordinates[k]) >= 0 && !constrained.count(d.coordinates[k].name))
        chosen.push_back(static_cast<int>(k));
    if (chosen.empty()) fail("no column of this file names a free coordinate of the model");
  } else {
    for (const std::string& name : options.coordinates) {
      const int k = d.findCoordinate(name);
      if (k < 0) fail("--prescribe-coordinates: the model has no coordinate '" + name + "'");
      if (osim::findCoordinateColumn(motion, d.coordinates[k]) < 0) fail("no column for coordinate '" + name + "'");
      if (constrained.count(name))
        fail("coordinate '" + name + "' is already locked, prescribed or coupled by the model");
      if (std::find(chosen.begin(), chosen.end(), k) != chosen.end()) fail("coordinate '" + name + "' named twice");
      chosen.push_back(k);
    }
  }
  MotionPrescription p;
  std::vector<std::pair<int, int>> order;  // (core index, description index)
  for (int k : chosen) {
    const int i = k < static_cast<int>(m.build.coordinate_index.size()) ? m.build.coordinate_index[k] : -1;
    if (i < 0) fail("coordinate '" + d.coordinates[k].name + "' is not a coordinate of the built model");
    order.emplace_back(i, k);
  }
  std::sort(order.begin(), order.end());

  MatX cols(motion.numRows(), static_cast<Eigen::Index>(order.size()));
  signal::CoordinateProcessingOptions po;
  po.lowpass_cutoff_hz = options.lowpass_cutoff_hz;
  for (size_t c = 0; c < order.size(); ++c) {
    const osim::CoordinateDesc& cd = d.coordinates[order[c].second];
    cols.col(static_cast<Eigen::Index>(c)) = motion.data.col(osim::findCoordinateColumn(motion, cd));
    po.column_scale.push_back(osim::coordinateScale(motion, cd));
    p.coordinates.push_back(cd.name);
    p.q_index.push_back(order[c].first);
    p.labels.push_back(cd.name + (cd.motion_type == osim::MotionType::Rotational ? "_moment" : "_force"));
  }
  auto splines = std::make_shared<MotionPrescription::Splines>();
  try {
    splines->processed = signal::processCoordinates(motion.time, cols, po);
  } catch (const signal::SignalError& e) {
    fail(e.what());
  }
  for (const auto& n : splines->processed.notes) p.warnings.push_back(file + ": " + n);
  p.t_first = motion.time.front();
  p.t_last = motion.time.back();
  p.splines = splines;

  const Model& model = m.system->model();
  for (size_t c = 0; c < p.q_index.size(); ++c) {
    // the spline is shared by the three callables; the prescription keeps it alive too
    const signal::NaturalSpline* s = &splines->processed.splines[c];
    auto f = makeConstraintFunction1([s, splines](double t) { return s->calcValue(t); },
                                     [s, splines](double t) { return s->calcDerivative(1, t); },
                                     [s, splines](double t) { return s->calcDerivative(2, t); });
    m.system->addConstraint(std::make_shared<PrescribedCoordinate>(model, p.q_index[c], f,
                                                                   "prescribed_" + p.coordinates[c] + "_from_motion"));
  }
  return p;
}

void applyPrescription(const SimulationModel& m, const MotionPrescription& p, State& s) {
  VecX q, qdot;
  p.values(s.t, q, qdot);
  for (size_t c = 0; c < p.q_index.size(); ++c) {
    s.q[p.q_index[c]] = q[static_cast<Eigen::Index>(c)];
    s.qdot[p.q_index[c]] = qdot[static_cast<Eigen::Index>(c)];
  }
  DynamicsWorkspace ws(*m.system);
  m.system->projectPositions(s, ws);
  m.system->projectVelocities(s, ws);
}

PrescribedForceRecorder::PrescribedForceRecorder(const SimulationModel& m, const MotionPrescription& p)
    : m_(m), q_index_(p.q_index), ws_(std::make_shared<DynamicsWorkspace>(*m.system)) {
  table_.name = "Prescribed generalized forces";
  table_.version = 1;
  table_.labels = p.labels;
  table_.data.resize(0, static_cast<Eigen::Index>(p.labels.size()));
}

PrescribedForceRecorder::PrescribedForceRecorder(const SimulationModel& m, const MarkerPrescription& p)
    : m_(m), ws_(std::make_shared<DynamicsWorkspace>(*m.system)) {
  table_.name = "Prescribed marker forces";
  table_.version = 1;
  table_.labels = p.labels;
  table_.data.resize(0, static_cast<Eigen::Index>(p.labels.size()));
  // each marker's rows in the stacked constraints (the System keeps them in the order added)
  marker_row_.assign(p.constraints.size(), -1);
  int row = 0;
  for (const auto& c : m.system->constraints()) {
    for (size_t k = 0; k < p.constraints.size(); ++k)
      if (c.get() == p.constraints[k].get()) marker_row_[k] = row;
    row += c->rows();
  }
  for (int r : marker_row_)
    if (r < 0) throw std::logic_error("PrescribedForceRecorder: a marker's constraint is not in the system");
  peak_force_.assign(p.constraints.size(), 0.0);
  peak_distance_.assign(p.constraints.size(), 0.0);
}

void PrescribedForceRecorder::record(const State& s) {
  m_.system->forwardDynamics(s, *ws_);
  const DynamicsWorkspace& ws = *ws_;
  const Eigen::Index r = table_.data.rows();
  table_.data.conservativeResize(r + 1, Eigen::NoChange);
  if (marker_row_.empty()) {
    const VecX tau = m_.system->prescribedForces(ws);
    for (size_t c = 0; c < q_index_.size(); ++c) table_.data(r, static_cast<Eigen::Index>(c)) = tau[q_index_[c]];
  } else {
    // lambda is the world force at the marker (prescribed_point.hpp); -G^T lambda its generalized force
    VecX tau = VecX::Zero(ws.G.cols());
    Eigen::Index col = 0;
    for (size_t k = 0; k < marker_row_.size(); ++k) {
      const Vec3 force = ws.lambda.segment<3>(marker_row_[k]);
      table_.data.block<1, 3>(r, col) = force.transpose();
      col += 3;
      tau.noalias() -= ws.G.middleRows(marker_row_[k], 3).transpose() * force;
      peak_force_[k] = std::max(peak_force_[k], force.norm());
      peak_distance_[k] = std::max(peak_distance_[k], ws.pos_err.segment<3>(marker_row_[k]).norm());
    }
    table_.data.block(r, col, 1, tau.size()) = tau.transpose();
  }
  table_.time.push_back(s.t);
}

std::function<std::string(const State&, double, double)> PrescribedForceRecorder::check(
    std::function<std::string(const State&, double, double)> previous) {
  return [this, previous](const State& s, double K, double V) -> std::string {
    record(s);
    return previous ? previous(s, K, V) : std::string();
  };
}

}  // namespace redmax::validation
