#include "validation/scenes/hybrid_scenes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <numbers>
#include <stdexcept>

#include "core/deformable/deformable_term.hpp"
#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/constraints/prescribed_point.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "validation/scenes/scene_io.hpp"

namespace redmax::scenes {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// a solid rod of mass m, length L and radius r along +x from the body origin: (com, inertia)
std::pair<Vec3, Mat3> rod(double m, double L, double r) {
  const double ia = m * r * r / 2, it = m * (L * L / 12 + r * r / 4);
  return {Vec3(L / 2, 0, 0), Vec3(ia, it, it).asDiagonal()};
}

// hand geometry (m)
constexpr double kForearm = 0.25, kPalm = 0.08;
constexpr double kPhalanx[3] = {0.045, 0.028, 0.02};
constexpr double kFingerZ[4] = {-0.027, -0.009, 0.009, 0.027};
// initial pose (rad): elbow, wrist flexion, MCP flexion, PIP (DIP = 0.5 PIP)
constexpr double kElbow0 = 0.4, kWrist0 = -0.2, kMcp0 = -0.6, kPip0 = -1.0;

// a Universal joint [D Sec. 4.5.6] turns about the joint frame's x then y; this frame puts its x
// along the world z (flexion) and its y along the world y (abduction, deviation)
const Mat3& universalFrame() {
  static const Mat3 R = (Mat3() << 0, 0, -1, 0, 1, 0, 1, 0, 0).finished();
  return R;
}

int handBody(int finger, int phalanx) { return 2 + 3 * finger + phalanx; }
int handCoordinate(int finger, int k) { return 3 + 4 * finger + k; }  // k: MCP flex, MCP abd, PIP, DIP

}  // namespace

Model handModel() {
  ModelBuilder b("hand");
  b.setGravity(Vec3(0, -9.81, 0));
  const auto [cf, If] = rod(1.2, kForearm, 0.03);
  const int forearm = b.addBody("forearm", 1.2, cf, If, -1, "elbow", Revolute{Vec3::UnitZ()});
  b.setCoordinateNames(forearm, {"elbow"});
  const Mat3& U = universalFrame();
  const Mat3 Ip = Vec3(4e-4, 2.5e-4, 2.5e-4).asDiagonal();
  const int palm = b.addBody("palm", 0.4, Vec3(kPalm / 2, 0, 0), Ip, forearm, "wrist", Universal{},
                             makeE(U, Vec3(kForearm, 0, 0)), makeE(U, Vec3::Zero()));
  b.setCoordinateNames(palm, {"wrist_flexion", "wrist_deviation"});
  const double mass[3] = {0.012, 0.007, 0.005};
  const char* names[3] = {"proximal", "middle", "distal"};
  for (int f = 0; f < 4; ++f) {
    const std::string fs = std::to_string(f + 2);  // index to little finger: digits 2-5
    int parent = palm;
    for (int p = 0; p < 3; ++p) {
      const auto [c, I] = rod(mass[p], kPhalanx[p], 0.008);
      const std::string body = names[p] + std::string("_") + fs;
      if (p == 0) {
        parent = b.addBody(body, mass[p], c, I, parent, "mcp_" + fs, Universal{}, makeE(U, Vec3(kPalm, 0, kFingerZ[f])),
                           makeE(U, Vec3::Zero()));
        b.setCoordinateNames(parent, {"mcp_flexion_" + fs, "mcp_abduction_" + fs});
      } else {
        const std::string joint = (p == 1 ? "pip_" : "dip_") + fs;
        parent = b.addBody(body, mass[p], c, I, parent, joint, Revolute{Vec3::UnitZ()},
                           makeTranslation(Vec3(kPhalanx[p - 1], 0, 0)));
        b.setCoordinateNames(parent, {joint});
      }
    }
  }
  // joint dampers everywhere, and a soft wrist spring: with the elbow and the tips prescribed
  // the wrist's two degrees of freedom are the passive ones
  for (int k = 0; k < b.nr(); ++k) b.coordinateAt(k).damping = k < 3 ? 0.05 : 0.002;
  for (int k : {1, 2}) b.coordinateAt(k).stiffness = 5.0;
  b.coordinateAt(1).rest_value = kWrist0;
  b.coordinateAt(0).default_value = kElbow0;
  b.coordinateAt(1).default_value = kWrist0;
  for (int f = 0; f < 4; ++f) {
    b.coordinateAt(handCoordinate(f, 0)).default_value = kMcp0;
    b.coordinateAt(handCoordinate(f, 1)).default_value = 0.08 * (f - 1.5);
    b.coordinateAt(handCoordinate(f, 2)).default_value = kPip0;
    b.coordinateAt(handCoordinate(f, 3)).default_value = 0.5 * kPip0;
  }
  return b.finalize();
}

