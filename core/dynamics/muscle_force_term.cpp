#include "core/dynamics/muscle_force_term.hpp"

#include <cmath>

#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax {

MuscleForceTerm::MuscleForceTerm(const Model& model, const std::vector<Muscle>& muscles,
                                 const std::vector<std::shared_ptr<const hill::MuscleModel>>& models) {
  if (muscles.size() != models.size())
    throw ModelError("MuscleForceTerm: " + std::to_string(muscles.size()) + " muscles but " +
                     std::to_string(models.size()) + " muscle models");
  for (size_t k = 0; k < muscles.size(); ++k) {
    if (!models[k]) continue;
    validatePath(model, muscles[k].path, muscles[k].name);
    Actuated a;
    a.muscle = muscles[k];
    a.muscle.mass_points = MassPoints{};  // the inertia is MuscleTerm's
    a.model = models[k];
    a.z_offset = nz_;
    nz_ += a.model->numStates();
    actuated_.push_back(std::move(a));
  }
}

std::unique_ptr<TermScratch> MuscleForceTerm::makeScratch(const Model& model) const {
  if (actuated_.empty()) return nullptr;
  auto sc = std::make_unique<MuscleForceScratch>();
  sc->muscles.resize(actuated_.size());
  for (size_t k = 0; k < actuated_.size(); ++k) {
    initMuscleKinematics(model, actuated_[k].muscle.path, sc->muscles[k].mk);
    sc->muscles[k].zdot.setZero(actuated_[k].model->numStates());
  }
  sc->E_wi.resize(model.nb());
  return sc;
}

std::vector<std::string> MuscleForceTerm::stateNames() const {
  std::vector<std::string> names;
  for (const Actuated& a : actuated_)
    for (const std::string& n : a.model->stateNames()) names.push_back("/forceset/" + a.muscle.name + "/" + n);
  return names;
}

std::vector<std::string> MuscleForceTerm::controlNames() const {
  std::vector<std::string> names;
  for (const Actuated& a : actuated_) names.push_back(a.muscle.name);
  return names;
}

void MuscleForceTerm::defaultStates(const Model&, Eigen::Ref<VecX> z) const {
  for (const Actuated& a : actuated_)
    if (a.model->numStates() > 0) a.model->defaultState(z.data() + a.z_offset);
}

