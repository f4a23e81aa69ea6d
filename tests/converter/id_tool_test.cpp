// The inverse-dynamics tool (converter/id/) on project-authored models with closed-form motions:
// a planar double pendulum and a cart-pole whose ID torques are known analytically, external
// loads in body and ground frames, degrees/radians per motion type, OpenSim's time window and
// default-held coordinates, the Ball/Free speed map (finite differences, power balance), and bad
// inputs. Runs everywhere (no ../shared needed).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter_test_util.hpp"
#include "core/joints/joint.hpp"

namespace redmax::osim {
namespace {

using test::TempDir;

constexpr double kG = 9.80665;

std::string num(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}
std::string vec3(double a, double b, double c) { return num(a) + " " + num(b) + " " + num(c); }

std::string frameXml(const std::string& name, const std::string& parent, const std::string& t) {
  return "<PhysicalOffsetFrame name=\"" + name + "\"><socket_parent>" + parent +
         "</socket_parent><translation>" + t + "</translation><orientation>0 0 0</orientation>"
         "</PhysicalOffsetFrame>\n";
}

// a body with COM at (0, -c, 0) and inertia I about the COM (Izz = I, others 2I)
std::string linkXml(const std::string& name, double m, double c, double I) {
  return "<Body name=\"" + name + "\"><mass>" + num(m) + "</mass><mass_center>" + vec3(0, -c, 0) +
         "</mass_center><inertia>" + vec3(2 * I, 2 * I, I) + " 0 0 0</inertia></Body>\n";
}

// a joint from parent frame (offset t_parent) to the child body's origin
std::string jointXml(const std::string& type, const std::string& name, const std::string& parent,
                     const std::string& child, const std::string& t_parent,
                     const std::vector<std::string>& coords) {
  std::string x = "<" + type + " name=\"" + name + "\"><socket_parent_frame>" + name +
                  "_p</socket_parent_frame><socket_child_frame>" + name +
                  "_c</socket_child_frame><coordinates>";
  for (const auto& c : coords) x += "<Coordinate name=\"" + c + "\"><default_value>0.1</default_value></Coordinate>";
  x += "</coordinates><frames>" + frameXml(name + "_p", parent, t_parent) +
       frameXml(name + "_c", child, "0 0 0") + "</frames></" + type + ">\n";
  return x;
}

std::string modelXml(const std::string& bodies, const std::string& joints) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
         "<Model name=\"authored\"><Ground name=\"ground\"/><gravity>0 -9.80665 0</gravity>\n"
         "<BodySet name=\"bodyset\"><objects>\n" + bodies + "</objects></BodySet>\n"
         "<JointSet name=\"jointset\"><objects>\n" + joints + "</objects></JointSet>\n"
         "</Model>\n</OpenSimDocument>\n";
}

// a .mot with the given columns sampled at n points on [t0, t1]
std::string motion(const std::vector<std::string>& labels,
                   const std::vector<std::function<double(double)>>& f, double t0, double t1, int n,
                   bool degrees) {
  std::ostringstream os;
  os.precision(17);
  os << "motion\nversion=1\nnRows=" << n << "\nnColumns=" << labels.size() + 1
     << "\ninDegrees=" << (degrees ? "yes" : "no") << "\nendheader\ntime";
  for (const auto& l : labels) os << "\t" << l;
  os << "\n";
  for (int i = 0; i < n; ++i) {
    const double t = t0 + (t1 - t0) * i / (n - 1);
    os << t;
    for (const auto& g : f) os << "\t" << g(t);
    os << "\n";
  }
  return os.str();
}

// q(t) = a + b sin(w t + p) with its derivatives
struct Sine {
  double a, b, w, p;
  double q(double t) const { return a + b * std::sin(w * t + p); }
  double qd(double t) const { return b * w * std::cos(w * t + p); }
  double qdd(double t) const { return -b * w * w * std::sin(w * t + p); }
};

// largest |a - b| over all entries relative to the largest |b| of each column
double worstRelative(const MatX& a, const MatX& b) {
  double worst = 0;
  for (Eigen::Index c = 0; c < b.cols(); ++c) {
    const double peak = std::max(b.col(c).cwiseAbs().maxCoeff(), 1e-300);
    worst = std::max(worst, (a.col(c) - b.col(c)).cwiseAbs().maxCoeff() / peak);
  }
  return worst;
}

// ---- double pendulum ------------------------------------------------------------------------
// link i: mass m_i, COM c_i below its joint, Izz I_i about the COM; joint 2 at L1 below joint 1
struct DoublePendulum {
  double m1 = 1.3, c1 = 0.45, I1 = 0.07, L1 = 0.9;
  double m2 = 0.8, c2 = 0.35, I2 = 0.04;
  Sine s1{0.2, 0.7, 2 * M_PI * 0.8, 0.3}, s2{-0.1, 0.9, 2 * M_PI * 1.1, -0.4};