HandResult runHand(const HandOptions& opt) {
  if (!(opt.dt > 0) || !(opt.duration > 0) || !(opt.frame_interval >= opt.dt))
    throw std::invalid_argument("hand: need dt > 0, duration > 0 and frame_interval >= dt");
  const Model m = handModel();
  System sys(m);
  // DIP = 0.5 PIP: hyper-reduced coordinates [D Sec. 4.6.2, Sec. 6.1.3]
  auto map = std::make_shared<CoordinateMap>(m);
  for (int f = 0; f < 4; ++f)
    map->addDependent(handCoordinate(f, 3), {handCoordinate(f, 2)}, makeLinearFunction({0.5}));
  sys.setCoordinateMap(map);
  // the elbow prescribed in reduced coordinates [D Eq. 4.109]
  const double A = opt.elbow_amplitude, we = kTwoPi * opt.elbow_frequency;
  sys.addConstraint(std::make_shared<PrescribedCoordinate>(
      m, 0,
      makeConstraintFunction1([=](double t) { return kElbow0 + A * std::sin(we * t); },
                              [=](double t) { return A * we * std::cos(we * t); },
                              [=](double t) { return -A * we * we * std::sin(we * t); }),
      "prescribed_elbow"));
  // fingertips prescribed in maximal coordinates: small circles from where they start
  State s_r;
  s_r.q = m.defaultQ();
  s_r.qdot = VecX::Zero(m.nr());
  std::vector<Mat4> E;
  calcBodyPoses(m, s_r.q, E);
  const Vec3 tip_local(kPhalanx[2], 0, 0);
  const double r = opt.tip_radius, wt = kTwoPi * opt.tip_frequency;
  for (int f = 0; f < 4; ++f) {
    const Vec3 x0 = transformPoint(E[handBody(f, 2)], tip_local);
    const double ph = 0.5 * std::numbers::pi * f;
    sys.addConstraint(std::make_shared<PrescribedPoint>(
        m, handBody(f, 2), tip_local,
        [=](double t) {
          const double c = std::cos(wt * t + ph), s = std::sin(wt * t + ph);
          PointSample p;
          p.x = x0 + r * Vec3(c - std::cos(ph), s - std::sin(ph), 0);
          p.v = r * wt * Vec3(-s, c, 0);
          p.a = -r * wt * wt * Vec3(c, s, 0);
          return p;
        },
        "prescribed_tip_" + std::to_string(f + 2)));
  }
  HandResult res;
  res.nr = m.nr();
  res.nR = sys.ndof();
  res.rows = sys.numConstraintRows();
  DynamicsWorkspace ws(sys);
  State s = sys.reduceState(s_r);
  s.z = sys.defaultState().z;
  sys.projectVelocities(s, ws);  // start on the prescribed velocities

  IntegratorOptions io;
  io.dt = opt.dt;
  auto integ = makeIntegrator(opt.integrator, io);
  // errors of the elbow row and the largest tip error at s (after calcConstraints)
  auto errors = [&](const State& st, double& point, double& angle) {
    sys.calcMassAndForce(st, ws);
    sys.calcConstraints(st, ws);
    angle = std::max(angle, std::abs(ws.pos_err[0]));
    for (int f = 0; f < 4; ++f) point = std::max(point, ws.pos_err.segment<3>(1 + 3 * f).norm());
  };
  // output: expanded coordinates, the elbow torque and the tip forces (the multipliers)
  for (const auto& c : m.coordinates()) res.run.columns.push_back(c.name);
  res.run.columns.push_back("elbow_torque");
  for (int f = 0; f < 4; ++f)
    for (char c : {'x', 'y', 'z'}) res.run.columns.push_back("tip_force_" + std::to_string(f + 2) + "_" + c);
  res.run.lines.push_back({0, 1});
  for (int f = 0; f < 4; ++f) {
    const int o = 2 + 4 * f;
    res.run.lines.push_back({1, o});
    for (int k = 0; k < 3; ++k) res.run.lines.push_back({o + k, o + k + 1});
  }
  auto record = [&](const State& st) {
    sys.forwardDynamics(st, ws);
    const State x = sys.expandState(st);
    VecX row(m.nr() + 13);
    row << x.q, ws.lambda;
    res.max_elbow_torque = std::max(res.max_elbow_torque, std::abs(ws.lambda[0]));
    for (int f = 0; f < 4; ++f) res.max_tip_force = std::max(res.max_tip_force, ws.lambda.segment<3>(1 + 3 * f).norm());
    for (int f = 0; f < 4; ++f)
      res.coupling_deviation =
          std::max(res.coupling_deviation, std::abs(x.q[handCoordinate(f, 3)] - 0.5 * x.q[handCoordinate(f, 2)]));
    res.run.t.push_back(st.t);
    res.run.rows.push_back(row);
    std::vector<Mat4> Ew;
    calcBodyPoses(m, x.q, Ew);
    std::vector<Vec3> pts{Vec3::Zero(), transformPoint(Ew[0], Vec3(kForearm, 0, 0))};
    for (int f = 0; f < 4; ++f) {
      pts.push_back(transformPoint(Ew[1], Vec3(kPalm, 0, kFingerZ[f])));
      for (int p = 0; p < 3; ++p) pts.push_back(transformPoint(Ew[handBody(f, p)], Vec3(kPhalanx[p], 0, 0)));
    }
    res.run.points.push_back(pts);
  };
  errors(s, res.point_error, res.angle_error);
  record(s);
  const int steps = static_cast<int>(std::llround(opt.duration / opt.dt));
  const int every = std::max(1, static_cast<int>(std::llround(opt.frame_interval / opt.dt)));
  for (int k = 1; k <= steps; ++k) {
    integ->advance(sys, s, k * opt.dt);
    errors(s, res.point_step_error, res.angle_step_error);
    if (opt.project) {
      sys.projectPositions(s, ws, 1e-14);
      sys.projectVelocities(s, ws);
    }
    errors(s, res.point_error, res.angle_error);
    if (k % every == 0) record(s);
  }
  return res;
}

