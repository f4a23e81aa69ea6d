// Inverse dynamics with muscle mass (converter/id + converter/build/muscle_mass + cli):
//  - a hinge with a straight muscle from the ground to the link, fraction F of the link's mass
//    transferred into the muscle: ID through the tool equals the closed form to 1e-12 of the peak
//    (added inertia r^2 sum m_a alpha_a^2, gravity through sum m_a alpha_a, no quadratic term);
//  - zero mass (transfer fraction 0) gives the none result to 1e-14 of the peak;
//  - Euler-rate speeds (rates_as_u, a ball-jointed arm): the engine with a MuscleTerm equals the map
//    done by hand around an independently built System + MuscleTerm (1e-12 of the peak);
//  - the torques are affine in the mass: physiological density x s and transfer fraction s give
//    tau(2s) - tau(0) = 2 (tau(s) - tau(0)) to 1e-9 of the change (running leg swing trial);
//  - `redmax id` with the muscle-mass flags: summary on stderr (not with --quiet), bad flags exit 2
//    with the flag named and nothing written; --engine simbody with muscle mass (plugin/simbody/
//    muscle_inertia.hpp) equals --engine core to 1e-9 of each column's peak.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/storage.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "tests/validation/pendulum_cli_fixture.hpp"

namespace {

namespace fs = std::filesystem;
using namespace redmax;
using namespace redmax::osim;
using redmax_test::CmdResult;
using redmax_test::num;
using redmax_test::redmaxExe;
using Source = MuscleMassOptions::Source;

std::string sourcePath(const std::string& rel) { return std::string(REDMAX_SOURCE_DIR) + "/" + rel; }

struct IdRun {
  Storage out;
  std::vector<VecX> q, qddot;  // the tool's inputs at the output frames
  double muscle_mass = 0.0;
  MuscleMassPlan plan;
};

IdRun runId(const std::string& model, const std::string& motion, const MuscleMassOptions& mm) {
  IdToolSettings s;
  s.model_file = model;
  s.coordinates_file = motion;
  s.muscle_mass = mm;
  const IdToolConfig config = resolveIdSettings(s);
  InverseDynamicsTool tool(config);
  CoreIdEngine engine(tool.musculoskeletalModel(), tool.engineOptions());
  IdRun r;
  r.out = tool.run(engine);
  r.muscle_mass = engine.muscleMass();
  r.plan = tool.muscleMassPlan();
  VecX q, v, a;
  std::vector<IdLoadSample> loads;
  for (int k = 0; k < tool.numFrames(); ++k) {
    tool.calcInputs(tool.frameTime(k), q, v, a, loads);
    r.q.push_back(q);
    r.qddot.push_back(a);
  }
  return r;
}

class IdMuscleMass : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("redmax_id_muscle_mass_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  fs::path dir_;
};

// a 2 kg arm on a z hinge at the ground origin (body frame at the pivot, COM 0.5 m down, Izz 0.1
// about the COM) and a straight muscle from the ground at (0.2, 0, 0) to the arm at (0, -0.6, 0),
// fibre share l_opt / (l_opt + l_ts) = 1/2
const char* kHinge = R"(<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000">
<Model name="hinge"><Ground name="ground"/><gravity>0 -9.80665 0</gravity>
<BodySet name="bodyset"><objects>
<Body name="arm"><mass>2</mass><mass_center>0 -0.5 0</mass_center><inertia>0.1 0.02 0.1 0 0 0</inertia></Body>
</objects></BodySet>
<JointSet name="jointset"><objects>
<PinJoint name="hinge"><socket_parent_frame>/ground</socket_parent_frame><socket_child_frame>/bodyset/arm</socket_child_frame>
<coordinates><Coordinate name="theta"/></coordinates></PinJoint>
</objects></JointSet>
<ForceSet name="forceset"><objects>
<Thelen2003Muscle name="flexor"><max_isometric_force>500</max_isometric_force>
<optimal_fiber_length>0.1</optimal_fiber_length><tendon_slack_length>0.1</tendon_slack_length>
<GeometryPath name="path"><PathPointSet><objects>
<PathPoint name="o"><socket_parent_frame>/ground</socket_parent_frame><location>0.2 0 0</location></PathPoint>
<PathPoint name="i"><socket_parent_frame>/bodyset/arm</socket_parent_frame><location>0 -0.6 0</location></PathPoint>
</objects></PathPointSet></GeometryPath></Thelen2003Muscle>
</objects></ForceSet>
</Model></OpenSimDocument>
)";

