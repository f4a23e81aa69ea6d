#include "core/adjoint/adjoint.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "core/dynamics/coordinate_actuator_term.hpp"
#include "core/dynamics/id_derivatives.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "core/integrators/integrator.hpp"
#include "core/integrators/sdirk2.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::adjoint {
namespace {

// an excitation-driven control: its nodes' parameter indices (into Problem::excitations)
struct Excited {
  int control = -1;
  int nodes = 1;
  double min = 0.0, max = 1.0;
  std::vector<int> param;  // per node
};

// the system of a run: the problem's system plus one CoordinateActuatorTerm (optimal force 1)
// whose controls are the generalized forces of the driven coordinates, after the system's own
// controls (muscle excitations)
struct RunSystem {
  std::shared_ptr<System> sys;
  int nu_base = 0;                   // the problem system's own controls
  std::vector<int> driven;           // distinct driven coordinates, in control order
  std::vector<int> control_of;       // per force parameter: its control index (after nu_base)
  std::vector<Excited> excited;      // distinct excitation-driven controls
};

RunSystem makeRunSystem(const Problem& pr, const VecX& system_params) {
  if (!pr.make_system) throw AdjointError("adjoint: the problem has no system");
  const std::shared_ptr<const System> base = pr.make_system(system_params);
  if (!base) throw AdjointError("adjoint: the system factory returned no system");
  if (!base->controllers().empty())
    throw AdjointError("adjoint: the system has controllers; only generalized-force and excitation parameters drive it");
  if (base->coordinateMap()) throw AdjointError("adjoint: hyper-reduced coordinates (a coordinate map) are not supported");
  // the contact QP's active set switches are not differentiated (docs/contact.md §6)
  if (base->unilateral())
    throw AdjointError("adjoint: hard unilateral constraints (joint limits, contacts) are not supported");
  RunSystem rs;
  rs.sys = std::make_shared<System>(*base);
  rs.nu_base = base->numControls();
  if (pr.controls.size() != 0 && pr.controls.size() != rs.nu_base)
    throw AdjointError("adjoint: " + std::to_string(pr.controls.size()) + " constant controls for a system with " +
                       std::to_string(rs.nu_base));
  std::map<int, int> ex_index;
  for (size_t j = 0; j < pr.excitations.size(); ++j) {
    const ExcitationParameter& ep = pr.excitations[j];
    if (ep.control < 0 || ep.control >= rs.nu_base)
      throw AdjointError("adjoint: excitation parameter on control " + std::to_string(ep.control) +
                         " outside the system's " + std::to_string(rs.nu_base));
    if (ep.nodes < 1 || ep.node < 0 || ep.node >= ep.nodes || !(ep.min <= ep.max))
      throw AdjointError("adjoint: excitation parameter node " + std::to_string(ep.node) + " of " +
                         std::to_string(ep.nodes) + " or bounds [" + std::to_string(ep.min) + ", " +
                         std::to_string(ep.max) + "]");
    auto [it, fresh] = ex_index.emplace(ep.control, static_cast<int>(rs.excited.size()));
    if (fresh) rs.excited.push_back({ep.control, ep.nodes, ep.min, ep.max, std::vector<int>(ep.nodes, -1)});
    Excited& ex = rs.excited[it->second];
    if (ex.nodes != ep.nodes || ex.min != ep.min || ex.max != ep.max || ex.param[ep.node] >= 0)
      throw AdjointError("adjoint: the excitation parameters of control " + std::to_string(ep.control) +
                         " disagree on their nodes or bounds, or repeat a node");
    ex.param[ep.node] = static_cast<int>(j);
  }
  for (const Excited& ex : rs.excited)
    for (int i : ex.param)
      if (i < 0) throw AdjointError("adjoint: control " + std::to_string(ex.control) + " lacks an excitation node");
  const int nr = base->model().nr();
  std::map<int, int> index;
  std::vector<CoordinateActuatorTerm::Actuator> acts;
  for (const ForceParameter& fp : pr.forces) {
    if (fp.coordinate < 0 || fp.coordinate >= nr)
      throw AdjointError("adjoint: force parameter on coordinate " + std::to_string(fp.coordinate) +
                         " outside the model's " + std::to_string(nr));
    if (fp.pieces < 1 || fp.piece < 0 || fp.piece >= fp.pieces)
      throw AdjointError("adjoint: force parameter piece " + std::to_string(fp.piece) + " of " +
                         std::to_string(fp.pieces));
    if (fp.shape == ForceParameter::Shape::Cubic && fp.pieces < 4)
      throw AdjointError("adjoint: a cubic B-spline force needs at least 4 control points, got " +
                         std::to_string(fp.pieces));
    auto [it, fresh] = index.emplace(fp.coordinate, static_cast<int>(rs.driven.size()));
    if (fresh) {
      rs.driven.push_back(fp.coordinate);
      acts.push_back({"u_" + std::to_string(fp.coordinate), fp.coordinate, 1.0});
    }
    rs.control_of.push_back(rs.nu_base + it->second);
  }
  if (!acts.empty()) rs.sys->addTerm(std::make_shared<CoordinateActuatorTerm>(base->model(), std::move(acts)));
  return rs;
}

int numSteps(const Problem& pr) {
  if (!(pr.dt > 0.0) || !(pr.duration > 0.0)) throw AdjointError("adjoint: dt and duration must be positive");
  const double ratio = pr.duration / pr.dt;
  if (!(ratio < 1e8)) throw AdjointError("adjoint: duration / dt too large");
  return static_cast<int>(std::max(1L, static_cast<long>(std::ceil(ratio - 1e-9))));  // as advance()
}

// the hat-function weights of step k of n on a piecewise-linear excitation with `nodes` nodes
// over the run: w0 on node i0, w1 on node i0 + 1 (the interpolant at the step's start time)
void hatWeights(int nodes, int k, int n, int& i0, double& w0, double& w1) {
  if (nodes == 1) {
    i0 = 0;
    w0 = 1.0;
    w1 = 0.0;
    return;
  }
  const double s = static_cast<double>(k) * (nodes - 1) / n;  // in [0, nodes - 1)
  i0 = std::min(static_cast<int>(std::floor(s)), nodes - 2);
  w1 = s - i0;
  w0 = 1.0 - w1;
}

// basis function i of the clamped uniform cubic B-spline with m control points at x in [0, 1]
// (Cox-de Boor; knots 0,0,0,0, 1/(m-3), ..., (m-4)/(m-3), 1,1,1,1)
double cubicBSpline(int i, int m, double x) {
  const int segments = m - 3;
  auto knot = [&](int j) { return std::clamp(static_cast<double>(j - 3) / segments, 0.0, 1.0); };
  if (x >= 1.0) return i == m - 1 ? 1.0 : 0.0;
  // degree 0 on [knot(j), knot(j + 1)), then the recursion up to degree 3
  double N[4][4] = {};
  for (int d = 0; d <= 3; ++d)
    for (int j = 0; j <= 3 - d; ++j) {
      const int a = i + j;  // N_{a,d}
      if (d == 0) {
        N[0][j] = (knot(a) <= x && x < knot(a + 1)) ? 1.0 : 0.0;
        continue;
      }
      double v = 0.0;
      const double l = knot(a + d) - knot(a), r = knot(a + d + 1) - knot(a + 1);
      if (l > 0.0) v += (x - knot(a)) / l * N[d - 1][j];
      if (r > 0.0) v += (knot(a + d + 1) - x) / r * N[d - 1][j + 1];
      N[d][j] = v;
    }
  return N[3][0];
}

}  // namespace