TetMesh makeStarTetMesh(int arms, double r_in, double r_out, double thickness, int angles, int rings, int layers) {
  if (arms < 1 || angles < 3 || rings < 1 || layers < 1 || !(r_in > 0) || !(r_out > r_in) || !(thickness > 0))
    throw std::invalid_argument("star mesh: bad parameters");
  TetMesh mesh;
  // one layer: the centre, then ring i (1..rings) at angle j: index 1 + (i - 1) angles + j
  const int per_layer = 1 + rings * angles;
  for (int l = 0; l <= layers; ++l) {
    const double y = thickness * (static_cast<double>(l) / layers - 0.5);
    mesh.nodes.emplace_back(0, y, 0);
    for (int i = 1; i <= rings; ++i)
      for (int j = 0; j < angles; ++j) {
        const double a = kTwoPi * j / angles, c = (1 + std::cos(arms * a)) / 2;
        const double R = (r_in + (r_out - r_in) * c * c) * i / rings;
        mesh.nodes.emplace_back(R * std::cos(a), y, R * std::sin(a));
      }
  }
  auto id = [&](int i, int j) { return i == 0 ? 0 : 1 + (i - 1) * angles + (j % angles); };
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j < angles; ++j) tris.push_back({id(0, 0), id(1, j), id(1, j + 1)});
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < angles; ++j) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (int l = 0; l < layers; ++l)
    for (auto t : tris) {
      std::sort(t.begin(), t.end());
      const int a = t[0] + l * per_layer, b = t[1] + l * per_layer, c = t[2] + l * per_layer;
      const int A = a + per_layer, B = b + per_layer, C = c + per_layer;
      // each quad face is cut from its smallest-index corner (a bottom one), so neighbours agree
      for (std::array<int, 4> tet : {std::array<int, 4>{a, b, c, C}, {a, b, B, C}, {a, A, B, C}}) {
        if (tetVolume(mesh.nodes, tet) < 0) std::swap(tet[2], tet[3]);
        mesh.tets.push_back(tet);
      }
    }
  return mesh;
}