std::string hingeMotion() {
  std::ostringstream os;
  os.precision(17);
  os << "motion\nversion=1\nnRows=401\nnColumns=2\ninDegrees=yes\nendheader\ntime\ttheta\n";
  for (int i = 0; i <= 400; ++i) {
    const double t = 0.005 * i;
    os << t << "\t" << 70.0 * std::sin(2 * M_PI * 0.7 * t) + 10.0 << "\n";
  }
  return os.str();
}

TEST_F(IdMuscleMass, HingeTransferMatchesClosedForm) {
  const std::string model = write("hinge.osim", kHinge), motion = write("hinge.mot", hingeMotion());
  const double F = 0.5, g = 9.80665, r = 0.6;
  MuscleMassOptions mm;
  mm.source = Source::Transfer;
  mm.transfer_body = "arm";
  mm.transfer_fraction = F;
  const IdRun run = runId(model, motion, mm);
  EXPECT_NEAR(run.muscle_mass, F * 2.0, 1e-15);
  ASSERT_EQ(run.out.numColumns(), 1);

  // the arm keeps (1 - F) of its mass and of its inertia about the COM
  const double m_arm = (1 - F) * 2.0, I_pivot = (1 - F) * 0.1 + m_arm * 0.25;
  // the muscle: N = 20 points of F * 2 / N kg at alpha_k = 1/4 + (1/2)(k + 1/2)/N (fibre half of
  // the path, centred); a point moves with alpha times the insertion's velocity
  const int N = 20;
  double S1 = 0, S2 = 0;
  for (int k = 0; k < N; ++k) {
    const double alpha = 0.25 + 0.5 * (k + 0.5) / N, m = F * 2.0 / N;
    S1 += m * alpha;
    S2 += m * alpha * alpha;
  }
  double worst = 0, peak = 0, effect = 0;
  for (int k = 0; k < run.out.numRows(); ++k) {
    const double th = run.q[k][0], thdd = run.qddot[k][0];
    const double tau = (I_pivot + r * r * S2) * thdd + g * std::sin(th) * (0.5 * m_arm + r * S1);
    const double lumped = (0.1 + 2.0 * 0.25) * thdd + g * std::sin(th) * 0.5 * 2.0;
    worst = std::max(worst, std::abs(run.out.data(k, 0) - tau));
    peak = std::max(peak, std::abs(tau));
    effect = std::max(effect, std::abs(tau - lumped));
  }
  EXPECT_LE(worst, 1e-12 * peak);
  EXPECT_GT(effect, 1e-3 * peak);  // the case is not trivial: the muscle's inertia shows
  std::printf("[ measured ] hinge, 1 kg straight muscle: |tau - closed form| / peak = %.2e; effect %.3f%% of peak\n",
              worst / peak, 100 * effect / peak);
}

TEST_F(IdMuscleMass, ZeroMassEqualsNone) {
  const std::string model = sourcePath("osim_models/running_leg.osim");
  const std::string motion = sourcePath("osim_models/running_leg_swing.mot");
  const IdRun none = runId(model, motion, {});
  MuscleMassOptions mm;
  mm.source = Source::Transfer;
  mm.transfer_body = "tibia_r";
  mm.transfer_fraction = 0.0;
  const IdRun zero = runId(model, motion, mm);
  EXPECT_EQ(zero.muscle_mass, 0.0);
  ASSERT_EQ(zero.out.numRows(), none.out.numRows());
  const double peak = none.out.data.cwiseAbs().maxCoeff();
  EXPECT_LE((zero.out.data - none.out.data).cwiseAbs().maxCoeff(), 1e-14 * peak);
  EXPECT_TRUE(none.plan.bodies.empty());
}

// tau(2s) - tau(0) against 2 (tau(s) - tau(0)): mass, first and second moments of every body and
// of every point are affine in s, so the torques are too
double affineDefect(const IdRun& r0, const IdRun& r1, const IdRun& r2, double* change) {
  const MatX d1 = r1.out.data - r0.out.data, d2 = r2.out.data - r0.out.data;
  *change = d2.cwiseAbs().maxCoeff();
  return (d2 - 2.0 * d1).cwiseAbs().maxCoeff() / *change;
}

