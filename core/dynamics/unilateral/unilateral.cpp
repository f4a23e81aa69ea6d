#include "core/dynamics/unilateral/unilateral.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/dynamics/constraints/body_point.hpp"
#include "core/dynamics/unilateral/qp_solver.hpp"

namespace redmax {
namespace {

Mat4 worldPose(const SkeletonWorkspace& sk, const CollisionGeometry& g) {
  return g.body < 0 ? g.X_body : Mat4(sk.E_wi[g.body] * g.X_body);
}

// the sphere centres (radius r) or surface points (radius 0) a shape offers to a half-space of
// outward normal n, world
void shapePoints(const CollisionGeometry& g, const Mat4& X, const Vec3& n, std::vector<Vec3>& pts, double& r) {
  pts.clear();
  const Vec3 o = X.topRightCorner<3, 1>();
  const Mat3 R = X.topLeftCorner<3, 3>();
  switch (g.shape) {
    case CollisionShape::Ellipsoid: {
      // the support point along -n: x = o + R A u with |u| = 1 minimising n . x, u = -A R^T n / |A R^T n|
      const Vec3 An = g.half_extents.cwiseProduct(R.transpose() * n);
      pts.push_back(o - R * (g.half_extents.cwiseProduct(An) / An.norm()));
      r = 0.0;
      break;
    }
    case CollisionShape::Sphere:
      pts.push_back(o);
      r = g.radius;
      break;
    case CollisionShape::Capsule:
      pts.push_back(o - g.half_length * R.col(0));
      pts.push_back(o + g.half_length * R.col(0));
      r = g.radius;
      break;
    case CollisionShape::Box:
      for (int k = 0; k < 8; ++k) {
        const Vec3 s((k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0, (k & 4) ? 1.0 : -1.0);
        pts.push_back(o + R * s.cwiseProduct(g.half_extents));
      }
      r = 0.0;
      break;
    case CollisionShape::HalfSpace:
      break;
  }
}

long rowKey(const UnilateralRows::Candidate& c) {
  return (c.limit ? (1L << 40) : 0L) | (static_cast<long>(c.source) << 8) | c.sub;
}

const char* shapeName(CollisionShape s) {
  switch (s) {
    case CollisionShape::Sphere: return "sphere";
    case CollisionShape::Capsule: return "capsule";
    case CollisionShape::Box: return "box";
    case CollisionShape::HalfSpace: return "half-space";
    case CollisionShape::Ellipsoid: return "ellipsoid";
  }
  return "?";
}

// the contact points of a pair (a: half-space, sphere or capsule; b: the other) at world poses
// Xa, Xb: (point, gap) with the normal n from a into b
void pairContacts(const CollisionGeometry& ga, const CollisionGeometry& gb, const Mat4& Xa, const Mat4& Xb,
                  std::vector<std::pair<Vec3, double>>& contacts, Vec3& n, std::vector<Vec3>& pts) {
  contacts.clear();
  if (ga.shape == CollisionShape::HalfSpace) {
    n = -Xa.topLeftCorner<3, 3>().col(0);
    const Vec3 o_a = Xa.topRightCorner<3, 1>();
    double r = 0.0;
    shapePoints(gb, Xb, n, pts, r);
    for (const Vec3& c : pts) contacts.emplace_back(c - r * n, n.dot(c - o_a) - r);
    return;
  }
  // sphere or capsule a against sphere b: a's nearest point to b's centre (the capsule's axis
  // segment clamped), then two spheres
  Vec3 ca = Xa.topRightCorner<3, 1>();
  const Vec3 cb = Xb.topRightCorner<3, 1>();
  if (ga.shape == CollisionShape::Capsule) {
    const Vec3 axis = Xa.topLeftCorner<3, 3>().col(0);
    const double t = std::clamp(axis.dot(cb - ca), -ga.half_length, ga.half_length);
    ca += t * axis;
  }
  const Vec3 dlt = cb - ca;
  const double dist = dlt.norm();
  n = dist > 1e-12 ? Vec3(dlt / dist) : Vec3::UnitY();
  const double gap = dist - ga.radius - gb.radius;
  contacts.emplace_back(ca + (ga.radius + 0.5 * gap) * n, gap);
}

}  // namespace

UnilateralConstraints::UnilateralConstraints(const Model& model, std::vector<CollisionGeometry> geometry,
                                             std::vector<CollisionPair> pairs, std::vector<JointLimit> limits,
                                             UnilateralOptions options)
    : geometry_(std::move(geometry)), pairs_(std::move(pairs)), limits_(std::move(limits)), options_(options) {
  for (const auto& g : geometry_) {
    detail::checkBodyIndex(model, g.body, "collision geometry " + g.name);
    if (!(g.radius >= 0.0) || !(g.half_length >= 0.0) || !(g.half_extents.minCoeff() >= 0.0) ||
        !g.X_body.allFinite())
      throw ModelError("collision geometry " + g.name + ": negative or non-finite size or frame");
    if ((g.shape == CollisionShape::Sphere || g.shape == CollisionShape::Capsule) && !(g.radius > 0.0))
      throw ModelError("collision geometry " + g.name + ": radius must be positive");
    if (g.shape == CollisionShape::Ellipsoid && !(g.half_extents.minCoeff() > 0.0))
      throw ModelError("collision geometry " + g.name + ": the ellipsoid's semi-axes must be positive");
  }
  const int ng = static_cast<int>(geometry_.size());
  for (auto& p : pairs_) {
    if (p.first < 0 || p.first >= ng || p.second < 0 || p.second >= ng)
      throw ModelError("collision pair: geometry index out of range");
    // the half-space first, a capsule before a sphere
    if (geometry_[p.second].shape == CollisionShape::HalfSpace ||
        (geometry_[p.second].shape == CollisionShape::Capsule && geometry_[p.first].shape == CollisionShape::Sphere))
      std::swap(p.first, p.second);
    const CollisionGeometry &a = geometry_[p.first], &b = geometry_[p.second];
    const std::string what = "collision pair " + a.name + " - " + b.name;
    const bool ok = (a.shape == CollisionShape::HalfSpace && b.shape != CollisionShape::HalfSpace) ||
                    (a.shape == CollisionShape::Sphere && b.shape == CollisionShape::Sphere) ||
                    (a.shape == CollisionShape::Capsule && b.shape == CollisionShape::Sphere);
    if (!ok)
      throw ModelError(what + ": " + shapeName(a.shape) + " against " + shapeName(b.shape) +
                       " is not supported (half-space with sphere, capsule, box or ellipsoid; sphere with sphere or "
                       "capsule)");
    if (a.body == b.body) throw ModelError(what + ": both on one body");
    if (!(p.friction >= 0.0) || !std::isfinite(p.friction)) throw ModelError(what + ": friction must be >= 0");
    if (!(p.restitution >= 0.0 && p.restitution <= 1.0)) throw ModelError(what + ": restitution must be in [0, 1]");
  }
  for (const auto& l : limits_) {
    if (l.coordinate < 0 || l.coordinate >= model.nr())
      throw ModelError("joint limit " + l.name + ": coordinate index out of range");
    if (!(l.lower <= l.upper)) throw ModelError("joint limit " + l.name + ": lower bound above upper bound");
    if (!(l.restitution >= 0.0 && l.restitution <= 1.0))
      throw ModelError("joint limit " + l.name + ": restitution must be in [0, 1]");
  }
  const auto& o = options_;
  if (!(o.stabilization >= 0.0 && o.stabilization <= 1.0) || !(o.slop >= 0.0) || !(o.restitution_threshold >= 0.0) ||
      !(o.margin >= 0.0) || !(o.regularization > 0.0) || o.friction_iterations < 1 || !(o.friction_tolerance > 0.0))
    throw ModelError("unilateral options out of range");
}

void UnilateralConstraints::detect(const Model& model, const State& s, const SkeletonWorkspace& sk, int ndof,
                                   double h, UnilateralRows& out, const Subset* only) const {
  const auto& o = options_;
  const int nr = model.nr();
  out.c.clear();
  out.max_penetration = 0.0;
  out.h = h;
  std::vector<VecX> jn, jt;
  auto add = [&](UnilateralRows::Candidate c, const VecX& row_n, double vn, double e, const VecX* t1,
                 const VecX* t2) {
    out.max_penetration = std::max(out.max_penetration, -c.gap);
    if (row_n.squaredNorm() == 0.0) return;  // moves nothing (both sides fixed)
    c.approach = vn;
    c.target = c.gap >= 0.0 ? -c.gap / h : o.stabilization * std::max(0.0, -c.gap - o.slop) / h;
    if (e > 0.0 && vn < -o.restitution_threshold && c.gap + h * vn < 0.0) c.target = std::max(c.target, -e * vn);
    if (t1 && c.mu > 0.0) {
      c.tangent_row = static_cast<int>(jt.size());
      jt.push_back(*t1);
      jt.push_back(*t2);
    } else {
      c.mu = 0.0;
    }
    jn.push_back(row_n);
    out.c.push_back(c);
  };

  // joint limits: reduced rows +-e_i
  for (size_t i = 0; i < limits_.size(); ++i) {
    if (only && !only->limits[i]) continue;
    const JointLimit& l = limits_[i];
    const int k = l.coordinate;
    for (int side = 0; side < 2; ++side) {
      UnilateralRows::Candidate c;
      c.limit = true;
      c.source = static_cast<int>(i);
      c.sub = side;
      const double sign = side == 0 ? 1.0 : -1.0;
      c.gap = side == 0 ? s.q[k] - l.lower : l.upper - s.q[k];
      VecX row = VecX::Zero(ndof);
      row[k] = sign;
      add(c, row, sign * s.qdot[k], l.restitution, nullptr, nullptr);
    }
  }

  // collisions: maximal rows n^T (J_b(p) - J_a(p))
  const VecX qdot_r = s.qdot.head(nr);
  detail::PointKinematics ka, kb;
  std::vector<Vec3> pts;
  for (size_t i = 0; i < pairs_.size(); ++i) {
    if (only && !only->pairs[i]) continue;
    const CollisionPair& p = pairs_[i];
    const CollisionGeometry &ga = geometry_[p.first], &gb = geometry_[p.second];
    const Mat4 Xa = worldPose(sk, ga), Xb = worldPose(sk, gb);
    std::vector<std::pair<Vec3, double>> contacts;  // (contact point, gap) with the normal n
    Vec3 n;
    pairContacts(ga, gb, Xa, Xb, contacts, n, pts);
    // tangents: world x projected on the plane (z if x is nearly normal), and n x t1
    Vec3 t1 = Vec3::UnitX() - n.x() * n;
    if (t1.norm() < 0.1) t1 = Vec3::UnitZ() - n.z() * n;
    t1.normalize();
    const Vec3 t2 = n.cross(t1);
    for (size_t k = 0; k < contacts.size(); ++k) {
      const Vec3& pw = contacts[k].first;
      auto local = [&](int body) {
        return body < 0 ? pw : Vec3(transformPoint(inverseE(sk.E_wi[body]), pw));
      };
      detail::calcPointKinematics(model, sk, qdot_r, ga.body, local(ga.body), ka);
      detail::calcPointKinematics(model, sk, qdot_r, gb.body, local(gb.body), kb);
      const Eigen::Matrix<double, 3, Eigen::Dynamic> dJ = kb.J - ka.J;
      VecX rn = VecX::Zero(ndof), r1 = VecX::Zero(ndof), r2 = VecX::Zero(ndof);
      rn.head(nr) = dJ.transpose() * n;
      r1.head(nr) = dJ.transpose() * t1;
      r2.head(nr) = dJ.transpose() * t2;
      UnilateralRows::Candidate c;
      c.source = static_cast<int>(i);
      c.sub = static_cast<int>(k);
      c.gap = contacts[k].second;
      c.mu = p.friction;
      c.point = pw;
      c.normal = n;
      add(c, rn, n.dot(kb.v - ka.v), p.restitution, &r1, &r2);
    }
  }
  out.Jn.resize(static_cast<int>(jn.size()), ndof);
  for (size_t k = 0; k < jn.size(); ++k) out.Jn.row(static_cast<int>(k)) = jn[k].transpose();
  out.Jt.resize(static_cast<int>(jt.size()), ndof);
  for (size_t k = 0; k < jt.size(); ++k) out.Jt.row(static_cast<int>(k)) = jt[k].transpose();
}

std::vector<double> UnilateralConstraints::gaps(const Model& model, const State& s,
                                                const SkeletonWorkspace& sk) const {
  (void)model;
  std::vector<double> out;
  for (const auto& l : limits_) {
    out.push_back(s.q[l.coordinate] - l.lower);
    out.push_back(l.upper - s.q[l.coordinate]);
  }
  std::vector<Vec3> pts;
  std::vector<std::pair<Vec3, double>> contacts;
  Vec3 n;
  for (const auto& p : pairs_) {
    const CollisionGeometry &ga = geometry_[p.first], &gb = geometry_[p.second];
    pairContacts(ga, gb, worldPose(sk, ga), worldPose(sk, gb), contacts, n, pts);
    for (const auto& c : contacts) out.push_back(c.second);
  }
  return out;
}

VecX solveUnilateralStep(const MatX& A, const VecX& a, const MatX& G, const VecX& b, const UnilateralRows& all,
                         const UnilateralOptions& opt, UnilateralWarmStart* warm, VecX* mu_bilateral,
                         UnilateralStepStats* stats) {
  const int n = static_cast<int>(A.rows()), mb = static_cast<int>(G.rows());
  // the constrained inverse W of A (bilateral rows eliminated by their Schur complement, redundant
  // rows by a complete orthogonal decomposition, as System::solveKKT)
  Eigen::PartialPivLU<MatX> lu(A);
  MatX AiGt;
  Eigen::CompleteOrthogonalDecomposition<MatX> cod;
  VecX vf = lu.solve(a);
  VecX Lf;
  if (mb > 0) {
    AiGt = lu.solve(G.transpose());
    cod.compute(G * AiGt);
    Lf = cod.solve(G * vf - b);
    vf.noalias() -= AiGt * Lf;
  }
  // the rows that can close within the step, at the start's or the free step's velocity
  const VecX wf_all = all.Jn * vf;
  std::vector<int> keep;
  for (int i = 0; i < static_cast<int>(all.c.size()); ++i)
    if (all.c[i].gap + all.h * std::min({0.0, all.c[i].approach, wf_all[i]}) < opt.margin) keep.push_back(i);
  // Rows left out can still close: the impulses of the others move their coordinates (a limit's
  // impulse throws a neighbouring joint into its own limit). After each solve the rows the
  // result would close join the set and it is solved again (at most once per row).
  std::vector<char> in_set(all.c.size(), 0);
  for (int i : keep) in_set[i] = 1;
  int rounds_qp = 0, rounds_friction = 0;
  for (;;) {
  const int kn = static_cast<int>(keep.size());
  if (kn == 0) {
    if (mu_bilateral) *mu_bilateral = mb > 0 ? Lf : VecX();
    if (stats) *stats = UnilateralStepStats{};
    if (warm) warm->active_keys.clear();
    return vf;
  }
  UnilateralRows rows;
  int kt = 0;
  for (int i : keep) kt += all.c[i].tangent_row >= 0 ? 2 : 0;
  rows.c.reserve(kn);
  rows.Jn.resize(kn, n);
  rows.Jt.resize(kt, n);
  for (int j = 0, t = 0; j < kn; ++j) {
    rows.c.push_back(all.c[keep[j]]);
    rows.Jn.row(j) = all.Jn.row(keep[j]);
    if (rows.c[j].tangent_row >= 0) {
      rows.Jt.middleRows(t, 2) = all.Jt.middleRows(rows.c[j].tangent_row, 2);
      rows.c[j].tangent_row = t;
      t += 2;
    }
  }
  const int m = kn + kt;
  MatX Jall(m, n);
  Jall.topRows(kn) = rows.Jn;
  if (kt > 0) Jall.bottomRows(kt) = rows.Jt;
  MatX X = lu.solve(Jall.transpose());  // W J^T
  MatX L;                               // bilateral multipliers per unit contact impulse
  if (mb > 0) {
    L = cod.solve(G * X);
    X.noalias() -= AiGt * L;
  }
  MatX Wc = Jall * X;
  Wc = 0.5 * (Wc + Wc.transpose()).eval();
  const VecX bc = Jall * vf;               // contact velocities without impulses
  double mean_diag = Wc.diagonal().head(kn).mean();
  if (!(mean_diag > 0.0)) mean_diag = 1.0;
  const double eps = opt.regularization * mean_diag;

  VecX target(kn);
  for (int i = 0; i < kn; ++i) target[i] = rows.c[i].target;

  // frictionless QP first (bounds for the friction iterations), warm-started from the last step
  std::vector<int> warm_idx;
  if (warm) {
    std::unordered_map<long, int> idx;
    for (int i = 0; i < kn; ++i) idx[rowKey(rows.c[i])] = i;
    for (long key : warm->active_keys) {
      auto it = idx.find(key);
      if (it != idx.end()) warm_idx.push_back(it->second);
    }
  }
  UnilateralStepStats st;
  st.candidates = kn;
  QpProblem qp;
  qp.H = Wc.topLeftCorner(kn, kn) + eps * MatX::Identity(kn, kn);
  qp.g = bc.head(kn) - target;
  qp.C = MatX::Identity(kn, kn);
  qp.d = VecX::Zero(kn);
  QpOptions qo;
  qo.warm_active = &warm_idx;
  QpResult r = solveQp(qp, qo);
  st.qp_iterations += r.iterations;
  st.friction_iterations = 1;
  VecX p = VecX::Zero(m);
  p.head(kn) = r.x;
  std::vector<int> active_normals = r.active;

  if (kt > 0) {
    VecX pbar = r.x.cwiseMax(0.0);
    std::vector<int> prev_active, prev_sel;
    st.friction_converged = false;
    for (int it = 0; it < opt.friction_iterations; ++it) {
      // friction variables of the contacts with a positive bound
      std::vector<int> sel;  // rows of Jt (indices into kt)
      std::vector<double> bound;
      for (int i = 0; i < kn; ++i) {
        const auto& c = rows.c[i];
        if (c.tangent_row < 0) continue;
        const double beta = c.mu * pbar[i];
        if (beta <= 1e-14 * (1.0 + pbar.cwiseAbs().maxCoeff())) continue;
        sel.push_back(c.tangent_row);
        sel.push_back(c.tangent_row + 1);
        bound.push_back(beta);
        bound.push_back(beta);
      }
      const int ns = static_cast<int>(sel.size()), nv = kn + ns;
      std::vector<int> var(nv);  // contact-space index of each variable
      for (int i = 0; i < kn; ++i) var[i] = i;
      for (int j = 0; j < ns; ++j) var[kn + j] = kn + sel[j];
      QpProblem q;
      q.H.resize(nv, nv);
      q.g.resize(nv);
      for (int i = 0; i < nv; ++i) {
        q.g[i] = bc[var[i]] - (i < kn ? target[i] : 0.0);
        for (int j = 0; j < nv; ++j) q.H(i, j) = Wc(var[i], var[j]);
      }
      q.H.diagonal().array() += eps;
      q.C = MatX::Zero(kn + 2 * ns, nv);
      q.d = VecX::Zero(kn + 2 * ns);
      for (int i = 0; i < kn; ++i) q.C(i, i) = 1.0;
      for (int j = 0; j < ns; ++j) {
        q.C(kn + 2 * j, kn + j) = 1.0;   // p_t >= -beta
        q.d[kn + 2 * j] = -bound[j];
        q.C(kn + 2 * j + 1, kn + j) = -1.0;  // -p_t >= -beta
        q.d[kn + 2 * j + 1] = -bound[j];
      }
      QpOptions o2;
      if (sel == prev_sel) o2.warm_active = &prev_active;
      else o2.warm_active = &active_normals;
      const QpResult rf = solveQp(q, o2);
      st.qp_iterations += rf.iterations;
      ++st.friction_iterations;
      p.setZero();
      for (int i = 0; i < nv; ++i) p[var[i]] = rf.x[i];
      const VecX pn = rf.x.head(kn).cwiseMax(0.0);
      const double change = (pn - pbar).cwiseAbs().maxCoeff();
      pbar = pn;
      prev_active = rf.active;
      prev_sel = sel;
      active_normals.clear();
      for (int k : rf.active)
        if (k < kn) active_normals.push_back(k);
      if (change <= opt.friction_tolerance * std::max(pn.cwiseAbs().maxCoeff(), 1e-300)) {
        st.friction_converged = true;
        break;
      }
    }
  }
  const VecX v = vf + X * p;
  {
    const VecX w_all = all.Jn * v;
    bool added = false;
    for (int i = 0; i < static_cast<int>(all.c.size()); ++i)
      if (!in_set[i] && all.c[i].gap + all.h * std::min({0.0, all.c[i].approach, w_all[i]}) < opt.margin) {
        keep.push_back(i);
        in_set[i] = 1;
        added = true;
      }
    rounds_qp += st.qp_iterations;
    rounds_friction += st.friction_iterations;
    if (added) {
      std::sort(keep.begin(), keep.end());
      continue;
    }
  }
  st.qp_iterations = rounds_qp;
  st.friction_iterations = rounds_friction;
  for (int i = 0; i < kn; ++i) st.contacts += p[i] > 0.0;
  if (warm) {
    warm->active_keys.clear();
    for (int k : active_normals) warm->active_keys.push_back(rowKey(rows.c[k]));
  }
  if (mu_bilateral) {
    if (mb > 0) *mu_bilateral = Lf + L * p;
    else mu_bilateral->resize(0);
  }
  if (stats) *stats = st;
  return v;
  }
}

}  // namespace redmax
