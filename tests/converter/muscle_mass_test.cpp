// Where muscle mass comes from (converter/build/muscle_mass.hpp):
//  - the physiological mass formula, checked by hand;
//  - physiological mass conserves the total mass and the whole-body centre of mass at the default
//    pose (1e-12 relative) on the project's scenes and on gait2392 / gait10dof18musc (shared);
//  - a rigid motion of the whole model (only the root moving) has the same inertia with and
//    without mass points at the default pose: the root block of M agrees to 1e-10 (running_leg,
//    gait models), since each point was removed exactly where it sits;
//  - transfer: body mass and inertia x (1 - F), COM kept, muscle masses sum to F m_body, split in
//    proportion to physiological mass;
//  - a body left non-physical is a ConvertError naming it at its line;
//  - --muscles REGEX and top:K (ranking shares scale linearly with the density), Type III muscles
//    lumped with the reason, bad options rejected with clear messages.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "converter/build/muscle_mass.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using Source = MuscleMassOptions::Source;

std::string scenePath(const std::string& file) {
  return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + file;
}

const std::string kGait2392 = "opensim-models/Models/Gait2392_Simbody/gait2392_thelen2003muscle.osim";
const std::string kGait10 = "opensim-models/Models/Gait10dof18musc/gait10dof18musc.osim";

BuildOptions idBuild() {
  BuildOptions bo;
  bo.constraints = false;
  return bo;
}

// total mass and mass-weighted position sum at the default pose: bodies of the description placed
// by the core model's poses, plus the mass points of the muscles
struct MassMoment {
  double mass = 0.0;
  Vec3 first = Vec3::Zero();
};

MassMoment massMoment(const ModelDescription& d, const BuildResult& r) {
  MassMoment out;
  std::vector<Mat4> E_wi;
  const VecX q = r.model.skeleton().defaultQ();
  calcBodyPoses(r.model, q, E_wi);
  for (size_t bi = 0; bi < d.bodies.size(); ++bi) {
    const int cb = r.body_index[bi];
    if (cb < 0) continue;
    out.mass += d.bodies[bi].mass;
    out.first += d.bodies[bi].mass * transformPoint(E_wi[cb], d.bodies[bi].mass_center);
  }
  State s;
  s.q = q;
  s.qdot = VecX::Zero(r.model.nr());
  SkeletonWorkspace sk(r.model);
  calcKinematics(r.model, s, sk);
  for (const Muscle& m : r.model.muscles()) {
    if (m.mass_points.size() == 0) continue;
    MuscleKinematics mk;
    calcMuscleKinematics(r.model, s, sk, m, mk, false);
    for (int a = 0; a < m.mass_points.size(); ++a) {
      out.mass += m.mass_points.mass[a];
      out.first += m.mass_points.mass[a] * mk.x_a[a];
    }
  }
  return out;
}

void expectConserved(const ModelDescription& d, const MuscleMassOptions& o, const std::string& what) {
  SCOPED_TRACE(what);
  const BuildResult before = buildCoreModel(d, idBuild());
  const MuscleMassModel after = applyMuscleMass(d, idBuild(), o);
  EXPECT_GT(after.plan.total_muscle_mass, 0.0);
  const MassMoment a = massMoment(d, before), b = massMoment(after.description, after.build);
  EXPECT_NEAR(b.mass, a.mass, 1e-12 * a.mass);
  const Vec3 com_a = a.first / a.mass, com_b = b.first / b.mass;
  // relative to the model's size: the largest |COM| of any body, at least 1 m
  double size = 1.0;
  for (const auto& body : d.bodies) size = std::max(size, body.mass_center.norm());
  EXPECT_LE((com_b - com_a).norm(), 1e-12 * std::max(size, com_a.norm())) << com_a.transpose() << " vs "
                                                                           << com_b.transpose();
  std::printf("[ measured ] %s: %.4g kg moved; total mass error %.1e relative, whole-body COM moved %.1e m\n",
              what.c_str(), after.plan.total_muscle_mass, std::abs(b.mass - a.mass) / a.mass, (com_b - com_a).norm());
  // total mass moved equals the sum over the bodies' losses
  double lost = 0.0;
  for (const auto& c : after.plan.bodies) lost += c.mass_before - c.mass_after;
  EXPECT_NEAR(lost, after.plan.total_muscle_mass, 1e-12 * a.mass);
}