TEST_F(IdMuscleMass, TorquesAreAffineInTheMuscleMass) {
  const std::string model = sourcePath("osim_models/running_leg.osim");
  const std::string motion = sourcePath("osim_models/running_leg_swing.mot");
  const IdRun none = runId(model, motion, {});
  const double peak = none.out.data.cwiseAbs().maxCoeff();
  {
    MuscleMassOptions mm;
    mm.source = Source::Physiological;
    mm.density = 0.5 * kDefaultMuscleDensity;
    const IdRun half = runId(model, motion, mm);
    mm.density = kDefaultMuscleDensity;
    const IdRun full = runId(model, motion, mm);
    EXPECT_NEAR(full.muscle_mass, 2.0 * half.muscle_mass, 1e-12 * full.muscle_mass);
    EXPECT_FALSE(full.plan.bodies.empty());
    double change = 0;
    const double defect = affineDefect(none, half, full, &change);
    EXPECT_LE(defect, 1e-9);
    EXPECT_GT(change, 1e-4 * peak);
    std::printf("[ measured ] running leg physiological (%.3f kg): max |tau - tau_none| = %.3g (%.2f%% of peak), "
                "affine defect %.2e\n", full.muscle_mass, change, 100 * change / peak, defect);
  }
  {
    MuscleMassOptions mm;
    mm.source = Source::Transfer;
    mm.transfer_body = "tibia_r";
    mm.transfer_fraction = 0.4;
    const IdRun s = runId(model, motion, mm);
    mm.transfer_fraction = 0.8;
    const IdRun s2 = runId(model, motion, mm);
    double change = 0;
    const double defect = affineDefect(none, s, s2, &change);
    EXPECT_LE(defect, 1e-9);
    EXPECT_GT(change, 1e-4 * peak);
    std::printf("[ measured ] running leg tibia transfer 80%%: max |tau - tau_none| = %.3g (%.2f%% of peak), "
                "affine defect %.2e\n", change, 100 * change / peak, defect);
  }
}

// a ball-jointed upper arm (OpenSim's Euler-angle rates read as angular velocity: rates_as_u) and
// a pinned forearm with a straight muscle between them
const char* kBallArm = R"(<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000">
<Model name="ballarm"><Ground name="ground"/><gravity>0 -9.80665 0</gravity>
<BodySet name="bodyset"><objects>
<Body name="upper"><mass>2</mass><mass_center>0 -0.15 0</mass_center><inertia>0.02 0.005 0.02 0 0 0</inertia></Body>
<Body name="fore"><mass>1</mass><mass_center>0 -0.12 0</mass_center><inertia>0.01 0.002 0.01 0 0 0</inertia></Body>
</objects></BodySet>
<JointSet name="jointset"><objects>
<BallJoint name="shoulder"><socket_parent_frame>/ground</socket_parent_frame><socket_child_frame>/bodyset/upper</socket_child_frame>
<coordinates><Coordinate name="b1"/><Coordinate name="b2"/><Coordinate name="b3"/></coordinates></BallJoint>
<PinJoint name="elbow"><socket_parent_frame>elbow_p</socket_parent_frame><socket_child_frame>/bodyset/fore</socket_child_frame>
<coordinates><Coordinate name="e"/></coordinates>
<frames><PhysicalOffsetFrame name="elbow_p"><socket_parent>/bodyset/upper</socket_parent><translation>0 -0.3 0</translation>
<orientation>0 0 0</orientation></PhysicalOffsetFrame></frames></PinJoint>
</objects></JointSet>
<ForceSet name="forceset"><objects>
<Thelen2003Muscle name="biceps"><max_isometric_force>600</max_isometric_force>
<optimal_fiber_length>0.12</optimal_fiber_length><tendon_slack_length>0.1</tendon_slack_length>
<GeometryPath name="path"><PathPointSet><objects>
<PathPoint name="o"><socket_parent_frame>/bodyset/upper</socket_parent_frame><location>0.03 -0.05 0</location></PathPoint>
<PathPoint name="i"><socket_parent_frame>/bodyset/fore</socket_parent_frame><location>0.02 -0.05 0</location></PathPoint>
</objects></PathPointSet></GeometryPath></Thelen2003Muscle>
</objects></ForceSet>
</Model></OpenSimDocument>
)";