double forceBasis(const ForceParameter& fp, int k, int n) {
  switch (fp.shape) {
    case ForceParameter::Shape::Pieces: return static_cast<long>(k) * fp.pieces / n == fp.piece ? 1.0 : 0.0;
    case ForceParameter::Shape::Linear: {
      int i0 = 0;
      double w0 = 0.0, w1 = 0.0;
      hatWeights(fp.pieces, k, n, i0, w0, w1);
      return fp.piece == i0 ? w0 : fp.piece == i0 + 1 ? w1 : 0.0;
    }
    case ForceParameter::Shape::Cubic: return cubicBSpline(fp.piece, fp.pieces, static_cast<double>(k) / n);
  }
  return 0.0;
}

namespace {

// the interpolated excitation of ex at step k of n, before clamping
double excitationAt(const Excited& ex, const VecX& p, int nf, int k, int n) {
  int i0 = 0;
  double w0 = 0.0, w1 = 0.0;
  hatWeights(ex.nodes, k, n, i0, w0, w1);
  double e = w0 * p[nf + ex.param[i0]];
  if (w1 != 0.0) e += w1 * p[nf + ex.param[i0 + 1]];
  return e;
}

// the controls during step k of n: the system's own (constant, or the clamped excitations), then
// one per driven coordinate
VecX controlsAt(const Problem& pr, const RunSystem& rs, const VecX& p, int k, int n) {
  VecX u = VecX::Zero(rs.nu_base + static_cast<Eigen::Index>(rs.driven.size()));
  if (pr.controls.size() != 0) u.head(rs.nu_base) = pr.controls;
  const int nf = static_cast<int>(pr.forces.size());
  for (const Excited& ex : rs.excited)
    u[ex.control] = std::clamp(excitationAt(ex, p, nf, k, n), ex.min, ex.max);
  for (size_t j = 0; j < pr.forces.size(); ++j) {
    const double b = forceBasis(pr.forces[j], k, n);
    if (b != 0.0) u[rs.control_of[j]] += b * p[static_cast<Eigen::Index>(j)];
  }
  return u;
}

// one fixed step as FixedStepIntegrator::advance takes it, on packed y = (q, qdot, z)
class Stepper {
 public:
  Stepper(const Problem& pr, const System& sys) : sys_(sys), ws_(sys) {
    IntegratorOptions opt;
    opt.dt = pr.dt;
    opt.newton_tol = pr.newton_tol;
    if (pr.integrator != "euler" && pr.integrator != "bdf1" && pr.integrator != "sdirk2")
      throw AdjointError("adjoint: integrator '" + pr.integrator + "' has no adjoint (euler, bdf1, sdirk2)");
    owner_ = makeIntegrator(pr.integrator, opt);
    integ_ = dynamic_cast<FixedStepIntegrator*>(owner_.get());
    n_ = sys.ndof();
    nz_ = sys.numStates();
    term_step_ = pr.jacobian_step;
    for (const auto& t : sys.terms())
      if (const auto* mf = dynamic_cast<const MuscleForceTerm*>(t.get()); mf && !mf->actuated().empty())
        state_terms_ = true;
  }
  int size() const { return 2 * n_ + nz_; }
  State unpack(const VecX& y, double t) const {
    State s;
    s.t = t;
    s.q = y.head(n_);
    s.qdot = y.segment(n_, n_);
    s.z = y.tail(nz_);
    return s;
  }
  static VecX pack(const State& s) {
    VecX y(s.q.size() + s.qdot.size() + s.z.size());
    y << s.q, s.qdot, s.z;
    return y;
  }
  VecX step(const VecX& y, double t, double h, const VecX& u) {
    ++evaluations;
    State s = unpack(y, t);
    ws_.controls = u;
    VecX zdot;
    // auxiliary states: explicit Euler with the rate at the step's start (integrator.hpp)
    if (nz_ > 0) {
      sys_.calcStateDerivatives(s, ws_);
      zdot = ws_.zdot;
    }
    integ_->step(sys_, s, h, ws_);
    if (nz_ > 0) s.z.noalias() += h * zdot;
    return pack(s);
  }