// ||M_root(lumped) - M_root(mass points)||_F / ||M_root(lumped)||_F at the default pose
double rootBlockDifference(const ModelDescription& d, const MuscleMassOptions& o, int root_dofs) {
  const BuildResult before = buildCoreModel(d, idBuild());
  const MuscleMassModel after = applyMuscleMass(d, idBuild(), o);
  EXPECT_GT(after.plan.total_muscle_mass, 0.0);
  System s0(before.model);
  System s1(after.build.model);
  s1.addTerm(std::make_shared<MuscleTerm>(after.build.model, after.build.model.muscles()));
  State st;
  st.q = before.model.skeleton().defaultQ();
  st.qdot = VecX::Zero(st.q.size());
  DynamicsWorkspace w0(s0.model()), w1(s1.model());
  s0.calcMassAndForce(st, w0);
  s1.calcMassAndForce(st, w1);
  const MatX A = w0.M.topLeftCorner(root_dofs, root_dofs), B = w1.M.topLeftCorner(root_dofs, root_dofs);
  // the mass points do change the rest of M (they slide along their paths)
  EXPECT_GT((w1.M - w0.M).norm(), 1e-6 * w0.M.norm());
  return (A - B).norm() / A.norm();
}

int findEntry(const MuscleMassPlan& p, const std::string& name) {
  for (size_t k = 0; k < p.muscles.size(); ++k)
    if (p.muscles[k].name == name) return static_cast<int>(k);
  return -1;
}

// ---------------------------------------------------------------------------------------------

TEST(MuscleMass, PhysiologicalMassByHand) {
  PathForceDesc m;
  m.max_isometric_force = 300.0;
  m.optimal_fiber_length = 0.8;
  MuscleMassOptions o;
  o.specific_tension = 0.25e6;
  // 1059.7 kg/m^3 * (300 N / 0.25e6 Pa) * 0.8 m = 1059.7 * 0.0012 * 0.8 m^3
  EXPECT_NEAR(physiologicalMass(m, o), 1.017312, 1e-14);
  o.density = 1000.0;
  o.specific_tension = 0.6e6;
  EXPECT_NEAR(physiologicalMass(m, o), 0.4, 1e-15);
  EXPECT_DOUBLE_EQ(kDefaultSpecificTension, 0.6e6);
  EXPECT_DOUBLE_EQ(kDefaultMuscleDensity, 1059.7);
}

TEST(MuscleMass, SourceNames) {
  for (Source s : {Source::None, Source::Physiological, Source::Transfer})
    EXPECT_EQ(parseMuscleMassSource(toString(s)), s);
  EXPECT_THROW(parseMuscleMassSource("Physiological"), std::invalid_argument);
  EXPECT_THROW(parseMuscleMassSource(""), std::invalid_argument);
}

TEST(MuscleMass, NoneBuildsTheModelAsIs) {
  const ModelDescription d = readOsimModel(scenePath("double_pendulum_via.osim"));
  const MuscleMassModel r = applyMuscleMass(d, idBuild(), {});
  ASSERT_EQ(r.plan.muscles.size(), 1u);
  EXPECT_EQ(r.plan.muscles[0].mass, 0.0);
  EXPECT_FALSE(r.plan.muscles[0].lumped_why.empty());
  EXPECT_EQ(r.build.model.muscles()[0].mass_points.size(), 0);
  EXPECT_TRUE(r.plan.bodies.empty());
  EXPECT_EQ(r.description.bodies[0].mass, d.bodies[0].mass);
}

