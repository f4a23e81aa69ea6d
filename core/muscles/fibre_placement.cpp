#include "core/muscles/fibre_placement.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/muscles/path_kinematics.hpp"

namespace redmax {

namespace {

constexpr int kMaxStates = 8;  // a Hill model has at most activation and one fibre/tendon state

int stateIndex(const hill::MuscleModel& model, const std::string& name) {
  const auto& names = model.stateNames();
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

}  // namespace

int fiberStateIndex(const hill::MuscleModel& model) { return stateIndex(model, "fiber_length"); }

std::string fibrePlacementUnsupportedReason(const Muscle& mu, const hill::MuscleModel* model) {
  if (!model) return "no muscle model (its class is not modelled)";
  if (mu.mass_points.size() == 0) return "no mass points";
  if (pathType(mu.path) == PathType::III) return "wrapping (Type III) path";
  if (model->numStates() > kMaxStates) return "more than 8 states";
  // a state that sets the tendon length other than through the fibre length (DeGrooteFregly2016's
  // normalized tendon force): its rate follows the path's speed, so the fibre's acceleration
  // would hold qddot
  if (fiberStateIndex(*model) < 0)
    for (const std::string& n : model->stateNames())
      if (n != "activation") return "its state '" + n + "' is not a fibre length";
  return "";
}

TendonKinematics calcTendonKinematics(const Muscle& mu, double L, double Ldot, const FibreStates& fs,
                                      bool velocity) {
  const hill::MuscleModel& model = *mu.fibre.model;
  const int n = model.numStates();
  std::array<double, kMaxStates> z{}, zdot{}, zp{}, zm{}, rp{}, rm{};
  hill::MusculotendonInput in;
  in.length = L;
  in.speed = Ldot;
  in.excitation = fs.excitation;
  hill::MuscleOutput out;
  TendonKinematics tk;
  if (!fs.z) {
    // no states: equilibrium at the default activation, the tendon held at that length
    model.defaultState(z.data());
    const int act = stateIndex(model, "activation");
    if (act >= 0) in.excitation = z[act];
    try {
      model.equilibrate(in, z.data());
      model.calc(z.data(), in, out, zdot.data());
      tk.length = out.tendon_length;
    } catch (const hill::MuscleModelError&) {
      tk.length = mu.tendon_slack_length;  // no fibre length balances the tendon here
    }
    return tk;
  }
  std::copy(fs.z, fs.z + n, z.begin());
  model.calc(z.data(), in, out, zdot.data());
  tk.length = out.tendon_length;
  const int f = mu.fibre.fiber_state;
  if (f < 0) return tk;  // rigid tendon: l_T = l_ts
  tk.dT_dL = 1.0;
  if (!velocity) return tk;
  // P(l_M) = l_M cos(alpha) with l_M sin(alpha) = w fixed (header)
  const double lM = out.fiber_length, cosa = std::cos(out.pennation_angle);
  const double P = lM * cosa, w = lM * std::sin(out.pennation_angle);
  const double Pp = lM / P, Ppp = -w * w / (P * P * P);
  const double vM = zdot[f];
  tk.rate = -Pp * vM;
  // dv_M/dt: central difference of the model's rate along the motion; h moves every state by
  // about 1e-5 of its size (or of 1e-2 for one near zero) and the path by 1e-5 of its length
  double rel = 1.0;
  for (int j = 0; j < n; ++j) rel = std::max(rel, std::abs(zdot[j]) / std::max(std::abs(z[j]), 1e-2));
  rel = std::max(rel, std::abs(Ldot) / L);
  const double h = 1e-5 / rel;
  for (int j = 0; j < n; ++j) {
    zp[j] = z[j] + h * zdot[j];
    zm[j] = z[j] - h * zdot[j];
  }
  hill::MusculotendonInput ip = in, im = in;
  ip.length = L + h * Ldot;
  im.length = L - h * Ldot;
  hill::MuscleOutput op, om;
  model.calc(zp.data(), ip, op, rp.data());
  model.calc(zm.data(), im, om, rm.data());
  const double vM_dot = (rp[f] - rm[f]) / (2.0 * h);
  tk.rate_dot = -Ppp * vM * vM - Pp * vM_dot;
  return tk;
}

void calcFibreMassPoints(const std::vector<double>& c, const TendonKinematics& tk, MuscleKinematics& mk,
                         const std::string& muscle_name) {
  const int P = static_cast<int>(mk.x_w.size()), nseg = P - 1, N = static_cast<int>(c.size());
  const int k = static_cast<int>(mk.J_xr.cols());
  const bool vel = mk.velocity;
  const double L = mk.length;
  if (!(L > 0.0))
    throw MuscleError("muscle '" + muscle_name + "': origin and insertion coincide here; mass points need a path of positive length");
  mk.x_a.resize(N);
  mk.segment.resize(N);
  mk.beta.resize(N);
  if (mk.J_ar.rows() != 3 * N || mk.J_ar.cols() != k) mk.J_ar.resize(3 * N, k);
  mk.J_aT.resize(3 * N);
  if (vel) {
    if (mk.Jdot_ar.rows() != 3 * N || mk.Jdot_ar.cols() != k) mk.Jdot_ar.resize(3 * N, k);
    mk.v_z.resize(3 * N);
    mk.a_z.resize(3 * N);
  }
  // dl_j/dq = t_j^T (J_j+1 - J_j) and its time derivative, per segment [D Eq. 5.27]
  if (mk.seg_lq.rows() != nseg || mk.seg_lq.cols() != k) mk.seg_lq.resize(nseg, k);
  if (vel && (mk.seg_lqdot.rows() != nseg || mk.seg_lqdot.cols() != k)) mk.seg_lqdot.resize(nseg, k);
  for (int j = 0; j < nseg; ++j) {
    const Vec3& t = mk.dxbar[j];
    mk.seg_lq.row(j).noalias() = t.transpose() * (mk.J_xr.middleRows<3>(3 * (j + 1)) - mk.J_xr.middleRows<3>(3 * j));
    if (!vel) continue;
    const double l = mk.l[j];
    const Vec3 tdot = l > 0.0 ? Vec3((mk.xdot_w[j + 1] - mk.xdot_w[j] - t * mk.ldot[j]) / l) : Vec3::Zero();
    mk.seg_lqdot.row(j).noalias() =
        tdot.transpose() * (mk.J_xr.middleRows<3>(3 * (j + 1)) - mk.J_xr.middleRows<3>(3 * j)) +
        t.transpose() * (mk.Jdot_xr.middleRows<3>(3 * (j + 1)) - mk.Jdot_xr.middleRows<3>(3 * j));
  }
  const Eigen::RowVectorXd L_q = mk.seg_lq.colwise().sum();
  Eigen::RowVectorXd Ldot_q;
  if (vel) Ldot_q = mk.seg_lqdot.colwise().sum();
  const double Ldot = mk.lengthening_speed;

  Eigen::RowVectorXd u_q(k), udot_q(k);
  Eigen::Matrix<double, 3, Eigen::Dynamic> dJ(3, k), dJd(3, k), T(3, k), Tdot(3, k);
  for (int a = 0; a < N; ++a) {
    const double ca = c[a], half = 0.5 - ca;
    // sigma = l_T / 2 + c (L - l_T); d sigma / dL at fixed states
    const double sigma = 0.5 * tk.length + ca * (L - tk.length);
    const double sL = ca + half * tk.dT_dL;
    // segment holding sigma: the last one starting at or before it (points beyond an end stay on
    // the end segment's line, smooth in sigma)
    int i = 0;
    double S = 0.0;
    while (i + 1 < nseg && S + mk.l[i] <= sigma) S += mk.l[i++];
    const double li = mk.l[i];
    if (!(li > 0.0))
      throw MuscleError("muscle '" + muscle_name + "': segment " + std::to_string(i) +
                        " has zero length here; a mass point sits on it");
    const Vec3& t = mk.dxbar[i];
    const double u = sigma - S;
    mk.segment[a] = i;
    mk.beta[a] = u / li;
    mk.x_a[a] = mk.x_w[i] + u * t;
    // dS_i/dq: sum of the segments before i
    u_q = sL * L_q;
    for (int j = 0; j < i; ++j) u_q -= mk.seg_lq.row(j);
    const Mat3 Pt = Mat3::Identity() - t * t.transpose();
    dJ = mk.J_xr.middleRows<3>(3 * (i + 1)) - mk.J_xr.middleRows<3>(3 * i);
    T.noalias() = Pt * dJ / li;
    auto J = mk.J_ar.middleRows<3>(3 * a);
    J = mk.J_xr.middleRows<3>(3 * i);
    J.noalias() += t * u_q;
    J += u * T;
    mk.J_aT.segment<3>(3 * a) = half * t;
    if (!vel) continue;
    const Vec3 tdot = Pt * (mk.xdot_w[i + 1] - mk.xdot_w[i]) / li;
    double Sdot = 0.0;
    udot_q = sL * Ldot_q;
    for (int j = 0; j < i; ++j) {
      Sdot += mk.ldot[j];
      udot_q -= mk.seg_lqdot.row(j);
    }
    const double udot = sL * Ldot + half * tk.rate - Sdot;
    dJd = mk.Jdot_xr.middleRows<3>(3 * (i + 1)) - mk.Jdot_xr.middleRows<3>(3 * i);
    // d/dt [(I - t t^T) / l] dJ + (I - t t^T) / l dJd
    Tdot = -(tdot * (t.transpose() * dJ) + t * (tdot.transpose() * dJ));
    Tdot.noalias() += Pt * dJd;
    Tdot -= (mk.ldot[i] / li) * (Pt * dJ);
    Tdot /= li;
    auto Jd = mk.Jdot_ar.middleRows<3>(3 * a);
    Jd = mk.Jdot_xr.middleRows<3>(3 * i);
    Jd.noalias() += tdot * u_q;
    Jd.noalias() += t * udot_q;
    Jd += udot * T + u * Tdot;
    mk.v_z.segment<3>(3 * a) = half * tk.rate * t;
    mk.a_z.segment<3>(3 * a) = half * (tk.rate * tdot + tk.rate_dot * t);
  }
}

void setFibrePlacement(const Model& model, const VecX& q, const std::vector<Mat4>& E_wi,
                       std::shared_ptr<const hill::MuscleModel> muscle_model, Muscle& mu) {
  const std::string why = fibrePlacementUnsupportedReason(mu, muscle_model.get());
  if (!why.empty())
    throw ModelError("muscle '" + mu.name + "': no fibre-following mass placement: " + why);
  const int N = mu.mass_points.size();
  mu.fibre.model = std::move(muscle_model);
  mu.fibre.fiber_state = fiberStateIndex(*mu.fibre.model);
  mu.fibre.c.resize(N);
  for (int a = 0; a < N; ++a) mu.fibre.c[a] = (a + 0.5) / N;
  // the arc fractions at q with the fibre at equilibrium (at rest)
  const double L = calcPathLength(model, mu.path, q, E_wi);
  if (!(L > 0.0)) throw ModelError("muscle '" + mu.name + "': path of zero length at the default pose");
  const TendonKinematics tk = calcTendonKinematics(mu, L, 0.0, FibreStates{}, false);
  for (int a = 0; a < N; ++a)
    mu.mass_points.alpha[a] = std::clamp((0.5 * tk.length + mu.fibre.c[a] * (L - tk.length)) / L, 0.0, 1.0);
}

}  // namespace redmax