  // Whether the step's Jacobians can be formed from the ID derivatives (docs/gradients.md §2.1):
  // no auxiliary states but the Hill-type muscles', constraints on the skeleton's coordinates, and
  // every term with derivatives (written, or differenced alone).
  bool analyticAvailable(std::string* why) const {
    if (nz_ > 0 && !state_terms_) {
      *why = "auxiliary states of a term other than Hill-type muscles";
      return false;
    }
    if (sys_.numConstraintRows() > 0 && !constraintRowDerivativesAvailable(sys_, why)) return false;
    return systemIdDerivativesAvailable(sys_, why);
  }

  // The step's Jacobians from the derivatives of inverse dynamics (docs/gradients.md §2.1):
  // Jy = dy+/dy (2n x 2n) and Jf = dy+/dF (2n x n) for a generalized force F added to f during the
  // step (the driven coordinates' controls enter so, with optimal force 1). With a = qddot(q, v),
  // da/dq = -M^-1 dtau/dq, da/dv = -M^-1 dtau/dv at tau's qddot = a, da/dF = M^-1, each
  // integrator's own equations are differentiated:
  //   euler   v+ = v + h a,  q+ = q + h v+   (M^-1 (M v + h f) as computed)
  //   bdf1    (M + h D + h^2 K) v+ = M v + h (f + D v), K and D constant (joint springs and
  //           dampers: the terms with derivatives add none): A dv+ = -h dtau(a') dy + (M + h D) dv
  //           + h dF, a' = (v+ - v) / h
  //   sdirk2  the stage equations V - zv - hg a(zq + hg V, V) = 0 by the implicit function theorem
  //           at the converged stages, chained through stage 2's start (zq, zv)
  // System parameters s (muscle masses) enter as the generalized force -dtau/ds at the step's (or
  // each stage's) state and acceleration: with `dtau_ds` (n x ns at a state and acceleration),
  // Js = dy+/ds (2n + nz x ns).
  // Hill-type muscles (auxiliary states z, controls u_m; docs/gradients.md §2.1) enter the same
  // way: the step holds z and u during q's and qdot's update, so df/dz and df/du at each stage's
  // state are generalized forces like -dtau/ds, and z+ = z + h zdot(q, v, z, u) at the step's
  // start adds its rows [h dzdot/dq, h dzdot/dv, I + h dzdot/dz], h dzdot/du. Then Jy is
  // (2n + nz) square, and Ju (2n + nz x nu, with `Ju`) holds the columns of the terms' controls.
  using ParamIdDerivative = std::function<MatX(const State&, const VecX&)>;
  void analyticJacobians(const VecX& y, double t, double h, const VecX& u, MatX& Jy, MatX& Jf,
                         const ParamIdDerivative* dtau_ds = nullptr, MatX* Js = nullptr, MatX* Ju = nullptr) {
    const int n = n_;
    const MatX I = MatX::Identity(n, n);
    State s = unpack(y, t);
    ws_.controls = u;
    MatX Dq, Dv;
    // the Hill-type muscles' derivatives at the state of the last idDerivatives call: the same
    // evaluations as the ID derivatives there (euler and bdf1: the step's start, whose rates the
    // z update needs; sdirk2: each stage, for its forces, and the start again below)
    StateTermDerivatives sd;
    bool sd_at_start = false;
    // the ID derivatives at a state and acceleration
    auto idDerivatives = [&](const State& st, const VecX& a, bool start) {
      std::string why;
      if (!systemIdDerivatives(sys_, st, a, ws_, Dq, Dv, &why, term_step_, state_terms_ ? &sd : nullptr))
        throw AdjointError("adjoint: analytic step Jacobians: " + why);
      sd_at_start = start && state_terms_;
    };
    // the generalized forces of the step's parameters at the state and acceleration of the last
    // idDerivatives call: -dtau/ds of the system parameters, then df/dz and df/du of the Hill-type
    // muscles (n x (ns + nz + nu))
    int ns = 0;
    auto forceColumns = [&](const State& st, const VecX& a) {
      MatX gs = dtau_ds ? MatX(-(*dtau_ds)(st, a)) : MatX(n, 0);
      ns = static_cast<int>(gs.cols());
      if (!state_terms_) return gs;
      MatX g(n, gs.cols() + sd.df_dz.cols() + sd.df_du.cols());
      g << gs, sd.df_dz, sd.df_du;
      return g;
    };
    const bool columns = dtau_ds || state_terms_;
    MatX JG;  // d(q+, v+)/d(s, z, u) through forceColumns
    MatX dv_dy(n, 2 * n), dv_dF(n, n), Gs;  // Gs: forceColumns at the step's state and acceleration
    const int nc = sys_.numConstraintRows();
    ConstraintRowDerivatives crd;
    if (integ_->name() == "euler" || integ_->name() == "bdf1") {
      // euler: M v+ = M v + h f;  bdf1: A v+ = M v + h (f + D v), A = M + h D + h^2 K (K, D the
      // joint springs' and dampers' constants); with constraint rows, the KKT system
      // [A G^T; G 0] [v+; lambda] = [.; G v + h rhs - vel_err] (A = M for euler). Differentiated:
      //   [A G^T; G 0] [dv+; dlambda] = [-h dtau(a') - d(G^T lambda) + (M + h D) dv + h dF - h dtau/ds ds;
      //                                  d(G (v - v+)) + h drhs - dvel_err + G dv]
      // with a' = (v+ - v) / h, the acceleration at which dtau is taken.
      const bool euler = integ_->name() == "euler";
      sys_.calcMassAndForce(s, ws_);
      MatX Mv = ws_.M, A = ws_.M;
      VecX top = ws_.M * s.qdot + h * ws_.f;
      if (!euler) {
        sys_.calcStiffnessDamping(s, ws_);
        Mv += h * ws_.D;
        A += h * ws_.D + (h * h) * ws_.K;
        top += h * (ws_.D * s.qdot);
      }
      VecX vplus, lambda;
      MatX G;
      if (nc > 0) {
        sys_.calcConstraints(s, ws_);
        G = ws_.G;
        vplus = System::solveKKT(A, G, top, G * s.qdot + h * ws_.rhs - ws_.vel_err, &lambda);
      } else {
        vplus = A.ldlt().solve(top);
      }
      const VecX a = (vplus - s.qdot) / h;
      idDerivatives(s, a, true);
      if (columns) Gs = forceColumns(s, a);
      if (nc == 0) {
        const Eigen::LDLT<MatX> ldlt(A);
        dv_dy.leftCols(n) = -h * ldlt.solve(Dq);
        dv_dy.rightCols(n) = ldlt.solve(Mv - h * Dv);
        dv_dF = h * ldlt.solve(I);
      } else {
        constraintRowDerivatives(sys_, s, s.qdot - vplus, lambda, crd);
        auto kkt = [&](const VecX& t, const VecX& b) { return System::solveKKT(A, G, t, b, nullptr); };
        for (int j = 0; j < n; ++j) {
          dv_dy.col(j) = kkt(-h * Dq.col(j) - crd.dGTl_dq.col(j),
                             crd.dGw_dq.col(j) + h * crd.drhs_dq.col(j) - crd.dverr_dq.col(j));
          dv_dy.col(n + j) = kkt(-h * Dv.col(j) + Mv.col(j), G.col(j) + h * crd.drhs_dv.col(j) - crd.dverr_dv.col(j));
          dv_dF.col(j) = kkt(h * I.col(j), VecX::Zero(nc));
        }
      }
    } else {  // sdirk2
      const double g = Sdirk2::gamma(), hg = h * g, c = (1.0 - g) / g;
      const VecX yplus = step(y, t, h, u);
      const VecX V2 = yplus.segment(n, n);
      // stage 1's velocity from q+ = q0 + h (1 - g) V1 + hg V2 (the integrator keeps no stages)
      const VecX V1 = (yplus.head(n) - s.q - hg * V2) / (h * (1.0 - g));
      // one stage's a_q, a_F and dR/dV for R = V - zv - hg a(zq + hg V, V); then
      // dV = dR/dV^-1 (hg a_q dzq + dzv + hg a_F dF)
      auto stage = [&](const VecX& zq, const VecX& zv, const VecX& V, double ts, MatX& a_q, MatX& dR_dV,
                       MatX& a_F, MatX& G_s) {
        State st;
        st.t = ts;
        st.q = zq + hg * V;
        st.qdot = V;
        st.z = s.z;  // held during the step
        sys_.calcMassAndForce(st, ws_);
        const VecX a = (V - zv) / hg;
        idDerivatives(st, a, false);
        if (columns) G_s = forceColumns(st, a);
        MatX a_v;
        if (nc == 0) {
          const Eigen::LDLT<MatX> ldlt(ws_.M);
          a_q = -ldlt.solve(Dq);
          a_v = -ldlt.solve(Dv);
          a_F = ldlt.solve(I);
        } else {
          // the constrained acceleration [M G^T; G 0] [a; mu] = [f; rhs], differentiated:
          // [M G^T; G 0] [da; dmu] = [-dtau(a) - d(G^T mu) + dF; drhs - d(G a)]
          sys_.calcConstraints(st, ws_);
          const MatX M = ws_.M, G = ws_.G;
          VecX mu;
          System::solveKKT(M, G, ws_.f, ws_.rhs, &mu);
          constraintRowDerivatives(sys_, st, a, mu, crd);
          auto kkt = [&](const VecX& t, const VecX& b) { return System::solveKKT(M, G, t, b, nullptr); };
          a_q.resize(n, n);
          a_v.resize(n, n);
          a_F.resize(n, n);
          for (int j = 0; j < n; ++j) {
            a_q.col(j) = kkt(-Dq.col(j) - crd.dGTl_dq.col(j), crd.drhs_dq.col(j) - crd.dGw_dq.col(j));
            a_v.col(j) = kkt(-Dv.col(j), crd.drhs_dv.col(j));
            a_F.col(j) = kkt(I.col(j), VecX::Zero(nc));
          }
        }
        dR_dV = I - hg * (hg * a_q + a_v);
      };
      MatX aq1, A1, aF1, aq2, A2, aF2, G1, G2;
      stage(s.q, s.qdot, V1, t + hg, aq1, A1, aF1, G1);
      const Eigen::PartialPivLU<MatX> lu1(A1);
      MatX dV1(n, 2 * n);
      dV1.leftCols(n) = lu1.solve(hg * aq1);
      dV1.rightCols(n) = lu1.solve(I);
      const MatX dV1_dF = lu1.solve(hg * aF1);
      const VecX zq2 = s.q + h * (1.0 - g) * V1;
      const VecX zv2 = s.qdot + c * (V1 - s.qdot);
      stage(zq2, zv2, V2, t + h, aq2, A2, aF2, G2);
      const Eigen::PartialPivLU<MatX> lu2(A2);
      MatX dzq(n, 2 * n), dzv(n, 2 * n);
      dzq << I, MatX::Zero(n, n);
      dzq += h * (1.0 - g) * dV1;
      dzv << MatX::Zero(n, n), I;
      dzv += c * (dV1 - dzv);
      dv_dy = lu2.solve(hg * aq2 * dzq + dzv);
      dv_dF = lu2.solve(hg * aq2 * (h * (1.0 - g) * dV1_dF) + c * dV1_dF + hg * aF2);
      // q+ = zq2 + hg V2
      Jy.resize(2 * n, 2 * n);
      Jy.topRows(n) = dzq + hg * dv_dy;
      Jy.bottomRows(n) = dv_dy;
      Jf.resize(2 * n, n);
      Jf.topRows(n) = h * (1.0 - g) * dV1_dF + hg * dv_dF;
      Jf.bottomRows(n) = dv_dF;
      if (columns) {
        // each stage's own forces, through the same chain as F
        const MatX dV1_ds = dV1_dF * G1;
        const MatX dV2_ds = lu2.solve(hg * aq2 * (h * (1.0 - g) * dV1_ds) + c * dV1_ds + hg * aF2 * G2);
        JG.resize(2 * n, G1.cols());
        JG.topRows(n) = h * (1.0 - g) * dV1_ds + hg * dV2_ds;
        JG.bottomRows(n) = dV2_ds;
      }
    }
    if (integ_->name() != "sdirk2") {
      // euler and bdf1: q+ = q + h v+
      Jy.resize(2 * n, 2 * n);
      Jy.topRows(n) = h * dv_dy;
      Jy.topLeftCorner(n, n) += I;
      Jy.bottomRows(n) = dv_dy;
      Jf.resize(2 * n, n);
      Jf.topRows(n) = h * dv_dF;
      Jf.bottomRows(n) = dv_dF;
      if (columns) JG = Jf * Gs;
    }
    if (dtau_ds && Js) *Js = JG.leftCols(ns);
    if (nz_ == 0 && !state_terms_) return;
    // the Hill-type muscles' states: z+ = z + h zdot(q, v, z, u) at the step's start
    const int nz = nz_, nu = sys_.numControls();
    ws_.controls = u;
    if (!sd_at_start) stateTermDerivatives(sys_, s, ws_, term_step_, sd);
    MatX Jfull = MatX::Zero(2 * n + nz, 2 * n + nz);
    Jfull.topLeftCorner(2 * n, 2 * n) = Jy;
    Jfull.block(0, 2 * n, 2 * n, nz) = JG.middleCols(ns, nz);
    Jfull.block(2 * n, 0, nz, n) = h * sd.dzdot_dq;
    Jfull.block(2 * n, n, nz, n) = h * sd.dzdot_dv;
    Jfull.bottomRightCorner(nz, nz) = MatX::Identity(nz, nz) + h * sd.dzdot_dz;
    Jy = std::move(Jfull);
    Jf.conservativeResize(2 * n + nz, n);
    Jf.bottomRows(nz).setZero();
    if (dtau_ds && Js) {
      Js->conservativeResize(2 * n + nz, ns);
      Js->bottomRows(nz).setZero();
    }
    if (Ju) {
      Ju->resize(2 * n + nz, nu);
      Ju->topRows(2 * n) = JG.middleCols(ns + nz, nu);
      Ju->bottomRows(nz) = h * sd.dzdot_du;
    }
  }
  /// the system's inverse dynamics at (st, a) with controls u (the system-parameter columns)
  VecX inverseDynamics(const State& st, const VecX& a, const VecX& u) {
    ws_.controls = u;
    return sys_.inverseDynamics(st, a, ws_);
  }
  long evaluations = 0;