TEST(MuscleMass, PhysiologicalConservesMassAndComOnScenes) {
  for (const auto& entry : std::filesystem::directory_iterator(std::string(REDMAX_SOURCE_DIR) + "/osim_models")) {
    if (entry.path().extension() != ".osim") continue;
    const ModelDescription d = readOsimModel(entry.path().string());
    if (d.muscles.empty()) continue;  // the contact scenes (docs/contact.md): no muscle to give mass
    MuscleMassOptions o;
    o.source = Source::Physiological;
    const std::string name = entry.path().filename().string();
    if (name.rfind("double_pendulum", 0) == 0 || name == "finger.osim") {
      // thin rods (2 cm) and light phalanges: the scenes' muscles (the pendulums' own 1 kg at a
      // tension of 0.25 MPa; the finger's flexors, whose bellies lie in the unmodelled forearm)
      // cannot have been part of these bones: an error naming the body ...
      if (name != "double_pendulum_wrap.osim") {
        MuscleMassOptions heavy = o;
        if (name != "finger.osim") heavy.specific_tension = 0.25e6;
        try {
          applyMuscleMass(d, idBuild(), heavy);
          ADD_FAILURE() << name << ": expected ConvertError";
        } catch (const ConvertError& e) {
          const std::string body = name == "finger.osim" ? "'metacarpal'" : "'link1'";
          EXPECT_NE(std::string(e.what()).find(body + " would become non-physical"), std::string::npos)
              << e.what();
        }
      }
      // ... while 0.01% of it fits (a rod's moments sit at the edge of the triangle inequality);
      // a misplaced point would still move the COM by ~1e-6 m, far above the tolerance
      o.density = 1e-4 * kDefaultMuscleDensity;
    }
    if (entry.path().filename() == "double_pendulum_wrap.osim") {
      // the only muscle wraps: nothing moves
      const MuscleMassModel r = applyMuscleMass(d, idBuild(), o);
      EXPECT_EQ(r.plan.total_muscle_mass, 0.0);
      EXPECT_EQ(r.plan.muscles[0].lumped_why, "Type III path (wrap mass off: --wrap lumped)");
      continue;
    }
    // every muscle of the reaching arm wraps: its mass moves only with the wrap model's mass
    if (name == "reach_arm.osim") o.wrap_mass = true;
    expectConserved(d, o, entry.path().filename().string());
    o.region = MassPointOptions::Region::WholePath;
    o.mass_points = 3;
    expectConserved(d, o, entry.path().filename().string() + " whole path, 3 points");
  }
}

TEST(MuscleMass, PhysiologicalConservesMassAndComOnGaitModels) {
  REDMAX_REQUIRE_SHARED();
  for (const std::string& f : {kGait2392, kGait10}) {
    const ModelDescription d = readOsimModel(test::sharedOpenSim(f));
    MuscleMassOptions o;
    o.source = Source::Physiological;
    expectConserved(d, o, f);
  }
}

TEST(MuscleMass, RootBlockOfMassMatrixUnchanged) {
  MuscleMassOptions o;
  o.source = Source::Physiological;
  {
    const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
    const double diff = rootBlockDifference(d, o, 6);
    EXPECT_LE(diff, 1e-10);
    std::printf("[ measured ] running_leg: root block of M with/without mass points differs by %.1e relative\n", diff);
  }
  if (!test::haveSharedOpenSim()) GTEST_SKIP() << "shared OpenSim data not found at " REDMAX_SHARED_DIR "/opensim; gait models not checked";
  for (const std::string& f : {kGait2392, kGait10}) {
    SCOPED_TRACE(f);
    const ModelDescription d = readOsimModel(test::sharedOpenSim(f));
    // gait10dof18musc's pelvis is planar (3 dofs)
    const double diff = rootBlockDifference(d, o, f == kGait10 ? 3 : 6);
    EXPECT_LE(diff, 1e-10);
    std::printf("[ measured ] %s: root block of M with/without mass points differs by %.1e relative\n", f.c_str(), diff);
  }
}

