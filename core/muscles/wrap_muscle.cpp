#include "core/muscles/wrap_muscle.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/muscles/path_kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

namespace {

// a length scale of the surface (m): finite-difference steps are relative to it
double surfaceSize(const WrapSurface& s) {
  switch (s.type) {
    case WrapType::Cylinder:
    case WrapType::Sphere: return s.radius;
    case WrapType::Ellipsoid: return s.dimensions.maxCoeff();
    case WrapType::Torus: return s.inner_radius;
  }
  return 1.0;
}

// coordinates of the joints above body b (none for the world)
void markBody(const Model& model, int b, std::vector<char>& used) {
  if (b < 0) return;
  for (int j : model.ancestors(b))
    for (int c = 0; c < model.joints[j].nq; ++c) used[model.joints[j].q_index + c] = 1;
}

// rows (6 x k, compact columns) of J_mr (or Jdot_mr) for body b
void gatherBodyRows(const Model& model, const MatX& J_mr, int b, const MuscleKinematics& mk, MatX& out) {
  out.setZero(6, static_cast<int>(mk.cols.size()));
  for (int j : model.ancestors(b)) {
    const JointSlot& sj = model.joints[j];
    if (sj.nq == 0) continue;
    out.middleCols(mk.col_of[sj.q_index], sj.nq) = J_mr.block(6 * b, sj.q_index, 6, sj.nq);
  }
}

// the exact library's points at alphas for end points (a, b), frame s
void exactPoints(const WrapSurface& surface, const Vec3& a, const Vec3& b, const std::vector<double>& alphas,
                 std::vector<Vec3>& xs) {
  const WrapResult r = calcWrap(surface, a, b);
  for (size_t k = 0; k < alphas.size(); ++k) xs[k] = calcWrappedPathPoint(surface, r, a, b, alphas[k]);
}

}  // namespace

std::string wrapMassPointsUnsupportedReason(const Muscle& muscle) {
  const MusclePath& path = muscle.path;
  if (path.wraps.empty())
    return "the path only counts its wrap objects (num_wraps = " + std::to_string(path.num_wraps) +
           ") without describing them";
  if (path.wraps.size() != 1 || (path.num_wraps != 0 && path.num_wraps != 1))
    return "inertial Type III muscles support one wrap object per path, this one has " +
           std::to_string(std::max<int>(static_cast<int>(path.wraps.size()), path.num_wraps));
  if (path.points.size() != 2)
    return "inertial Type III muscles support exactly two path points (origin and insertion) around "
           "the wrap object, this path has " + std::to_string(path.points.size());
  const PathWrap& w = path.wraps[0];
  // OpenSim's 1-based range must include the only segment, points 1..2
  const bool covers = w.range_begin <= 1 && (w.range_end < 1 || w.range_end >= 2);
  if (!covers)
    return "wrap object '" + w.name + "' has range " + std::to_string(w.range_begin) + " " +
           std::to_string(w.range_end) + ", which excludes the origin-insertion segment";
  if (!w.surface.active) return "wrap object '" + w.name + "' is inactive";
  if (muscle.wrap.model == WrapModel::Smooth) {
    const std::string why = smoothWrapUnsupportedReason(w.surface);
    if (!why.empty()) return "the smooth wrap model cannot take wrap object '" + w.name + "': " + why;
  }
  return "";
}

void initWrapMuscleColumns(const Model& model, const Muscle& muscle, MuscleKinematics& mk) {
  const int nr = model.nr();
  std::vector<char> used(nr, 0);
  for (const PathPoint& pt : muscle.path.points) {
    markBody(model, pt.body, used);
    if (pt.kind == PathPointKind::Moving && pt.coordinate >= 0) used[pt.coordinate] = 1;
  }
  for (const PathWrap& w : muscle.path.wraps) markBody(model, w.body, used);
  // nothing to do when mk's columns are exactly these
  bool same = static_cast<int>(mk.col_of.size()) == nr;
  for (int c = 0; c < nr && same; ++c) same = (mk.col_of[c] >= 0) == (used[c] != 0);
  if (same) return;
  initMuscleKinematics(model, muscle, mk);  // buffers for all points and mass points
  mk.cols.clear();
  mk.col_of.assign(nr, -1);
  for (int c = 0; c < nr; ++c)
    if (used[c]) {
      mk.col_of[c] = static_cast<int>(mk.cols.size());
      mk.cols.push_back(c);
    }
  const int k = static_cast<int>(mk.cols.size());
  mk.J_xr.setZero(mk.J_xr.rows(), k);
  mk.Jdot_xr.setZero(mk.Jdot_xr.rows(), k);
  mk.J_ar.setZero(mk.J_ar.rows(), k);
  mk.Jdot_ar.setZero(mk.Jdot_ar.rows(), k);
}

