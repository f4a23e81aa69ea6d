// The core and Simbody engines of `redmax id` on a project-authored model with every joint type
// the Simbody plugin builds (Free, Ball, Gimbal, Pin, Universal, Slider), offset frames with
// rotations, and external loads expressed in moving bodies. In OpenSim-compatible mode the
// Simbody engine does exactly what OpenSim does (the data's Euler-angle rates go into the Ball and
// Free mobilizers' u as they are), so agreement with the core's change of velocity variables
// (core_id_engine.hpp) tests that mapping; in exact mode both engines must agree too. Runs
// everywhere (no ../shared needed).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "plugin/simbody/id_engine.hpp"

namespace redmax::osim {
namespace {

namespace fs = std::filesystem;

std::string num(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}

std::string frameXml(const std::string& name, const std::string& parent, const std::string& t,
                     const std::string& o) {
  return "<PhysicalOffsetFrame name=\"" + name + "\"><socket_parent>" + parent +
         "</socket_parent><translation>" + t + "</translation><orientation>" + o +
         "</orientation></PhysicalOffsetFrame>\n";
}

std::string bodyXml(const std::string& name, double m, const std::string& com) {
  return "<Body name=\"" + name + "\"><mass>" + num(m) + "</mass><mass_center>" + com +
         "</mass_center><inertia>0.04 0.05 0.03 0.004 -0.002 0.001</inertia></Body>\n";
}

std::string jointXml(const std::string& type, const std::string& name, const std::string& parent,
                     const std::string& child, const std::vector<std::string>& coords) {
  std::string x = "<" + type + " name=\"" + name + "\"><socket_parent_frame>" + name +
                  "_p</socket_parent_frame><socket_child_frame>" + name + "_c</socket_child_frame><coordinates>";
  for (const auto& c : coords) x += "<Coordinate name=\"" + c + "\"/>";
  x += "</coordinates><frames>" + frameXml(name + "_p", parent, "0.05 -0.3 0.02", "0.2 -0.1 0.3") +
       frameXml(name + "_c", child, "-0.02 0.1 0.01", "-0.15 0.25 0.05") + "</frames></" + type + ">\n";
  return x;
}

struct Scene {
  fs::path dir;
  std::string model, coords, loads;
  std::vector<std::string> names;
};

// a branched tree: ground -free-> torso -ball-> arm -pin-> forearm; torso -gimbal-> leg
// -universal-> foot -slider-> toe; every coordinate a sinusoid at 100 Hz over 2 s
Scene makeScene() {
  Scene s;
  s.dir = fs::temp_directory_path() / ("redmax_id_compat_" + std::to_string(::getpid()));
  fs::create_directories(s.dir);
  const std::string bodies = bodyXml("torso", 20.0, "0 0.2 0") + bodyXml("arm", 2.0, "0 -0.15 0.01") +
                             bodyXml("forearm", 1.2, "0.01 -0.12 0") + bodyXml("leg", 6.0, "0 -0.2 0") +
                             bodyXml("foot", 1.0, "0.05 -0.02 0") + bodyXml("toe", 0.3, "0.02 0 0");
  const std::string joints =
      jointXml("FreeJoint", "free", "/ground", "/bodyset/torso", {"rx", "ry", "rz", "tx", "ty", "tz"}) +
      jointXml("BallJoint", "shoulder", "/bodyset/torso", "/bodyset/arm", {"b1", "b2", "b3"}) +
      jointXml("PinJoint", "elbow", "/bodyset/arm", "/bodyset/forearm", {"elbow"}) +
      jointXml("GimbalJoint", "hip", "/bodyset/torso", "/bodyset/leg", {"g1", "g2", "g3"}) +
      jointXml("UniversalJoint", "ankle", "/bodyset/leg", "/bodyset/foot", {"u1", "u2"}) +
      jointXml("SliderJoint", "toes", "/bodyset/foot", "/bodyset/toe", {"slide"});
  s.model = (s.dir / "tree.osim").string();
  std::ofstream(s.model) << "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
                            "<Model name=\"tree\"><Ground name=\"ground\"/><gravity>0 -9.80665 0</gravity>\n"
                            "<BodySet name=\"bodyset\"><objects>\n"
                         << bodies << "</objects></BodySet>\n<JointSet name=\"jointset\"><objects>\n"
                         << joints << "</objects></JointSet>\n</Model>\n</OpenSimDocument>\n";
  s.names = {"rx", "ry", "rz", "tx", "ty", "tz", "b1", "b2", "b3", "elbow", "g1", "g2", "g3", "u1", "u2", "slide"};
  s.coords = (s.dir / "motion.mot").string();
  {
    std::ofstream os(s.coords);
    os.precision(17);
    const int n = 201;
    os << "motion\nversion=1\nnRows=" << n << "\nnColumns=" << s.names.size() + 1
       << "\ninDegrees=no\nendheader\ntime";
    for (const auto& l : s.names) os << "\t" << l;
    os << "\n";
    for (int i = 0; i < n; ++i) {
      const double t = 0.01 * i;
      os << t;
      for (size_t k = 0; k < s.names.size(); ++k)
        os << "\t" << 0.1 * std::cos(0.7 * k) + 0.5 * std::sin((1.3 + 0.37 * k) * t + 0.5 * k);
      os << "\n";
    }
  }
  // loads: on the foot (force in leg, point in forearm), torque in torso; and a force on the torso
  // with no point (at its origin)
  const std::vector<std::string> cols = {"a_vx", "a_vy", "a_vz", "a_px", "a_py", "a_pz",
                                         "a_tx", "a_ty", "a_tz", "b_vx", "b_vy", "b_vz"};
  {
    std::ofstream os((s.dir / "loads.mot").string());
    os.precision(17);
    const int n = 41;
    os << "loads\nversion=1\nnRows=" << n << "\nnColumns=" << cols.size() + 1 << "\ninDegrees=no\nendheader\ntime";
    for (const auto& l : cols) os << "\t" << l;
    os << "\n";
    for (int i = 0; i < n; ++i) {
      const double t = -0.5 + 0.075 * i;
      os << t;
      for (size_t k = 0; k < cols.size(); ++k) os << "\t" << (k % 3 == 1 ? 20.0 : 3.0) * std::sin(0.9 * t + k);
      os << "\n";
    }
  }
  s.loads = (s.dir / "loads.xml").string();
  std::ofstream(s.loads)
      << "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\"><ExternalLoads name=\"l\"><objects>\n"
         "<ExternalForce name=\"a\"><applied_to_body>foot</applied_to_body>"
         "<force_expressed_in_body>leg</force_expressed_in_body><point_expressed_in_body>/bodyset/forearm"
         "</point_expressed_in_body><force_identifier>a_v</force_identifier><point_identifier>a_p"
         "</point_identifier><torque_identifier>a_t</torque_identifier></ExternalForce>\n"
         "<ExternalForce name=\"b\"><applied_to_body>torso</applied_to_body>"
         "<force_identifier>b_v</force_identifier></ExternalForce>\n"
         "</objects><datafile>loads.mot</datafile></ExternalLoads></OpenSimDocument>\n";
  return s;
}

class IdEngines : public ::testing::Test {
 protected:
  void SetUp() override { scene_ = makeScene(); }
  void TearDown() override { fs::remove_all(scene_.dir); }