void MuscleForceTerm::evalPath(const Model& model, const State& s, const SkeletonWorkspace& sk, int k,
                               MuscleForceScratch& sc) const {
  const MusclePath& path = actuated_[k].muscle.path;
  MuscleForceScratch::Entry& e = sc.muscles[k];
  MuscleKinematics& mk = e.mk;
  if (path.wraps.empty()) {
    // polyline: l = sum_i |x_i+1 - x_i|, dl/dq = sum_i dxbar_i^T (J_x,i+1 - J_x,i)   [D Eq. 5.18-5.19],
    // applied as OpenSim's GeometryPath::produceForces applies the tension: along each segment whose
    // ends lie on different bodies only (a segment within one body applies nothing, even where a
    // MovingPathPoint changes its length), and a MovingPathPoint's own term dP/dq . direction taken
    // at its coordinate's unclamped value (getdPointdQ), while its location is clamped to the
    // coordinate's range; the lengthening speed likewise (getVelocity, every segment). Inside the
    // range and without such same-body segments this is -dl/dq exactly (docs/forward.md §3).
    calcPathPoints(model, s, sk, path, mk, true);
    const int kc = static_cast<int>(mk.J_xr.cols());
    const int P = static_cast<int>(mk.active.size());
    // what carries point a: its body (-1 the world), or for a deformable node the node itself
    auto body = [&](int a) {
      const PathPoint& pt = path.points[mk.active[a]];
      return pt.kind == PathPointKind::Node ? -2 - pt.coordinate : pt.body;
    };
    e.dl_dq.setZero(kc);
    for (int i = 0; i + 1 < P; ++i)
      if (body(i) != body(i + 1))
        e.dl_dq.noalias() += (mk.J_xr.middleRows<3>(3 * (i + 1)) - mk.J_xr.middleRows<3>(3 * i)).transpose() * mk.dxbar[i];
    e.length = mk.length;
    e.speed = mk.lengthening_speed;
    for (int a = 0; a < P; ++a) {
      const PathPoint& pt = path.points[mk.active[a]];
      if (pt.kind != PathPointKind::Moving || !pt.clamp || pt.coordinate < 0) continue;
      const double qc = s.q[pt.coordinate];
      if (qc >= pt.clamp_lo && qc <= pt.clamp_hi) continue;  // J_xr holds OpenSim's derivative already
      Vec3 dw = calcPointLocationDerivativeUnclamped(pt, qc);
      if (pt.body >= 0) dw = sk.E_wi[pt.body].topLeftCorner<3, 3>() * dw;
      const int cc = mk.col_of[pt.coordinate];
      const double v = s.qdot[pt.coordinate];
      if (a > 0) {
        const double g = mk.dxbar[a - 1].dot(dw);
        if (body(a - 1) != body(a)) e.dl_dq[cc] += g;
        e.speed += g * v;
      }
      if (a + 1 < P) {
        const double g = mk.dxbar[a].dot(dw);
        if (body(a + 1) != body(a)) e.dl_dq[cc] -= g;
        e.speed -= g * v;
      }
    }
    return;
  }
  // wrapped path: OpenSim's length; the generalized force and the lengthening speed as OpenSim
  // applies them, the tension along the final straight segments with every point held in its
  // body (tangent points in their surface's body): d/dq of the polyline through the points frozen
  // there, by central differences over the path's columns. A segment whose ends share a body
  // keeps its length, so the arc over a surface adds nothing (docs/forward.md §3).
  if (mk.col_of.size() != static_cast<size_t>(model.nr())) initMuscleKinematics(model, path, mk);
  const VecX q = s.q.head(model.nr());
  const WrappedPath wp = calcWrappedPath(model, path, q, sk.E_wi);
  e.length = wp.length;
  struct Frozen {
    int body;
    Vec3 x_b;
    int point;  // path point index (moving points are re-evaluated), -1 for a tangent point
  };
  std::vector<Frozen> pts;
  pts.reserve(wp.points.size());
  for (const WrappedPathPoint& p : wp.points) {
    Frozen f{-1, p.x_w, p.point};
    f.body = p.point >= 0 ? path.points[p.point].body : path.wraps[p.wrap].body;
    if (f.body >= 0) {
      const Mat4& E = sk.E_wi[f.body];
      f.x_b = E.topLeftCorner<3, 3>().transpose() * (p.x_w - E.topRightCorner<3, 1>());
    }
    pts.push_back(f);
  }
  auto polyline = [&](const VecX& qq, const std::vector<Mat4>& E_wi) {
    double L = 0.0;
    Vec3 prev = Vec3::Zero();
    for (size_t i = 0; i < pts.size(); ++i) {
      Vec3 x_b = pts[i].x_b;
      if (pts[i].point >= 0 && path.points[pts[i].point].kind == PathPointKind::Moving) {
        Vec3 d1, d2;
        calcPointLocation(path.points[pts[i].point], qq, x_b, d1, d2);
      }
      const Vec3 x = pts[i].body >= 0 ? Vec3(E_wi[pts[i].body].topLeftCorner<3, 3>() * x_b +
                                             E_wi[pts[i].body].topRightCorner<3, 1>())
                                      : x_b;
      if (i > 0) L += (x - prev).norm();
      prev = x;
    }
    return L;
  };
  const int kc = static_cast<int>(mk.cols.size());
  e.dl_dq.setZero(kc);
  sc.q = q;
  if (sc.E_wi.size() != static_cast<size_t>(model.nb())) sc.E_wi.resize(model.nb());
  constexpr double h = 1e-7;
  for (int j = 0; j < kc; ++j) {
    const int c = mk.cols[j];
    const double q0 = sc.q[c];
    sc.q[c] = q0 + h;
    calcBodyPoses(model, sc.q, sc.E_wi);
    const double lp = polyline(sc.q, sc.E_wi);
    sc.q[c] = q0 - h;
    calcBodyPoses(model, sc.q, sc.E_wi);
    const double lm = polyline(sc.q, sc.E_wi);
    sc.q[c] = q0;
    e.dl_dq[j] = (lp - lm) / (2.0 * h);
  }
  double speed = 0.0;
  for (int j = 0; j < kc; ++j) speed += e.dl_dq[j] * s.qdot[mk.cols[j]];
  e.speed = speed;
}

