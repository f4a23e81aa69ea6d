#include "validation/scenes/deformable_scenes.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "core/deformable/deformable_term.hpp"
#include "core/dynamics/controller.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/muscles/hill/factory.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/integrators/integrator.hpp"
#include "validation/scenes/scene_io.hpp"

namespace redmax::scenes {

namespace {

std::vector<Vec3> toPoints(const VecX& x) {
  std::vector<Vec3> p(x.size() / 3);
  for (size_t n = 0; n < p.size(); ++n) p[n] = x.segment<3>(3 * n);
  return p;
}

// simulate sys from s, recording every frame_interval; the term's node positions per frame
DeformableRun simulate(const System& sys, State s, const DeformableTerm& term, const std::string& integrator,
                       double dt, double tolerance, double duration, double frame_interval) {
  DeformableRun run;
  IntegratorOptions io;
  io.dt = dt;
  io.rtol = tolerance;
  io.atol = 1e-2 * tolerance;
  auto integ = makeIntegrator(integrator, io);
  DynamicsWorkspace ws(sys);
  SkeletonWorkspace sk(sys.model());
  const int frames = static_cast<int>(std::llround(duration / frame_interval));
  for (int k = 0; k <= frames; ++k) {
    if (k > 0) integ->advance(sys, s, k * frame_interval);
    run.t.push_back(s.t);
    run.q.push_back(s.q);
    run.energy.push_back(sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws));
    calcKinematics(sys.model(), s, sk);
    run.nodes.push_back(toPoints(term.nodePositions(sys.model(), s, TermContext(sk))));
  }
  for (int i = 0; i < sys.model().nr(); ++i) run.coordinates.push_back(sys.model().coordinates()[i].name);
  // a free node's coordinates are its world position: node<n>_x, _y, _z
  run.coordinates.resize(sys.ndof());
  for (size_t n = 0; n < term.nodes().size(); ++n)
    if (term.nodes()[n].kind == NodeBinding::Kind::Free)
      for (int c = 0; c < 3; ++c)
        run.coordinates[term.nodes()[n].index + c] = "node" + std::to_string(n) + "_" + "xyz"[c];
  return run;
}

void writeStates(const std::filesystem::path& path, const DeformableRun& run) {
  std::vector<std::string> columns{"time"};
  columns.insert(columns.end(), run.coordinates.begin(), run.coordinates.end());
  columns.push_back("energy");
  std::vector<VecX> rows;
  for (size_t k = 0; k < run.t.size(); ++k) {
    VecX r(run.q[k].size() + 2);
    r << run.t[k], run.q[k], run.energy[k];
    rows.push_back(r);
  }
  writeCsv(path, columns, rows);
}

}  // namespace

CantileverResult solveCantilever(const CantileverOptions& opt) {
  if (opt.refinement < 1) throw std::invalid_argument("cantilever: refinement must be >= 1");
  const int k = opt.refinement;
  CantileverResult r;
  r.mesh = makeBoxTetMesh(Vec3(opt.length, opt.width, opt.width), 10 * k, k, k,
                          Vec3(0, -opt.width / 2, -opt.width / 2), opt.split);
  const DeformableBody body = makeFemBody(r.mesh, opt.E, opt.nu, opt.rho);
  NodeSpaceProblem p;
  p.body = &body;
  p.gravity = Vec3(0, -opt.g, 0);
  p.fixed.assign(body.numNodes(), 0);
  for (int n = 0; n < body.numNodes(); ++n) p.fixed[n] = r.mesh.nodes[n].x() < 1e-12 * opt.length;
  r.x = restPositions(body);
  r.solve = solveStatic(p, r.x, 1e-9 * opt.rho * opt.g * std::pow(opt.width, 3));
  if (!r.solve.converged) throw std::runtime_error("cantilever: Newton did not converge");
  int tip = 0;
  for (int n = 0; n < body.numNodes(); ++n)
    if (r.mesh.nodes[n].x() > opt.length * (1 - 1e-12)) {
      r.tip_deflection += r.mesh.nodes[n].y() - r.x[3 * n + 1];
      ++tip;
    }
  r.tip_deflection /= tip;
  const double A = opt.width * opt.width, I = std::pow(opt.width, 4) / 12.0;
  r.beam_theory = opt.rho * opt.g * A * std::pow(opt.length, 4) / (8.0 * opt.E * I);
  return r;
}