 private:
  const System& sys_;
  DynamicsWorkspace ws_;
  std::unique_ptr<Integrator> owner_;
  FixedStepIntegrator* integ_ = nullptr;
  int n_ = 0, nz_ = 0;
  double term_step_ = 6e-6;     // the Hill-type muscles' term-local differences (Problem::jacobian_step)
  bool state_terms_ = false;    // the system has Hill-type muscles (MuscleForceTerm with a model)
};

double fdStep(double rel, double x) { return rel * std::max(1.0, std::abs(x)); }

// w/2 |x(q) - target|^2 for a point x_i of `body` (kinematics of the state in ws), its derivative
// with respect to q added to dJ_dq (when given): dx/dq is the point's velocity Jacobian, since
// dq/dt = qdot for every joint (integrator.hpp)
double pointTerm(const Model& model, const SkeletonWorkspace& ws, int body, const Vec3& x_i, const Vec3& target,
                 double w, MatX& Jp, Eigen::Ref<VecX> dJ_dq, bool gradient) {
  const Vec3 e = pointPosition(ws, body, x_i) - target;
  if (gradient) {
    Jp.setZero();
    pointJacobian(model, ws, body, x_i, Jp);
    dJ_dq += w * (Jp.transpose() * e);
  }
  return 0.5 * w * e.squaredNorm();
}

// objective at the final state and its explicit derivatives (dJ/dy_N, dJ/du summed per step)
double objectiveValue(const System& sys, const Objective& obj, const State& fin, VecX* dJ_dy) {
  const Model& model = sys.model();
  const int n = sys.ndof();
  double J = 0.0;
  if (dJ_dy) dJ_dy->setZero(2 * n + fin.z.size());
  if (!obj.points.empty()) {
    SkeletonWorkspace ws(model);
    calcKinematics(model, fin, ws);
    MatX Jp(3, model.nr());
    VecX unused;
    for (const Objective::Point& pt : obj.points)
      J += pointTerm(model, ws, pt.body, pt.x_i, pt.target, pt.weight, Jp,
                     dJ_dy ? dJ_dy->head(model.nr()) : unused.head(0), dJ_dy != nullptr);
  }
  if (obj.speed_weight != 0.0) {
    J += 0.5 * obj.speed_weight * fin.qdot.squaredNorm();
    if (dJ_dy) dJ_dy->segment(n, n) += obj.speed_weight * fin.qdot;
  }
  return J;
}

// the tracking terms at one state (step k >= 1): h w/2 |x - target(t)|^2 per marker and
// h w/2 (q_c - target(t))^2 per coordinate, and their derivative with respect to y added to dJ_dy
// (when given); callers skip it without tracking terms
double trackValue(const System& sys, const Objective& obj, const State& s, double h, VecX* dJ_dy) {
  const Model& model = sys.model();
  double J = 0.0;
  if (!obj.tracks.empty()) {
    SkeletonWorkspace ws(model);
    calcKinematics(model, s, ws);
    MatX Jp(3, model.nr());
    VecX unused;
    for (const Objective::Track& tr : obj.tracks)
      J += pointTerm(model, ws, tr.body, tr.x_i, tr.at(s.t), h * tr.weight, Jp,
                     dJ_dy ? dJ_dy->head(model.nr()) : unused.head(0), dJ_dy != nullptr);
  }
  for (const Objective::CoordinateTrack& ct : obj.coordinate_tracks) {
    const double e = s.q[ct.coordinate] - ct.at(s.t);
    J += 0.5 * h * ct.weight * e * e;
    if (dJ_dy) (*dJ_dy)[ct.coordinate] += h * ct.weight * e;
  }
  return J;
}

void checkProblem(const Problem& pr, const VecX& p, const System& sys) {
  if (p.size() != pr.numParameters())
    throw AdjointError("adjoint: " + std::to_string(p.size()) + " parameter values for " +
                       std::to_string(pr.numParameters()) + " parameters");
  const int n = sys.ndof();
  if (pr.initial.q.size() != n || pr.initial.qdot.size() != n || pr.initial.z.size() != sys.numStates())
    throw AdjointError("adjoint: the initial state does not fit the system");
  for (int c : pr.initial_q)
    if (c < 0 || c >= n) throw AdjointError("adjoint: initial-q parameter outside the coordinates");
  for (int c : pr.initial_qdot)
    if (c < 0 || c >= n) throw AdjointError("adjoint: initial-qdot parameter outside the coordinates");
  if (pr.step_jacobians != "auto" && pr.step_jacobians != "analytic" && pr.step_jacobians != "differences")
    throw AdjointError("adjoint: step_jacobians must be auto, analytic or differences, not '" + pr.step_jacobians + "'");
  if (!(pr.jacobian_step > 0.0 && pr.jacobian_step < 1.0))
    throw AdjointError("adjoint: the step Jacobians' relative difference step must lie in (0, 1)");
  if (pr.num_system_params > 0 && pr.system_param_delta.size() != pr.num_system_params)
    throw AdjointError("adjoint: system_param_delta needs one entry per system parameter");
}

}  // namespace