void calcExactWrapPointsFd(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                           const Vec3& p2dot, const std::vector<double>& alphas, WrapMassPoints& out, double h,
                           bool with_jdot) {
  const int n = static_cast<int>(alphas.size());
  const double size = surfaceSize(surface);
  if (!(h > 0.0)) h = 1e-5 * size;
  out.used_network = false;
  out.x.resize(n);
  out.J.resize(n);
  out.Jdot.resize(n);
  exactPoints(surface, p1, p2, alphas, out.x);
  std::vector<Vec3> xp(n), xm(n), xpp(n), xpm(n), xmp(n), xmm(n);
  // J: central differences on each of the 6 end-point coordinates
  for (int i = 0; i < 6; ++i) {
    Vec3 e1 = Vec3::Zero(), e2 = Vec3::Zero();
    (i < 3 ? e1 : e2)[i % 3] = h;
    exactPoints(surface, p1 + e1, p2 + e2, alphas, xp);
    exactPoints(surface, p1 - e1, p2 - e2, alphas, xm);
    for (int k = 0; k < n; ++k) out.J[k].col(i) = (xp[k] - xm[k]) / (2.0 * h);
  }
  for (int k = 0; k < n; ++k) out.Jdot[k].setZero();
  const double speed = std::sqrt(p1dot.squaredNorm() + p2dot.squaredNorm());
  if (!with_jdot || !(speed > 0.0)) return;
  // Jdot column i = d2x / (dp_i dv): a mixed central difference with steps s along e_i and along
  // the velocity; s is wider than h because the product of the two steps divides the round-off
  // (1e-3 size keeps that noise below 1e-9 of J / size, which a tight adaptive integrator needs)
  const double s = 1e-3 * size, tau = s / speed;
  const Vec3 d1 = tau * p1dot, d2 = tau * p2dot;
  for (int i = 0; i < 6; ++i) {
    Vec3 e1 = Vec3::Zero(), e2 = Vec3::Zero();
    (i < 3 ? e1 : e2)[i % 3] = s;
    exactPoints(surface, p1 + e1 + d1, p2 + e2 + d2, alphas, xpp);
    exactPoints(surface, p1 + e1 - d1, p2 + e2 - d2, alphas, xpm);
    exactPoints(surface, p1 - e1 + d1, p2 - e2 + d2, alphas, xmp);
    exactPoints(surface, p1 - e1 - d1, p2 - e2 - d2, alphas, xmm);
    for (int k = 0; k < n; ++k) out.Jdot[k].col(i) = (xpp[k] - xpm[k] - xmp[k] + xmm[k]) / (4.0 * s * tau);
  }
}