Model singlePendulum() {
  ModelBuilder b("single_pendulum");
  b.setGravity(Vec3(0, -9.81, 0));
  const double m = 1.0, L = 1.0;
  // a thin uniform rod along -y (a small inertia about its axis keeps the body inertia regular)
  const Mat3 I = Vec3(m * L * L / 12, 1e-4, m * L * L / 12).asDiagonal();
  const int b1 = b.addBody("link", m, Vec3(0, -L / 2, 0), I, -1, "pin", Revolute{Vec3::UnitZ()});
  b.setCoordinateNames(b1, {"q"});
  return b.finalize();
}

DeformableRun runStrand(const StrandOptions& opt) {
  if (opt.segments < 1) throw std::invalid_argument("strand: segments must be >= 1");
  std::vector<Vec3> pts;
  for (int i = 0; i <= opt.segments; ++i) pts.emplace_back(opt.length * i / opt.segments, 0, 0);
  // the strand alone: a model without bodies, gravity -9.81 y
  ModelBuilder mb("strand");
  mb.setGravity(Vec3(0, -9.81, 0));
  System sys(mb.finalize());
  auto term = addDeformableBody(sys, makeStrand(pts, opt.mass, opt.stiffness), {{0, -1}});
  State s = sys.defaultState();
  term->setRestState(s);
  DeformableRun run = simulate(sys, s, *term, opt.integrator, opt.dt, opt.tolerance, opt.duration, opt.frame_interval);
  run.mesh.nodes = pts;
  for (int i = 0; i < opt.segments; ++i) run.lines.push_back({i, i + 1});
  return run;
}

namespace {

// singlePendulum()'s link with a soft block (0.2 x 0.1 x 0.1 m, 2k x k x k cubes) on its tip, its
// top face attached (every node when `rigid`): the soft-pendulum and soft-insertion scenes
std::shared_ptr<const DeformableTerm> addBlockOnLink(System& sys, int k, double E, double nu, double rho,
                                                     double rayleigh_mass, double rayleigh_stiffness, bool rigid,
                                                     TetMesh& mesh) {
  mesh = makeBoxTetMesh(Vec3(0.2, 0.1, 0.1), 2 * k, k, k, Vec3(-0.1, -1.1, -0.05));
  DeformableBody body = makeFemBody(mesh, E, nu, rho);
  body.rayleigh_mass = rayleigh_mass;
  body.rayleigh_stiffness = rayleigh_stiffness;
  std::vector<NodeAttachment> att;
  for (int n = 0; n < mesh.numNodes(); ++n)
    if (rigid || mesh.nodes[n].y() > -1.0 - 1e-12) att.push_back({n, 0});
  return addDeformableBody(sys, body, att);
}

}  // namespace

DeformableRun runSoftPendulum(const SoftPendulumOptions& opt) {
  if (opt.refinement < 1) throw std::invalid_argument("soft-pendulum: refinement must be >= 1");
  System sys(singlePendulum());
  TetMesh mesh;
  auto term = addBlockOnLink(sys, opt.refinement, opt.E, opt.nu, opt.rho, opt.rayleigh_mass, opt.rayleigh_stiffness,
                             opt.rigid, mesh);
  State s = sys.defaultState();
  s.q[0] = opt.q0;
  term->setRestState(sys.model(), s, 0);
  DeformableRun run = simulate(sys, s, *term, opt.integrator, opt.dt, opt.tolerance, opt.duration, opt.frame_interval);
  run.mesh = mesh;
  return run;
}

