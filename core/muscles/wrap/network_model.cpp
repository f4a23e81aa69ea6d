#include "core/muscles/wrap/network_model.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/geometry/constructions.hpp"
#include "core/geometry/dual.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/muscles/path.hpp"

namespace redmax {

namespace {

// y, dy/dX and (with_jdot) its derivative along ws.Xdot at the inputs ws.X
void evalNetwork(const Mlp& net, const NetworkWrapOptions& options, bool with_jdot, NetworkWrapWorkspace& ws) {
  if (!with_jdot)
    net.calcJacobian(ws.X, ws.Y, ws.J, ws.mlp);
  else if (options.fd_jdot)
    net.calcJacobianDotFd(ws.X, ws.Xdot, options.fd_eps > 0.0 ? options.fd_eps : 1e-6, ws.Y, ws.J, ws.Jdot, ws.mlp);
  else
    net.calcJacobianDot(ws.X, ws.Xdot, ws.Y, ws.J, ws.Jdot, ws.mlp);
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Where a quadrant changes OpenSim's path from the unconstrained one (which the networks learnt).
// Cylinders: a forced wrap round the active side (neither end active, or the ends on opposite
// sides of the quadrant plane with the line's point nearest the axis, the "foot", on the inactive
// side), or a contact (d > 0) whose foot lies on the inactive side, which the library also wraps
// round the active side. The same split as the smooth model's (smooth.cpp smoothSetup), on plain
// doubles. Spheres: the library's quadrant choice is discrete (core/geometry/sphere.cpp), so it is
// asked directly: the path changes where the library with the quadrant and without it disagree
// (wrap or not, the tangent points, the far side).
bool sphereQuadrantChangesPath(const WrapSurface& s, const Vec3& a, const Vec3& b) {
  WrapSurface free = s;
  free.quadrant_axis = -1;
  free.quadrant_sign = 0;
  const WrapResult q = calcWrap(s, a, b), u = calcWrap(free, a, b);
  if (q.wraps() != u.wraps()) return true;
  if (!q.wraps()) return false;
  const double tol = 1e-12 * s.radius;
  return q.far_side || (q.r1 - u.r1).norm() > tol || (q.r2 - u.r2).norm() > tol;
}

bool quadrantChangesPath(const WrapSurface& s, const Vec3& a, const Vec3& b) {
  if (s.quadrant_sign == 0 || s.quadrant_axis < 0) return false;
  if (s.type == WrapType::Sphere) return sphereQuadrantChangesPath(s, a, b);
  if (s.type != WrapType::Cylinder) return false;
  const int axis = s.quadrant_axis, sign = s.quadrant_sign;
  auto dsign = [](double v) { return v >= 0.0 ? 1 : -1; };
  const Vec3 u = b - a;
  const bool s1 = dsign(a[axis]) == sign, s2 = dsign(b[axis]) == sign;
  const double uu = u.head<2>().squaredNorm();
  const double near_axis = a[axis] + (uu > 0.0 ? -a.head<2>().dot(u.head<2>()) / uu : 0.0) * u[axis];
  const bool forced = (!s1 && !s2) || (dsign(a[axis]) != dsign(b[axis]) && dsign(near_axis) != sign);
  return forced || (calcWrapPenetration(s, a, b) > 0.0 && !(sign * near_axis > 0.0));
}

// Where the cylinder's finite length changes the path the networks learnt (an effectively infinite
// cylinder): the library and the smooth model give no wrap when both tangent points lie beyond the
// ends (|z| > L/2), and only then; an end point beyond an end alone changes nothing. Only asked
// when an end point lies beyond an end (otherwise the tangent points lie within).
bool finiteLengthChangesPath(const WrapSurface& s, const Vec3& p1, const Vec3& p2) {
  if (s.type != WrapType::Cylinder) return false;
  if (std::abs(p1.z()) <= 0.5 * s.length && std::abs(p2.z()) <= 0.5 * s.length) return false;
  detail::V3<double> r1, r2;
  bool long_wrap = false;
  return !detail::cylinderTangentPoints(s.radius, s.length, s.quadrant_axis, s.quadrant_sign,
                                        detail::constant<double>(p1), detail::constant<double>(p2), r1, r2, long_wrap);
}

void checkEndPoints(const WrapSurface& s, const Vec3& p1, const Vec3& p2) {
  if (!p1.allFinite() || !p2.allFinite() || p1 == p2)
    throw std::invalid_argument("network wrap: degenerate end points");
  if (s.contains(p1) || s.contains(p2)) throw std::invalid_argument("network wrap: an end point lies inside the surface");
}

}  // namespace

WrapNetworkMap wrapNetworkMap(const Mlp& net) {
  WrapNetworkMap m;
  const auto it = net.meta.find("wrap_map");
  if (it == net.meta.end()) return m;
  std::istringstream is(it->second);
  std::string kind, extra;
  double C = 0.0;
  if (!(is >> kind) || kind != "compact" || !(is >> C) || (is >> extra) || !std::isfinite(C) || !(C > 0.0))
    throw std::invalid_argument("meta wrap_map '" + it->second + "': expected 'compact C' with a number C > 0");
  m.compact = C;
  return m;
}

std::string formatCompactWrapMap(double C) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "compact %.17g", C);
  return buf;
}