  IdToolConfig config(bool compat) const {
    IdToolSettings st;
    st.model_file = scene_.model;
    st.coordinates_file = scene_.coords;
    st.external_loads_file = scene_.loads;
    st.lowpass_cutoff_hz = 6.0;
    st.t0 = 0.2;
    st.t1 = 1.8;
    st.opensim_compat = compat;
    return resolveIdSettings(st);
  }
  Scene scene_;
};

// largest |a - b| / peak |b| over the columns
double worstRelative(const Storage& a, const Storage& b, std::string* column = nullptr) {
  double worst = 0;
  for (int c = 0; c < b.numColumns(); ++c) {
    const double peak = b.data.col(c).cwiseAbs().maxCoeff();
    const double e = (a.data.col(c) - b.data.col(c)).cwiseAbs().maxCoeff() / peak;
    if (e > worst) {
      worst = e;
      if (column) *column = b.labels[c];
    }
  }
  return worst;
}

TEST_F(IdEngines, CompatibleModeMatchesSimbodyWithOpenSimSpeeds) {
  const InverseDynamicsTool tool(config(true));
  // the free and ball joints are marked; the gimbal is not (u = qdot in OpenSim)
  const Model& m = tool.model();
  int marked = 0;
  for (int j = 0; j < m.nb(); ++j) marked += tool.engineOptions().marked(j);
  EXPECT_EQ(marked, 2);
  CoreIdEngine core(m, tool.engineOptions());
  simbody::SimbodyIdEngine sim(m, tool.engineOptions());
  const Storage a = tool.run(core), b = tool.run(sim);
  std::string col;
  const double err = worstRelative(a, b, &col);
  std::printf("[ measured ] opensim-compat, core vs Simbody: worst |diff| / peak = %.3g (%s)\n", err, col.c_str());
  EXPECT_LE(err, 1e-9);
}

TEST_F(IdEngines, ExactModeMatchesSimbody) {
  const InverseDynamicsTool tool(config(false));
  for (int j = 0; j < tool.model().nb(); ++j) EXPECT_FALSE(tool.engineOptions().marked(j));
  CoreIdEngine core(tool.model(), tool.engineOptions());
  simbody::SimbodyIdEngine sim(tool.model(), tool.engineOptions());
  const Storage a = tool.run(core), b = tool.run(sim);
  std::string col;
  const double err = worstRelative(a, b, &col);
  std::printf("[ measured ] exact, core vs Simbody: worst |diff| / peak = %.3g (%s)\n", err, col.c_str());
  EXPECT_LE(err, 1e-9);
}

TEST_F(IdEngines, CompatibleDiffersFromExactOnBallAndFreeColumns) {
  const Storage compat = [&] {
    const InverseDynamicsTool t(config(true));
    CoreIdEngine e(t.model(), t.engineOptions());
    return t.run(e);
  }();
  const Storage exact = [&] {
    const InverseDynamicsTool t(config(false));
    CoreIdEngine e(t.model(), t.engineOptions());
    return t.run(e);
  }();
  std::printf("[ measured ] exact vs opensim-compat, max |diff| / peak per column:\n");
  for (int c = 0; c < compat.numColumns(); ++c) {
    const double peak = compat.data.col(c).cwiseAbs().maxCoeff();
    const double d = (exact.data.col(c) - compat.data.col(c)).cwiseAbs().maxCoeff() / peak;
    std::printf("    %-16s %10.3g\n", compat.labels[c].c_str(), d);
  }
  // the ball's moments: OpenSim reads Euler rates as angular velocity, a different motion and a
  // different force basis
  const int b1 = compat.findColumn("b1_moment");
  ASSERT_GE(b1, 0);
  EXPECT_GT((exact.data.col(b1) - compat.data.col(b1)).cwiseAbs().maxCoeff(),
            1e-3 * compat.data.col(b1).cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace redmax::osim