void calcWrapMassPoints(const Model& model, const SkeletonWorkspace& sk, const Muscle& muscle, MuscleKinematics& mk) {
  const std::string why = wrapMassPointsUnsupportedReason(muscle);
  if (!why.empty()) throw std::logic_error("muscle '" + muscle.name + "': " + why);
  if (mk.x_w.size() != 2) throw std::logic_error("calcWrapMassPoints: needs the path stage of a two-point path");
  const MassPoints& mp = muscle.mass_points;
  const PathWrap& w = muscle.path.wraps[0];
  const int N = mp.size();
  const int k = static_cast<int>(mk.cols.size());
  const int b = w.body;
  const bool vel = mk.velocity;
  if (b >= 0 && (static_cast<int>(mk.col_of.size()) != model.nr() || [&] {
        for (int j : model.ancestors(b))
          if (model.joints[j].nq > 0 && mk.col_of[model.joints[j].q_index] < 0) return true;
        return false;
      }()))
    throw std::logic_error("calcWrapMassPoints: mk's columns do not cover the wrap body (initWrapMuscleColumns)");

  // surface pose E_ws = E_wb E_bs and the body's motion [D Eq. 5.39-5.41]
  const Mat4 E_ws = b >= 0 ? Mat4(sk.E_wi[b] * w.E_bs) : w.E_bs;
  const Mat3 R = E_ws.topLeftCorner<3, 3>();
  const Vec3 p = E_ws.topRightCorner<3, 1>();
  const Vec3 x_bs = w.E_bs.topRightCorner<3, 1>();
  MatX J_om = MatX::Zero(3, k), J_p = MatX::Zero(3, k), Jdot_om = MatX::Zero(3, k), Jdot_p = MatX::Zero(3, k);
  Vec3 omega = Vec3::Zero(), pdot = Vec3::Zero();
  if (b >= 0) {
    const Mat3 R_wb = sk.E_wi[b].topLeftCorner<3, 3>();
    const Mat3x6 G = R_wb * Gamma(x_bs);  // surface origin's point Jacobian block [D Eq. 5.9]
    MatX J_mb;
    gatherBodyRows(model, sk.J_mr, b, mk, J_mb);
    J_om.noalias() = R_wb * J_mb.topRows<3>();
    J_p.noalias() = G * J_mb;
    if (vel) {
      const Vec6& phi = sk.phi[b];
      const Vec3 omega_b = phi.head<3>();
      omega = R_wb * omega_b;
      pdot = G * phi;
      MatX Jdot_mb;
      gatherBodyRows(model, sk.Jdot_mr, b, mk, Jdot_mb);
      // d/dt R_wb = R_wb [omega_b]; x_bs is fixed in the body [D Eq. 5.11]
      Jdot_om.noalias() = R_wb * (skew(omega_b) * J_mb.topRows<3>() + Jdot_mb.topRows<3>());
      Jdot_p.noalias() = R_wb * (skew(omega_b) * Gamma(x_bs) * J_mb + Gamma(x_bs) * Jdot_mb);
    }
  }

  // end points in the surface frame and their Jacobians A_i = dp_i/dq
  const Vec3 r1 = mk.x_w[0] - p, r2 = mk.x_w[1] - p;
  const Vec3 p1 = R.transpose() * r1, p2 = R.transpose() * r2;
  const auto J_x1 = mk.J_xr.topRows<3>();
  const auto J_x2 = mk.J_xr.middleRows<3>(3);
  const MatX B1 = J_x1 - J_p + skew(r1) * J_om;  // R A_1
  const MatX B2 = J_x2 - J_p + skew(r2) * J_om;
  const MatX A1 = R.transpose() * B1, A2 = R.transpose() * B2;
  Vec3 p1dot = Vec3::Zero(), p2dot = Vec3::Zero();
  MatX A1dot, A2dot;
  if (vel) {
    const Vec3 r1dot = mk.xdot_w[0] - pdot, r2dot = mk.xdot_w[1] - pdot;
    p1dot = R.transpose() * (r1dot - omega.cross(r1));
    p2dot = R.transpose() * (r2dot - omega.cross(r2));
    const Mat3 W = skew(omega);
    A1dot = R.transpose() * (-W * B1 + mk.Jdot_xr.topRows<3>() - Jdot_p + skew(r1dot) * J_om + skew(r1) * Jdot_om);
    A2dot = R.transpose() * (-W * B2 + mk.Jdot_xr.middleRows<3>(3) - Jdot_p + skew(r2dot) * J_om + skew(r2) * Jdot_om);
  }

  // the wrap model's points in the surface frame [D Eq. 5.38, 5.44]
  WrapMassPoints wp;
  try {
    if (muscle.wrap.model == WrapModel::Smooth) {
      SmoothWrapOptions so;
      so.width = muscle.wrap.width;
      wp.x.resize(N);
      wp.J.resize(N);
      wp.Jdot.resize(N);
      for (int a = 0; a < N; ++a) {
        const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(w.surface, p1, p2, mp.alpha[a], p1dot, p2dot, so);
        wp.x[a] = sp.x;
        wp.J[a] = sp.J;
        wp.Jdot[a] = sp.Jdot;
      }
    } else {
      calcExactWrapPointsFd(w.surface, p1, p2, p1dot, p2dot, mp.alpha, wp, muscle.wrap.fd_step, vel);
    }
  } catch (const std::invalid_argument& e) {
    throw MuscleError("muscle '" + muscle.name + "', wrap object '" + w.name + "': " + e.what());
  }

  // chain rule to the reduced coordinates [D Eq. 5.45-5.57]
  mk.x_a.resize(N);
  mk.segment.assign(N, 0);
  mk.beta.resize(N);
  if (mk.J_ar.rows() != 3 * N || mk.J_ar.cols() != k) mk.J_ar.resize(3 * N, k);
  if (vel && (mk.Jdot_ar.rows() != 3 * N || mk.Jdot_ar.cols() != k)) mk.Jdot_ar.resize(3 * N, k);
  for (int a = 0; a < N; ++a) {
    mk.beta[a] = mp.alpha[a];
    const Vec3 Rw = R * wp.x[a];
    mk.x_a[a] = Rw + p;
    const Mat3 Jw1 = wp.J[a].leftCols<3>(), Jw2 = wp.J[a].rightCols<3>();
    const MatX JwA = Jw1 * A1 + Jw2 * A2;  // dw/dq in the surface frame
    mk.J_ar.middleRows(3 * a, 3).noalias() = R * JwA - skew(Rw) * J_om + J_p;
    if (!vel) continue;
    const Vec3 Rwdot = omega.cross(Rw) + R * (Jw1 * p1dot + Jw2 * p2dot);
    const Mat3 Jw1dot = wp.Jdot[a].leftCols<3>(), Jw2dot = wp.Jdot[a].rightCols<3>();
    mk.Jdot_ar.middleRows(3 * a, 3).noalias() =
        skew(omega) * R * JwA + R * (Jw1dot * A1 + Jw2dot * A2 + Jw1 * A1dot + Jw2 * A2dot) -
        skew(Rwdot) * J_om - skew(Rw) * Jdot_om + Jdot_p;
  }
}

}  // namespace redmax