Vec3 Objective::Track::at(double time) const {
  if (t.empty()) return Vec3::Zero();
  if (time <= t.front()) return target.front();
  if (time >= t.back()) return target.back();
  const size_t i = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());  // t[i-1] <= time < t[i]
  const double w = (time - t[i - 1]) / (t[i] - t[i - 1]);
  return (1.0 - w) * target[i - 1] + w * target[i];
}

double Objective::CoordinateTrack::at(double time) const {
  if (t.empty()) return 0.0;
  if (time <= t.front()) return value.front();
  if (time >= t.back()) return value.back();
  const size_t i = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());  // t[i-1] <= time < t[i]
  const double w = (time - t[i - 1]) / (t[i] - t[i - 1]);
  return (1.0 - w) * value[i - 1] + w * value[i];
}

Result evaluate(const Problem& pr, const Objective& obj, const VecX& p, bool with_gradient) {
  const int nf = static_cast<int>(pr.forces.size());
  const int ne = static_cast<int>(pr.excitations.size());
  const int nq0 = static_cast<int>(pr.initial_q.size()), nv0 = static_cast<int>(pr.initial_qdot.size());
  const int ns = pr.num_system_params;
  const VecX sp = p.size() == pr.numParameters() ? VecX(p.tail(ns)) : VecX();
  const RunSystem rs = makeRunSystem(pr, sp);
  const System& sys = *rs.sys;
  checkProblem(pr, p, sys);
  const int n = sys.ndof();
  for (const Objective::CoordinateTrack& ct : obj.coordinate_tracks)
    if (ct.coordinate < 0 || ct.coordinate >= n || ct.t.empty() || ct.t.size() != ct.value.size())
      throw AdjointError("adjoint: a coordinate track outside the coordinates or without samples");
  const int N = numSteps(pr);
  const double h = pr.duration / N;
  const double t0 = pr.initial.t;
  auto timeAt = [&](int k) { return k == N ? t0 + pr.duration : t0 + k * h; };

  // initial state with its parameters
  State s0 = pr.initial;
  const int iq0 = nf + ne;  // the first initial-state parameter
  for (int j = 0; j < nq0; ++j) s0.q[pr.initial_q[j]] = p[iq0 + j];
  for (int j = 0; j < nv0; ++j) s0.qdot[pr.initial_qdot[j]] = p[iq0 + nq0 + j];

  Stepper stepper(pr, sys);
  const int ny = stepper.size();
  const std::vector<std::string> z_names = sys.numStates() > 0 ? sys.stateNames() : std::vector<std::string>{};
  std::vector<VecX> y(N + 1);
  y[0] = Stepper::pack(s0);
  checkFinite(s0, h, pr.integrator.c_str(), &z_names);
  double effort = 0.0, excitation_effort = 0.0, tracking = 0.0;
  const int nub = rs.nu_base;
  const int nd = static_cast<int>(rs.driven.size());
  const auto forward_start = std::chrono::steady_clock::now();
  for (int k = 0; k < N; ++k) {
    const VecX u = controlsAt(pr, rs, p, k, N);
    effort += h * u.tail(nd).squaredNorm();
    for (const Excited& ex : rs.excited) excitation_effort += h * u[ex.control] * u[ex.control];
    y[k + 1] = stepper.step(y[k], timeAt(k), h, u);
    checkFinite(stepper.unpack(y[k + 1], timeAt(k + 1)), h, pr.integrator.c_str(), &z_names);
    if (obj.tracking()) tracking += trackValue(sys, obj, stepper.unpack(y[k + 1], timeAt(k + 1)), h, nullptr);
  }

  Result res;
  res.forward_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - forward_start).count();
  res.final = stepper.unpack(y[N], timeAt(N));
  res.steps = N;
  VecX lambda;
  res.objective = objectiveValue(sys, obj, res.final, with_gradient ? &lambda : nullptr) + obj.effort_weight * effort +
                  obj.excitation_weight * excitation_effort + tracking;
  if (with_gradient && obj.tracking()) trackValue(sys, obj, res.final, h, &lambda);  // the last step's term
  if (!with_gradient) {
    res.step_evaluations = stepper.evaluations;
    return res;
  }

  // systems at s -+ delta and s -+ 2 delta for the system parameters (e.g. muscle masses), with
  // steppers: their derivative is a fourth-order central difference of the step, so that delta
  // can be large enough for the round-off (eps |y| / delta) to stay small
  const double at[4] = {-2.0, -1.0, 1.0, 2.0};
  std::vector<RunSystem> sys_at;
  std::vector<std::unique_ptr<Stepper>> step_at;  // 4 per system parameter
  for (int j = 0; j < ns; ++j)
    for (double a : at) {
      VecX x = sp;
      x[j] += a * pr.system_param_delta[j];
      sys_at.push_back(makeRunSystem(pr, x));
      step_at.push_back(std::make_unique<Stepper>(pr, *sys_at.back().sys));
    }

  // the step Jacobians' route (docs/gradients.md §2.1)
  std::string why;
  bool analytic = false;
  if (pr.step_jacobians != "differences") analytic = stepper.analyticAvailable(&why);
  if (pr.step_jacobians == "analytic" && !analytic)
    throw AdjointError("adjoint: analytic step Jacobians do not apply: " + why);
  res.analytic_jacobians = analytic;
  res.jacobian_note = analytic ? systemIdDerivativesLocalDifferences(sys) : why;

  // reverse sweep: lambda_k = (dPhi_k/dy)^T lambda_{k+1}, parameter terms from lambda_{k+1}
  res.gradient = VecX::Zero(pr.numParameters());
  MatX Jy(ny, ny), Jf, Js;
  VecX Ju(nub + nd), u;
  // analytic route, system parameters: dtau/ds by the fourth-order difference of inverse dynamics
  // between the systems at s -+ delta, -+ 2 delta (exact up to round-off where tau is linear in s,
  // as in a muscle's mass: its mass points' share scales with it), at the step's controls u
  const Stepper::ParamIdDerivative dtau_ds = [&](const State& st, const VecX& a) {
    MatX d(n, ns);
    for (int j = 0; j < ns; ++j) {
      auto tau = [&](int m) { return step_at[4 * j + m]->inverseDynamics(st, a, u); };
      d.col(j) = (tau(0) - 8.0 * tau(1) + 8.0 * tau(2) - tau(3)) / (12.0 * pr.system_param_delta[j]);
    }
    return d;
  };
  // an excitation-driven control's column d = lambda^T dy+/de at step k, at the clamped value the
  // step used: through the clamp (zero outside [min, max]) and the hat weights to the step's two nodes
  auto addExcitation = [&](const Excited& ex, int k, double d) {
    const double raw = excitationAt(ex, p, nf, k, N);
    if (raw < ex.min || raw > ex.max) return;
    int i0 = 0;
    double w0 = 0.0, w1 = 0.0;
    hatWeights(ex.nodes, k, N, i0, w0, w1);
    res.gradient[nf + ex.param[i0]] += w0 * d;
    if (w1 != 0.0) res.gradient[nf + ex.param[i0 + 1]] += w1 * d;
  };
  MatX Jm;  // analytic: the Hill-type muscles' control columns
  for (int k = N - 1; k >= 0; --k) {
    const double t = timeAt(k);
    u = controlsAt(pr, rs, p, k, N);
    if (analytic) {
      stepper.analyticJacobians(y[k], t, h, u, Jy, Jf, ns > 0 ? &dtau_ds : nullptr, ns > 0 ? &Js : nullptr,
                                rs.excited.empty() ? nullptr : &Jm);
      if (ns > 0) res.gradient.tail(ns) += Js.transpose() * lambda;
      const VecX lf = Jf.transpose() * lambda;
      for (int c = nub; c < nub + nd; ++c) Ju[c] = lf[rs.driven[c - nub]];
      for (const Excited& ex : rs.excited) addExcitation(ex, k, lambda.dot(Jm.col(ex.control)));
    } else {
      // generalized-force columns: one central difference per driven coordinate (the step is
      // linear in them for euler and bdf1, so this is exact up to round-off there)
      for (int c = nub; c < nub + nd; ++c) {
        const double e = fdStep(pr.jacobian_step, u[c]);
        VecX up = u, um = u;
        up[c] += e;
        um[c] -= e;
        Ju[c] = lambda.dot(stepper.step(y[k], t, h, up) - stepper.step(y[k], t, h, um)) / (2.0 * e);
      }
      // excitation columns: one central difference per excitation-driven control, at the clamped
      // value the step used; through the clamp (zero outside [min, max]) and the hat weights to
      // the step's two nodes
      for (const Excited& ex : rs.excited) {
        const int c = ex.control;
        const double e = fdStep(pr.jacobian_step, u[c]);
        VecX up = u, um = u;
        up[c] += e;
        um[c] -= e;
        addExcitation(ex, k, lambda.dot(stepper.step(y[k], t, h, up) - stepper.step(y[k], t, h, um)) / (2.0 * e));
      }
      for (int j = 0; j < ns; ++j) {
        auto phi = [&](int m) { return step_at[4 * j + m]->step(y[k], t, h, u); };
        const VecX d = phi(0) - 8.0 * phi(1) + 8.0 * phi(2) - phi(3);
        res.gradient[iq0 + nq0 + nv0 + j] += lambda.dot(d) / (12.0 * pr.system_param_delta[j]);
      }
      // state Jacobian of the step, column by column
      for (int i = 0; i < ny; ++i) {
        const double e = fdStep(pr.jacobian_step, y[k][i]);
        VecX yp = y[k], ym = y[k];
        yp[i] += e;
        ym[i] -= e;
        Jy.col(i) = (stepper.step(yp, t, h, u) - stepper.step(ym, t, h, u)) / (2.0 * e);
      }
    }
    // the force parameters of this step, through their basis weights
    for (int j = 0; j < nf; ++j) {
      const double b = forceBasis(pr.forces[j], k, N);
      if (b != 0.0) res.gradient[j] += b * Ju[rs.control_of[j]];
    }
    lambda = (Jy.transpose() * lambda).eval();
    // the tracking term at y_k (k >= 1) joins its adjoint
    if (k >= 1 && obj.tracking()) trackValue(sys, obj, stepper.unpack(y[k], t), h, &lambda);
  }
  for (int j = 0; j < nq0; ++j) res.gradient[iq0 + j] += lambda[pr.initial_q[j]];
  for (int j = 0; j < nv0; ++j) res.gradient[iq0 + nq0 + j] += lambda[n + pr.initial_qdot[j]];
  // effort: w sum_k h u_k^2, each step's u the sum of its active force parameters
  if (obj.effort_weight != 0.0) {
    for (int k = 0; k < N; ++k) {
      const VecX u = controlsAt(pr, rs, p, k, N);
      for (int j = 0; j < nf; ++j) {
        const double b = forceBasis(pr.forces[j], k, N);
        if (b != 0.0) res.gradient[j] += 2.0 * obj.effort_weight * h * b * u[rs.control_of[j]];
      }
    }
  }
  // excitation effort: w sum_k h e_k^2 of the clamped excitations
  if (obj.excitation_weight != 0.0) {
    for (int k = 0; k < N; ++k)
      for (const Excited& ex : rs.excited) {
        const double raw = excitationAt(ex, p, nf, k, N);
        if (raw < ex.min || raw > ex.max) continue;
        int i0 = 0;
        double w0 = 0.0, w1 = 0.0;
        hatWeights(ex.nodes, k, N, i0, w0, w1);
        const double g = 2.0 * obj.excitation_weight * h * raw;
        res.gradient[nf + ex.param[i0]] += w0 * g;
        if (w1 != 0.0) res.gradient[nf + ex.param[i0 + 1]] += w1 * g;
      }
  }
  res.step_evaluations = stepper.evaluations;
  for (const auto& s : step_at) res.step_evaluations += s->evaluations;
  return res;
}