  std::string osim() const {
    return modelXml(linkXml("link1", m1, c1, I1) + linkXml("link2", m2, c2, I2),
                    jointXml("PinJoint", "j1", "/ground", "/bodyset/link1", "0 0 0", {"q1"}) +
                        jointXml("PinJoint", "j2", "/bodyset/link1", "/bodyset/link2", vec3(0, -L1, 0), {"q2"}));
  }
  std::string mot(int n, double t0, double t1, bool degrees) const {
    const double k = degrees ? 180.0 / M_PI : 1.0;
    return motion({"q1", "q2"}, {[=, this](double t) { return k * s1.q(t); }, [=, this](double t) { return k * s2.q(t); }},
                  t0, t1, n, degrees);
  }
  // tau = M qddot + C + G (Lagrange), planar, gravity -y
  Eigen::Vector2d tau(double t) const {
    const double a = s1.q(t), b = s2.q(t), ad = s1.qd(t), bd = s2.qd(t), add = s1.qdd(t), bdd = s2.qdd(t);
    const double h = m2 * L1 * c2 * std::sin(b);
    const double M11 = I1 + m1 * c1 * c1 + I2 + m2 * (L1 * L1 + c2 * c2 + 2 * L1 * c2 * std::cos(b));
    const double M12 = I2 + m2 * (c2 * c2 + L1 * c2 * std::cos(b));
    const double M22 = I2 + m2 * c2 * c2;
    const double G1 = (m1 * c1 + m2 * L1) * kG * std::sin(a) + m2 * c2 * kG * std::sin(a + b);
    const double G2 = m2 * c2 * kG * std::sin(a + b);
    return {M11 * add + M12 * bdd - h * (2 * ad * bd + bd * bd) + G1,
            M12 * add + M22 * bdd + h * ad * ad + G2};
  }
};

IdToolConfig configFor(const std::string& model, const std::string& coords, double t0, double t1,
                       double lowpass = -1.0) {
  IdToolSettings s;
  s.model_file = model;
  s.coordinates_file = coords;
  s.t0 = t0;
  s.t1 = t1;
  s.lowpass_cutoff_hz = lowpass;
  return resolveIdSettings(s);
}

Storage runCore(const InverseDynamicsTool& tool) {
  CoreIdEngine engine(tool.model(), tool.engineOptions());
  return tool.run(engine);
}

TEST(IdTool, DoublePendulumMatchesClosedForm) {
  TempDir dir;
  const DoublePendulum dp;
  const std::string model = dir.write("dp.osim", dp.osim());
  // 2 s at 500 Hz; solve 0.5-1.5 s, away from the natural splines' end effects
  const std::string coords = dir.write("dp.mot", dp.mot(1001, 0.0, 2.0, false));
  InverseDynamicsTool tool(configFor(model, coords, 0.5, 1.5));
  ASSERT_EQ(tool.outputLabels(), (std::vector<std::string>{"q1_moment", "q2_moment"}));
  const Storage out = runCore(tool);
  EXPECT_EQ(out.name, "Inverse Dynamics Generalized Forces");
  ASSERT_EQ(out.numRows(), 501);
  EXPECT_DOUBLE_EQ(out.time.front(), 0.5);
  MatX ref(out.numRows(), 2);
  for (int r = 0; r < out.numRows(); ++r) ref.row(r) = dp.tau(out.time[r]).transpose();
  // quintic interpolation of a 1.1 Hz sinusoid at 2 ms: measured ~6e-11 of the peak
  const double err = worstRelative(out.data, ref);
  EXPECT_LT(err, 1e-9) << "double pendulum ID vs closed form, worst |error| / column peak";
  std::printf("[ measured ] double pendulum: worst error / peak = %.3g\n", err);
}

TEST(IdTool, DegreesConvertOnlyRotationalColumns) {
  // cart-pole: a SliderJoint (x, metres) and a PinJoint (theta); the file says inDegrees=yes and
  // gives x in metres, theta in degrees: only theta is converted (docs/opensim_compatibility.md §3.4, 7)
  TempDir dir;
  const double M = 2.0, m = 0.7, c = 0.4, I = 0.03;
  const Sine sx{0.1, 0.3, 2 * M_PI * 0.6, 0.2}, sth{0.3, 0.8, 2 * M_PI * 0.9, 1.0};
  const std::string model = dir.write(
      "cp.osim", modelXml("<Body name=\"cart\"><mass>" + num(M) +
                              "</mass><mass_center>0 0 0</mass_center><inertia>1 1 1 0 0 0</inertia></Body>\n" +
                              linkXml("pole", m, c, I),
                          jointXml("SliderJoint", "slide", "/ground", "/bodyset/cart", "0 0 0", {"x"}) +
                              jointXml("PinJoint", "hinge", "/bodyset/cart", "/bodyset/pole", "0 0 0", {"theta"})));
  const std::string coords = dir.write(
      "cp.mot", motion({"theta", "x"},
                       {[&](double t) { return sth.q(t) * 180.0 / M_PI; }, [&](double t) { return sx.q(t); }},
                       0.0, 2.0, 801, true));
  InverseDynamicsTool tool(configFor(model, coords, 0.6, 1.4));
  ASSERT_EQ(tool.outputLabels(), (std::vector<std::string>{"x_force", "theta_moment"}));
  EXPECT_FALSE(tool.coordinateSources()[0].converted);
  EXPECT_TRUE(tool.coordinateSources()[1].converted);
  const Storage out = runCore(tool);
  MatX ref(out.numRows(), 2);
  for (int r = 0; r < out.numRows(); ++r) {
    const double t = out.time[r], th = sth.q(t), thd = sth.qd(t), thdd = sth.qdd(t), xdd = sx.qdd(t);
    ref(r, 0) = (M + m) * xdd + m * c * (thdd * std::cos(th) - thd * thd * std::sin(th));
    ref(r, 1) = (I + m * c * c) * thdd + m * c * xdd * std::cos(th) + m * kG * c * std::sin(th);
  }
  const double err = worstRelative(out.data, ref);
  EXPECT_LT(err, 2e-9);  // measured 1.2e-10
  std::printf("[ measured ] cart-pole (degrees file): worst error / peak = %.3g\n", err);
}

TEST(IdTool, ExternalLoadsInBodyAndGroundFrames) {
  // a load on link2: force expressed in link1, point expressed in ground, torque in link1; data
  // linear in time, so the natural cubic interpolation is exact. Generalized force of a force F at
  // world point P on link2: tau_k = ((P - O_k) x F)_z; a pure torque T adds T_z to both joints.
  TempDir dir;
  const DoublePendulum dp;
  const std::string model = dir.write("dp.osim", dp.osim());
  const std::string coords = dir.write("dp.mot", dp.mot(1001, 0.0, 2.0, false));
  auto F1 = [](double t) { return Vec3(3.0 + 2.0 * t, -5.0 + t, 0.7); };  // in link1
  auto P = [](double t) { return Vec3(0.3 - 0.1 * t, -1.1 + 0.2 * t, 0.05); };  // in ground
  auto T1 = [](double t) { return Vec3(0.2, -0.1, 1.5 - 0.5 * t); };  // in link1
  std::vector<std::function<double(double)>> cols;
  for (int k = 0; k < 3; ++k) cols.push_back([=](double t) { return F1(t)[k]; });
  for (int k = 0; k < 3; ++k) cols.push_back([=](double t) { return P(t)[k]; });
  for (int k = 0; k < 3; ++k) cols.push_back([=](double t) { return T1(t)[k]; });
  dir.write("loads.mot", motion({"f_vx", "f_vy", "f_vz", "f_px", "f_py", "f_pz", "f_tx", "f_ty", "f_tz"},
                                cols, -0.5, 2.5, 31, false));
  const std::string xml = dir.write(
      "loads.xml",
      "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
      "<ExternalLoads name=\"loads\"><objects>\n"
      "<ExternalForce name=\"push\"><applied_to_body>link2</applied_to_body>"
      "<force_expressed_in_body>link1</force_expressed_in_body>"
      "<point_expressed_in_body>ground</point_expressed_in_body>"
      "<force_identifier>f_v</force_identifier><point_identifier>f_p</point_identifier>"
      "<torque_identifier>f_t</torque_identifier></ExternalForce>\n"
      "</objects><datafile>loads.mot</datafile></ExternalLoads>\n</OpenSimDocument>\n");
  IdToolSettings s;
  s.model_file = model;
  s.coordinates_file = coords;
  s.external_loads_file = xml;
  s.t0 = 0.5;
  s.t1 = 1.5;
  const IdToolConfig cfg = resolveIdSettings(s);
  InverseDynamicsTool tool(cfg);
  ASSERT_EQ(tool.loadSources().size(), 1u);
  const Storage out = runCore(tool);
  MatX ref(out.numRows(), 2);
  for (int r = 0; r < out.numRows(); ++r) {
    const double t = out.time[r], a = dp.s1.q(t), b = dp.s2.q(t);
    const Mat3 R1 = rotationAxisAngle(Vec3::UnitZ(), a);
    const Vec3 F = R1 * F1(t), T = R1 * T1(t);
    const Vec3 O2(dp.L1 * std::sin(a), -dp.L1 * std::cos(a), 0.0);
    const Eigen::Vector2d ext(P(t).cross(F).z() + T.z(), (P(t) - O2).cross(F).z() + T.z());
    ref.row(r) = (dp.tau(t) - ext).transpose();
    (void)b;
  }
  const double err = worstRelative(out.data, ref);
  EXPECT_LT(err, 1e-9);  // measured 5.0e-11
  std::printf("[ measured ] external loads (force in link1, point in ground): worst error / peak = %.3g\n", err);
}

TEST(IdTool, MissingColumnsKeepDefaultsAndPathLabelsAreNotMatched) {
  // q2 is labelled with a path: OpenSim converts it but builds q2's function from the default
  TempDir dir;
  const DoublePendulum dp;
  const std::string model = dir.write("dp.osim", dp.osim());
  const std::string coords = dir.write(
      "dp.mot", motion({"q1", "/jointset/j2/q2/value"},
                       {[&](double t) { return dp.s1.q(t); }, [&](double t) { return dp.s2.q(t); }}, 0.0,
                       2.0, 201, false));
  InverseDynamicsTool tool(configFor(model, coords, 0.5, 1.5));
  EXPECT_EQ(tool.coordinateSources()[1].spline, -1);
  EXPECT_DOUBLE_EQ(tool.coordinateSources()[1].constant, 0.1);
  bool warned = false;
  for (const auto& w : tool.warnings()) warned = warned || w.find("q2") != std::string::npos;
  EXPECT_TRUE(warned);
  VecX q, v, vdot;
  std::vector<IdLoadSample> loads;
  tool.calcInputs(1.0, q, v, vdot, loads);
  EXPECT_DOUBLE_EQ(q[1], 0.1);
  EXPECT_EQ(v[1], 0.0);
  EXPECT_EQ(vdot[1], 0.0);
  EXPECT_NEAR(q[0], dp.s1.q(1.0), 1e-9);
}

TEST(IdTool, TimeWindowFollowsFindIndex) {
  // rows run from the last sample at or before t0 to the last at or before t1
  TempDir dir;
  const DoublePendulum dp;
  const std::string model = dir.write("dp.osim", dp.osim());
  const std::string coords = dir.write("dp.mot", dp.mot(21, 0.0, 2.0, false));  // dt = 0.1
  InverseDynamicsTool tool(configFor(model, coords, 0.55, 1.27));
  ASSERT_EQ(tool.numFrames(), 8);
  EXPECT_NEAR(tool.frameTime(0), 0.5, 1e-15);
  EXPECT_NEAR(tool.frameTime(7), 1.2, 1e-15);
  // and the whole file when no range is given
  InverseDynamicsTool all(configFor(model, coords, -INFINITY, INFINITY));
  EXPECT_EQ(all.numFrames(), 21);
}

TEST(IdTool, FilteringPadsAndResamples) {
  // with a cutoff the grid is padded by N/2 samples each side before the window is applied, so
  // the first row can precede t0's sample; a slow sinusoid passes the 6 Hz filter nearly intact
  TempDir dir;
  const DoublePendulum dp;
  const std::string model = dir.write("dp.osim", dp.osim());
  const std::string coords = dir.write("dp.mot", dp.mot(241, 0.0, 2.0, false));
  InverseDynamicsTool tool(configFor(model, coords, -INFINITY, INFINITY, 6.0));
  EXPECT_TRUE(tool.processed().filtered);
  EXPECT_EQ(tool.processed().pad, 120);
  EXPECT_LT(tool.frameTime(0), 0.0);  // padded times precede the data
  const Storage out = runCore(tool);
  EXPECT_TRUE(out.data.allFinite());
}

TEST(IdTool, ExactAndCompatibleAgreeWithoutBallOrCustomJoints) {
  TempDir dir;
  const DoublePendulum dp;
  const std::string model = dir.write("dp.osim", dp.osim());
  const std::string coords = dir.write("dp.mot", dp.mot(201, 0.0, 2.0, false));
  IdToolConfig cfg = configFor(model, coords, 0.5, 1.5);
  const Storage compat = runCore(InverseDynamicsTool(cfg));
  cfg.opensim_compat = false;
  const Storage exact = runCore(InverseDynamicsTool(cfg));
  EXPECT_EQ((compat.data - exact.data).cwiseAbs().maxCoeff(), 0.0);
}

// ---- the OpenSim speed map of ball and free joints ------------------------------------------
TEST(IdSpeedMap, TdotMatchesCentralDifferences) {
  const VecJ q = (VecJ(6) << 0.3, -0.5, 0.8, 0.1, -0.2, 0.3).finished();
  const VecJ qd = (VecJ(6) << 0.7, -1.1, 0.4, 0.5, 0.2, -0.9).finished();
  const double h = 1e-6;
  const std::vector<std::pair<std::string, Joint>> joints = {
      {"ball", SphericalEuler{EulerSequence::XYZ}},
      {"free", Free3D::opensim()},
      {"ellipsoid", Ellipsoid{Vec3(0.1, 0.2, 0.15)}},
      {"reversed ball", Reversed(Joint(SphericalEuler{EulerSequence::XYZ}))}};
  for (const auto& [name, j] : joints) {
    const int n = j.nq();
    const VecJ qj = q.head(n), qdj = qd.head(n);
    MatJ T, Tdot, Tp, Tm;
    calcOpenSimSpeedMap(j, qj, qdj, T, &Tdot);
    calcOpenSimSpeedMap(j, qj + h * qdj, qdj, Tp, nullptr);
    calcOpenSimSpeedMap(j, qj - h * qdj, qdj, Tm, nullptr);
    const MatJ fd = (Tp - Tm) / (2 * h);
    EXPECT_LE((Tdot - fd).norm(), 1e-7 * (1 + fd.norm())) << name;
  }
  // u of a ball joint is w_FM in F: compare with the rotation's own derivative
  const Joint ball = SphericalEuler{EulerSequence::XYZ};
  JointKinematics jp, jm, j0;
  jp.resize(3);
  jm.resize(3);
  j0.resize(3);
  ball.calc(q.head(3) + h * qd.head(3), qd.head(3), jp);
  ball.calc(q.head(3) - h * qd.head(3), qd.head(3), jm);
  ball.calc(q.head(3), qd.head(3), j0);
  const Mat3 Rdot = (jp.Q.topLeftCorner<3, 3>() - jm.Q.topLeftCorner<3, 3>()) / (2 * h);
  const Vec3 w_F = unskew(Rdot * j0.Q.topLeftCorner<3, 3>().transpose());
  MatJ T;
  calcOpenSimSpeedMap(ball, q.head(3), qd.head(3), T, nullptr);
  EXPECT_LE((T * qd.head(3) - w_F).norm(), 1e-7 * (1 + w_F.norm()));
  EXPECT_THROW(calcOpenSimSpeedMap(Joint(Revolute{Vec3::UnitZ()}), q.head(1), qd.head(1), T, nullptr),
               IdEngineError);
}

TEST(IdSpeedMap, CoreEngineKeepsPowerBalanceAndDiffersFromExact) {
  // one free body on a ball-jointed link: with rates_as_u the engine returns tau_u for u = rates;
  // then tau_u . u equals the exact engine's tau . qdot for the same motion (qdot = T^-1 u)
  ModelBuilder mb("ballfree");
  const int a = mb.addBody("a", 1.2, Vec3(0.1, -0.2, 0.05), Vec3(0.05, 0.04, 0.03).asDiagonal(), -1,
                           "ball", SphericalEuler{EulerSequence::XYZ}, makeTranslation(Vec3(0, 1, 0)));
  mb.addBody("b", 0.9, Vec3(0.0, 0.1, -0.1), Vec3(0.02, 0.03, 0.025).asDiagonal(), a, "free",
             Free3D::opensim(), makeTranslation(Vec3(0.2, -0.4, 0.1)));
  const Model model = mb.finalize();
  IdEngineOptions marked;
  marked.rates_as_u = {true, true};
  CoreIdEngine compat(model, marked), exact(model);
  VecX q(9), u(9), udot(9), tau_u, tau;
  q << 0.3, -0.4, 0.6, 0.2, 0.1, -0.3, 0.05, -0.1, 0.2;
  u << 0.8, -0.3, 0.5, 1.1, -0.7, 0.2, 0.3, 0.4, -0.2;
  udot << -1.0, 0.6, 0.9, -0.4, 0.8, 1.5, -0.6, 0.2, 0.7;
  std::vector<IdLoadSample> loads(1);
  loads[0].body = 1;
  loads[0].force_frame = 0;
  loads[0].point_frame = -1;
  loads[0].has_force = loads[0].has_point = loads[0].has_torque = true;
  loads[0].force = Vec3(3, -20, 1);
  loads[0].point = Vec3(0.3, 0.5, -0.1);
  loads[0].torque = Vec3(0.5, 0.1, -0.3);
  compat.calcGeneralizedForces(0.0, q, u, udot, loads, tau_u);
  exact.calcGeneralizedForces(0.0, compat.lastState().q, compat.lastState().qdot, compat.lastQddot(), loads, tau);
  EXPECT_NEAR(tau_u.dot(u), tau.dot(compat.lastState().qdot), 1e-10 * (1 + std::abs(tau.dot(u))));
  // reading the rates as qdot instead (the exact tool) is a different motion
  VecX tau_rates;
  exact.calcGeneralizedForces(0.0, q, u, udot, loads, tau_rates);
  EXPECT_GT((tau_rates - tau_u).norm(), 1e-3 * tau_u.norm());
}

// ---- setup files and bad input --------------------------------------------------------------
TEST(IdTool, SetupFileResolvesPathsAndFlagsOverride) {
  TempDir dir;
  const DoublePendulum dp;
  dir.write("in/dp.osim", dp.osim());
  dir.write("in/dp.mot", dp.mot(201, 0.0, 2.0, false));
  const std::string setup = dir.write(
      "in/setup.xml",
      "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\"><InverseDynamicsTool name=\"t\">\n"
      "<results_directory>out</results_directory><model_file>dp.osim</model_file>\n"
      "<time_range>0.2 1.8</time_range><forces_to_exclude>Muscles</forces_to_exclude>\n"
      "<coordinates_file>dp.mot</coordinates_file>\n"
      "<lowpass_cutoff_frequency_for_coordinates>6</lowpass_cutoff_frequency_for_coordinates>\n"
      "<output_gen_force_file>id.sto</output_gen_force_file></InverseDynamicsTool></OpenSimDocument>\n");
  IdToolSettings s;
  s.setup_file = setup;
  IdToolConfig c = resolveIdSettings(s);
  EXPECT_EQ(c.model_file, dir.file("in/dp.osim"));
  EXPECT_EQ(c.output_file, dir.file("in/out/id.sto"));
  EXPECT_EQ(c.lowpass_cutoff_hz, 6.0);
  EXPECT_EQ(c.t0, 0.2);
  s.lowpass_cutoff_hz = -1.0;
  s.t1 = 1.0;
  c = resolveIdSettings(s);
  EXPECT_EQ(c.lowpass_cutoff_hz, -1.0);
  EXPECT_EQ(c.t1, 1.0);
  EXPECT_NO_THROW(InverseDynamicsTool{c});
}

// the message of the ConvertError f throws ("" if none)
std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConvertError& e) {
    return e.what();
  }
  return "";
}