SoftInsertionRun runSoftInsertion(const SoftInsertionOptions& opt) {
  if (opt.refinement < 1) throw std::invalid_argument("soft-insertion: refinement must be >= 1");
  System sys(singlePendulum());
  const Model& model = sys.model();
  TetMesh mesh;
  auto term = addBlockOnLink(sys, opt.refinement, opt.E, opt.nu, opt.rho, opt.rayleigh_mass, opt.rayleigh_stiffness,
                             opt.rigid, mesh);
  SoftInsertionRun out;
  for (int n = 0; n < mesh.numNodes(); ++n)
    if ((mesh.nodes[n] - Vec3(0.1, -1.1, -0.05)).norm() < 1e-12) out.insertion_node = n;
  if (out.insertion_node < 0) throw std::logic_error("soft-insertion: no node at the insertion");
  // the muscle: from a world point up and to the side to the block's far bottom edge
  Muscle mu;
  mu.name = "soft_flexor";
  mu.path.points = {makeFixedPoint(-1, Vec3(0.4, -0.3, 0.0), "origin"),
                    musclePointAtNode(*term, out.insertion_node, "insertion")};
  mu.optimal_fiber_length = opt.optimal_fiber_length;
  mu.tendon_slack_length = opt.tendon_slack_length;
  MassPointOptions mpo;
  mpo.count = opt.mass_points;
  mu.mass_points = makeMassPoints(opt.muscle_mass, opt.optimal_fiber_length, opt.tendon_slack_length, mpo);
  hill::MuscleParameters par;
  par.name = mu.name;
  par.set("max_isometric_force", opt.max_isometric_force);
  par.set("optimal_fiber_length", opt.optimal_fiber_length);
  par.set("tendon_slack_length", opt.tendon_slack_length);
  par.set("pennation_angle_at_optimal", 0.0);
  const auto hill_model = hill::makeMuscleModel("Thelen2003Muscle", par);
  sys.addTerm(std::make_shared<MuscleTerm>(model, std::vector<Muscle>{mu}));
  auto force = std::make_shared<MuscleForceTerm>(model, std::vector<Muscle>{mu},
                                                 std::vector<std::shared_ptr<const hill::MuscleModel>>{hill_model});
  sys.addTerm(force);
  const int force_term = static_cast<int>(sys.terms().size()) - 1;
  sys.addController(std::make_shared<PrescribedControls>(
      "excitation", std::vector<PrescribedControls::Entry>{{0, std::make_shared<ConstantFunction>(opt.excitation, 1)}}));

  State s = sys.defaultState();
  term->setRestState(model, s, 0);
  DynamicsWorkspace ws(sys);
  sys.equilibrateStates(s, ws);
  IntegratorOptions io;
  io.dt = opt.dt;
  io.rtol = opt.tolerance;
  io.atol = 1e-2 * opt.tolerance;
  auto integ = makeIntegrator(opt.integrator, io);
  SkeletonWorkspace sk(model);
  DeformableRun& run = out.run;
  const Vec3 X_ins = mesh.nodes[out.insertion_node];
  const int frames = static_cast<int>(std::llround(opt.duration / opt.frame_interval));
  for (int f = 0; f <= frames; ++f) {
    if (f > 0) integ->advance(sys, s, f * opt.frame_interval);
    run.t.push_back(s.t);
    run.q.push_back(s.q);
    run.energy.push_back(sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws));
    calcKinematics(model, s, sk);
    const VecX x = term->nodePositions(model, s, TermContext(sk));
    run.nodes.push_back(toPoints(x));
    // where the link would carry the insertion node from its rest position (the link's pose at
    // the default configuration is the identity)
    const Vec3 carried = transformPoint(sk.E_wi[0], X_ins);
    out.insertion_offset.push_back((x.segment<3>(3 * out.insertion_node) - carried).norm());
    TermContext ctx(sk, nullptr, 0);  // (the tendon force follows the states, not the excitation)
    ctx.z_offset = sys.stateOffset(force_term);
    out.tendon_force.push_back(force->calcOutput(model, s, ctx, 0).tendon_force);
  }
  run.mesh = mesh;
  for (int i = 0; i < model.nr(); ++i) run.coordinates.push_back(model.coordinates()[i].name);
  run.coordinates.resize(sys.ndof());
  for (size_t n = 0; n < term->nodes().size(); ++n)
    if (term->nodes()[n].kind == NodeBinding::Kind::Free)
      for (int c = 0; c < 3; ++c) run.coordinates[term->nodes()[n].index + c] = "node" + std::to_string(n) + "_" + "xyz"[c];
  return out;
}

std::vector<std::string> deformableSceneNames() { return {"cantilever", "strand", "soft-pendulum", "soft-insertion"}; }