Trajectory simulateTrajectory(const Problem& pr, const VecX& p) {
  const int nf = static_cast<int>(pr.forces.size());
  const int ne = static_cast<int>(pr.excitations.size());
  const int nq0 = static_cast<int>(pr.initial_q.size()), nv0 = static_cast<int>(pr.initial_qdot.size());
  const VecX sp = p.size() == pr.numParameters() ? VecX(p.tail(pr.num_system_params)) : VecX();
  const RunSystem rs = makeRunSystem(pr, sp);
  checkProblem(pr, p, *rs.sys);
  const int N = numSteps(pr);
  const double h = pr.duration / N;
  State s0 = pr.initial;
  for (int j = 0; j < nq0; ++j) s0.q[pr.initial_q[j]] = p[nf + ne + j];
  for (int j = 0; j < nv0; ++j) s0.qdot[pr.initial_qdot[j]] = p[nf + ne + nq0 + j];
  Stepper stepper(pr, *rs.sys);
  const std::vector<std::string> z_names = rs.sys->numStates() > 0 ? rs.sys->stateNames() : std::vector<std::string>{};
  Trajectory tr;
  tr.system = rs.sys;
  VecX y = Stepper::pack(s0);
  tr.states.push_back(s0);
  for (int k = 0; k < N; ++k) {
    const double t = pr.initial.t + k * h;
    tr.controls.push_back(controlsAt(pr, rs, p, k, N));
    y = stepper.step(y, t, h, tr.controls.back());
    const double t1 = k + 1 == N ? pr.initial.t + pr.duration : t + h;
    tr.states.push_back(stepper.unpack(y, t1));
    checkFinite(tr.states.back(), h, pr.integrator.c_str(), &z_names);
  }
  return tr;
}