TEST(IdTool, BadInputsAreConvertErrorsNamingTheFile) {
  TempDir dir;
  const DoublePendulum dp;
  const std::string model = dir.write("dp.osim", dp.osim());
  const std::string coords = dir.write("dp.mot", dp.mot(201, 0.0, 2.0, false));
  // missing files
  EXPECT_NE(errorOf([&] { InverseDynamicsTool t(configFor(dir.file("none.osim"), coords, 0, 1)); })
                .find("none.osim"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { InverseDynamicsTool t(configFor(model, dir.file("none.mot"), 0, 1)); })
                .find("none.mot"),
            std::string::npos);
  // no column of the model
  const std::string other = dir.write("other.mot", motion({"a", "b"}, {[](double t) { return t; }, [](double t) { return -t; }}, 0, 1, 11, false));
  const std::string e1 = errorOf([&] { InverseDynamicsTool t(configFor(model, other, 0, 1)); });
  EXPECT_NE(e1.find("other.mot"), std::string::npos);
  EXPECT_NE(e1.find("none of the model's"), std::string::npos);
  // too few rows for quintic splines
  const std::string few = dir.write("few.mot", dp.mot(4, 0.0, 1.0, false));
  EXPECT_NE(errorOf([&] { InverseDynamicsTool t(configFor(model, few, 0, 1)); }).find("few.mot"), std::string::npos);
  // an external load on an unknown body names the loads file and line
  dir.write("l.mot", motion({"f_vx", "f_vy", "f_vz"}, {[](double) { return 1.0; }, [](double) { return 2.0; }, [](double) { return 3.0; }}, 0, 1, 5, false));
  const std::string xml = dir.write(
      "l.xml", "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\"><ExternalLoads name=\"x\"><objects>\n"
               "<ExternalForce name=\"f\"><applied_to_body>nobody</applied_to_body>"
               "<force_identifier>f_v</force_identifier></ExternalForce>\n"
               "</objects><datafile>l.mot</datafile></ExternalLoads></OpenSimDocument>\n");
  IdToolSettings s;
  s.model_file = model;
  s.coordinates_file = coords;
  s.external_loads_file = xml;
  const std::string e2 = errorOf([&] { InverseDynamicsTool t(resolveIdSettings(s)); });
  EXPECT_NE(e2.find("l.xml:3"), std::string::npos) << e2;
  // settings
  IdToolSettings none;
  EXPECT_NE(errorOf([&] { resolveIdSettings(none); }).find("no model file"), std::string::npos);
  IdToolSettings bad_range;
  bad_range.model_file = model;
  bad_range.coordinates_file = coords;
  bad_range.t0 = 2;
  bad_range.t1 = 1;
  EXPECT_NE(errorOf([&] { resolveIdSettings(bad_range); }).find("time range"), std::string::npos);
}

