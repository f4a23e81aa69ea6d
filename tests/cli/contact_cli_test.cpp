// Contact in forward runs end to end (docs/contact.md): `redmax simulate` and `redmax forward` on
// the contact scenes of osim_models/ (ball drop, sliding block, 2-D walker) against closed forms,
// the summary's contact line, every force and geometry not applied named in a warning, --strict
// refusing to run (exit 2), and a time step too large for the contact stiffness stopping with a
// clear error (exit 1, no NaN, nothing written).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "converter/storage.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;
namespace fs = std::filesystem;
using redmax::osim::readStorage;
using redmax::osim::Storage;

constexpr double kG = 9.80665;

// Simbody's Hertz law for two equal materials of stiffness k: rest penetration under m g
double restPenetration(double mass, double r, double k) {
  const double E = std::pow(0.5 * std::pow(k, 2.0 / 3.0), 1.5);
  return std::pow(3.0 * mass * kG / (4.0 * E * std::sqrt(r)), 2.0 / 3.0);
}

class ContactCli : public CliTempDirTest {
 protected:
  ContactCli() : CliTempDirTest("contact_cli") {}
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return path(name);
  }
  CmdResult run(const std::string& args) const { return runRedmax(dir_, args); }
  double last(const Storage& s, const std::string& column) const {
    const int c = s.findColumn(column);
    EXPECT_GE(c, 0) << column;
    return c >= 0 ? s.data(s.numRows() - 1, c) : std::nan("");
  }
  // ball_drop.osim with its ForceSet and ContactGeometrySet replaced
  std::string ballWith(const std::string& name, const std::string& geometry, const std::string& forces) const {
    std::string text = slurp(scene("ball_drop.osim"));
    const auto g0 = text.find("<ContactGeometrySet"), g1 = text.find("</ForceSet>") + std::string("</ForceSet>").size();
    text.replace(g0, g1 - g0,
                 "<ContactGeometrySet name=\"contactgeometryset\"><objects>\n" + geometry +
                     "</objects></ContactGeometrySet>\n<ForceSet name=\"forceset\"><objects>\n" + forces +
                     "</objects></ForceSet>");
    return write(name, text);
  }
};