// With rates_as_u the engine maps OpenSim's u to the core's qdot, solves with the muscle term in
// the System, and maps the forces back: the same as doing it by hand with an independently built
// System + MuscleTerm (1e-12 of the peak), and different from --exact (the map is active)
TEST_F(IdMuscleMass, OpenSimSpeedMapAppliesWithMuscleMass) {
  const std::string model = write("ballarm.osim", kBallArm);
  std::ostringstream os;
  os.precision(17);
  os << "motion\nversion=1\nnRows=201\nnColumns=5\ninDegrees=yes\nendheader\ntime\tb1\tb2\tb3\te\n";
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.005 * i, w = 2 * M_PI;
    os << t << "\t" << 40 * std::sin(w * 0.6 * t) << "\t" << 30 * std::sin(w * 0.9 * t + 0.3) << "\t"
       << 25 * std::sin(w * 0.5 * t + 1.0) << "\t" << 60 + 40 * std::sin(w * 1.1 * t) << "\n";
  }
  const std::string motion = write("ballarm.mot", os.str());
  MuscleMassOptions mm;
  mm.source = Source::Physiological;
  IdToolSettings st;
  st.model_file = model;
  st.coordinates_file = motion;
  st.muscle_mass = mm;
  const InverseDynamicsTool tool(resolveIdSettings(st));
  ASSERT_TRUE(tool.engineOptions().marked(0)) << "the ball joint takes OpenSim's u";
  CoreIdEngine engine(tool.musculoskeletalModel(), tool.engineOptions());
  EXPECT_GT(engine.muscleMass(), 0.05);
  const Storage out = tool.run(engine);

  // by hand: qdot = T^-1 u, qddot = T^-1 (udot - Tdot qdot), tau_u = T^-T tau_qdot on the ball block
  System sys(tool.model());
  sys.addTerm(std::make_shared<MuscleTerm>(tool.model(), tool.musculoskeletalModel().muscles()));
  DynamicsWorkspace ws(sys.model());
  const Joint& ball = tool.model().joints()[0].joint;
  double worst = 0, peak = 0, muscle_effect = 0;
  System lumped(tool.model());
  DynamicsWorkspace wl(lumped.model());
  for (int k = 0; k < tool.numFrames(); ++k) {
    VecX q, u, udot;
    std::vector<IdLoadSample> loads;
    tool.calcInputs(tool.frameTime(k), q, u, udot, loads);
    MatJ T, Tdot;
    const VecJ qb = q.head(3);
    calcOpenSimSpeedMap(ball, qb, VecJ::Zero(3), T, nullptr);
    const VecJ qdot_b = T.lu().solve(VecJ(u.head(3)));
    calcOpenSimSpeedMap(ball, qb, qdot_b, T, &Tdot);
    State s;
    s.q = q;
    s.qdot = u;
    s.qdot.head(3) = qdot_b;
    VecX qddot = udot;
    qddot.head(3) = T.lu().solve(VecJ(udot.head(3) - Tdot * qdot_b));
    VecX tau = sys.inverseDynamics(s, qddot, ws);
    VecX tau_l = lumped.inverseDynamics(s, qddot, wl);
    tau.head(3) = T.transpose().lu().solve(VecJ(tau.head(3)));
    tau_l.head(3) = T.transpose().lu().solve(VecJ(tau_l.head(3)));
    worst = std::max(worst, (out.data.row(k).transpose() - tau).cwiseAbs().maxCoeff());
    peak = std::max(peak, tau.cwiseAbs().maxCoeff());
    muscle_effect = std::max(muscle_effect, (tau - tau_l).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, 1e-12 * peak);
  EXPECT_GT(muscle_effect, 1e-4 * peak);

  // --exact reads the same columns as qdot: a different answer, so the map above was in play
  st.opensim_compat = false;
  const InverseDynamicsTool exact_tool(resolveIdSettings(st));
  CoreIdEngine exact(exact_tool.musculoskeletalModel(), exact_tool.engineOptions());
  const Storage ex = exact_tool.run(exact);
  EXPECT_GT((ex.data - out.data).cwiseAbs().maxCoeff(), 1e-3 * peak);
}

// ---------------------------------------------------------------------------------------------
// the command line

class IdMuscleMassCli : public IdMuscleMass {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to validation_tests (build target redmax)";
    IdMuscleMass::SetUp();
  }
  CmdResult run(const std::string& args) const {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = "cd " + dir_.string() + " && " + redmaxExe().string() + " id --model " +
                            sourcePath("osim_models/running_leg.osim") + " --coordinates " +
                            sourcePath("osim_models/running_leg_swing.mot") + " " + args + " >" + out.string() +
                            " 2>" + err.string();
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, redmax_test::slurp(out), redmax_test::slurp(err)};
  }
};