TEST(IdTool, ReportsForcesOpenSimWouldStillApply) {
  TempDir dir;
  const DoublePendulum dp;
  std::string osim = dp.osim();
  const std::string forces =
      "<ForceSet name=\"forceset\"><objects>"
      "<CoordinateLimitForce name=\"limit\"><coordinate>q1</coordinate></CoordinateLimitForce>"
      "<CoordinateActuator name=\"act\"><coordinate>q2</coordinate></CoordinateActuator>"
      "</objects></ForceSet>\n";
  osim.insert(osim.find("</Model>"), forces);
  const std::string model = dir.write("dpf.osim", osim);
  const std::string coords = dir.write("dp.mot", dp.mot(201, 0.0, 2.0, false));
  InverseDynamicsTool tool(configFor(model, coords, 0.5, 1.5));
  // the limit force is not modelled; the actuator has zero control, hence no force
  ASSERT_EQ(tool.unmodelledForces().size(), 1u);
  EXPECT_NE(tool.unmodelledForces()[0].find("limit"), std::string::npos);
  IdToolSettings s;
  s.model_file = model;
  s.coordinates_file = coords;
  s.forces_to_exclude = std::vector<std::string>{"limit"};
  EXPECT_TRUE(InverseDynamicsTool(resolveIdSettings(s)).unmodelledForces().empty());
  s.forces_to_exclude = std::vector<std::string>{"ALL"};
  EXPECT_TRUE(InverseDynamicsTool(resolveIdSettings(s)).unmodelledForces().empty());
}

}  // namespace
}  // namespace redmax::osim