TEST(MuscleMass, TransferScalesTheBodyAndSplitsByPhysiologicalMass) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  MuscleMassOptions o;
  o.source = Source::Transfer;
  o.transfer_body = "tibia_r";
  o.transfer_fraction = 0.4;
  const MuscleMassModel r = applyMuscleMass(d, idBuild(), o);
  const int ti = d.findBody("tibia_r");
  const BodyDesc& b0 = d.bodies[ti];
  const BodyDesc& b1 = r.description.bodies[ti];
  EXPECT_NEAR(b1.mass, 0.6 * b0.mass, 1e-15 * b0.mass);
  EXPECT_EQ(b1.mass_center, b0.mass_center);
  EXPECT_LE((b1.inertiaMatrix() - 0.6 * b0.inertiaMatrix()).norm(), 1e-15 * b0.inertiaMatrix().norm());
  // other bodies untouched
  for (size_t k = 0; k < d.bodies.size(); ++k)
    if (static_cast<int>(k) != ti) {
      EXPECT_EQ(r.description.bodies[k].mass, d.bodies[k].mass);
    }
  ASSERT_EQ(r.plan.bodies.size(), 1u);
  EXPECT_EQ(r.plan.bodies[0].name, "tibia_r");

  // soleus (I) and tibialis anterior (II) have points on the tibia; the gastrocnemii wrap
  const int sol = findEntry(r.plan, "soleus_r"), ta = findEntry(r.plan, "tib_ant_r");
  const int mg = findEntry(r.plan, "med_gas_r");
  ASSERT_GE(sol, 0);
  ASSERT_GE(ta, 0);
  ASSERT_GE(mg, 0);
  EXPECT_EQ(r.plan.muscles[mg].mass, 0.0);
  EXPECT_NE(r.plan.muscles[mg].lumped_why.find("Type III"), std::string::npos);
  const double m_sol = r.plan.muscles[sol].mass, m_ta = r.plan.muscles[ta].mass;
  EXPECT_NEAR(m_sol + m_ta, 0.4 * b0.mass, 1e-14);
  EXPECT_NEAR(r.plan.total_muscle_mass, 0.4 * b0.mass, 1e-14);
  const double p_sol = physiologicalMass(d.muscles[r.build.muscle_source[sol]], o);
  const double p_ta = physiologicalMass(d.muscles[r.build.muscle_source[ta]], o);
  EXPECT_NEAR(m_sol / m_ta, p_sol / p_ta, 1e-12 * p_sol / p_ta);
  EXPECT_EQ(r.plan.muscles[sol].points, 20);
  EXPECT_NEAR(r.build.model.muscles()[sol].mass_points.totalMass(), m_sol, 1e-15);

  // --muscles narrows the set: all of it goes to the soleus
  o.muscles = "soleus.*";
  const MuscleMassModel s = applyMuscleMass(d, idBuild(), o);
  EXPECT_NEAR(s.plan.muscles[sol].mass, 0.4 * b0.mass, 1e-14);
  EXPECT_EQ(s.plan.muscles[ta].mass, 0.0);
  EXPECT_NE(s.plan.muscles[ta].lumped_why.find("not selected"), std::string::npos);

  // a body that no selected muscle spans
  o.muscles = "tib_ant_r";
  o.transfer_body = "pelvis";
  try {
    applyMuscleMass(d, idBuild(), o);
    ADD_FAILURE() << "expected ConvertError";
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), d.bodies[d.findBody("pelvis")].line);
    EXPECT_NE(std::string(e.what()).find("pelvis"), std::string::npos) << e.what();
  }
}