Vec3 calcCompactWrapInput(const Vec3& q, double C, Mat3* M, const Vec3* qdot, Mat3* Mdot) {
  const double r = q.norm();
  const double g = 1.0 / (1.0 + r / C);
  if (r == 0.0) {  // du/dq = I there (the second derivative has no limit; no end point sits there)
    if (M) M->setIdentity();
    if (Mdot) Mdot->setZero();
    return q;
  }
  // M = g I - h q q^T with h = g^2 / (C r)
  const double h = g * g / (C * r);
  if (M) *M = g * Mat3::Identity() - h * q * q.transpose();
  if (Mdot && qdot) {
    const double rdot = q.dot(*qdot) / r;
    const double gdot = -g * g * rdot / C;
    const double hdot = 2.0 * g * gdot / (C * r) - g * g * rdot / (C * r * r);
    *Mdot = gdot * Mat3::Identity() - hdot * q * q.transpose() - h * (*qdot * q.transpose() + q * qdot->transpose());
  } else if (Mdot) {
    Mdot->setZero();
  }
  return g * q;
}

Vec3 calcCompactWrapInputInverse(const Vec3& u, double C) { return u / (1.0 - u.norm() / C); }

int wrapInputSize(WrapType type) {
  switch (type) {
    case WrapType::Cylinder:
    case WrapType::Sphere: return 8;
    case WrapType::Ellipsoid: return 10;
    case WrapType::Torus: return 9;
  }
  return 0;
}

WrapSurface makeWrapSurfaceFromInput(WrapType type, const VecX& in) {
  switch (type) {
    case WrapType::Cylinder: return WrapSurface::makeCylinder(in[7], 1000.0 * in[7]);
    case WrapType::Sphere: return WrapSurface::makeSphere(in[7]);
    case WrapType::Ellipsoid: return WrapSurface::makeEllipsoid(Vec3(in[7], in[8], in[9]));
    case WrapType::Torus: return WrapSurface::makeTorus(in[7], in[8]);
  }
  return {};
}

std::string toString(NetworkWrapFallback why) {
  switch (why) {
    case NetworkWrapFallback::None: return "network";
    case NetworkWrapFallback::NoNetwork: return "no network";
    case NetworkWrapFallback::SurfaceType: return "network trained for another surface type";
    case NetworkWrapFallback::Quadrant: return "the quadrant changes the path (a wrap round the active side, or none)";
    case NetworkWrapFallback::FiniteLength: return "both tangent points beyond the cylinder's ends";
    case NetworkWrapFallback::OutsideBox: return "outside the training box";
  }
  return "?";
}

