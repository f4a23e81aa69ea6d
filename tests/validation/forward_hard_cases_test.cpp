// Muscle-driven hard cases through the ForwardTool (validation/forward/forward_tool.hpp), on
// osim_models/tug_of_war_step.osim (a block between two mirrored Millard muscles), each with the
// failure it guards against:
//   - excitation steps: the activation must follow OpenSim's first-order activation ODE
//     (MuscleFirstOrderActivationDynamicModel, [Thelen 2003, Eqs. 6-7]) in closed form, rising with
//     tau_a (0.5 + 1.5 a) and falling with tau_d / (0.5 + 1.5 a); a controller evaluated at the
//     wrong time, a state read from the wrong slot or an activation clamped in the wrong place
//     shows here. The tendon force must rise while the activation rises and settle at the
//     isometric equilibrium (the model's own equilibrate() at the final activation);
//   - a stiff tendon (strain 0.002 at F_max): rk45 needs thousands of steps where cvode needs
//     hundreds; cvode must complete and agree with rk45 at tight tolerance (docs/forward.md §5).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/dynamics/muscle_force_term.hpp"
#include "core/dynamics/system.hpp"
#include "tests/converter/converter_test_util.hpp"
#include "validation/forward/forward_tool.hpp"

namespace redmax::validation {
namespace {

const std::string kScene = std::string(REDMAX_SOURCE_DIR) + "/osim_models/tug_of_war_step.osim";

/// a ForwardTool setup for `model` over [0, t1] with a PrescribedController of `functions`
std::string forwardSetup(const std::string& model, double t1, const std::string& functions, double tol) {
  std::ostringstream f;
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenSimDocument Version=\"40000\">\n"
    << "<ForwardTool name=\"tow\">\n<model_file>" << model << "</model_file>\n"
    << "<initial_time>0</initial_time>\n<final_time>" << t1 << "</final_time>\n"
    << "<solve_for_equilibrium_for_auxiliary_states>true</solve_for_equilibrium_for_auxiliary_states>\n"
    << "<maximum_number_of_integrator_steps>100000</maximum_number_of_integrator_steps>\n"
    << "<integrator_error_tolerance>" << tol << "</integrator_error_tolerance>\n"
    << "<ControllerSet><objects><PrescribedController name=\"step\">\n<FunctionSet><objects>\n"
    << functions << "</objects></FunctionSet>\n</PrescribedController></objects></ControllerSet>\n"
    << "</ForwardTool>\n</OpenSimDocument>\n";
  return f.str();
}

/// a PiecewiseConstantFunction driving `muscle`
std::string piecewiseConstant(const std::string& muscle, const std::string& x, const std::string& y) {
  return "<PiecewiseConstantFunction name=\"" + muscle + "\"><x>" + x + "</x><y>" + y + "</y></PiecewiseConstantFunction>\n";
}

const MuscleForceTerm& muscleForceTerm(const System& sys) {
  for (const auto& t : sys.terms())
    if (const auto* m = dynamic_cast<const MuscleForceTerm*>(t.get())) return *m;
  throw std::logic_error("no MuscleForceTerm");
}

/// rising (u > a): tau_a [(0.5 + 1.5 u) ln((u - a0)/(u - a)) - 1.5 (a - a0)] = t, solved for a by
/// bisection on [a0, u)
double riseClosedForm(double a0, double u, double tau_a, double t) {
  double lo = a0, hi = u;
  for (int i = 0; i < 200; ++i) {
    const double a = 0.5 * (lo + hi);
    const double ta = tau_a * ((0.5 + 1.5 * u) * std::log((u - a0) / (u - a)) - 1.5 * (a - a0));
    (ta < t ? lo : hi) = a;
  }
  return 0.5 * (lo + hi);
}

/// falling (u < a): R = (0.5 + 1.5 a)/(a - u) grows as R0 exp((0.5 + 1.5 u) t / tau_d), so
/// a = (R u + 0.5)/(R - 1.5)
double fallClosedForm(double a0, double u, double tau_d, double t) {
  const double R = (0.5 + 1.5 * a0) / (a0 - u) * std::exp((0.5 + 1.5 * u) * t / tau_d);
  return (R * u + 0.5) / (R - 1.5);
}

TEST(ForwardHardCases, ExcitationStepsFollowTheActivationClosedFormAndSettleIsometrically) {
  // excitation 0.05 (the default activation: at rest) -> 0.8 at 0.05 s -> 0.2 at 0.3 s; the fall's
  // time constant tends to tau_d / 0.8 = 0.05 s, so 0.6 s more settle it to 1e-5 of the step
  const double t_up = 0.05, t_down = 0.3, t_end = 0.9, u0 = 0.05, u1 = 0.8, u2 = 0.2;
  const double tau_a = 0.01, tau_d = 0.04;  // the file's time constants, for both classes
  for (const std::string cls : {"", "Thelen2003Muscle"}) {
    osim::test::TempDir dir;
    ForwardToolSettings s;
    const std::string nodes_t = "0 0.05 0.3", nodes_u = "0.05 0.8 0.2";
    s.setup_file = dir.write("setup.xml", forwardSetup(kScene, t_end,
                                                       piecewiseConstant("left_muscle", nodes_t, nodes_u) +
                                                           piecewiseConstant("right_muscle", nodes_t, nodes_u),
                                                       1e-9));
    s.muscle_class = cls;
    s.report_interval = 0.005;
    const ForwardTool tool(s);
    const ForwardResult r = tool.run();
    const std::string name = cls.empty() ? "Millard2012EquilibriumMuscle" : cls;
    ASSERT_FALSE(r.failed) << name << ": " << r.failure;
    const osim::Storage& st = r.states;
    const int ca = st.findColumn("/forceset/left_muscle/activation");
    const int cl = st.findColumn("/forceset/left_muscle/fiber_length");
    const int cr = st.findColumn("/forceset/right_muscle/fiber_length");
    const int cx = st.findColumn("/jointset/slider/block_x/value");
    ASSERT_TRUE(ca >= 0 && cl >= 0 && cr >= 0 && cx >= 0);

    // activation against the closed forms (the integrator's error at rtol = atol = 1e-9)
    const double a_top = riseClosedForm(u0, u1, tau_a, t_down - t_up);
    double act_err = 0, block = 0, mirror = 0;
    for (int k = 0; k < st.numRows(); ++k) {
      const double t = st.time[k];
      const double exact = t <= t_up ? u0 : t <= t_down ? riseClosedForm(u0, u1, tau_a, t - t_up)
                                                        : fallClosedForm(a_top, u2, tau_d, t - t_down);
      act_err = std::max(act_err, std::abs(st.data(k, ca) - exact));
      block = std::max(block, std::abs(st.data(k, cx)));
      mirror = std::max(mirror, std::abs(st.data(k, cl) - st.data(k, cr)));
    }
    std::printf("[ measured ] %s: activation vs closed form %.2e, |block_x| %.2e, left - right fibre %.2e; "
                "rk45 %ld steps\n", name.c_str(), act_err, block, mirror, r.stats.steps);
    EXPECT_LT(act_err, 5e-7) << name;  // measured 5.8e-8 (Millard), 1.9e-7 (Thelen)
    // the mirror image: equal forces, the block stays and each muscle is isometric
    EXPECT_EQ(block, 0.0) << name;
    EXPECT_EQ(mirror, 0.0) << name;

    // tendon force: rises with the activation, then settles at the isometric equilibrium
    const System& sys = tool.system();
    const MuscleForceTerm& mft = muscleForceTerm(sys);
    const auto& model = *mft.actuated()[0].model;
    DynamicsWorkspace ws(sys);
    State x = tool.initialState();
    double prev = -1, settle_up = 0, settle_end = 0;
    for (int k = 0; k < st.numRows(); ++k) {
      const double t = st.time[k];
      x.t = t;
      x.q[0] = st.data(k, cx);
      for (int j = 0; j < x.z.size(); ++j) x.z[j] = st.data(k, st.findColumn(sys.stateNames()[j]));
      sys.calcMassAndForce(x, ws);  // the path kinematics at x
      const hill::MuscleOutput out = mft.calcOutput(sys.model(), x, TermContext(ws.sk, nullptr, 0), 0);
      if (t > t_up && t <= t_down) {
        EXPECT_GT(out.tendon_force, prev) << name << " t " << t;  // strictly rising after the step
        prev = out.tendon_force;
      }
      // at the end of each phase: the equilibrium at that activation and the path's 0.45 m
      if (std::abs(t - t_down) < 1e-9 || std::abs(t - t_end) < 1e-9) {
        double z[2] = {st.data(k, ca), st.data(k, cl)};
        model.equilibrate({0.45, 0.0, z[0]}, z);
        double zd[2];
        hill::MuscleOutput eq;
        model.calc(z, {0.45, 0.0, z[0]}, eq, zd);
        const double rel = std::abs(out.tendon_force - eq.tendon_force) / eq.tendon_force;
        (t < t_end ? settle_up : settle_end) = rel;
        std::printf("[ measured ] %s t = %.2f: tendon force %.6f N, equilibrium %.6f N (%.1e relative), "
                    "fibre %.6e vs %.6e m\n", name.c_str(), t, out.tendon_force, eq.tendon_force, rel,
                    st.data(k, cl), z[1]);
      }
    }
    // measured: Millard 4.2e-6 at 0.3 s, 1.8e-6 at 0.9 s; Thelen 5.5e-7, 7.5e-6
    EXPECT_LT(settle_up, cls.empty() ? 1e-5 : 2e-6) << name;
    EXPECT_LT(settle_end, cls.empty() ? 5e-6 : 1.5e-5) << name;
  }
}

TEST(ForwardHardCases, StiffTendonNeedsCvode) {
  // both muscles' tendons 25 times stiffer than OpenSim's default (strain 0.002 at F_max instead of
  // 0.049): with fibre damping 0.1 the fibre-tendon time constant is about 1e-6 s. The left muscle
  // steps to full excitation at 0.05 s, the right stays at 0.05: the block is pulled left
  std::ifstream in(kScene);
  std::stringstream text;
  text << in.rdbuf();
  std::string model = text.str();
  const std::string damping = "<fiber_damping>0.1</fiber_damping>";
  const std::string stiff = damping + "<TendonForceLengthCurve name=\"stiff\"><strain_at_one_norm_force>0.002"
                                      "</strain_at_one_norm_force></TendonForceLengthCurve>";
  for (size_t p = model.find(damping); p != std::string::npos; p = model.find(damping, p + stiff.size()))
    model.replace(p, damping.size(), stiff);
  osim::test::TempDir dir;
  const std::string file = dir.write("stiff.osim", model);
  ForwardToolSettings s;
  s.setup_file = dir.write("setup.xml", forwardSetup(file, 0.3,
                                                     piecewiseConstant("left_muscle", "0 0.05", "0.05 1") +
                                                         "<Constant name=\"right_muscle\"><value>0.05</value></Constant>\n",
                                                     1e-8));
  s.report_interval = 0.01;
  ForwardResult run[2];
  const char* integrators[2] = {"rk45", "cvode"};
  for (int i = 0; i < 2; ++i) {
    s.integrator = integrators[i];
    const ForwardTool tool(s);
    run[i] = tool.run();
    ASSERT_FALSE(run[i].failed) << integrators[i] << ": " << run[i].failure;
    std::printf("[ measured ] stiff tendon, %s at 1e-8: %ld steps, %ld rhs, %ld failed, %.2f s wall\n",
                integrators[i], run[i].stats.steps, run[i].stats.rhs_evals, run[i].stats.failed_steps, run[i].wall_s);
  }
  // rk45 is held by stability, not accuracy: thousands of steps where cvode takes hundreds
  EXPECT_GT(run[0].stats.steps, 1500);                      // measured 2257
  EXPECT_GT(run[0].stats.steps, 3 * run[1].stats.steps);    // measured 2257 / 522 = 4.3
  EXPECT_GT(run[0].stats.rhs_evals, 8 * run[1].stats.rhs_evals);  // measured 13766 / 1015 = 13.6
  // and both follow the same motion: the block moves about 8.6 cm to the left
  const osim::Storage &a = run[0].states, &b = run[1].states;
  ASSERT_EQ(a.numRows(), b.numRows());
  ASSERT_EQ(a.labels, b.labels);
  const int cx = a.findColumn("/jointset/slider/block_x/value");
  ASSERT_GE(cx, 0);
  EXPECT_LT(a.data(a.numRows() - 1, cx), -0.08);
  double worst = 0;
  std::string which;
  for (int j = 0; j < a.numColumns(); ++j)
    for (int k = 0; k < a.numRows(); ++k)
      if (std::abs(a.data(k, j) - b.data(k, j)) > worst) {
        worst = std::abs(a.data(k, j) - b.data(k, j));
        which = a.labels[j];
      }
  std::printf("[ measured ] rk45 vs cvode, worst state difference %.2e (%s)\n", worst, which.c_str());
  EXPECT_LT(worst, 3e-6);  // measured 1.6e-6 (left_muscle's activation)
}

TEST(ForwardHardCases, SplineKneeInertialAgainstLumped) {
  // osim_models/spline_knee.osim (a shank on gait2392's spline knee, a quadriceps over a pulley
  // point and a hamstring): quad 0.05 -> 0.15 over [0.05, 0.2) s, hamstring 0.05 -> 0.6 from
  // 0.2 s; the knee extends from -0.5 rad to +0.32 rad, then flexes. Lumped (the model as OpenSim
  // sees it) against 0% and 30% of the tibia's mass moved into the muscles
  osim::test::TempDir dir;
  ForwardToolSettings s;
  s.setup_file = dir.write(
      "setup.xml",
      forwardSetup(std::string(REDMAX_SOURCE_DIR) + "/osim_models/spline_knee.osim", 0.6,
                   piecewiseConstant("quad", "0 0.05 0.2", "0.05 0.15 0.05") +
                       piecewiseConstant("hamstring", "0 0.2", "0.05 0.6"),
                   1e-8));
  s.report_interval = 0.01;
  const ForwardResult lumped = ForwardTool(s).run();
  ASSERT_FALSE(lumped.failed) << lumped.failure;
  const osim::Storage& l = lumped.states;
  const int cq = l.findColumn("/jointset/knee/knee_angle/value");
  ASSERT_GE(cq, 0);
  // the scene does what it is built for: the quadriceps extends the knee through straight (0), then
  // the hamstring flexes it again (measured peak 0.3172 rad at 0.4 s; end 0.6 s)
  auto peakKnee = [cq](const osim::Storage& st) {
    double q = -1e9;
    for (int k = 0; k < st.numRows(); ++k) q = std::max(q, st.data(k, cq));
    return q;
  };
  const double q_max = peakKnee(l);
  EXPECT_GT(q_max, 0.0);
  EXPECT_LT(l.data(l.numRows() - 1, cq), q_max);
  s.muscle_mass.source = osim::MuscleMassOptions::Source::Transfer;
  s.muscle_mass.transfer_body = "tibia";
  std::vector<osim::Storage> heavy_q;
  double dq_uniform = 0;
  for (const auto placement : {osim::MuscleMassOptions::Placement::Uniform, osim::MuscleMassOptions::Placement::Fibre}) {
    s.muscle_mass.placement = placement;
    const char* pname = osim::toString(placement);
    // zero mass: the same run, bit for bit (points of zero mass add exact zeros)
    s.muscle_mass.transfer_fraction = 0.0;
    const ForwardResult zero = ForwardTool(s).run();
    ASSERT_FALSE(zero.failed) << pname << ": " << zero.failure;
    ASSERT_EQ(zero.states.numRows(), l.numRows());
    EXPECT_EQ(zero.stats.steps, lumped.stats.steps) << pname;
    double diff = 0;
    for (int k = 0; k < l.numRows(); ++k)
      for (int j = 0; j < l.numColumns(); ++j) diff = std::max(diff, std::abs(zero.states.data(k, j) - l.data(k, j)));
    EXPECT_EQ(diff, 0.0) << pname;
    // 30% of the tibia (1.05 kg) in the two muscles: the knee's path changes by millirad
    s.muscle_mass.transfer_fraction = 0.3;
    const ForwardResult heavy = ForwardTool(s).run();
    ASSERT_FALSE(heavy.failed) << pname << ": " << heavy.failure;
    double dq = 0;
    for (int k = 0; k < l.numRows(); ++k) dq = std::max(dq, std::abs(heavy.states.data(k, cq) - l.data(k, cq)));
    std::printf("[ measured ] spline knee, 30%% of the tibia in the muscles (%s): max knee change %.3e rad, "
                "peak %.4f rad (lumped %.4f), rk45 %ld steps (lumped %ld)\n", pname, dq, peakKnee(heavy.states), q_max,
                heavy.stats.steps, lumped.stats.steps);
    // the shank loses 1.05 kg to muscles that span the knee, whose points move less than the shank's
    // centre of mass: the same muscle forces extend it further (measured change 0.1263 rad, both
    // placements)
    EXPECT_GT(peakKnee(heavy.states), q_max) << pname;
    EXPECT_GT(dq, 1e-3) << pname;
    if (placement == osim::MuscleMassOptions::Placement::Uniform) dq_uniform = dq;
    heavy_q.push_back(heavy.states);
  }
  // the placements differ little here (short tendons: l_ts / (l_opt + l_ts) 0.76 and 0.71, and the
  // fibre carries the mass either way)
  double dp = 0;
  for (int k = 0; k < l.numRows(); ++k) dp = std::max(dp, std::abs(heavy_q[0].data(k, cq) - heavy_q[1].data(k, cq)));
  std::printf("[ measured ] spline knee, uniform vs fibre placement: max knee difference %.3e rad\n", dp);
  EXPECT_GT(dp, 0.0);
  // ... so the placement changes the run by far less than the mass does (measured 3.3e-5 of 0.1263 rad)
  EXPECT_LT(dp, 1e-3 * dq_uniform);
}

}  // namespace
}  // namespace redmax::validation