TEST_F(IdMuscleMassCli, PrintsThePlanAndChangesTheTorques) {
  const CmdResult none = run("--full-precision --out none.sto");
  ASSERT_EQ(none.code, 0) << none.err;
  EXPECT_EQ(none.err.find("muscle mass"), std::string::npos) << none.err;
  const CmdResult r = run("--muscle-mass physiological --mass-points 10 --wrap lumped --full-precision --out phys.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const std::string want : {"muscle mass: physiological", "tibia_r: ", "soleus_r: ", "10 points",
                                 "med_gas_r: Type III path (wrap mass off: --wrap lumped)"})
    EXPECT_NE(r.err.find(want), std::string::npos) << want << "\n" << r.err;
  const Storage a = readStorage((dir_ / "none.sto").string()), b = readStorage((dir_ / "phys.sto").string());
  ASSERT_EQ(a.numRows(), b.numRows());
  EXPECT_GT((a.data - b.data).cwiseAbs().maxCoeff(), 1e-6);
  // the same through the library
  MuscleMassOptions mm;
  mm.source = Source::Physiological;
  mm.mass_points = 10;
  const IdRun lib = runId(sourcePath("osim_models/running_leg.osim"), sourcePath("osim_models/running_leg_swing.mot"), mm);
  EXPECT_LE((lib.out.data - b.data).cwiseAbs().maxCoeff(), 1e-12 * b.data.cwiseAbs().maxCoeff());

  const CmdResult q = run("--muscle-mass transfer --transfer-body tibia_r --transfer-fraction 0.5 --muscles top:1 "
                          "--quiet --out q.sto");
  ASSERT_EQ(q.code, 0) << q.err;
  EXPECT_EQ(q.err.find("muscle mass"), std::string::npos) << q.err;
  const CmdResult t = run("--muscle-mass transfer --transfer-body tibia_r --transfer-fraction 0.5 --muscles top:1 "
                          "--out t.sto");
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.err.find("ranking"), std::string::npos) << t.err;
  EXPECT_NE(t.err.find("not in the top 1"), std::string::npos) << t.err;
}

TEST_F(IdMuscleMassCli, SimbodyEngineWithMassEqualsCore) {
  const std::string mass = "--muscle-mass transfer --transfer-body tibia_r --transfer-fraction 0.8 --quiet --full-precision ";
  const CmdResult c = run(mass + "--engine core --out core.sto");
  ASSERT_EQ(c.code, 0) << c.err;
  const CmdResult s = run(mass + "--engine simbody --out simbody.sto");
  ASSERT_EQ(s.code, 0) << s.err;
  const CmdResult n = run("--quiet --full-precision --engine simbody --out none.sto");
  ASSERT_EQ(n.code, 0) << n.err;
  const Storage a = readStorage((dir_ / "core.sto").string()), b = readStorage((dir_ / "simbody.sto").string());
  const Storage z = readStorage((dir_ / "none.sto").string());
  ASSERT_EQ(a.numRows(), b.numRows());
  ASSERT_EQ(a.data.cols(), b.data.cols());
  for (int j = 0; j < a.data.cols(); ++j) {  // data columns (time is separate)
    const double peak = a.data.col(j).cwiseAbs().maxCoeff();
    EXPECT_LE((a.data.col(j) - b.data.col(j)).cwiseAbs().maxCoeff(), 1e-9 * peak) << "column " << j;
  }
  EXPECT_GT((b.data - z.data).cwiseAbs().maxCoeff(), 1e-6);  // the mass changed the Simbody torques
}

TEST_F(IdMuscleMassCli, BadFlagsExitTwo) {
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"--muscle-mass heavy", "--muscle-mass must be none, physiological or transfer"},
      {"--muscle-mass physiological --mass-points 0", "--mass-points"},
      {"--muscle-mass physiological --mass-points two", "--mass-points expects an integer"},
      {"--muscle-mass physiological --muscles 'sol(' ", "regular expression"},
      {"--muscle-mass physiological --muscles top:0", "top:K"},
      {"--muscle-mass physiological --specific-tension -1", "--specific-tension"},
      {"--muscle-mass physiological --muscle-density 0", "--muscle-density"},
      {"--muscle-mass physiological --mass-region skin", "--mass-region"},
      {"--muscle-mass physiological --transfer-fraction 0.3", "--transfer-fraction needs --muscle-mass transfer"},
      {"--muscles all", "--muscles needs --muscle-mass"},
      {"--muscle-mass transfer --transfer-fraction 0.3", "--transfer-body"},
      {"--muscle-mass transfer --transfer-body tibia_r", "--transfer-fraction"},
      {"--muscle-mass transfer --transfer-body tibia_r --transfer-fraction 1", "[0, 1)"},
      {"--muscle-mass transfer --transfer-body shin --transfer-fraction 0.3", "'shin' is not a body"},
      {"--muscle-mass transfer --transfer-body pelvis --transfer-fraction 0.3 --muscles soleus_r",
       "running_leg.osim:"},
  };
  for (const Case& c : cases) {
    const CmdResult r = run(c.args + " --out o.sto");
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << "\nstderr: " << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << c.args << "\nstderr: " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "o.sto")) << c.args;
  }
}

}  // namespace