std::string NetworkWrapEval::describe(const Mlp* net) const {
  if (fallback != NetworkWrapFallback::OutsideBox || !net || input < 0 || input >= net->inputs()) return toString(fallback);
  const std::string name =
      input < static_cast<int>(net->input_names.size()) ? net->input_names[input] : "#" + std::to_string(input);
  std::string s = "input " + name + " = " + num(value) + " (size units) outside the training box [" +
                  num(net->input_min[input]) + ", " + num(net->input_max[input]) + "]";
  if (point >= 0) s += " at mass point " + std::to_string(point);
  return s;
}

std::string networkWrapUnsupportedReason(const Mlp& net) {
  if (net.inputs() != 8 || net.outputs() != 3)
    return "a wrap network maps 8 inputs (origin, insertion, alpha, radius) to 3 outputs, this one maps " +
           std::to_string(net.inputs()) + " to " + std::to_string(net.outputs());
  if (net.input_min.size() != 8 || net.input_max.size() != 8) return "the network stores no training box";
  try {
    wrapNetworkMap(net);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

std::string neuralWrapUnsupportedReason(const Mlp* net, const WrapSurface& surface) {
  if (!net) return "no wrap network was given (WrapMassOptions::network)";
  std::string why = networkWrapUnsupportedReason(*net);
  if (!why.empty()) return why;
  // the fallback must exist for every configuration
  why = smoothWrapUnsupportedReason(surface);
  if (!why.empty()) return why + " (the network model falls back to the smooth model)";
  return "";
}

NetworkWrapEval calcNetworkWrapModel(const Mlp* net, const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                     const Vec3& p1dot, const Vec3& p2dot, const std::vector<double>& alphas,
                                     bool with_jdot, WrapMassPoints& out, NetworkWrapWorkspace& ws,
                                     const NetworkWrapOptions& options, const std::vector<double>& alphadots,
                                     std::vector<Vec3>* x_alpha, std::vector<Vec3>* x_alphadot) {
  const std::string why = smoothWrapUnsupportedReason(surface);
  if (!why.empty()) throw std::invalid_argument("network wrap: " + why);
  if (net) {
    const std::string bad = networkWrapUnsupportedReason(*net);
    if (!bad.empty()) throw std::invalid_argument("network wrap: " + bad);
  }
  checkEndPoints(surface, p1, p2);
  const int n = static_cast<int>(alphas.size());
  if (!alphadots.empty() && static_cast<int>(alphadots.size()) != n)
    throw std::invalid_argument("network wrap: alphadots must be empty or one per fraction");
  auto alphadot = [&](int k) { return with_jdot && !alphadots.empty() ? alphadots[k] : 0.0; };
  out.x.resize(n);
  out.J.resize(n);
  out.Jdot.resize(n);
  if (x_alpha) x_alpha->resize(n);
  if (x_alphadot) x_alphadot->resize(n);

  // which model: checked on every call [D Sec. 6.2.7]
  NetworkWrapEval ev;
  if (!net) {
    ev.fallback = NetworkWrapFallback::NoNetwork;
  } else if (auto it = net->meta.find("surface"); it != net->meta.end() && it->second != wrapTypeName(surface.type)) {
    ev.fallback = NetworkWrapFallback::SurfaceType;
  } else if (surface.type != WrapType::Cylinder && surface.type != WrapType::Sphere) {
    ev.fallback = NetworkWrapFallback::SurfaceType;  // networks take one radius: cylinders and spheres
  } else if (quadrantChangesPath(surface, p1, p2)) {
    ev.fallback = NetworkWrapFallback::Quadrant;
  } else if (finiteLengthChangesPath(surface, p1, p2)) {
    ev.fallback = NetworkWrapFallback::FiniteLength;
  } else {
    // scaled inputs (size units, radius 1; through the compact map when the file declares it) and
    // the box test on each of them
    const double c = 1.0 / surface.radius;
    const WrapNetworkMap map = wrapNetworkMap(*net);
    Vec3 u1 = c * p1, u2 = c * p2;
    if (map.isCompact()) {
      u1 = calcCompactWrapInput(c * p1, map.compact);
      u2 = calcCompactWrapInput(c * p2, map.compact);
    }
    ws.X.resize(8, n);
    for (int k = 0; k < n; ++k) ws.X.col(k) << u1, u2, alphas[k], 1.0;
    for (int k = 0; k < n && ev.usedNetwork(); ++k)
      for (int i = 0; i < 8; ++i) {
        const double v = ws.X(i, k);
        if (!(v >= net->input_min[i] && v <= net->input_max[i])) {
          ev = {NetworkWrapFallback::OutsideBox, i, v, k};
          break;
        }
      }
  }

  if (ev.usedNetwork() && wrapNetworkMap(*net).isCompact()) {
    // displacement from the straight line over compact inputs (header)
    const double R = surface.radius, c = 1.0 / R, C = wrapNetworkMap(*net).compact;
    const Vec3 q1 = c * p1, q2 = c * p2, q1d = c * p1dot, q2d = c * p2dot;
    Mat3 M1, M2, M1d, M2d;
    calcCompactWrapInput(q1, C, &M1, with_jdot ? &q1d : nullptr, &M1d);
    calcCompactWrapInput(q2, C, &M2, with_jdot ? &q2d : nullptr, &M2d);
    if (with_jdot) {
      const Vec3 u1d = M1 * q1d, u2d = M2 * q2d;
      ws.Xdot.resize(8, n);
      for (int k = 0; k < n; ++k) ws.Xdot.col(k) << u1d, u2d, alphadot(k), 0.0;
    }
    evalNetwork(*net, options, with_jdot, ws);
    const Mat3 I = Mat3::Identity();
    for (int k = 0; k < n; ++k) {
      const double a = alphas[k], ad = alphadot(k);
      const auto Jn = ws.J.block<3, 8>(0, 8 * k);
      out.x[k] = R * (q1 + a * (q2 - q1) + ws.Y.col(k));
      out.J[k].leftCols<3>() = (1.0 - a) * I + Jn.leftCols<3>() * M1;
      out.J[k].rightCols<3>() = a * I + Jn.middleCols<3>(3) * M2;
      if (with_jdot) {
        const auto Jnd = ws.Jdot.block<3, 8>(0, 8 * k);
        out.Jdot[k].leftCols<3>() = -ad * I + Jnd.leftCols<3>() * M1 + Jn.leftCols<3>() * M1d;
        out.Jdot[k].rightCols<3>() = ad * I + Jnd.middleCols<3>(3) * M2 + Jn.middleCols<3>(3) * M2d;
      } else {
        out.Jdot[k].setZero();
      }
      if (x_alpha) (*x_alpha)[k] = (p2 - p1) + R * Jn.col(6);
      if (x_alphadot)
        (*x_alphadot)[k] = with_jdot ? Vec3((p2dot - p1dot) + R * ws.Jdot.col(8 * k + 6)) : Vec3::Zero();
    }
    out.used_network = true;
    return ev;
  }

  if (ev.usedNetwork()) {
    const double R = surface.radius, c = 1.0 / R;
    if (with_jdot) {
      ws.Xdot.resize(8, n);
      for (int k = 0; k < n; ++k) ws.Xdot.col(k) << c * p1dot, c * p2dot, alphadot(k), 0.0;
    }
    evalNetwork(*net, options, with_jdot, ws);
    for (int k = 0; k < n; ++k) {
      // w = R y(u): Jw = dy/du, Jwdot = its derivative along the scaled velocity; alpha is not
      // scaled, so dw/dalpha = R dy/dalpha (header)
      out.x[k] = R * ws.Y.col(k);
      out.J[k] = ws.J.block<3, 6>(0, 8 * k);
      if (with_jdot) out.Jdot[k] = ws.Jdot.block<3, 6>(0, 8 * k);
      else out.Jdot[k].setZero();
      if (x_alpha) (*x_alpha)[k] = R * ws.J.col(8 * k + 6);
      if (x_alphadot) (*x_alphadot)[k] = with_jdot ? Vec3(R * ws.Jdot.col(8 * k + 6)) : Vec3::Zero();
    }
    out.used_network = true;
    return ev;
  }

  out.used_network = false;
  const Vec3 v1 = with_jdot ? p1dot : Vec3::Zero(), v2 = with_jdot ? p2dot : Vec3::Zero();
  // the smooth model on the same points, sharing its construction (wrap/smooth.hpp)
  calcSmoothWrapPoints(surface, p1, p2, v1, v2, alphas, with_jdot ? alphadots : std::vector<double>{},
                       options.fallback, out, x_alpha, x_alphadot);
  out.used_network = false;
  return ev;
}

// ---------------------------------------------------------------------------------------------

void WrapFallbackCounts::record(const NetworkWrapEval& e, int wrap) {
  ++evaluations;
  if (e.usedNetwork()) return;
  ++by_reason[static_cast<int>(e.fallback)];
  if (fallbacks++ > 0) return;
  first = e;
  first_wrap = wrap;
}

WrapFallbackMonitor::WrapFallbackMonitor(Sink sink) : sink_(std::move(sink)) {}

void WrapFallbackMonitor::warnFirst(const std::string& muscle, const std::string& wrap, long before, const Counts& c) {
  if (before > 0 || c.fallbacks == 0 || !sink_) return;
  sink_("muscle '" + muscle + "', wrap object '" + wrap + "': the network wrap model fell back to the smooth model (" +
        c.first + "); further fallbacks of this muscle are counted in the run summary");
}

void WrapFallbackMonitor::record(const std::string& muscle, const std::string& wrap, const NetworkWrapEval& e,
                                 const Mlp* net) {
  Counts& c = counts_[muscle];
  ++c.evaluations;
  if (e.usedNetwork()) return;
  ++c.by_reason[e.fallback];
  const long before = c.fallbacks++;
  if (before == 0) c.first = e.describe(net);
  warnFirst(muscle, wrap, before, c);
}

void WrapFallbackMonitor::add(const Muscle& muscle, const WrapFallbackCounts& w) {
  if (w.evaluations == 0) return;
  Counts& c = counts_[muscle.name];
  const long before = c.fallbacks;
  c.evaluations += w.evaluations;
  c.fallbacks += w.fallbacks;
  for (int i = 1; i < WrapFallbackCounts::kReasons; ++i)
    if (w.by_reason[i] > 0) c.by_reason[static_cast<NetworkWrapFallback>(i)] += w.by_reason[i];
  if (before > 0 || w.fallbacks == 0) return;
  const auto& wraps = muscle.path.wraps;
  const bool named = w.first_wrap >= 0 && w.first_wrap < static_cast<int>(wraps.size());
  c.first = w.first.describe(named ? muscle.wrap.networkFor(wraps[w.first_wrap].name,
                                                            wrapTypeName(wraps[w.first_wrap].surface.type))
                                   : muscle.wrap.network.get());
  warnFirst(muscle.name, named ? wraps[w.first_wrap].name : std::string("?"), before, c);
}

void WrapFallbackMonitor::setSink(Sink sink) { sink_ = std::move(sink); }

std::map<std::string, WrapFallbackMonitor::Counts> WrapFallbackMonitor::counts() const { return counts_; }

long WrapFallbackMonitor::fallbacks(const std::string& muscle) const {
  const auto it = counts_.find(muscle);
  return it == counts_.end() ? 0 : it->second.fallbacks;
}

long WrapFallbackMonitor::evaluations(const std::string& muscle) const {
  const auto it = counts_.find(muscle);
  return it == counts_.end() ? 0 : it->second.evaluations;
}

long WrapFallbackMonitor::totalFallbacks() const {
  long t = 0;
  for (const auto& [name, c] : counts_) t += c.fallbacks;
  return t;
}

std::string WrapFallbackMonitor::summary() const {
  std::ostringstream os;
  for (const auto& [name, c] : counts_) {
    os << "  " << name << ": " << c.fallbacks << " of " << c.evaluations
       << " evaluations fell back to the smooth model";
    if (c.fallbacks > 0) {
      os << " (";
      for (const auto& [why, n] : c.by_reason) os << toString(why) << " " << n << "; ";
      os << "first: " << c.first << ")";
    }
    os << "\n";
  }
  return os.str();
}

void WrapFallbackMonitor::reset() { counts_.clear(); }

// ---------------------------------------------------------------------------------------------

NetworkWrapEval calcNeuralWrapModelPoints(const WrapMassOptions& options, const WrapSurface& surface, const Vec3& p1,
                                          const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot,
                                          const std::vector<double>& alphas, const std::vector<double>& alphadots,
                                          bool velocity, WrapMassPoints& out, NetworkWrapWorkspace& ws,
                                          std::vector<Vec3>* x_alpha, std::vector<Vec3>* x_alphadot, const Mlp* net) {
  NetworkWrapOptions o;
  o.fd_jdot = options.network_fd_jdot;
  o.fd_eps = options.network_fd_eps > 0.0 ? options.network_fd_eps : 1e-6;
  o.fallback.width = options.width;
  return calcNetworkWrapModel(net ? net : options.network.get(), surface, p1, p2, p1dot, p2dot, alphas, velocity, out, ws, o,
                              alphadots, x_alpha, x_alphadot);
}

std::shared_ptr<const Mlp> loadWrapNetwork(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error(path + ": cannot open");
  std::ostringstream ss;
  ss << f.rdbuf();
  const std::string text = ss.str();
  auto net = std::make_shared<Mlp>(Mlp::fromText(text, path));
  try {
    wrapNetworkMap(*net);
  } catch (const std::invalid_argument& e) {
    // name the meta line, as the format's own errors do
    std::istringstream in(text);
    std::string line;
    int no = 0, at = 0;
    while (std::getline(in, line) && at == 0) {
      ++no;
      if (line.rfind("meta wrap_map", 0) == 0) at = no;
    }
    throw NetworkFormatError(path + ":" + std::to_string(at) + ": " + e.what());
  }
  const std::string why = networkWrapUnsupportedReason(*net);
  if (!why.empty()) throw std::runtime_error(path + ": not a wrap network: " + why);
  return net;
}

std::string defaultWrapNetworkPath(const std::string& source_dir, WrapType type) {
  if (type != WrapType::Cylinder && type != WrapType::Sphere) return "";
  const std::filesystem::path p =
      std::filesystem::path(source_dir) / "osim_models" / "networks" / (wrapTypeName(type) + "_3x64.txt");
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec) ? p.string() : "";
}

double calcNetworkWrapPathLength(const Mlp* net, const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                 int segments, NetworkWrapWorkspace& ws, NetworkWrapEval* eval,
                                 const NetworkWrapOptions& options) {
  if (segments < 1) throw std::invalid_argument("network wrap length: segments must be >= 1");
  std::vector<double> alphas(segments + 1);
  for (int k = 0; k <= segments; ++k) alphas[k] = static_cast<double>(k) / segments;
  WrapMassPoints pts;
  const NetworkWrapEval ev =
      calcNetworkWrapModel(net, surface, p1, p2, Vec3::Zero(), Vec3::Zero(), alphas, false, pts, ws, options);
  if (eval) *eval = ev;
  // the network's own curve, ends included: its alpha = 0, 1 outputs only approximate p1, p2, and
  // joining the attachments instead adds a detour that grows as the segments shrink
  double L = 0.0;
  for (int k = 0; k < segments; ++k) L += (pts.x[k + 1] - pts.x[k]).norm();
  return L;
}

}  // namespace redmax