TEST_F(ContactCli, BallDropComesToRestAtTheHertzPenetration) {
  const CmdResult r = run("simulate --model " + scene("ball_drop.osim") +
                          " --duration 5 --rtol 1e-8 --atol 1e-10 --full-precision --out " + path("ball.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("not applied"), std::string::npos) << r.err;
  // the summary's contact line
  EXPECT_NE(r.out.find("contacts: 1 pairs, 1 active at the end"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("largest penetration"), std::string::npos) << r.out;
  const Storage s = readStorage(path("ball.sto"));
  const double d = 0.1 - last(s, "/jointset/ball_free/ball_ty/value"), d_eq = restPenetration(1.0, 0.1, 1e7);
  // closed form 3.5109e-4 m; measured relative difference 1.0e-6 (still ringing: speed 9e-8 m/s)
  EXPECT_NEAR(d, d_eq, 5e-6 * d_eq) << d;
  EXPECT_LT(std::abs(last(s, "/jointset/ball_free/ball_ty/speed")), 1e-6);
  // the run started 0.4 m above the floor and never fell through
  const int ty = s.findColumn("/jointset/ball_free/ball_ty/value");
  EXPECT_GT(s.data.col(ty).minCoeff(), 0.09);
}

TEST_F(ContactCli, BlockSlidesToTheFrictionDistance) {
  const CmdResult r = run("simulate --model " + scene("sliding_block.osim") +
                          " --duration 1 --rtol 1e-9 --atol 1e-12 --full-precision --out " + path("block.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage s = readStorage(path("block.sto"));
  // (v0^2 + vt^2) / (2 ud g) with v0 = 2, vt = 0.01, ud = 0.5; measured relative difference 1.2e-9
  const double ref = (4.0 + 1e-4) / (2 * 0.5 * kG);
  EXPECT_NEAR(last(s, "/jointset/slide_x/block_x/value"), ref, 1e-8 * ref);
  EXPECT_LT(std::abs(last(s, "/jointset/slide_x/block_x/speed")), 1e-6);
}

TEST_F(ContactCli, UnsupportedContactIsNamedAndStrictRefuses) {
  const std::string geometry =
      "<ContactHalfSpace name=\"floor\"><socket_frame>/ground</socket_frame><orientation>0 0 -1.5707963267948966</orientation></ContactHalfSpace>\n"
      "<ContactMesh name=\"ball_mesh\"><socket_frame>/bodyset/ball</socket_frame><filename>ball.obj</filename></ContactMesh>\n"
      "<ContactSphere name=\"spare\"><socket_frame>/bodyset/ball</socket_frame><radius>0.1</radius></ContactSphere>\n";
  const std::string forces =
      "<ElasticFoundationForce name=\"foundation\"><contact_parameters /></ElasticFoundationForce>\n";
  const std::string model = ballWith("mesh.osim", geometry, forces);
  CmdResult r = run("simulate --model " + model + " --duration 0.1 --out " + path("m.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  // the force, the mesh and the sphere no force uses are each named
  EXPECT_NE(r.err.find("warning: not applied: ElasticFoundationForce 'foundation' is not modelled"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ContactMesh 'ball_mesh': this contact geometry is not modelled"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ContactSphere 'spare': no applied contact force uses it"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ContactHalfSpace 'floor': no applied contact force uses it"), std::string::npos) << r.err;
  r = run("simulate --model " + model + " --duration 0.1 --strict --out " + path("strict.sto"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("--strict: 4 forces or geometries are not applied"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ElasticFoundationForce 'foundation'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("strict.sto")));
  // a supported model passes --strict
  r = run("simulate --model " + scene("ball_drop.osim") + " --duration 0.1 --strict --out " + path("ok.sto"));
  EXPECT_EQ(r.code, 0) << r.err;
  // the Simbody engine applies the contact forces only: the walker's joint springs are named, and
  // --strict refuses them; the ball (contact alone) passes
  r = run("simulate --model " + scene("ball_drop.osim") + " --duration 0.1 --engine simbody --strict --out " +
          path("sb.sto"));
  EXPECT_EQ(r.code, 0) << r.err;
  r = run("simulate --model " + scene("walker2d.osim") + " --duration 0.1 --engine simbody --strict --out " +
          path("sbw.sto"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("hip_flexion_r_spring (SpringGeneralizedForce)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("it applies the contact forces only"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("sbw.sto")));
}

// Side by side with Simbody's own compliant contact (plugin/simbody/contact_forces.hpp): the same
// model run by the core's HuntCrossley and SmoothSphereHalfSpace terms and by Simbody's
// HuntCrossleyForce and SmoothSphereHalfSpaceForce, both rk45 at 1e-10, 1 s: the coordinates agree
// to the integrators' error (docs/contact.md §5.1 has the table)
TEST_F(ContactCli, SimbodysCompliantContactGivesTheCoresTrajectories) {
  struct Case {
    const char* model;
    double bound;  // largest coordinate difference (m or rad)
  };
  for (const Case& c : {Case{"ball_drop.osim", 1e-8},      // measured 1.6e-9 m (the ball's height, three impacts)
                        Case{"sliding_block.osim", 2e-10},  // measured 1.7e-11 m
                        Case{"walker2d.osim", 1e-9}}) {     // measured 1.4e-10 m (SmoothSphereHalfSpaceForce feet)
    const std::string base = "simulate --model " + scene(c.model) +
                             " --duration 1 --rtol 1e-10 --atol 1e-12 --full-precision --quiet --out ";
    const std::string name(c.model);
    const CmdResult rc = run(base + path(name + "_core.sto"));
    ASSERT_EQ(rc.code, 0) << rc.err;
    const CmdResult rs = run(base + path(name + "_sb.sto") + " --engine simbody");
    ASSERT_EQ(rs.code, 0) << rs.err;
    const Storage a = readStorage(path(name + "_core.sto")), b = readStorage(path(name + "_sb.sto"));
    ASSERT_EQ(a.data.rows(), b.data.rows());
    double worst = 0.0, moved = 0.0;
    for (size_t j = 0; j < a.labels.size(); ++j) {
      if (a.labels[j].find("/value") == std::string::npos) continue;
      const int k = b.findColumn(a.labels[j]);
      ASSERT_GE(k, 0) << a.labels[j];
      worst = std::max(worst, (a.data.col(static_cast<int>(j)) - b.data.col(k)).cwiseAbs().maxCoeff());
      moved = std::max(moved, a.data.col(static_cast<int>(j)).maxCoeff() - a.data.col(static_cast<int>(j)).minCoeff());
    }
    std::printf("[ measured ] %s: core against Simbody's contact, largest coordinate difference %.3e (range %.3g)\n",
                c.model, worst, moved);
    EXPECT_LE(worst, c.bound) << c.model;
    EXPECT_GT(moved, 0.01) << c.model;  // it moved: the contact acted
  }
}

TEST_F(ContactCli, MusclesAndActuatorsWithoutControlsAreNamed) {
  const CmdResult r = run("simulate --model " + scene("double_pendulum_via.osim") + " --duration 0.05 --out " +
                          path("p.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: not applied: 1 path forces exert no force without --controls"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("via_muscle (Thelen2003Muscle)"), std::string::npos) << r.err;
}

TEST_F(ContactCli, StepTooLargeForTheStiffnessIsAClearError) {
  const CmdResult r = run("simulate --model " + scene("ball_drop.osim") +
                          " --integrator euler --dt 0.01 --duration 20 --out " + path("big.sto"));
  EXPECT_EQ(r.code, 1) << r.err;
  // the step against the contact's frequency: at rest omega = 205 rad/s, in the first impact more
  EXPECT_NE(r.err.find("the step h = 0.01 s is too large for the contact's stiffness"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("needs h < 1 / omega"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("nan"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("big.sto")));
  // the same model at dt 1e-4 runs (the contact's linearized period at rest is 2 pi / 205 rad/s = 31 ms)
  const CmdResult ok = run("simulate --model " + scene("ball_drop.osim") +
                           " --integrator euler --dt 1e-4 --duration 1 --out " + path("small.sto"));
  EXPECT_EQ(ok.code, 0) << ok.err;
}

TEST_F(ContactCli, WalkerStandsOnItsFootSpheres) {
  const CmdResult r = run("simulate --model " + scene("walker2d.osim") + " --duration 2 --out " + path("w.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("contacts: 4 pairs, 4 active at the end"), std::string::npos) << r.out;
  const Storage s = readStorage(path("w.sto"));
  // standing: the pelvis settles below its touching height 0.95 m by the spheres' penetration
  // (about 9 mm under a quarter of the weight each) and stops
  const double ty = last(s, "/jointset/ground_pelvis/pelvis_ty/value");
  EXPECT_GT(ty, 0.93);
  EXPECT_LT(ty, 0.95);
  EXPECT_LT(std::abs(last(s, "/jointset/ground_pelvis/pelvis_ty/speed")), 1e-3);
}

TEST_F(ContactCli, ForwardToolAppliesContactAndStrictRefusesUnsupported) {
  auto setup = [&](const std::string& name, const std::string& model) {
    return write(name, "<OpenSimDocument Version=\"40000\">\n<ForwardTool name=\"ball\">\n<model_file>" + model +
                           "</model_file>\n<results_directory>res</results_directory>\n"
                           "<initial_time>0</initial_time>\n<final_time>1.5</final_time>\n"
                           "</ForwardTool>\n</OpenSimDocument>\n");
  };
  CmdResult r = run("forward --setup " + setup("ball.xml", scene("ball_drop.osim")) + " --strict --report-interval 0.05");
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage s = readStorage(path("res/ball_states.sto"));
  const int ty = s.findColumn("/jointset/ball_free/ball_ty/value");
  ASSERT_GE(ty, 0);
  // on the floor, not through it: within 2 mm of the rest height after 1.5 s
  EXPECT_NEAR(s.data(s.numRows() - 1, ty), 0.1 - restPenetration(1.0, 0.1, 1e7), 2e-3);
  EXPECT_GT(s.data.col(ty).minCoeff(), 0.09);
  const std::string mesh = ballWith(
      "fmesh.osim",
      "<ContactHalfSpace name=\"floor\"><socket_frame>/ground</socket_frame></ContactHalfSpace>\n",
      "<ElasticFoundationForce name=\"foundation\" />\n");
  r = run("forward --setup " + setup("mesh.xml", mesh) + " --out-dir " + path("out2"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: not applied: ElasticFoundationForce 'foundation'"), std::string::npos) << r.err;
  r = run("forward --setup " + setup("mesh2.xml", mesh) + " --strict --out-dir " + path("out3"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--strict"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("out3")));
}

}  // namespace

// hard unilateral constraints (docs/contact.md §6): `simulate --integrator bdf1 --contact hard`
TEST_F(ContactCli, HardContactBallRestsOnTheFloorWithoutPenetration) {
  const CmdResult r = run("simulate --model " + scene("ball_drop.osim") +
                          " --integrator bdf1 --contact hard --contact-restitution 0.5 --duration 2 --full-precision --out " +
                          path("hard.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("not applied"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("unilateral: 0 joint limits, 1 contact pairs;"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("QP iterations"), std::string::npos) << r.out;
  const Storage s = readStorage(path("hard.sto"));
  const int ty = s.findColumn("/jointset/ball_free/ball_ty/value");
  EXPECT_NEAR(last(s, "/jointset/ball_free/ball_ty/value"), 0.1, 1e-8);  // resting on its radius
  EXPECT_GT(s.data.col(ty).minCoeff(), 0.1 - 1e-8);                       // never below it
}

TEST_F(ContactCli, HardContactBlockSlidesTheCoulombDistance) {
  const CmdResult r = run("simulate --model " + scene("sliding_block.osim") +
                          " --integrator bdf1 --contact hard --duration 1 --full-precision --out " + path("hb.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage s = readStorage(path("hb.sto"));
  // v0^2 / (2 ud g) with v0 = 2, ud = 0.5 (Coulomb, no transition velocity); first order in dt:
  // within dt v0 (measured 1.35e-3 m short: dt v0 / 2 and the model's initial overlap pushed out)
  EXPECT_NEAR(last(s, "/jointset/slide_x/block_x/value"), 4.0 / (2 * 0.5 * kG), 1e-3 * 2.0);
  EXPECT_LT(std::abs(last(s, "/jointset/slide_x/block_x/speed")), 1e-8);
}

TEST_F(ContactCli, HardContactUnderRk45SlidesTheClosedFormDistance) {
  // the same block under rk45 (the default) by event location: the slide is v0^2 / (2 ud g) to the
  // integrator's tolerance (measured 5e-16 m), where bdf1 is first order in dt
  const CmdResult r = run("simulate --model " + scene("sliding_block.osim") +
                          " --contact hard --duration 1 --full-precision --out " + path("rk.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("1 contact pairs by event location; 1 impacts, 0 releases, 0 slips, 1 sticks"), std::string::npos)
      << r.out;
  const Storage s = readStorage(path("rk.sto"));
  EXPECT_NEAR(last(s, "/jointset/slide_x/block_x/value"), 4.0 / (2 * 0.5 * kG), 1e-12);
  EXPECT_LT(std::abs(last(s, "/jointset/slide_x/block_x/speed")), 1e-12);
}

TEST_F(ContactCli, HardJointLimitHoldsTheClampedCoordinate) {
  std::string text = slurp(scene("double_pendulum_straight.osim"));
  // the second coordinate's range [-0.1, 0.6] rad, clamped
  const auto p = text.find("<range>", text.find("0.523598775598299"));
  text.replace(p, text.find("</clamped>", p) - p,
               "<range>-0.1 0.6</range>\n<clamped>true");
  const std::string model = write("clamped.osim", text);
  CmdResult r = run("simulate --model " + model + " --integrator bdf1 --joint-limits clamped --duration 2 --out " +
                    path("lim.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("unilateral: 1 joint limits, 0 contact pairs;"), std::string::npos) << r.out;
  const Storage s = readStorage(path("lim.sto"));
  const int dc = s.findColumn("/jointset/pin2/q2/value");
  ASSERT_GE(dc, 0);
  EXPECT_LE(s.data.col(dc).maxCoeff(), 0.6 + 1e-8);
  EXPECT_GE(s.data.col(dc).minCoeff(), -0.1 - 1e-8);
  // without the limit the coordinate leaves the range (the limit did something)
  r = run("simulate --model " + model + " --integrator bdf1 --duration 2 --out " + path("free.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage f = readStorage(path("free.sto"));
  EXPECT_TRUE(f.data.col(dc).maxCoeff() > 0.6 + 1e-3 || f.data.col(dc).minCoeff() < -0.1 - 1e-3);
}

TEST_F(ContactCli, HardModesNeedBdf1AndTheirFlags) {
  CmdResult r = run("simulate --model " + scene("ball_drop.osim") + " --contact hard --integrator sdirk2 --duration 0.1 --out " +
                    path("x.sto"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--contact hard needs --integrator bdf1, rk45 or cvode"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("x.sto")));
  // joint limits: bdf1, or rk45 / cvode by event location; not the other fixed-step methods
  r = run("simulate --model " + scene("finger.osim") + " --joint-limits hard --integrator euler --duration 0.1 --out " +
          path("x.sto"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--joint-limits needs --integrator bdf1, rk45 or cvode"), std::string::npos) << r.err;
  r = run("simulate --model " + scene("finger.osim") +
          " --joint-limits hard --duration 0.5 --impulse fingertip:0,20,0:0.002 --full-precision --out " + path("rk.sto"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("0 contact pairs by event location"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("; 0 impacts"), std::string::npos) << r.out;  // the flicked finger hits its limits
  {
    // never beyond a range (mcp -0.35 .. 1.57, pip 0 .. 1.92, dip 0 .. 1.57) at any output row
    const Storage st = readStorage(path("rk.sto"));
    const char* cols[3] = {"/jointset/mcp/mcp_flexion/value", "/jointset/pip/pip_flexion/value",
                           "/jointset/dip/dip_flexion/value"};
    const double lo[3] = {-0.35, 0.0, 0.0}, hi[3] = {1.57, 1.92, 1.57};
    for (int j = 0; j < 3; ++j) {
      const int c = st.findColumn(cols[j]);
      ASSERT_GE(c, 0) << cols[j];
      EXPECT_GE(st.data.col(c).minCoeff(), lo[j] - 1e-9) << cols[j];
      EXPECT_LE(st.data.col(c).maxCoeff(), hi[j] + 1e-9) << cols[j];
    }
  }
  r = run("simulate --model " + scene("ball_drop.osim") + " --integrator bdf1 --limit-restitution 0.5 --duration 0.1 --out " +
          path("x.sto"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--limit-restitution needs --joint-limits"), std::string::npos) << r.err;
  r = run("simulate --model " + scene("ball_drop.osim") + " --integrator bdf1 --contact-restitution 0.5 --duration 0.1 --out " +
          path("x.sto"));
  EXPECT_EQ(r.code, 2);
  r = run("simulate --model " + scene("ball_drop.osim") + " --engine simbody --integrator bdf1 --contact hard --duration 0.1 --out " +
          path("x.sto"));
  EXPECT_EQ(r.code, 2);
}

TEST_F(ContactCli, HardContactNamesGeometryItCannotUseAndStrictRefuses) {
  std::string text = slurp(scene("ball_drop.osim"));
  const std::string anchor = "</ContactSphere>";
  text.insert(text.find(anchor) + anchor.size(),
              "\n<ContactMesh name=\"ball_mesh\"><socket_frame>/bodyset/ball</socket_frame><filename>ball.obj</filename></ContactMesh>\n"
              "<ContactSphere name=\"spare\"><socket_frame>/bodyset/ball</socket_frame><radius>0.05</radius></ContactSphere>\n");
  const std::string model = write("hard_mesh.osim", text);
  CmdResult r = run("simulate --model " + model + " --integrator bdf1 --contact hard --duration 0.1 --out " + path("h.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("ContactMesh 'ball_mesh': only ContactSphere and ContactHalfSpace can be hard contacts"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("ContactSphere 'spare': no contact force pairs it"), std::string::npos) << r.err;
  // the pair the HuntCrossleyForce names is hard; the force itself is not also applied
  EXPECT_NE(r.out.find("1 contact pairs"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("HuntCrossleyForce"), std::string::npos) << r.err;
  r = run("simulate --model " + model + " --integrator bdf1 --contact hard --strict --duration 0.1 --out " + path("s.sto"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(fs::exists(path("s.sto")));
}