MuscleForceScratch& MuscleForceTerm::evaluate(const Model& model, const State& s, const TermContext& ctx,
                                              MuscleForceScratch& local) const {
  auto* slot = dynamic_cast<MuscleForceScratch*>(ctx.scratch);
  if (slot && ctx.evaluation != 0 && slot->evaluation == ctx.evaluation) return *slot;
  MuscleForceScratch& sc = slot ? *slot : local;
  if (sc.muscles.size() != actuated_.size()) {
    sc.muscles.resize(actuated_.size());
    for (size_t k = 0; k < actuated_.size(); ++k) initMuscleKinematics(model, actuated_[k].muscle.path, sc.muscles[k].mk);
  }
  const int nz_all = static_cast<int>(s.z.size());
  if (nz_ > 0 && ctx.z_offset + nz_ > nz_all)
    throw ModelError("MuscleForceTerm: the state has " + std::to_string(nz_all) + " auxiliary states, the muscles need " +
                     std::to_string(ctx.z_offset + nz_));
  for (size_t k = 0; k < actuated_.size(); ++k) {
    const Actuated& a = actuated_[k];
    MuscleForceScratch::Entry& e = sc.muscles[k];
    evalPath(model, s, ctx.sk, static_cast<int>(k), sc);
    hill::MusculotendonInput in;
    in.length = e.length;
    in.speed = e.speed;
    in.excitation = ctx.control(static_cast<int>(k));
    e.zdot.setZero(a.model->numStates());
    const double* z = nz_ > 0 ? s.z.data() + ctx.z_offset + a.z_offset : nullptr;
    a.model->calc(z, in, e.out, e.zdot.data());
  }
  sc.evaluation = slot ? ctx.evaluation : 0;
  return sc;
}

void MuscleForceTerm::addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const {
  if (actuated_.empty()) return;
  MuscleForceScratch local;
  const MuscleForceScratch& sc = evaluate(model, s, ctx, local);
  // f -= F_t (dl/dq)^T: the tendon tension shortens the path
  for (size_t k = 0; k < actuated_.size(); ++k) {
    const MuscleForceScratch::Entry& e = sc.muscles[k];
    const double Ft = e.out.tendon_force;
    for (int j = 0; j < e.dl_dq.size(); ++j) f[e.mk.cols[j]] -= Ft * e.dl_dq[j];
  }
}

void MuscleForceTerm::calcStateDerivatives(const Model& model, const State& s, const TermContext& ctx,
                                           Eigen::Ref<VecX> zdot) const {
  if (actuated_.empty()) return;
  MuscleForceScratch local;
  const MuscleForceScratch& sc = evaluate(model, s, ctx, local);
  for (size_t k = 0; k < actuated_.size(); ++k) {
    const int m = actuated_[k].model->numStates();
    if (m > 0) zdot.segment(actuated_[k].z_offset, m) = sc.muscles[k].zdot;
  }
}

void MuscleForceTerm::equilibrateStates(const Model& model, const State& s, const TermContext& ctx,
                                        Eigen::Ref<VecX> z) const {
  MuscleForceScratch sc;
  sc.muscles.resize(actuated_.size());
  for (size_t k = 0; k < actuated_.size(); ++k) {
    const Actuated& a = actuated_[k];
    if (a.model->numStates() == 0) continue;
    initMuscleKinematics(model, a.muscle.path, sc.muscles[k].mk);
    evalPath(model, s, ctx.sk, static_cast<int>(k), sc);
    hill::MusculotendonInput in;
    in.length = sc.muscles[k].length;
    in.speed = sc.muscles[k].speed;
    in.excitation = ctx.control(static_cast<int>(k));
    a.model->equilibrate(in, z.data() + a.z_offset);
  }
}

hill::MuscleOutput MuscleForceTerm::calcOutput(const Model& model, const State& s, const TermContext& ctx,
                                               int k) const {
  MuscleForceScratch local;
  return evaluate(model, s, ctx.withoutScratch(), local).muscles.at(k).out;
}

void MuscleForceTerm::calcPath(const Model& model, const State& s, const SkeletonWorkspace& sk, int k,
                               double& length, double& speed, VecX& dl_dq) const {
  MuscleForceScratch sc;
  sc.muscles.resize(actuated_.size());
  initMuscleKinematics(model, actuated_.at(k).muscle.path, sc.muscles[k].mk);
  calcPath(model, s, sk, k, sc, length, speed, dl_dq);
}

void MuscleForceTerm::calcPath(const Model& model, const State& s, const SkeletonWorkspace& sk, int k,
                               MuscleForceScratch& sc, double& length, double& speed, VecX& dl_dq) const {
  if (sc.muscles.size() != actuated_.size()) {
    sc.muscles.resize(actuated_.size());
    for (size_t m = 0; m < actuated_.size(); ++m) initMuscleKinematics(model, actuated_[m].muscle.path, sc.muscles[m].mk);
  }
  evalPath(model, s, sk, k, sc);
  const MuscleForceScratch::Entry& e = sc.muscles[k];
  length = e.length;
  speed = e.speed;
  dl_dq.setZero(std::max<int>(model.nr(), static_cast<int>(s.q.size())));  // with extra coordinates: all of q
  for (int j = 0; j < e.dl_dq.size(); ++j) dl_dq[e.mk.cols[j]] = e.dl_dq[j];
}

}  // namespace redmax