void runDeformableScene(const std::string& name, const std::string& out_dir, std::ostream& summary) {
  namespace fs = std::filesystem;
  bool known = false;
  for (const auto& n : deformableSceneNames()) known = known || n == name;
  if (!known)
    throw std::invalid_argument("unknown scene '" + name + "' (expected cantilever, strand, soft-pendulum or soft-insertion)");
  const fs::path dir(out_dir);
  fs::create_directories(dir);
  summary << std::setprecision(6);
  if (name == "cantilever") {
    CantileverOptions opt;
    const CantileverResult r = solveCantilever(opt);
    DeformableRun run;
    run.mesh = r.mesh;
    run.t = {0.0, 1.0};  // load factor: unloaded, loaded
    run.nodes = {r.mesh.nodes, toPoints(r.x)};
    writeSeries(dir, name, run.mesh, run.lines, run.t, run.nodes);
    std::ostringstream o;
    o << std::setprecision(17) << "node,X,Y,Z,ux,uy,uz\n";
    for (int n = 0; n < r.mesh.numNodes(); ++n) {
      const Vec3 X = r.mesh.nodes[n], u = r.x.segment<3>(3 * n) - X;
      o << n << ',' << X[0] << ',' << X[1] << ',' << X[2] << ',' << u[0] << ',' << u[1] << ',' << u[2] << '\n';
    }
    writeAtomically((dir / "states.csv").string(), o.str());
    summary << "cantilever: " << opt.length << " x " << opt.width << " x " << opt.width << " m, E " << opt.E
            << " Pa, nu " << opt.nu << ", rho " << opt.rho << " kg/m^3, " << r.mesh.numNodes() << " nodes, "
            << r.mesh.numTets() << " tets, Newton " << r.solve.iterations << " iterations\n";
    summary << "tip deflection " << r.tip_deflection << " m, beam theory " << r.beam_theory << " m\n";
    return;
  }
  DeformableRun run;
  if (name == "strand") {
    StrandOptions opt;
    run = runStrand(opt);
    double worst = 0;
    for (double e : run.energy) worst = std::max(worst, std::abs(e - run.energy.front()));
    summary << "strand: " << opt.segments << " springs, " << opt.mass << " kg, stiffness " << opt.stiffness
            << " J, integrator " << opt.integrator << ", dt " << opt.dt << " s, " << opt.duration << " s\n";
    summary << "energy " << run.energy.front() << " J at t = 0, " << run.energy.back() << " J at t = " << run.t.back()
            << " s, largest change " << worst << " J\n";
  } else if (name == "soft-insertion") {
    SoftInsertionOptions opt;
    const SoftInsertionRun soft = runSoftInsertion(opt);
    SoftInsertionOptions rigid = opt;
    rigid.rigid = true;
    const SoftInsertionRun ref = runSoftInsertion(rigid);
    run = soft.run;
    double worst = 0, offset = 0, peak = 0, peak_rigid = 0;
    for (size_t k = 0; k < run.t.size(); ++k) {
      worst = std::max(worst, std::abs(run.q[k][0] - ref.run.q[k][0]));
      offset = std::max(offset, soft.insertion_offset[k]);
      peak = std::max(peak, soft.tendon_force[k]);
      peak_rigid = std::max(peak_rigid, ref.tendon_force[k]);
    }
    summary << "soft-insertion: Thelen2003 muscle (" << opt.max_isometric_force << " N, " << opt.muscle_mass
            << " kg on " << opt.mass_points << " mass points) inserting on node " << soft.insertion_node << " of a soft block of "
            << run.mesh.numNodes() << " nodes, E " << opt.E << " Pa, excitation " << opt.excitation << ", integrator "
            << opt.integrator << ", dt " << opt.dt << " s, " << opt.duration << " s\n";
    summary << "link angle " << run.q.back()[0] << " rad at t = " << run.t.back() << " s, rigid insertion "
            << ref.run.q.back()[0] << " rad, largest difference " << worst << " rad\n";
    summary << "largest tendon force " << peak << " N (rigid insertion " << peak_rigid
            << " N), largest insertion displacement from the link's carry " << offset << " m\n";
  } else {
    SoftPendulumOptions opt;
    run = runSoftPendulum(opt);
    SoftPendulumOptions rigid = opt;
    rigid.rigid = true;
    const DeformableRun ref = runSoftPendulum(rigid);
    double worst = 0;
    for (size_t k = 0; k < run.t.size(); ++k) worst = std::max(worst, std::abs(run.q[k][0] - ref.q[k][0]));
    summary << "soft-pendulum: block of " << run.mesh.numNodes() << " nodes, E " << opt.E << " Pa, integrator "
            << opt.integrator << ", dt " << opt.dt << " s, " << opt.duration << " s\n";
    summary << "link angle " << run.q.back()[0] << " rad at t = " << run.t.back() << " s, rigid block "
            << ref.q.back()[0] << " rad, largest difference " << worst << " rad\n";
  }
  writeStates(dir / "states.csv", run);
  writeSeries(dir, name, run.mesh, run.lines, run.t, run.nodes);
}

}  // namespace redmax::scenes
