#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap/wrap_path.hpp"

#include <algorithm>

namespace redmax {

void initMuscleKinematics(const Model& model, const MusclePath& path, MuscleKinematics& mk) {
  // coordinates of every joint above any path body, those driving moving points, and the three of
  // each node point (extra coordinates after q_r: col_of then reaches past nr)
  int n = model.nr();
  for (const PathPoint& pt : path.points)
    if (pt.kind == PathPointKind::Node && pt.coordinate >= 0) n = std::max(n, pt.coordinate + 3);
  std::vector<char> used(n, 0);
  for (const PathPoint& pt : path.points) {
    if (pt.body >= 0)
      for (int j : model.ancestors(pt.body))
        for (int c = 0; c < model.joints()[j].nq; ++c) used[model.joints()[j].q_index + c] = 1;
    if (pt.kind == PathPointKind::Moving && pt.coordinate >= 0) used[pt.coordinate] = 1;
    if (pt.kind == PathPointKind::Node && pt.coordinate >= 0) used[pt.coordinate] = used[pt.coordinate + 1] = used[pt.coordinate + 2] = 1;
  }
  mk.cols.clear();
  mk.col_of.assign(n, -1);
  for (int c = 0; c < n; ++c)
    if (used[c]) {
      mk.col_of[c] = static_cast<int>(mk.cols.size());
      mk.cols.push_back(c);
    }
  // buffers for every point active; conditional switches only change the used part
  const int P = static_cast<int>(path.points.size());
  const int k = static_cast<int>(mk.cols.size());
  mk.active.reserve(P);
  mk.x_b.reserve(P);
  mk.x_w.reserve(P);
  mk.J_xm.reserve(P);
  mk.xdot_w.reserve(P);
  mk.Jdot_xm.reserve(P);
  mk.dxbar.reserve(P);
  mk.J_xr.setZero(3 * P, k);
  mk.Jdot_xr.setZero(3 * P, k);
}

void initMuscleKinematics(const Model& model, const Muscle& muscle, MuscleKinematics& mk) {
  initMuscleKinematics(model, muscle.path, mk);
  const int N = muscle.mass_points.size();
  const int k = static_cast<int>(mk.cols.size());
  mk.x_a.assign(N, Vec3::Zero());
  mk.segment.assign(N, 0);
  mk.beta.assign(N, 0.0);
  mk.J_ar.setZero(3 * N, k);
  mk.Jdot_ar.setZero(3 * N, k);
}

MuscleWorkspace::MuscleWorkspace(const Model& model, const std::vector<Muscle>& list) {
  muscles.resize(list.size());
  for (size_t m = 0; m < list.size(); ++m) initMuscleKinematics(model, list[m], muscles[m]);
}

MatX expandColumns(const MatX& J, const MuscleKinematics& mk, int nr) {
  MatX full = MatX::Zero(J.rows(), std::max<int>(nr, static_cast<int>(mk.col_of.size())));
  for (int j = 0; j < static_cast<int>(mk.cols.size()); ++j) full.col(mk.cols[j]) = J.col(j);
  return full;
}

VecX gatherColumns(const VecX& v, const MuscleKinematics& mk) {
  VecX g;
  gatherColumns(v, mk, g);
  return g;
}

void gatherColumns(const VecX& v, const MuscleKinematics& mk, VecX& out) {
  out.resize(static_cast<int>(mk.cols.size()));
  for (int j = 0; j < out.size(); ++j) out[j] = v[mk.cols[j]];
}

void scatterAddColumns(const VecX& compact, const MuscleKinematics& mk, VecX& full) {
  for (int j = 0; j < compact.size(); ++j) full[mk.cols[j]] += compact[j];
}

namespace {
// true if mk's columns cover every coordinate that can move `path`
bool columnsCover(const Model& model, const MusclePath& path, const MuscleKinematics& mk) {
  if (static_cast<int>(mk.col_of.size()) < model.nr()) return false;
  for (const PathPoint& pt : path.points) {
    if (pt.kind == PathPointKind::Node &&
        (pt.coordinate + 3 > static_cast<int>(mk.col_of.size()) || mk.col_of[pt.coordinate] < 0))
      return false;
    if (pt.body >= 0)
      for (int j : model.ancestors(pt.body))
        if (model.joints()[j].nq > 0 && mk.col_of[model.joints()[j].q_index] < 0) return false;
    if (pt.kind == PathPointKind::Moving && pt.coordinate >= 0 && mk.col_of[pt.coordinate] < 0) return false;
  }
  return true;
}
}  // namespace

void calcPointLocation(const PathPoint& p, const VecX& q, Vec3& x_b, Vec3& dx_b, Vec3& ddx_b) {
  x_b = p.location;
  dx_b.setZero();
  ddx_b.setZero();
  if (p.kind != PathPointKind::Moving) return;
  // OpenSim evaluates the functions at 0 when no coordinate is connected
  double arg = p.coordinate >= 0 ? q[p.coordinate] : 0.0;
  bool inside = p.coordinate >= 0;
  if (p.clamp && (arg < p.clamp_lo || arg > p.clamp_hi)) {
    // the clamped map is constant outside the range, so its derivatives vanish there
    arg = std::clamp(arg, p.clamp_lo, p.clamp_hi);
    inside = false;
  }
  FunctionValue fv;
  for (int k = 0; k < 3; ++k) {
    const AxisFunctionPtr& f = p.functions[k];
    if (!f) continue;
    // one argument (q), or none for a constant (validatePath rejects more)
    const int na = f->numArgs();
    VecJ x = VecJ::Constant(na, arg);
    const bool derivs = inside && na == 1;
    f->evaluate(x, derivs ? 2 : 0, fv);
    x_b[k] = fv.value;
    if (derivs) {
      dx_b[k] = fv.gradient[0];
      ddx_b[k] = fv.hessian(0, 0);
    }
  }
}

Vec3 calcPointLocationDerivativeUnclamped(const PathPoint& p, double q_c) {
  Vec3 d = Vec3::Zero();
  if (p.kind != PathPointKind::Moving || p.coordinate < 0) return d;
  FunctionValue fv;
  for (int k = 0; k < 3; ++k) {
    const AxisFunctionPtr& f = p.functions[k];
    if (!f || f->numArgs() != 1) continue;
    f->evaluate(VecJ::Constant(1, q_c), 1, fv);
    d[k] = fv.gradient[0];
  }
  return d;
}

void calcPathPoints(const Model& model, const State& state, const SkeletonWorkspace& sk,
                    const MusclePath& path, MuscleKinematics& mk, bool velocity) {
  if (!columnsCover(model, path, mk)) initMuscleKinematics(model, path, mk);
  const int k = static_cast<int>(mk.cols.size());
  const int need = velocity ? static_cast<int>(Stage::Velocity) : static_cast<int>(Stage::Position);
  if (static_cast<int>(sk.stage) < need)
    throw std::logic_error("calcPathPoints: skeleton workspace is not at the required stage (call calcKinematics)");

  // active set: conditional points by OpenSim's inclusive rule (path.hpp)
  activePathPoints(path, state.q, mk.active);
  const int P = static_cast<int>(mk.active.size());

  mk.x_b.resize(P);
  mk.x_w.resize(P);
  mk.J_xm.resize(P);
  if (mk.J_xr.rows() != 3 * P || mk.J_xr.cols() != k) mk.J_xr.resize(3 * P, k);
  mk.J_xr.setZero();
  if (velocity) {
    mk.xdot_w.resize(P);
    mk.Jdot_xm.resize(P);
    if (mk.Jdot_xr.rows() != 3 * P || mk.Jdot_xr.cols() != k) mk.Jdot_xr.resize(3 * P, k);
    mk.Jdot_xr.setZero();
  }

  for (int a = 0; a < P; ++a) {
    const PathPoint& pt = path.points[mk.active[a]];
    if (pt.kind == PathPointKind::Node) {
      // a free deformable node: its own three coordinates, J_xr = I there, Jdot_xr = 0
      mk.x_w[a] = mk.x_b[a] = nodeOrWorldPosition(pt, state.q);
      mk.J_xm[a].setZero();
      const int cc = mk.col_of[pt.coordinate];
      mk.J_xr.block<3, 3>(3 * a, cc).setIdentity();
      if (velocity) {
        mk.xdot_w[a] = state.qdot.segment<3>(pt.coordinate);
        mk.Jdot_xm[a].setZero();
      }
      continue;
    }
    Vec3 dx_b, ddx_b;
    calcPointLocation(pt, state.q, mk.x_b[a], dx_b, ddx_b);
    const Vec3& x_b = mk.x_b[a];
    const int b = pt.body;
    const int c = pt.kind == PathPointKind::Moving ? pt.coordinate : -1;
    const double qdot_c = c >= 0 ? state.qdot[c] : 0.0;
    const int cc = c >= 0 ? mk.col_of[c] : -1;  // its compact column
    auto J = mk.J_xr.middleRows<3>(3 * a);

    if (b < 0) {
      // world point: only a moving point's own coordinate moves it
      mk.x_w[a] = x_b;
      mk.J_xm[a].setZero();
      if (c >= 0) J.col(cc) += dx_b;
      if (velocity) {
        mk.xdot_w[a] = dx_b * qdot_c;
        mk.Jdot_xm[a].setZero();
        if (c >= 0) mk.Jdot_xr.middleRows<3>(3 * a).col(cc) += ddx_b * qdot_c;
      }
      continue;
    }

    // body point: x_w = R x_b + p, J_xm block R Gamma(x_b) [D Eq. 5.8-5.9]
    const Mat3 R = sk.E_wi[b].topLeftCorner<3, 3>();
    mk.x_w[a] = R * x_b + sk.E_wi[b].topRightCorner<3, 1>();
    mk.J_xm[a].noalias() = R * Gamma(x_b);
    // J_xr = J_xm J_mr over the columns of b's ancestor joints (others are zero in J_mr); a
    // joint's coordinates are consecutive in q and hence in the compact columns
    for (int j : model.ancestors(b)) {
      const JointSlot& sj = model.joints()[j];
      if (sj.nq == 0) continue;
      J.middleCols(mk.col_of[sj.q_index], sj.nq).noalias() =
          mk.J_xm[a] * sk.J_mr.block(6 * b, sj.q_index, 6, sj.nq);
    }
    // moving point: direct dependence on its coordinate, not through the body twist
    if (c >= 0) J.col(cc) += R * dx_b;

    if (!velocity) continue;
    const Vec6& phi = sk.phi[b];
    const Vec3 omega = phi.head<3>();
    const Vec3 xdot_b = dx_b * qdot_c;
    mk.xdot_w[a] = R * (Gamma(x_b) * phi + xdot_b);
    // Jdot_xm = R [omega] Gamma(x_b) + R Gamma(xdot_b), Gamma(xdot_b) = ([xdot_b]^T 0) [D Eq. 5.11]
    Mat3x6 Gdot = Mat3x6::Zero();
    Gdot.leftCols<3>() = skew(xdot_b).transpose();
    mk.Jdot_xm[a].noalias() = R * (skew(omega) * Gamma(x_b) + Gdot);
    auto Jd = mk.Jdot_xr.middleRows<3>(3 * a);
    // product rule on J_xm J_mr [D Eq. 5.5]
    for (int j : model.ancestors(b)) {
      const JointSlot& sj = model.joints()[j];
      if (sj.nq == 0) continue;
      Jd.middleCols(mk.col_of[sj.q_index], sj.nq).noalias() =
          mk.Jdot_xm[a] * sk.J_mr.block(6 * b, sj.q_index, 6, sj.nq) +
          mk.J_xm[a] * sk.Jdot_mr.block(6 * b, sj.q_index, 6, sj.nq);
    }
    // d/dt (R x_b') = R ([omega] x_b' + x_b'' qdot_c)
    if (c >= 0) Jd.col(cc) += R * (omega.cross(dx_b) + ddx_b * qdot_c);
  }

  calcPathSegments(mk, velocity);
  mk.velocity = velocity;
}

void calcPathSegments(MuscleKinematics& mk, bool velocity) {
  const int P = static_cast<int>(mk.x_w.size());
  // segments [D Eq. 5.17-5.19, 5.27]
  const int ns = std::max(P - 1, 0);
  mk.l.resize(ns);
  mk.dxbar.resize(ns);
  mk.length = 0.0;
  if (velocity) mk.ldot.resize(ns);
  mk.lengthening_speed = 0.0;
  for (int i = 0; i < ns; ++i) {
    const Vec3 dx = mk.x_w[i + 1] - mk.x_w[i];
    mk.l[i] = dx.norm();
    mk.dxbar[i] = mk.l[i] > 0.0 ? Vec3(dx * (1.0 / mk.l[i])) : Vec3::Zero();  // one division, not three
    mk.length += mk.l[i];
    if (velocity) {
      mk.ldot[i] = mk.dxbar[i].dot(mk.xdot_w[i + 1] - mk.xdot_w[i]);
      mk.lengthening_speed += mk.ldot[i];
    }
  }
}

double calcPathLength(const Model& model, const MusclePath& path, const VecX& q,
                      const std::vector<Mat4>& E_wi) {
  // Type III: OpenSim's wrapped path (core/muscles/wrap/wrap_path.hpp)
  if (!path.wraps.empty()) return calcWrappedPath(model, path, q, E_wi).length;
  std::vector<int> active;
  std::vector<Vec3> x_w;
  calcActivePoints(path, q, E_wi, active, x_w);
  double length = 0.0;
  for (size_t i = 1; i < x_w.size(); ++i) length += (x_w[i] - x_w[i - 1]).norm();
  return length;
}

void calcActivePoints(const MusclePath& path, const VecX& q, const std::vector<Mat4>& E_wi, std::vector<int>& active,
                      std::vector<Vec3>& x_w) {
  active.clear();
  x_w.clear();
  for (size_t i = 0; i < path.points.size(); ++i) {
    const PathPoint& pt = path.points[i];
    if (!isPathPointActive(pt, q)) continue;
    Vec3 x_b, dx, ddx;
    calcPointLocation(pt, q, x_b, dx, ddx);
    active.push_back(static_cast<int>(i));
    x_w.push_back(pt.body >= 0                      ? transformPoint(E_wi[pt.body], x_b)
                  : pt.kind == PathPointKind::Node ? nodeOrWorldPosition(pt, q)
                                                   : x_b);
  }
}

}  // namespace redmax