StarfishResult runStarfish(const StarfishOptions& opt) {
  if (!(opt.dt > 0) || !(opt.duration > 0) || !(opt.frame_interval >= opt.dt))
    throw std::invalid_argument("starfish: need dt > 0, duration > 0 and frame_interval >= dt");
  constexpr int kArms = 5, kLinks = 4;
  constexpr double kDisc = 0.05, kLink = 0.1;
  // skeleton: a disc on a free joint, and per arm a chain of hinges about the horizontal normal
  // of the arm (the arm curls up and down), the first at the rim of the disc
  ModelBuilder b("starfish");
  b.setGravity(Vec3(0, -9.81, 0));
  const double md = opt.disc_mass, hd = 0.02;
  const Mat3 Id = Vec3(md * (3 * kDisc * kDisc + hd * hd) / 12, md * kDisc * kDisc / 2,
                       md * (3 * kDisc * kDisc + hd * hd) / 12).asDiagonal();
  const int disc = b.addBody("disc", md, Vec3::Zero(), Id, -1, "disc", Free3D{});
  b.setCoordinateNames(disc, {"disc_x", "disc_y", "disc_z", "disc_rx", "disc_ry", "disc_rz"});
  constexpr int kFree = 6;  // the disc's coordinates come first: translation, then rotation
  std::vector<Vec3> dir(kArms);
  for (int a = 0; a < kArms; ++a) {
    const double phi = kTwoPi * a / kArms;
    dir[a] = Vec3(std::cos(phi), 0, std::sin(phi));
    // local x along the arm, local z = (-sin phi, 0, cos phi)
    const Mat3 R = Eigen::AngleAxisd(-phi, Vec3::UnitY()).toRotationMatrix();
    const auto [c, I] = rod(opt.link_mass, kLink, 0.01);
    int parent = disc;
    for (int k = 0; k < kLinks; ++k) {
      const std::string n = "arm" + std::to_string(a) + "_" + std::to_string(k);
      const Mat4 E_pf = k == 0 ? makeE(R, kDisc * dir[a]) : makeTranslation(Vec3(kLink, 0, 0));
      parent = b.addBody(n, opt.link_mass, c, I, parent, n, Revolute{Vec3::UnitZ()}, E_pf);
      b.setCoordinateNames(parent, {n});
    }
  }
  const Model m = b.finalize();
  System sys(m);
  // the mesh: disc nodes on the disc, nodes within 0.035 m of a link attached to it
  const TetMesh mesh = makeStarTetMesh(kArms, kDisc, kDisc + kLinks * kLink);
  DeformableBody body = makeFemBody(mesh, opt.E, opt.nu, opt.rho);
  body.rayleigh_mass = opt.rayleigh_mass;
  body.rayleigh_stiffness = opt.rayleigh_stiffness;
  std::vector<NodeAttachment> att;
  for (int n = 0; n < mesh.numNodes(); ++n) {
    const Vec3& x = mesh.nodes[n];
    if (Vec3(x.x(), 0, x.z()).norm() < kDisc - 1e-12) {
      att.push_back({n, disc});
      continue;
    }
    for (int a = 0; a < kArms; ++a) {
      const double s = x.dot(dir[a]), d = (x - s * dir[a]).norm();
      const int k = static_cast<int>(std::floor((s - kDisc) / kLink));
      if (d < 0.035 && s >= kDisc && k >= 0) {
        att.push_back({n, 1 + a * kLinks + std::min(k, kLinks - 1)});
        break;
      }
    }
  }
  auto term = addDeformableBody(sys, body, att);
  // the first joint of every arm prescribed
  const double A = opt.amplitude, w = kTwoPi * opt.frequency;
  std::vector<std::shared_ptr<const PrescribedCoordinate>> pres;
  for (int a = 0; a < kArms; ++a) {
    const double ph = kTwoPi * a / kArms;
    auto c = std::make_shared<PrescribedCoordinate>(
        m, kFree + a * kLinks,
        makeConstraintFunction1([=](double t) { return A * std::sin(w * t + ph) - A * std::sin(ph); },
                                [=](double t) { return A * w * std::cos(w * t + ph); },
                                [=](double t) { return -A * w * w * std::sin(w * t + ph); }));
    pres.push_back(c);
    sys.addConstraint(c);
  }
  // the disc's centre prescribed in maximal coordinates: it bobs up and down; its orientation
  // stays passive
  const double B = opt.disc_amplitude, wd = kTwoPi * opt.disc_frequency;
  auto disc_path = [=](double t) {
    PointSample p;
    p.x = Vec3(0, B * std::sin(wd * t), 0);
    p.v = Vec3(0, B * wd * std::cos(wd * t), 0);
    p.a = Vec3(0, -B * wd * wd * std::sin(wd * t), 0);
    return p;
  };
  sys.addConstraint(std::make_shared<PrescribedPoint>(m, disc, Vec3::Zero(), disc_path, "prescribed_disc"));
  StarfishResult res;
  res.joints = m.nr() - kFree;
  res.prescribed = kArms;
  res.nodes = mesh.numNodes();
  res.attached = static_cast<int>(att.size());
  res.tets = mesh.numTets();
  res.ndof = sys.ndof();
  DynamicsWorkspace ws(sys);
  State s = sys.defaultState();
  term->setRestState(s);
  sys.projectVelocities(s, ws);  // start on the prescribed velocities

  IntegratorOptions io;
  io.dt = opt.dt;
  auto integ = makeIntegrator(opt.integrator, io);
  SkeletonWorkspace sk(m);
  std::vector<double> V0(mesh.numTets());
  for (int e = 0; e < mesh.numTets(); ++e) V0[e] = tetVolume(mesh.nodes, mesh.tets[e]);
  res.min_volume_ratio = 1.0;
  for (const auto& c : m.coordinates()) res.run.columns.push_back(c.name);
  for (const char* c : {"kinetic_energy", "potential_energy"}) res.run.columns.push_back(c);
  for (int a = 0; a < kArms; ++a) res.run.columns.push_back("torque_arm" + std::to_string(a) + "_0");
  for (const char* c : {"disc_force_x", "disc_force_y", "disc_force_z"}) res.run.columns.push_back(c);
  res.run.mesh = mesh;
  auto record = [&] {
    const double T = sys.kineticEnergy(s, ws), V = sys.potentialEnergy(s, ws);
    // the prescribed joints' torques and the disc's force: the multipliers of the
    // acceleration-level KKT solve
    sys.forwardDynamics(s, ws);
    VecX row(m.nr() + 2 + kArms + 3);
    row << s.q.head(m.nr()), T, V, ws.lambda;
    res.max_torque = std::max(res.max_torque, ws.lambda.head(kArms).lpNorm<Eigen::Infinity>());
    res.max_disc_force = std::max(res.max_disc_force, ws.lambda.tail<3>().norm());
    res.run.t.push_back(s.t);
    res.run.rows.push_back(row);
    calcKinematics(m, s, sk);
    const VecX x = term->nodePositions(m, s, TermContext(sk));
    std::vector<Vec3> pts(mesh.numNodes());
    for (int n = 0; n < mesh.numNodes(); ++n) pts[n] = x.segment<3>(3 * n);
    for (int e = 0; e < mesh.numTets(); ++e)
      res.min_volume_ratio = std::min(res.min_volume_ratio, tetVolume(pts, mesh.tets[e]) / V0[e]);
    res.run.points.push_back(std::move(pts));
    res.max_kinetic = std::max(res.max_kinetic, T);
    res.final_kinetic = T;
  };
  record();
  res.steps = static_cast<int>(std::llround(opt.duration / opt.dt));
  const int every = std::max(1, static_cast<int>(std::llround(opt.frame_interval / opt.dt)));
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 1; k <= res.steps; ++k) {
    integ->advance(sys, s, k * opt.dt);
    if (!s.q.allFinite() || !s.qdot.allFinite())
      throw std::runtime_error("starfish: non-finite state at t = " + std::to_string(s.t) + " s");
    for (const auto& c : pres)
      res.prescribed_error = std::max(res.prescribed_error, std::abs(s.q[c->coordinate()] - c->position(s.t)));
    // the disc's origin is its translation coordinates (free joint, translation first, in the world)
    res.point_error = std::max(res.point_error, (s.q.head<3>() - disc_path(s.t).x).norm());
    if (k % every == 0) record();
  }
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