TEST(MuscleMass, NonPhysicalBodyIsNamed) {
  // a 10 g body with a 1 m muscle of 30 kN beside its bone: most of 53 g of muscle would leave it
  const std::string bodies =
      "<Body name=\"light\">\n<mass>0.01</mass>\n<mass_center>0.1 -1 0</mass_center>\n"
      "<inertia>0.001 0.001 0.001 0 0 0</inertia>\n</Body>\n" +
      test::bodyXml("heavy", 5.0);
  const std::string joints =
      test::pinXml("j1", "/ground", "/bodyset/heavy") + test::pinXml("j2", "/bodyset/heavy", "/bodyset/light");
  const std::string forces =
      "<ForceSet name=\"forceset\"><objects>\n<Thelen2003Muscle name=\"big\">\n"
      "<max_isometric_force>30000</max_isometric_force><optimal_fiber_length>0.1</optimal_fiber_length>"
      "<tendon_slack_length>0.01</tendon_slack_length>\n"
      "<GeometryPath name=\"path\"><PathPointSet><objects>\n"
      "<PathPoint name=\"o\"><socket_parent_frame>/bodyset/heavy</socket_parent_frame><location>0.1 0 0</location></PathPoint>\n"
      "<PathPoint name=\"i\"><socket_parent_frame>/bodyset/light</socket_parent_frame><location>0.1 -1 0</location></PathPoint>\n"
      "</objects></PathPointSet></GeometryPath>\n</Thelen2003Muscle>\n</objects></ForceSet>\n";
  test::TempDir dir;
  const std::string xml = test::modernOsim(bodies, joints, forces);
  const std::string file = dir.write("light.osim", xml);
  const ModelDescription d = readOsimModel(file);
  MuscleMassOptions o;
  o.source = Source::Physiological;
  try {
    applyMuscleMass(d, idBuild(), o);
    ADD_FAILURE() << "expected ConvertError";
  } catch (const ConvertError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'light'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-physical"), std::string::npos) << msg;
    EXPECT_EQ(e.line(), d.bodies[d.findBody("light")].line);
    EXPECT_EQ(e.line(), test::lineContaining(xml, "<Body name=\"light\">"));
  }
  // a lighter muscle passes
  o.density = 0.01;
  EXPECT_NO_THROW(applyMuscleMass(d, idBuild(), o));
}

TEST(MuscleMass, RegexSelection) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  MuscleMassOptions o;
  o.source = Source::Physiological;
  o.muscles = "tib_.*|soleus_r";
  const MuscleMassModel r = applyMuscleMass(d, idBuild(), o);
  for (const auto& e : r.plan.muscles) {
    const bool want = e.name == "tib_ant_r" || e.name == "soleus_r";
    EXPECT_EQ(e.mass > 0.0, want) << e.name;
    EXPECT_EQ(e.points, want ? 20 : 0) << e.name;
  }
  // whole-name match: a prefix alone selects nothing
  o.muscles = "tib";
  const MuscleMassModel n = applyMuscleMass(d, idBuild(), o);
  EXPECT_EQ(n.plan.total_muscle_mass, 0.0);
  EXPECT_TRUE(n.plan.bodies.empty());
}

