#include "validation/simulate/prescribe_markers.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/SVD>

#include "converter/error.hpp"
#include "converter/signal/coordinate_pipeline.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::validation {
namespace {

std::string seconds(double t) {
  std::ostringstream os;
  os << t;
  return os.str();
}

// numerical rank of G (rows x ndof), relative to its largest singular value
int numericalRank(const MatX& G) {
  if (G.rows() == 0 || G.cols() == 0) return 0;
  const VecX sv = Eigen::JacobiSVD<MatX>(G).singularValues();
  const double cut = 1e-9 * std::max(1.0, sv.size() > 0 ? sv[0] : 0.0);
  return static_cast<int>((sv.array() > cut).count());
}

}  // namespace

MarkerPrescription prescribeMarkers(SimulationModel& m, const osim::MarkerTable& trc, const std::string& file,
                                    const MarkerPrescriptionOptions& options) {
  const osim::ModelDescription& d = m.description;
  auto fail = [&](int line, const std::string& what) { throw osim::ConvertError(file, line, what); };
  if (trc.numRows() == 0) fail(0, "the marker file has no rows");
  const System& sys = *m.system;
  const Model& model = sys.model();
  if (sys.ndof() != model.nr()) fail(0, "markers cannot be prescribed on a model with hyper-reduced coordinates");

  // the chosen markers: (model marker, file column)
  auto inModel = [&](const std::string& name) {
    for (size_t k = 0; k < d.markers.size(); ++k)
      if (d.markers[k].name == name) return static_cast<int>(k);
    return -1;
  };
  std::vector<std::pair<int, int>> chosen;
  if (options.markers.empty()) {
    for (size_t k = 0; k < d.markers.size(); ++k) {
      const int c = trc.findMarker(d.markers[k].name);
      if (c >= 0) chosen.emplace_back(static_cast<int>(k), c);
    }
    if (chosen.empty())
      fail(trc.label_line, "no marker of this file is in the model's MarkerSet (" + std::to_string(d.markers.size()) +
                               " markers in the model)");
  } else {
    for (const std::string& name : options.markers) {
      const int k = inModel(name);
      if (k < 0) fail(0, "--prescribe-marker-names: the model has no marker '" + name + "' in its MarkerSet");
      const int c = trc.findMarker(name);
      if (c < 0) fail(trc.label_line, "no column for marker '" + name + "'");
      for (const auto& [k2, c2] : chosen)
        if (k2 == k) fail(0, "marker '" + name + "' named twice");
      chosen.emplace_back(k, c);
    }
  }

  // the run's window and the rows that bracket it
  MarkerPrescription p;
  p.t_first = trc.time.front();
  p.t_last = trc.time.back();
  const double a = std::isnan(options.t_begin) ? p.t_first : options.t_begin;
  const double b = std::isnan(options.t_end) ? p.t_last : options.t_end;
  if (a < p.t_first - 1e-9 || b > p.t_last + 1e-9 || b < a) {
    std::ostringstream os;
    os << "the run spans [" << a << ", " << b << "] s, outside the marker file's [" << p.t_first << ", " << p.t_last
       << "] s (the splines would extrapolate)";
    fail(0, os.str());
  }
  const int n = trc.numRows();
  int lo = 0, hi = 0;
  trc.bracketRows(a, b, lo, hi);

  p.free_coordinates = model.nr() - sys.numConstraintRows();
  for (const auto& [k, c] : chosen) {
    const osim::MarkerDesc& mk = d.markers[k];
    const CoreMarker cm = findCoreMarker(m, mk.name);
    const int body = cm.body;
    if (body < 0)  // a model error: named at the marker's line of the .osim
      throw osim::ConvertError(d.source_file, mk.line,
                               "marker '" + mk.name + "' is on '" + mk.body +
                                   "', which has no moving body in the core model (ground, or a loop's split body)");
    // no gap where the run needs the marker; then as many gap-free rows around it as the file has
    for (int r = lo; r <= hi; ++r)
      if (!trc.present(r, c))
        fail(trc.first_data_line > 0 ? trc.first_data_line + r : 0,
             "marker '" + mk.name + "' has a gap at t = " + seconds(trc.time[r]) + " s, inside the run's window [" +
                 seconds(a) + ", " + seconds(b) + "] s (the splines do not bridge gaps: fill it or shorten the run)");
    int r0 = lo, r1 = hi;
    while (r0 > 0 && trc.present(r0 - 1, c)) --r0;
    while (r1 + 1 < n && trc.present(r1 + 1, c)) ++r1;
    const std::vector<double> time(trc.time.begin() + r0, trc.time.begin() + r1 + 1);
    const MatX cols = trc.data.block(r0, 3 * c, r1 - r0 + 1, 3);
    signal::CoordinateProcessingOptions po;
    po.lowpass_cutoff_hz = options.lowpass_cutoff_hz;
    auto splines = std::make_shared<signal::ProcessedCoordinates>();
    try {
      *splines = signal::processCoordinates(time, cols, po);
    } catch (const signal::SignalError& e) {
      fail(trc.label_line, "marker '" + mk.name + "': " + e.what());
    }
    for (const auto& note : splines->notes) p.warnings.push_back(file + ": marker '" + mk.name + "': " + note);
    // x_p, xdot_p, xddot_p: each component's spline and its derivatives (the trajectory owns them)
    PointTrajectory traj = [splines](double t) {
      PointSample s;
      double v[3];
      for (int i = 0; i < 3; ++i) {
        splines->splines[i].calcDerivatives(t, v);
        s.x[i] = v[0];
        s.v[i] = v[1];
        s.a[i] = v[2];
      }
      return s;
    };
    const Vec3 point = cm.point;
    auto constraint =
        std::make_shared<PrescribedPoint>(model, body, point, std::move(traj), "prescribed_marker_" + mk.name);
    m.system->addConstraint(constraint);
    p.markers.push_back(mk.name);
    p.body.push_back(body);
    p.point.push_back(point);
    p.constraints.push_back(constraint);
    for (const char* axis : {"_fx", "_fy", "_fz"}) p.labels.push_back(mk.name + axis);
  }
  p.rows = 3 * static_cast<int>(p.markers.size());
  for (const auto& w : trc.warnings) p.warnings.push_back(w);

  // the generalized forces the markers take, one column per coordinate, named as `redmax id` does
  std::vector<std::string> coord_labels(model.nr());
  for (int i = 0; i < model.nr(); ++i) coord_labels[i] = m.coordinate_names[i] + "_force";
  for (size_t k = 0; k < d.coordinates.size(); ++k) {
    const int i = k < m.build.coordinate_index.size() ? m.build.coordinate_index[k] : -1;
    if (i >= 0 && d.coordinates[k].motion_type == osim::MotionType::Rotational)
      coord_labels[i] = d.coordinates[k].name + "_moment";
  }
  p.labels.insert(p.labels.end(), coord_labels.begin(), coord_labels.end());
  return p;
}