VecX finiteDifferenceGradient(const Problem& pr, const Objective& obj, const VecX& p) {
  VecX g(p.size());
  auto J = [&](const VecX& x) { return evaluate(pr, obj, x, false).objective; };
  // fourth-order central differences at relative steps 1e-3 .. 1e-6: a large step loses to the
  // run's nonlinearity (truncation), a small one to its round-off (eps |J| / e); the pair of
  // neighbouring steps whose estimates agree best gives the finer of the two
  const double rel[4] = {1e-3, 1e-4, 1e-5, 1e-6};
  static_assert(kDifferenceRunsPerParameter == 4 * 4, "four steps, four runs each");
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    double d[4];
    for (int j = 0; j < 4; ++j) {
      double e = rel[j] * std::max(1.0, std::abs(p[i]));
      // a system parameter (a mass) must stay admissible: never step to zero or below
      if (i >= p.size() - pr.num_system_params && p[i] > 0.0) e = std::min(e, 0.25 * p[i]);
      VecX x = p;
      double f[4];
      const double at[4] = {-2.0, -1.0, 1.0, 2.0};
      for (int k = 0; k < 4; ++k) {
        x[i] = p[i] + at[k] * e;
        f[k] = J(x);
      }
      d[j] = (f[0] - 8.0 * f[1] + 8.0 * f[2] - f[3]) / (12.0 * e);
    }
    int best = 0;
    for (int j = 1; j < 3; ++j)
      if (std::abs(d[j] - d[j + 1]) < std::abs(d[best] - d[best + 1])) best = j;
    g[i] = d[best + 1];
  }
  return g;
}

std::string stepJacobiansText(const Result& r) {
  if (r.analytic_jacobians)
    return "analytic (derivatives of inverse dynamics, docs/gradients.md §2.1)" +
           (r.jacobian_note.empty() ? std::string() : "; " + r.jacobian_note);
  return "central differences of the step" + (r.jacobian_note.empty() ? std::string() : "; not analytic: " + r.jacobian_note);
}

double worstRelativeError(const VecX& a, const VecX& b) {
  const double scale = b.size() > 0 ? b.cwiseAbs().maxCoeff() : 0.0;
  const double err = a.size() > 0 ? (a - b).cwiseAbs().maxCoeff() : 0.0;
  if (scale == 0.0) return err == 0.0 ? 0.0 : INFINITY;
  return err / scale;
}

}  // namespace redmax::adjoint
