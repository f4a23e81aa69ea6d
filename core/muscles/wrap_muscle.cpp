#include "core/muscles/wrap_muscle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/via_point.hpp"
#include "core/muscles/wrap_composite.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/skeleton/kinematics.hpp"
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
    for (int c = 0; c < model.joints()[j].nq; ++c) used[model.joints()[j].q_index + c] = 1;
}

// rows (6 x k, compact columns) of J_mr (or Jdot_mr) for body b
void gatherBodyRows(const Model& model, const MatX& J_mr, int b, const MuscleKinematics& mk, MatX& out) {
  out.setZero(6, static_cast<int>(mk.cols.size()));
  for (int j : model.ancestors(b)) {
    const JointSlot& sj = model.joints()[j];
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


void calcSurfaceMotion(const Model& model, const SkeletonWorkspace& sk, const PathWrap& w, const MuscleKinematics& mk,
                       bool vel, WrapSurfaceMotion& sm, MatX& J_mb, MatX& Jdot_mb) {
  const int k = static_cast<int>(mk.cols.size());
  const int b = w.body;
  const Mat4 E_ws = b >= 0 ? Mat4(sk.E_wi[b] * w.E_bs) : w.E_bs;
  sm.R = E_ws.topLeftCorner<3, 3>();
  sm.p = E_ws.topRightCorner<3, 1>();
  sm.J_om.setZero(3, k);
  sm.J_p.setZero(3, k);
  sm.Jdot_om.setZero(3, k);
  sm.Jdot_p.setZero(3, k);
  sm.omega.setZero();
  sm.pdot.setZero();
  if (b < 0) return;
  const Vec3 x_bs = w.E_bs.topRightCorner<3, 1>();
  const Mat3 R_wb = sk.E_wi[b].topLeftCorner<3, 3>();
  const Mat3x6 G = R_wb * Gamma(x_bs);  // surface origin's point Jacobian block [D Eq. 5.9]
  gatherBodyRows(model, sk.J_mr, b, mk, J_mb);
  sm.J_om.noalias() = R_wb * J_mb.topRows<3>();
  sm.J_p.noalias() = G * J_mb;
  if (!vel) return;
  const Vec6& phi = sk.phi[b];
  const Vec3 omega_b = phi.head<3>();
  sm.omega = R_wb * omega_b;
  sm.pdot = G * phi;
  gatherBodyRows(model, sk.Jdot_mr, b, mk, Jdot_mb);
  // d/dt R_wb = R_wb [omega_b]; x_bs is fixed in the body [D Eq. 5.11]; products of fixed-size
  // factors first, so that no 3 x k temporary is allocated
  const Mat3 RW = R_wb * skew(omega_b);
  sm.Jdot_om.noalias() = RW * J_mb.topRows<3>();
  sm.Jdot_om.noalias() += R_wb * Jdot_mb.topRows<3>();
  sm.Jdot_p.noalias() = (RW * Gamma(x_bs)) * J_mb;
  sm.Jdot_p.noalias() += G * Jdot_mb;
}

using SegmentEnds = WrapStageScratch::Ends;

// the ends (active points i, i + 1) of a segment in a surface frame (B, T: scratch)
void calcSegmentEnds(const WrapSurfaceMotion& sm, const MuscleKinematics& mk, int i, bool vel, SegmentEnds& e, MatX& B,
                     MatX& T) {
  const Mat3& R = sm.R;
  const Mat3 Rt = R.transpose();
  const Vec3 r[2] = {mk.x_w[i] - sm.p, mk.x_w[i + 1] - sm.p};
  e.p1 = Rt * r[0];
  e.p2 = Rt * r[1];
  e.p1dot.setZero();
  e.p2dot.setZero();
  Vec3 rdot[2] = {Vec3::Zero(), Vec3::Zero()};
  if (vel) {
    rdot[0] = mk.xdot_w[i] - sm.pdot;
    rdot[1] = mk.xdot_w[i + 1] - sm.pdot;
    e.p1dot = Rt * (rdot[0] - sm.omega.cross(r[0]));
    e.p2dot = Rt * (rdot[1] - sm.omega.cross(r[1]));
  }
  const Mat3 W = skew(sm.omega);
  for (int j = 0; j < 2; ++j) {
    const int row = 3 * (i + j);
    B = mk.J_xr.middleRows<3>(row) - sm.J_p;  // R A_j
    B.noalias() += skew(r[j]) * sm.J_om;
    MatX& A = j == 0 ? e.A1 : e.A2;
    A.noalias() = Rt * B;
    if (!vel) continue;
    // d/dt (R^T B) = R^T (-[omega] B + Bdot)
    T = mk.Jdot_xr.middleRows<3>(row) - sm.Jdot_p;
    T.noalias() -= W * B;
    T.noalias() += skew(rdot[j]) * sm.J_om;
    T.noalias() += skew(r[j]) * sm.Jdot_om;
    (j == 0 ? e.A1dot : e.A2dot).noalias() = Rt * T;
  }
}

// active segment and fraction of its length holding the point at alpha of the wrapped path
void locateOnWrappedPath(const WrappedPath& wp, double alpha, int& segment, double& beta) {
  const size_t n = wp.points.size();
  std::vector<double> piece(n > 0 ? n - 1 : 0);
  double total = 0.0;
  for (size_t i = 0; i + 1 < n; ++i) {
    const auto &a = wp.points[i], &b = wp.points[i + 1];
    piece[i] = (a.wrap >= 0 && a.wrap == b.wrap) ? wp.results[a.wrap].arcLength() : (b.x_w - a.x_w).norm();
    total += piece[i];
  }
  const double target = std::clamp(alpha, 0.0, 1.0) * total;
  segment = -1;
  double seg_start = 0.0, acc = 0.0, seg_len = 0.0;
  int found = -1;
  double found_start = 0.0;
  for (size_t i = 0; i + 1 < n; ++i) {
    if (wp.points[i].point >= 0) {
      // a path point opens the next active segment
      if (found >= 0 && segment == found) break;
      ++segment;
      seg_start = acc;
      seg_len = 0.0;
    }
    seg_len += piece[i];
    if (found < 0 && (target <= acc + piece[i] || i + 2 == n)) {
      found = segment;
      found_start = seg_start;
    }
    acc += piece[i];
  }
  if (found < 0) found = std::max(segment, 0);
  segment = found;
  beta = seg_len > 0.0 ? std::clamp((target - found_start) / seg_len, 0.0, 1.0) : 0.0;
}

}  // namespace

// OpenSim's 1-based range of a PathWrap as 0-based first and last point indices (< 1: the ends)
void wrapRange(const PathWrap& w, int np, int& lo, int& hi) {
  lo = w.range_begin < 1 ? 0 : w.range_begin - 1;
  hi = w.range_end < 1 ? np - 1 : std::min(w.range_end - 1, np - 1);
}

// the candidate segments [first, last) of wrap w over the active points (OpenSim's applyWrapObjects:
// from the first active point at/after the range's begin to the last one at/before its end)
bool wrapSegments(const PathWrap& w, const std::vector<int>& active, int np, int& first, int& last) {
  int lo = 0, hi = 0;
  wrapRange(w, np, lo, hi);
  const int P = static_cast<int>(active.size());
  first = -1;
  last = -1;
  for (int i = 0; i < P; ++i) {
    if (first < 0 && active[i] >= lo) first = i;
    if (active[i] <= hi) last = i;
  }
  return first >= 0 && last > first;
}

// true when the smooth (and network) wrap model refuses the segment p1 -> p2 (frame s): an end
// inside the surface, or input it cannot take (its checkInputs), tested directly rather than by
// computing a wrapped length that is thrown away on this per-evaluation path
bool endInsideSurface(const WrapSurface& surface, const Vec3& p1, const Vec3& p2) {
  if (!p1.allFinite() || !p2.allFinite() || p1 == p2 || !smoothWrapUnsupportedReason(surface).empty()) return true;
  return surface.contains(p1) || surface.contains(p2);
}

std::string wrapMassPointsUnsupportedReason(const Muscle& muscle) {
  const MusclePath& path = muscle.path;
  if (path.wraps.empty())
    return "the path only counts its wrap objects (num_wraps = " + std::to_string(path.num_wraps) +
           ") without describing them";
  const int np = static_cast<int>(path.points.size());
  for (const PathWrap& w : path.wraps) {
    int lo = 0, hi = 0;
    wrapRange(w, np, lo, hi);
    if (hi <= lo)
      return "wrap object '" + w.name + "' has range " + std::to_string(w.range_begin) + " " +
             std::to_string(w.range_end) + ", which excludes " +
             (np == 2 ? std::string("the origin-insertion segment") : std::string("every segment of the path"));
  }
  if (muscle.wrap.model == WrapModel::Exact) return "";  // the whole OpenSim path, any surfaces
  if (muscle.wrap.model == WrapModel::Neural)  // a usable network; the smooth model's checks below apply too (fallback)
    for (const PathWrap& w : path.wraps) {
      const std::string why = w.surface.active ? neuralWrapUnsupportedReason(muscle.wrap.networkFor(w.name, wrapTypeName(w.surface.type)), w.surface) : "";
      if (!why.empty()) return "the neural wrap model cannot take wrap object '" + w.name + "': " + why;
    }
  for (size_t k = 0; k < path.wraps.size(); ++k) {
    const PathWrap& w = path.wraps[k];
    if (!w.surface.active) continue;  // never wraps
    const std::string why = smoothWrapUnsupportedReason(w.surface);
    if (!why.empty()) return "the smooth wrap model cannot take wrap object '" + w.name + "': " + why;
    // two ranges sharing two points can land on one segment: OpenSim then applies both in turn
    // (and iterates); the smooth model composes cylinders and spheres there (wrap_composite.hpp),
    // the network nothing
    int lo = 0, hi = 0;
    wrapRange(w, np, lo, hi);
    for (size_t j = 0; j < k; ++j) {
      const PathWrap& v = path.wraps[j];
      if (!v.surface.active) continue;
      int lo2 = 0, hi2 = 0;
      wrapRange(v, np, lo2, hi2);
      if (!(std::min(hi, hi2) > std::max(lo, lo2))) continue;
      auto composable = [](const WrapSurface& x) { return x.type == WrapType::Cylinder || x.type == WrapType::Sphere; };
      if (muscle.wrap.model == WrapModel::Smooth) {
        if (composable(v.surface) && composable(w.surface)) continue;
        return "the smooth wrap model composes cylinders and spheres on one segment, but wrap objects '" + v.name +
               "' (" + wrapTypeName(v.surface.type) + ") and '" + w.name + "' (" + wrapTypeName(w.surface.type) +
               ") can both act on the segment between path points " + std::to_string(std::max(lo, lo2) + 1) +
               " and " + std::to_string(std::min(hi, hi2) + 1) + ": use the exact model";
      }
      return "the neural wrap model takes one wrap object per segment, but wrap objects '" + v.name + "' and '" +
             w.name + "' can both act on the segment between path points " + std::to_string(std::max(lo, lo2) + 1) +
             " and " + std::to_string(std::min(hi, hi2) + 1) +
             " (OpenSim applies them in turn and iterates; the smooth model composes them): use the smooth or the "
             "exact model";
    }
  }
  if (muscle.wrap.model == WrapModel::Smooth)  // the composition's limit (wrap/smooth_composite.hpp)
    for (int j = 0; j + 1 < np; ++j) {
      int n = 0;
      for (const PathWrap& w : path.wraps) {
        int lo = 0, hi = 0;
        wrapRange(w, np, lo, hi);
        n += w.surface.active && lo <= j && hi >= j + 1 ? 1 : 0;
      }
      if (n > 3)
        return "the smooth wrap model composes at most 3 wrap objects on one segment, but " + std::to_string(n) +
               " can act on the segment between path points " + std::to_string(j + 1) + " and " +
               std::to_string(j + 2) + ": use the exact model";
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

NetworkWrapEval calcWrapModelPoints(const WrapMassOptions& options, const WrapSurface& surface, const Vec3& p1,
                                    const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot,
                                    const std::vector<double>& alphas, const std::vector<double>& alphadots,
                                    bool with_alpha, bool velocity, WrapModelPoints& out, NetworkWrapWorkspace& network,
                                    const std::string& wrap_name) {
  const int n = static_cast<int>(alphas.size());
  const Vec3 v1 = velocity ? p1dot : Vec3::Zero(), v2 = velocity ? p2dot : Vec3::Zero();
  auto alphadot = [&](int a) { return velocity && !alphadots.empty() ? alphadots[a] : 0.0; };
  bool moving_alpha = false;
  for (int a = 0; a < n; ++a) moving_alpha = moving_alpha || alphadot(a) != 0.0;
  out.used_network = false;
  out.x.resize(n);
  out.J.resize(n);
  out.Jdot.resize(n);
  out.x_alpha.assign(with_alpha ? n : 0, Vec3::Zero());
  out.x_alphadot.assign(with_alpha ? n : 0, Vec3::Zero());
  switch (options.model) {
    case WrapModel::Smooth: {
      // one shared construction for all the points (the fraction is a seventh input when it
      // moves or its derivative is asked for: its rate enters Jdot)
      SmoothWrapOptions so;
      so.width = options.width;
      static const std::vector<double> kResting;  // (a reference, not a copy of alphadots per call)
      calcSmoothWrapPoints(surface, p1, p2, v1, v2, alphas, velocity ? alphadots : kResting, so, out,
                           with_alpha ? &out.x_alpha : nullptr, with_alpha ? &out.x_alphadot : nullptr);
      return {};
    }
    case WrapModel::Neural:  // the network, or the smooth model outside its training box (wrap/network_model.hpp)
      return calcNeuralWrapModelPoints(options, surface, p1, p2, v1, v2, alphas, alphadots, velocity, out, network,
                                       with_alpha ? &out.x_alpha : nullptr, with_alpha ? &out.x_alphadot : nullptr,
                                       options.networkFor(wrap_name, wrapTypeName(surface.type)));
    case WrapModel::Exact:
      if (with_alpha || moving_alpha)
        throw std::logic_error("calcWrapModelPoints: the exact model has no derivative along the fraction");
      calcExactWrapPointsFd(surface, p1, p2, v1, v2, alphas, out, options.fd_step, velocity);
      return {};
  }
  throw std::logic_error("calcWrapModelPoints: unknown wrap model");
}

SmoothWrapLength calcWrapModelLength(const WrapMassOptions& options, const WrapSurface& surface, const Vec3& p1,
                                     const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot) {
  SmoothWrapOptions so;
  so.width = options.width;
  return calcSmoothWrapLength(surface, p1, p2, p1dot, p2dot, so);
}

std::vector<int> calcSegmentWraps(const Muscle& muscle, const std::vector<int>& active, const std::vector<Vec3>& x_w,
                                  const std::vector<Mat4>& E_wi) {
  const MusclePath& path = muscle.path;
  const int P = static_cast<int>(x_w.size());
  const int nseg = std::max(P - 1, 0);
  const int np = static_cast<int>(path.points.size());
  const int nw = static_cast<int>(path.wraps.size());
  const bool single_shape = path.points.size() == 2 && path.wraps.size() == 1;
  std::vector<int> seg_wrap(nseg, -1);
  for (int w = 0; w < nw; ++w) {
    const PathWrap& pw = path.wraps[w];
    if (!pw.surface.active) continue;
    int first = 0, last = 0;
    if (!wrapSegments(pw, active, np, first, last)) continue;
    // the surface frame's pose, as calcSurfaceMotion computes it
    const Mat4 E_ws = pw.body >= 0 ? Mat4(E_wi[pw.body] * pw.E_bs) : pw.E_bs;
    const Mat3 R = E_ws.topLeftCorner<3, 3>();
    const Vec3 p = E_ws.topRightCorner<3, 1>();
    int best = -1;
    double best_d = -std::numeric_limits<double>::infinity();
    for (int i = first; i < last; ++i) {
      if (seg_wrap[i] >= 0) continue;
      if (single_shape) {
        best = i;
        break;
      }
      const Vec3 p1 = R.transpose() * (x_w[i] - p), p2 = R.transpose() * (x_w[i + 1] - p);
      // OpenSim gives a segment with an end inside the surface no wrap (InsideRadius), and so do
      // we on general paths (the positions jump there as OpenSim's path does); on origin -> surface ->
      // insertion it stays a MuscleError (the dissertation's shape, where nothing else can wrap)
      if (endInsideSurface(pw.surface, p1, p2)) continue;
      if (last - first == 1) {
        best = i;
        break;
      }
      const double d = calcWrapPenetration(pw.surface, p1, p2);
      if (d > best_d) {
        best_d = d;
        best = i;
      }
    }
    if (best >= 0) seg_wrap[best] = w;
  }
  return seg_wrap;
}

namespace {

bool coversBody(const Model& model, const MuscleKinematics& mk, int b) {
  if (b < 0) return true;
  if (static_cast<int>(mk.col_of.size()) != model.nr()) return false;
  for (int j : model.ancestors(b))
    if (model.joints()[j].nq > 0 && mk.col_of[model.joints()[j].q_index] < 0) return false;
  return true;
}

void sizeMassPointOutputs(int N, int k, MuscleKinematics& mk) {
  mk.x_a.resize(N);
  mk.segment.assign(N, 0);
  mk.beta.assign(N, 0.0);
  if (mk.J_ar.rows() != 3 * N || mk.J_ar.cols() != k) mk.J_ar.resize(3 * N, k);
  if (mk.velocity && (mk.Jdot_ar.rows() != 3 * N || mk.Jdot_ar.cols() != k)) mk.Jdot_ar.resize(3 * N, k);
}

// the segment construction of the header (smooth model; exact model with one segment and one wrap)
void calcSegmentWrapMassPoints(const Model& model, const SkeletonWorkspace& sk, const Muscle& muscle,
                               MuscleKinematics& mk) {
  const MusclePath& path = muscle.path;
  if (mk.x_w.size() < 2) throw std::logic_error("calcWrapMassPoints: needs the path stage");
  // which wrap acts on which segment (header): the candidate penetrating most
  WrapStageScratch& sc = mk.wrap_scratch;
  sc.seg_wrap = calcSegmentWraps(muscle, mk.active, mk.x_w, sk.E_wi);
  // the surfaces' motion from the skeleton, for the wraps that act (every active one when
  // several may share a segment: the composition picks its own, wrap_composite.hpp)
  const bool compose = muscle.wrap.model == WrapModel::Smooth && hasSharedWrapSegments(muscle);
  const int nw = static_cast<int>(path.wraps.size());
  sc.surfaces.resize(nw);
  for (int w = 0; w < nw; ++w) {
    const bool acts = compose ? path.wraps[w].surface.active
                              : std::find(sc.seg_wrap.begin(), sc.seg_wrap.end(), w) != sc.seg_wrap.end();
    if (!acts) continue;
    if (!coversBody(model, mk, path.wraps[w].body))
      throw std::logic_error("calcWrapMassPoints: mk's columns do not cover the wrap body (initWrapMuscleColumns)");
    calcSurfaceMotion(model, sk, path.wraps[w], mk, mk.velocity, sc.surfaces[w], sc.J_mb, sc.Jdot_mb);
  }
  calcWrapMassPointsOnSurfaces(muscle, sc.seg_wrap, sc.surfaces, mk);
}

}  // namespace

void straightSegmentLengthRow(const MuscleKinematics& mk, int i, bool vel, VecX& L, VecX& Ld, MatX& J_L, MatX& Jdot_L) {
  // l = |dx|, dl/dq = dxbar^T (J_{i+1} - J_i) [D Eq. 5.18-5.19, 5.27-5.28]
  const Vec3& u = mk.dxbar[i];
  const auto dJ = mk.J_xr.middleRows<3>(3 * (i + 1)) - mk.J_xr.middleRows<3>(3 * i);
  L[i] = mk.l[i];
  J_L.row(i).noalias() = u.transpose() * dJ;
  if (vel && L[i] > 0.0) {
    const Vec3 dv = mk.xdot_w[i + 1] - mk.xdot_w[i];
    const Vec3 ud = (Mat3::Identity() - u * u.transpose()) * dv / L[i];
    Ld[i] = u.dot(dv);
    Jdot_L.row(i).noalias() = ud.transpose() * dJ;
    Jdot_L.row(i).noalias() +=
        u.transpose() * (mk.Jdot_xr.middleRows<3>(3 * (i + 1)) - mk.Jdot_xr.middleRows<3>(3 * i));
  }
}

void calcEulerianFromSegmentLengths(const VecX& L, const VecX& Ld, const MatX& J_L, const MatX& Jdot_L, bool vel,
                                    const std::string& muscle_name, MuscleKinematics& mk) {
  const int nseg = static_cast<int>(L.size()), P = nseg + 1;
  const int k = static_cast<int>(J_L.cols());
  const double Lam = L.sum();
  for (int i = 0; i < nseg; ++i)
    if (!(L[i] > 1e-12 * (1.0 + Lam)))
      throw MuscleError("muscle '" + muscle_name + "': path segment " + std::to_string(i) + " (between active points " +
                        std::to_string(mk.active[i]) + " and " + std::to_string(mk.active[i + 1]) +
                        ") has zero length here; mass points need distinct consecutive path points");
  const Eigen::RowVectorXd J_Lam = J_L.colwise().sum();
  const double Lamdot = Ld.sum();
  const Eigen::RowVectorXd Jdot_Lam = Jdot_L.colwise().sum();
  double S = 0.0, Sdot = 0.0;
  Eigen::RowVectorXd J_S = Eigen::RowVectorXd::Zero(k), Jdot_S = Eigen::RowVectorXd::Zero(k);
  for (int i = 1; i < P - 1; ++i) {
    S += L[i - 1];
    J_S += J_L.row(i - 1);
    // s_i Lam = S_i, differentiated once and twice (header)
    mk.s[i] = S / Lam;
    mk.J_sr.row(i) = (J_S - mk.s[i] * J_Lam) / Lam;
    if (!vel) continue;
    Sdot += Ld[i - 1];
    Jdot_S += Jdot_L.row(i - 1);
    mk.sdot[i] = (Sdot - mk.s[i] * Lamdot) / Lam;
    mk.Jdot_sr.row(i) = (Jdot_S - mk.s[i] * Jdot_Lam - mk.sdot[i] * J_Lam - Lamdot * mk.J_sr.row(i)) / Lam;
  }
}

void locateWrapMassPoints(const MassPoints& mp, MuscleKinematics& mk, std::vector<double>& betadot) {
  const int N = mp.size(), P = static_cast<int>(mk.s.size());
  sizeMassPointOutputs(N, static_cast<int>(mk.cols.size()), mk);
  betadot.assign(N, 0.0);
  for (int a = 0; a < N; ++a) {
    const double s_a = mp.alpha[a];
    int i = 0;
    while (i < P - 2 && mk.s[i + 1] <= s_a) ++i;
    const double ds = mk.s[i + 1] - mk.s[i];
    mk.segment[a] = i;
    mk.beta[a] = (s_a - mk.s[i]) / ds;
    if (mk.velocity) betadot[a] = -((1.0 - mk.beta[a]) * mk.sdot[i] + mk.beta[a] * mk.sdot[i + 1]) / ds;
  }
}

void calcStraightSegmentMassPoints(const std::vector<int>& seg_wrap, const std::vector<double>& betadot, MatX& J_zr,
                                   MatX& Jdot_zr, MuscleKinematics& mk) {
  const int k = static_cast<int>(mk.cols.size());
  const int N = static_cast<int>(mk.segment.size());
  const bool vel = mk.velocity;
  J_zr.resize(8, k);
  Jdot_zr.resize(8, k);
  for (int a = 0; a < N; ++a) {
    const int i = mk.segment[a];
    if (seg_wrap[i] >= 0) continue;
    const double beta = mk.beta[a];
    const double ds = mk.s[i + 1] - mk.s[i];
    const Vec3 F = (mk.x_w[i + 1] - mk.x_w[i]) / ds;  // [D Eq. 5.33]
    mk.x_a[a] = (1.0 - beta) * mk.x_w[i] + beta * mk.x_w[i + 1];  // [D Eq. 5.30]
    J_zr.topRows<3>() = mk.J_xr.middleRows<3>(3 * i);
    J_zr.middleRows<3>(3) = mk.J_xr.middleRows<3>(3 * (i + 1));
    J_zr.row(6) = mk.J_sr.row(i);
    J_zr.row(7) = mk.J_sr.row(i + 1);
    const Eigen::Matrix<double, 3, 8> J_az = calcJ_az(beta, F);  // [D Eq. 5.34, 5.36]
    mk.J_ar.middleRows<3>(3 * a).noalias() = J_az * J_zr;
    if (!vel) continue;
    const Vec3 Fdot = (mk.xdot_w[i + 1] - mk.xdot_w[i] - F * (mk.sdot[i + 1] - mk.sdot[i])) / ds;
    Jdot_zr.topRows<3>() = mk.Jdot_xr.middleRows<3>(3 * i);
    Jdot_zr.middleRows<3>(3) = mk.Jdot_xr.middleRows<3>(3 * (i + 1));
    Jdot_zr.row(6) = mk.Jdot_sr.row(i);
    Jdot_zr.row(7) = mk.Jdot_sr.row(i + 1);
    mk.Jdot_ar.middleRows<3>(3 * a).noalias() = calcJdot_az(beta, betadot[a], F, Fdot) * J_zr;
    mk.Jdot_ar.middleRows<3>(3 * a).noalias() += J_az * Jdot_zr;
  }
}

void calcWrapMassPointsOnSurfaces(const Muscle& muscle, const std::vector<int>& seg_wrap,
                                  const std::vector<WrapSurfaceMotion>& surfaces, MuscleKinematics& mk) {
  if (muscle.wrap.model == WrapModel::Smooth && hasSharedWrapSegments(muscle)) {
    calcCompositeWrapMassPointsOnSurfaces(muscle, surfaces, mk);  // several wraps on a segment
    return;
  }
  const MassPoints& mp = muscle.mass_points;
  const MusclePath& path = muscle.path;
  const int N = mp.size();
  const int k = static_cast<int>(mk.cols.size());
  const int P = static_cast<int>(mk.x_w.size());
  const int nseg = P - 1;
  const bool vel = mk.velocity;
  if (P < 2) throw std::logic_error("calcWrapMassPoints: needs the path stage");
  if (static_cast<int>(seg_wrap.size()) != nseg || surfaces.size() != path.wraps.size())
    throw std::invalid_argument("calcWrapMassPointsOnSurfaces: muscle '" + muscle.name + "': " +
                                std::to_string(seg_wrap.size()) + " segment wraps for " + std::to_string(nseg) +
                                " segments, " + std::to_string(surfaces.size()) + " surfaces for " +
                                std::to_string(path.wraps.size()) + " wrap objects");
  auto who = [&] { return "muscle '" + muscle.name + "'"; };  // built only for a message
  WrapStageScratch& sc = mk.wrap_scratch;
  if (static_cast<int>(sc.ends.size()) < nseg) sc.ends.resize(nseg);
  for (int i = 0; i < nseg; ++i)
    if (seg_wrap[i] >= 0) calcSegmentEnds(surfaces[seg_wrap[i]], mk, i, vel, sc.ends[i], sc.B, sc.T);

  // Eulerian coordinates s_i = S_i / sum L over the segment lengths (header); one segment: (0, 1)
  mk.s.setZero(P);
  mk.s[P - 1] = 1.0;
  mk.J_sr.setZero(P, k);
  mk.sdot.setZero(P);
  if (vel) mk.Jdot_sr.setZero(P, k);
  if (nseg > 1) {
    VecX& L = sc.L;
    VecX& Ld = sc.Ld;
    MatX& J_L = sc.J_L;
    MatX& Jdot_L = sc.Jdot_L;
    L.resize(nseg);
    Ld.setZero(nseg);
    J_L.resize(nseg, k);
    Jdot_L.setZero(nseg, k);
    for (int i = 0; i < nseg; ++i) {
      if (seg_wrap[i] < 0) {
        straightSegmentLengthRow(mk, i, vel, L, Ld, J_L, Jdot_L);
      } else {
        const int w = seg_wrap[i];
        const SegmentEnds& e = sc.ends[i];
        SmoothWrapLength sl;
        try {
          sl = calcWrapModelLength(muscle.wrap, path.wraps[w].surface, e.p1, e.p2, e.p1dot, e.p2dot);
        } catch (const std::invalid_argument& ex) {
          throw MuscleError(who() + ", wrap object '" + path.wraps[w].name + "': " + ex.what());
        }
        L[i] = sl.length;
        J_L.row(i).noalias() = sl.J.leftCols<3>() * e.A1;
        J_L.row(i).noalias() += sl.J.rightCols<3>() * e.A2;
        if (vel) {
          Ld[i] = sl.J.leftCols<3>().dot(e.p1dot) + sl.J.rightCols<3>().dot(e.p2dot);
          Jdot_L.row(i).noalias() = sl.Jdot.leftCols<3>() * e.A1;
          Jdot_L.row(i).noalias() += sl.Jdot.rightCols<3>() * e.A2;
          Jdot_L.row(i).noalias() += sl.J.leftCols<3>() * e.A1dot;
          Jdot_L.row(i).noalias() += sl.J.rightCols<3>() * e.A2dot;
        }
      }
    }
    calcEulerianFromSegmentLengths(L, Ld, J_L, Jdot_L, vel, muscle.name, mk);
  }

  // mass points: segment, beta and betadot [D Eq. 5.29, 5.31]
  std::vector<double>& betadot = sc.betadot;
  locateWrapMassPoints(mp, mk, betadot);

  // straight segments: Type II's EOL construction (via_point.hpp) with these s
  calcStraightSegmentMassPoints(seg_wrap, betadot, sc.stackJ, sc.stackD, mk);

  // wrapped segments: one batch per segment through the dispatch, then the chain rule (header)
  const bool moving_beta = nseg > 1;
  std::vector<int>& idx = sc.idx;
  std::vector<double>& betas = sc.betas;
  std::vector<double>& betadots = sc.betadots;
  WrapModelPoints& wp = sc.points;
  for (int i = 0; i < nseg; ++i) {
    const int w = seg_wrap[i];
    if (w < 0) continue;
    idx.clear();
    betas.clear();
    betadots.clear();
    for (int a = 0; a < N; ++a)
      if (mk.segment[a] == i) {
        idx.push_back(a);
        betas.push_back(mk.beta[a]);
        betadots.push_back(betadot[a]);
      }
    if (idx.empty()) continue;
    const PathWrap& pw = path.wraps[w];
    const WrapSurfaceMotion& m = surfaces[w];
    const SegmentEnds& e = sc.ends[i];
    try {
      const NetworkWrapEval ev = calcWrapModelPoints(muscle.wrap, pw.surface, e.p1, e.p2, e.p1dot, e.p2dot, betas,
                                                     betadots, moving_beta, vel, wp, mk.network, pw.name);
      if (muscle.wrap.model == WrapModel::Neural) mk.wrap_counts.record(ev, w);  // summed by callers
    } catch (const std::invalid_argument& ex) {
      throw MuscleError(who() + ", wrap object '" + pw.name + "': " + ex.what());
    }
    const Mat3& R = m.R;
    const double ds = mk.s[i + 1] - mk.s[i];
    const double dsdot = vel ? mk.sdot[i + 1] - mk.sdot[i] : 0.0;
    // the segment's rows stacked once, and its n points' coefficient rows stacked, so that the
    // segment's J_ar and Jdot_ar are one product each (the header's formulas, terms regrouped):
    //   J_ar    = [R Jw, -[Rw], I, R w_a c_i, R w_a c_i1] [A; J_om; J_p; J_s,i; J_s,i+1]
    //   Jdot_ar = [[omega] R Jw + R Jwdot, R Jw, -[Rwdot], -[Rw], I, (beta rows)]
    //             [A; Adot; J_om; Jdot_om; Jdot_p; J_s,i; J_s,i+1; Jdot_s,i; Jdot_s,i+1]
    // with A = [A_1; A_2] and J_beta = c_i J_s,i + c_i1 J_s,i+1 (c_i = -(1 - beta) / ds, c_i1 = -beta / ds)
    const int nb = moving_beta ? 2 : 0;
    const int n = static_cast<int>(idx.size());
    MatX& stackJ = sc.stackJ;
    MatX& stackD = sc.stackD;
    MatX& cJ = sc.coefJ;
    MatX& cD = sc.coefD;
    stackJ.resize(12 + nb, k);
    stackJ.topRows(12) << e.A1, e.A2, m.J_om, m.J_p;
    if (moving_beta) stackJ.bottomRows(2) << mk.J_sr.row(i), mk.J_sr.row(i + 1);
    cJ.resize(3 * n, 12 + nb);
    if (vel) {
      stackD.resize(21 + 2 * nb, k);
      stackD.topRows(21) << e.A1, e.A2, e.A1dot, e.A2dot, m.J_om, m.Jdot_om, m.Jdot_p;
      if (moving_beta) stackD.bottomRows(4) << mk.J_sr.row(i), mk.J_sr.row(i + 1), mk.Jdot_sr.row(i), mk.Jdot_sr.row(i + 1);
      cD.resize(3 * n, 21 + 2 * nb);
    }
    const Mat3 WR = skew(m.omega) * R;
    for (int j = 0; j < n; ++j) {
      const int a = idx[j];
      const double beta = betas[j];
      const Vec3 Rw = R * wp.x[j];
      mk.x_a[a] = Rw + m.p;
      const Eigen::Matrix<double, 3, 6> RJw = R * wp.J[j];
      auto rJ = cJ.middleRows<3>(3 * j);
      rJ.leftCols<6>() = RJw;
      rJ.middleCols<3>(6) = -skew(Rw);
      rJ.middleCols<3>(9).setIdentity();
      const double ci = -(1.0 - beta) / ds, ci1 = -beta / ds;
      Vec3 Rwa = Vec3::Zero();
      if (moving_beta) {
        Rwa = R * wp.x_alpha[j];
        rJ.col(12) = ci * Rwa;
        rJ.col(13) = ci1 * Rwa;
      }
      if (!vel) continue;
      Vec3 wdot = wp.J[j].leftCols<3>() * e.p1dot + wp.J[j].rightCols<3>() * e.p2dot;
      const double bd = moving_beta ? betadots[j] : 0.0;
      if (moving_beta) wdot += wp.x_alpha[j] * bd;
      const Vec3 Rwdot = m.omega.cross(Rw) + R * wdot;
      auto rD = cD.middleRows<3>(3 * j);
      rD.leftCols<6>() = WR * wp.J[j] + R * wp.Jdot[j];
      rD.middleCols<6>(6) = RJw;
      rD.middleCols<3>(12) = -skew(Rwdot);
      rD.middleCols<3>(15) = -skew(Rw);
      rD.middleCols<3>(18).setIdentity();
      if (moving_beta) {
        // (WR w_a + R w_adot) J_beta + R w_a Jdot_beta, with Jdot_beta = c_i Jdot_s,i + c_i1 Jdot_s,i+1
        //   - (dsdot J_beta + bd (J_s,i+1 - J_s,i)) / ds
        const Vec3 cw = WR * wp.x_alpha[j] + R * wp.x_alphadot[j];
        rD.col(21) = ci * cw - (dsdot * ci - bd) / ds * Rwa;
        rD.col(22) = ci1 * cw - (dsdot * ci1 + bd) / ds * Rwa;
        rD.col(23) = ci * Rwa;
        rD.col(24) = ci1 * Rwa;
      }
    }
    // the points of a segment are consecutive rows of J_ar when alpha increases (makeMassPoints);
    // otherwise the products go through a buffer. A matrix-vector product per column: k is a
    // muscle's few coordinates, where a general product's packing of the 3n rows costs more
    // than the product (measured, docs/performance.md §7)
    const bool consecutive = idx.back() - idx.front() == n - 1;
    auto product = [&](const MatX& coef, const MatX& stack, MatX& buffer, MatX& out) {
      if (consecutive) {
        auto rows = out.middleRows(3 * idx.front(), 3 * n);
        for (int c = 0; c < k; ++c) rows.col(c).noalias() = coef * stack.col(c);
        return;
      }
      buffer.resize(3 * n, k);
      for (int c = 0; c < k; ++c) buffer.col(c).noalias() = coef * stack.col(c);
      for (int j = 0; j < n; ++j) out.middleRows<3>(3 * idx[j]) = buffer.middleRows<3>(3 * j);
    };
    product(cJ, stackJ, sc.outJ, mk.J_ar);
    if (vel) product(cD, stackD, sc.outD, mk.Jdot_ar);
  }
}

namespace {

// the exact model on any path: OpenSim's whole wrapped path, J and Jdot by differences in q (header)
void calcExactPathMassPointsFd(const Model& model, const State& state, const Muscle& muscle, MuscleKinematics& mk) {
  const MassPoints& mp = muscle.mass_points;
  const int N = mp.size();
  const int k = static_cast<int>(mk.cols.size());
  const bool vel = mk.velocity;
  sizeMassPointOutputs(N, k, mk);
  std::vector<Mat4> E_wi;
  auto eval = [&](const VecX& q, std::vector<Vec3>& xs, bool locate) {
    calcBodyPoses(model, q, E_wi);
    const WrappedPath wp = calcWrappedPath(model, muscle.path, q, E_wi);
    xs.resize(N);
    for (int a = 0; a < N; ++a) {
      xs[a] = calcWrappedPathPointWorld(muscle.path, wp, E_wi, mp.alpha[a]);
      if (locate) locateOnWrappedPath(wp, mp.alpha[a], mk.segment[a], mk.beta[a]);
    }
    if (!locate) return;
    // s: arc fractions of the active points along the wrapped path (no J_sr, sdot on this route)
    std::vector<double> s_pts;
    double acc = 0.0;
    for (size_t i = 0; i < wp.points.size(); ++i) {
      if (i > 0) {
        const auto &a = wp.points[i - 1], &b = wp.points[i];
        acc += (a.wrap >= 0 && a.wrap == b.wrap) ? wp.results[a.wrap].arcLength() : (b.x_w - a.x_w).norm();
      }
      if (wp.points[i].point >= 0) s_pts.push_back(acc);
    }
    mk.s.resize(static_cast<int>(s_pts.size()));
    for (size_t i = 0; i < s_pts.size(); ++i) mk.s[i] = acc > 0.0 ? s_pts[i] / acc : 0.0;
  };
  eval(state.q, mk.x_a, true);
  // steps in q (rad or m): central differences for J, a wider mixed stencil for Jdot (its round-off
  // is divided by the product of two steps: ~1e-16 |x| |qdot| / s^2, 1e-6 here). Not wider: with
  // several wraps OpenSim's tangency iterations and passes make the path only piecewise smooth at
  // a fine scale, and a 2e-4 stencil straddled such kinks on Rajagopal's gastrocnemii (O(1) errors)
  const double h = 1e-6, s = 1e-5;
  std::vector<Vec3> xp, xm, xpp, xpm, xmp, xmm;
  VecX q = state.q;
  for (int j = 0; j < k; ++j) {
    const int c = mk.cols[j];
    q[c] = state.q[c] + h;
    eval(q, xp, false);
    q[c] = state.q[c] - h;
    eval(q, xm, false);
    q[c] = state.q[c];
    for (int a = 0; a < N; ++a) mk.J_ar.block<3, 1>(3 * a, j) = (xp[a] - xm[a]) / (2.0 * h);
  }
  if (!vel) return;
  mk.Jdot_ar.setZero();
  VecX v = VecX::Zero(state.q.size());
  for (int j = 0; j < k; ++j) v[mk.cols[j]] = state.qdot[mk.cols[j]];
  const double speed = v.norm();
  if (!(speed > 0.0)) return;
  const double tau = s / speed;
  for (int j = 0; j < k; ++j) {
    const int c = mk.cols[j];
    VecX e = VecX::Zero(state.q.size());
    e[c] = s;
    eval(state.q + e + tau * v, xpp, false);
    eval(state.q + e - tau * v, xpm, false);
    eval(state.q - e + tau * v, xmp, false);
    eval(state.q - e - tau * v, xmm, false);
    for (int a = 0; a < N; ++a)
      mk.Jdot_ar.block<3, 1>(3 * a, j) = (xpp[a] - xpm[a] - xmp[a] + xmm[a]) / (4.0 * s * tau);
  }
}

// origin -> one surface -> insertion: the exact model's end-point differences (the dissertation's)
bool isSingleSegmentShape(const Muscle& muscle) {
  return muscle.path.points.size() == 2 && muscle.path.wraps.size() == 1;
}

}  // namespace

void calcWrapMassPoints(const Model& model, const State& state, const SkeletonWorkspace& sk, const Muscle& muscle,
                        MuscleKinematics& mk) {
  const std::string why = wrapMassPointsUnsupportedReason(muscle);
  if (!why.empty()) throw std::logic_error("muscle '" + muscle.name + "': " + why);
  if (muscle.wrap.model == WrapModel::Exact && !isSingleSegmentShape(muscle)) {
    calcExactPathMassPointsFd(model, state, muscle, mk);
    return;
  }
  calcSegmentWrapMassPoints(model, sk, muscle, mk);
}

void calcWrapMassPoints(const Model& model, const SkeletonWorkspace& sk, const Muscle& muscle, MuscleKinematics& mk) {
  const std::string why = wrapMassPointsUnsupportedReason(muscle);
  if (!why.empty()) throw std::logic_error("muscle '" + muscle.name + "': " + why);
  if (muscle.wrap.model == WrapModel::Exact && !isSingleSegmentShape(muscle))
    throw std::logic_error("calcWrapMassPoints: muscle '" + muscle.name +
                           "': the exact model on this path needs the state (the overload taking it)");
  calcSegmentWrapMassPoints(model, sk, muscle, mk);
}

}  // namespace redmax