std::vector<std::string> hybridSceneNames() { return {"hand", "starfish"}; }

void runHybridScene(const std::string& name, const std::string& out_dir, std::ostream& summary) {
  namespace fs = std::filesystem;
  const fs::path dir(out_dir);
  HybridRun run;
  summary << std::setprecision(6);
  if (name == "hand") {
    HandOptions opt;
    HandResult r = runHand(opt);
    summary << "hand: " << r.nr << " joint coordinates, " << r.nR << " after DIP = 0.5 PIP (hyper-reduced), "
            << r.rows << " prescribed rows (elbow, 4 fingertips x 3), integrator " << opt.integrator << ", dt "
            << opt.dt << " s, " << opt.duration << " s, positions and velocities projected every step\n";
    summary << "largest prescribed-point error " << r.point_error << " m (" << r.point_step_error
            << " m within a step, before its projection)\n";
    summary << "largest prescribed-angle error " << r.angle_error << " rad (" << r.angle_step_error
            << " rad within a step, before its projection)\n";
    summary << "largest DIP - 0.5 PIP deviation " << r.coupling_deviation << " rad\n";
    summary << "largest elbow torque " << r.max_elbow_torque << " N m, largest fingertip force " << r.max_tip_force
            << " N\n";
    run = std::move(r.run);
  } else if (name == "starfish") {
    StarfishOptions opt;
    StarfishResult r = runStarfish(opt);
    summary << "starfish: disc on a free joint, its centre prescribed; " << r.joints << " joints (" << r.prescribed
            << " prescribed, the rest passive), mesh of "
            << r.nodes << " nodes (" << r.attached << " attached to the disc and the links) and " << r.tets
            << " tets, " << r.ndof << " coordinates, E " << opt.E << " Pa, integrator " << opt.integrator << ", dt "
            << opt.dt << " s\n";
    summary << "steps " << r.steps << ", wall time " << r.wall_seconds << " s\n";
    summary << "largest prescribed-joint error " << r.prescribed_error << " rad, largest prescribed-joint torque "
            << r.max_torque << " N m\n";
    summary << "largest prescribed-point error " << r.point_error << " m (disc centre), largest force on it "
            << r.max_disc_force << " N\n";
    summary << "kinetic energy largest " << r.max_kinetic << " J, final " << r.final_kinetic
            << " J; smallest tet volume / rest volume " << r.min_volume_ratio << "\n";
    run = std::move(r.run);
  } else {
    throw std::invalid_argument("unknown hybrid scene '" + name + "'");
  }
  fs::create_directories(dir);
  std::vector<std::string> columns{"time"};
  columns.insert(columns.end(), run.columns.begin(), run.columns.end());
  std::vector<VecX> rows;
  for (size_t k = 0; k < run.t.size(); ++k) {
    VecX row(run.rows[k].size() + 1);
    row << run.t[k], run.rows[k];
    rows.push_back(row);
  }
  writeCsv(dir / "states.csv", columns, rows);
  writeSeries(dir, name, run.mesh, run.lines, run.t, run.points);
}

}  // namespace redmax::scenes
