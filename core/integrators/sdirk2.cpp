#include "core/integrators/sdirk2.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/Dense>

#include "core/integrators/implicit_solve.hpp"

namespace redmax {

double Sdirk2::gamma() { return 1.0 - 1.0 / std::sqrt(2.0); }

namespace {
bool allFinite(const VecX& v) { return v.allFinite(); }
}  // namespace

void Sdirk2::solveStage(const System& sys, double t, const VecX& zq, const VecX& zv, double hg,
                        double h, VecX& V, DynamicsWorkspace& ws) {
  const int n = sys.ndof();
  static const MatX no_rows;
  State st;
  st.t = t;
  st.z = z_;  // auxiliary states held over the step (integrator.hpp)
  // residual R(V) = V - zv - hg qddot(zq + hg V, V); fills ws (M, f, G) at the iterate
  auto residual = [&](const VecX& Vk) -> VecX {
    st.q = zq + hg * Vk;
    st.qdot = Vk;
    const VecX a = sys.forwardDynamics(st, ws);
    ++stats_.rhs_evals;
    return Vk - zv - hg * a;
  };

  // phase 1: approximate Newton with M + hg D + hg^2 K; phase 2: finite-difference Jacobian
  const VecX V_start = V;
  for (int phase = 0; phase < 2; ++phase) {
    if (phase == 1) {
      ++stats_.failed_steps;  // counts stages whose cheap iteration failed
      V = V_start;
    }
    double prev = -1.0;
    Eigen::PartialPivLU<MatX> J_lu;  // phase 2: LU of dR/dV
    bool refresh = true;             // phase 2: build dR/dV at the current iterate
    for (int it = 0; it < opt_.newton_max_iter; ++it) {
      const VecX R = residual(V);
      if (!allFinite(R)) {
        // NaN/Inf from the dynamics: no Jacobian will fix that
        std::ostringstream os;
        os << "sdirk2: non-finite qddot in the stage equation at t = " << t << " with step h = " << h;
        throw SimulationError(os.str(), t, h);
      }
      const MatX& G = sys.numConstraintRows() > 0 ? ws.G : no_rows;
      VecX dV;
      if (phase == 0) {
        // the articulated route leaves M unformed (DynamicsWorkspace::has_mass)
        if (!ws.has_mass) sys.calcMassAndForce(st, ws);
        sys.calcStiffnessDamping(st, ws);
        ++stats_.jacobian_evals;
        const MatX A = ws.M + hg * ws.D + (hg * hg) * ws.K;
        // Newton step from the M-scaled, linearised stage equation (see header); the constraint
        // rows keep G dV = -G R so the iterate stays consistent with the KKT accelerations
        dV = detail::solveImplicit(A, G, -(ws.M * R), G.rows() ? VecX(-(G * R)) : VecX(), nullptr);
      } else {
        if (refresh) {
          // forward differences of R (ws is overwritten; R was taken before)
          MatX J(n, n);
          ++stats_.jacobian_evals;
          for (int k = 0; k < n; ++k) {
            VecX Vp = V;
            const double e = 1.5e-8 * (1.0 + std::abs(V[k]));
            Vp[k] += e;
            J.col(k) = (residual(Vp) - R) / e;
          }
          J_lu.compute(J);
          // a Jacobian kept from a far-off predictor converges only linearly when the
          // velocity-product forces are large, so the fallback is full Newton: a new FD
          // Jacobian at every iterate (quadratic convergence)
          refresh = true;
        }
        dV = -J_lu.solve(R);
      }
      if (!allFinite(dV)) break;
      V += dV;
      const double nrm = dV.norm();
      const double bound = opt_.newton_tol * (1.0 + V.norm());
      if (nrm <= bound) return;
      if (prev > 0.0) {
        // linear convergence at rate theta leaves an error of about theta / (1 - theta) |dV|
        // after this update (Hairer and Wanner's stopping rule): often one evaluation fewer
        const double theta = nrm / prev;
        if (theta < 1.0 && theta / (1.0 - theta) * nrm <= bound) return;
        if (phase == 0) {
          // diverging, or too slow to reach the bound in the iterations left: give up early
          const int left = opt_.newton_max_iter - it - 1;
          if (theta >= 1.0 || std::pow(theta, left) / (1.0 - theta) * nrm > bound) break;
        }
      }
      prev = nrm;
    }
  }
  std::ostringstream os;
  os << "sdirk2: Newton iteration did not converge (stage at t = " << t << ", step h = " << h
     << ", tolerance " << opt_.newton_tol << ")";
  throw SimulationError(os.str(), t, h);
}

void Sdirk2::step(const System& sys, State& s, double h, DynamicsWorkspace& ws) {
  const double g = gamma();
  const double hg = h * g;
  const VecX q0 = s.q, v0 = s.qdot;
  z_ = s.z;

  // stage 1 at t + gamma h: Y1 = y0 + h gamma F(Y1); predictor from the previous step's end
  // acceleration when this step continues it, else the start velocity
  const bool continues = a_end_.size() == v0.size() && end_.q == q0 && end_.qdot == v0;
  VecX V1 = continues ? VecX(v0 + hg * a_end_) : v0;
  solveStage(sys, s.t + hg, q0, v0, hg, h, V1, ws);
  // F(Y1) = (Y1 - y0) / (h gamma), which avoids one more dynamics evaluation
  const VecX a1 = (V1 - v0) / hg;

  // stage 2 at t + h: Y2 = y0 + h (1 - gamma) F(Y1) + h gamma F(Y2)
  const VecX zq = q0 + h * (1.0 - g) * V1;
  const VecX zv = v0 + h * (1.0 - g) * a1;
  VecX V2 = v0 + h * a1;  // predictor: velocity extrapolated with the stage-1 acceleration
  solveStage(sys, s.t + h, zq, zv, hg, h, V2, ws);

  // stiffly accurate: y+ = Y2
  s.q = zq + hg * V2;
  s.qdot = V2;
  s.t += h;
  a_end_ = (V2 - zv) / hg;
  end_ = s;
}

}  // namespace redmax