TEST(MuscleMass, TopKRanksByInertiaShare) {
  REDMAX_REQUIRE_SHARED();
  const ModelDescription d = readOsimModel(test::sharedOpenSim(kGait10));
  MuscleMassOptions o;
  o.source = Source::Physiological;
  o.muscles = "top:4";
  // a few poses: the default and knees/hips bent
  const BuildResult base = buildCoreModel(d, idBuild());
  std::vector<VecX> samples{base.model.skeleton().defaultQ()};
  VecX q = base.model.skeleton().defaultQ();
  for (const char* c : {"hip_flexion_r", "knee_angle_r", "hip_flexion_l", "knee_angle_l"}) {
    const int k = base.model.skeleton().findCoordinate(c);
    ASSERT_GE(k, 0) << c;
    q[k] = std::string(c).find("knee") != std::string::npos ? -0.8 : 0.6;
  }
  samples.push_back(q);
  const MuscleMassModel r = applyMuscleMass(d, idBuild(), o, samples);
  int with = 0;
  for (const auto& e : r.plan.muscles) with += e.mass > 0.0;
  EXPECT_EQ(with, 4);
  ASSERT_EQ(r.plan.ranking.size(), r.plan.muscles.size());  // no wrapping muscle in this model? see below
  for (size_t k = 1; k < r.plan.ranking.size(); ++k)
    EXPECT_GE(r.plan.ranking[k - 1].second, r.plan.ranking[k].second);
  for (size_t k = 0; k < r.plan.ranking.size(); ++k) {
    const int e = findEntry(r.plan, r.plan.ranking[k].first);
    EXPECT_EQ(r.plan.muscles[e].mass > 0.0, k < 4) << r.plan.ranking[k].first;
    EXPECT_GT(r.plan.ranking[k].second, 0.0);
  }
  // M_muscle is linear in the muscle's mass: doubling the density doubles every share
  o.density *= 2.0;
  const MuscleMassModel r2 = applyMuscleMass(d, idBuild(), o, samples);
  ASSERT_EQ(r2.plan.ranking.size(), r.plan.ranking.size());
  for (size_t k = 0; k < r.plan.ranking.size(); ++k) {
    EXPECT_EQ(r2.plan.ranking[k].first, r.plan.ranking[k].first);
    EXPECT_NEAR(r2.plan.ranking[k].second, 2.0 * r.plan.ranking[k].second, 1e-12 * r.plan.ranking[k].second);
  }
  const std::string text = describeMuscleMass(r.plan);
  EXPECT_NE(text.find("ranking"), std::string::npos);
  EXPECT_NE(text.find(r.plan.ranking[0].first), std::string::npos);
}

TEST(MuscleMass, DescribeListsBodiesMusclesAndLumped) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  MuscleMassOptions o;
  o.source = Source::Physiological;
  const MuscleMassModel r = applyMuscleMass(d, idBuild(), o);
  const std::string text = describeMuscleMass(r.plan);
  for (const auto& b : r.plan.bodies) EXPECT_NE(text.find(b.name + ":"), std::string::npos) << text;
  EXPECT_NE(text.find("soleus_r: "), std::string::npos) << text;
  EXPECT_NE(text.find("20 points"), std::string::npos) << text;
  EXPECT_NE(text.find("med_gas_r: Type III path"), std::string::npos) << text;
}

TEST(MuscleMass, BadOptionsThrowClearly) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  auto expectInvalid = [&](MuscleMassOptions o, const std::string& needle) {
    try {
      applyMuscleMass(d, idBuild(), o);
      ADD_FAILURE() << "expected std::invalid_argument containing " << needle;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  MuscleMassOptions p;
  p.source = Source::Physiological;
  MuscleMassOptions t = p;
  t.source = Source::Transfer;
  t.transfer_body = "tibia_r";
  t.transfer_fraction = -0.1;
  expectInvalid(t, "--transfer-fraction");
  t.transfer_fraction = 1.0;
  expectInvalid(t, "--transfer-fraction");
  t.transfer_fraction = std::nan("");
  expectInvalid(t, "--transfer-fraction");
  t.transfer_fraction = 0.5;
  t.transfer_body = "";
  expectInvalid(t, "--transfer-body");
  t.transfer_body = "shin";
  EXPECT_THROW(applyMuscleMass(d, idBuild(), t), ConvertError);
  t.transfer_body = "ground";
  EXPECT_THROW(applyMuscleMass(d, idBuild(), t), ConvertError);
  MuscleMassOptions b = p;
  b.muscles = "soleus_r(";
  expectInvalid(b, "regular expression");
  b.muscles = "top:0";
  expectInvalid(b, "top:K");
  b.muscles = "top:x";
  expectInvalid(b, "top:K");
  b = p;
  b.mass_points = 0;
  expectInvalid(b, "--mass-points");
  b = p;
  b.specific_tension = 0.0;
  expectInvalid(b, "--specific-tension");
  b = p;
  b.density = -1.0;
  expectInvalid(b, "--muscle-density");
  b = p;
  EXPECT_THROW(applyMuscleMass(d, idBuild(), b, {VecX::Zero(3)}), std::invalid_argument);
}

}  // namespace
}  // namespace redmax::osim