MarkerStart applyMarkerPrescription(const SimulationModel& m, const MarkerPrescription& p, const std::string& file,
                                    State& s, double tolerance_m) {
  const System& sys = *m.system;
  DynamicsWorkspace ws(sys);
  sys.projectPositions(s, ws);
  sys.projectVelocities(s, ws);
  sys.calcMassAndForce(s, ws);
  sys.calcConstraints(s, ws);

  // rows of the markers in the stacked constraints; the others
  std::vector<int> first_row(p.constraints.size(), -1);
  std::vector<int> other_rows;
  int row = 0;
  for (const auto& c : sys.constraints()) {
    bool marker = false;
    for (size_t k = 0; k < p.constraints.size(); ++k)
      if (c.get() == p.constraints[k].get()) first_row[k] = row, marker = true;
    if (!marker)
      for (int r = 0; r < c->rows(); ++r) other_rows.push_back(row + r);
    row += c->rows();
  }
  MarkerStart start;
  for (size_t k = 0; k < p.constraints.size(); ++k) {
    const Vec3 target = p.target(static_cast<int>(k), s.t).x;
    const Vec3 at = transformPoint(ws.sk.E_wi[p.body[k]], p.point[k]);
    start.distance.push_back((target - at).norm());
  }
  for (size_t k = 0; k < p.constraints.size(); ++k)
    if (!(start.distance[k] <= tolerance_m)) {
      std::ostringstream os;
      os << "marker '" << p.markers[k] << "' is " << start.distance[k] << " m from its trajectory at t = " << s.t
         << " s after solving the initial coordinates (more than " << tolerance_m
         << " m: the model cannot reach it from its initial pose; " << p.rows << " marker rows on "
         << p.free_coordinates << " free coordinates)";
      throw osim::ConvertError(file, 0, os.str());
    }
  MatX others(static_cast<Eigen::Index>(other_rows.size()), ws.G.cols());
  for (size_t r = 0; r < other_rows.size(); ++r) others.row(static_cast<Eigen::Index>(r)) = ws.G.row(other_rows[r]);
  start.independent_rows = numericalRank(ws.G) - numericalRank(others);
  return start;
}

}  // namespace redmax::validation
