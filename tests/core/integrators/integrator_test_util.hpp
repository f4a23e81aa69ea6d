#pragma once
// Scenes and helpers shared by the integrator tests.
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/integrators/integrator.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax::testing_util {

inline const std::vector<std::string>& allIntegrators() {
  static const std::vector<std::string> names{"euler", "bdf1", "sdirk2", "rk45", "cvode"};
  return names;
}

/// rod of length L and radius 0.14 hanging along -y from its joint (a thick limb: the spin about
/// its axis is not much faster than the swing)
inline void rod(double m, double L, Vec3& com, Mat3& I) {
  com = Vec3(0.02, -0.5 * L, 0.01);  // slightly off-axis: general spatial inertia about the origin
  const double r2 = 0.14 * 0.14;
  I = Mat3::Zero();
  I(0, 0) = I(2, 2) = m * (L * L / 12.0 + r2 / 4.0);
  I(1, 1) = 0.5 * m * r2;
  I(0, 1) = I(1, 0) = 0.001 * m * L * L;
}

/// Conservative 5-link chain in 3D with mixed joints (10 coordinates): revolute z, universal,
/// prismatic along the link (sprung), spherical with XYZ Euler angles (its middle angle sprung,
/// which keeps it far from gimbal lock at this energy), spherical in exponential coordinates
/// (chart switches), under gravity. `k_stiff` > 0 gives the first hinge a spring of that
/// stiffness (a stiff system).
inline Model mixedChain(double k_stiff = 0.0) {
  ModelBuilder b("mixed_chain");
  b.setGravity(Vec3(0.0, -9.81, 0.0));
  const double L = 0.5;
  Vec3 c;
  Mat3 I;
  int parent = -1;
  std::vector<Joint> joints{Revolute{Vec3::UnitZ()}, Universal{}, Prismatic{Vec3::UnitY()},
                            SphericalEuler{}, SphericalExp{}};
  for (int i = 0; i < 5; ++i) {
    rod(1.0 + 0.1 * i, L, c, I);
    const Mat4 E_pf = parent < 0 ? Mat4::Identity() : makeTranslation(Vec3(0, -L, 0));
    parent = b.addBody("link" + std::to_string(i), 1.0 + 0.1 * i, c, I, parent,
                       "joint" + std::to_string(i), joints[i], E_pf);
  }
  Model m = b.finalize();
  m.coordinates[3].stiffness = 300.0;  // the slider stays near its link
  m.coordinates[5].stiffness = 40.0;  // Euler middle angle: 0.5 k (pi/2)^2 > the chain's energy
  if (k_stiff > 0.0) m.coordinates[0].stiffness = k_stiff;
  return m;
}

/// initial state of the chain: bent and moving
inline State chainInitialState(const System& sys) {
  State s = sys.defaultState();
  s.q << 0.6, 0.3, -0.3, 0.05, 0.2, -0.2, 0.3, 0.4, -0.5, 0.3;
  s.qdot << 0.5, -1.0, 0.5, 0.0, 0.7, 0.2, -0.5, 1.0, 0.5, -0.8;
  return s;
}

/// Three bodies on the world (hinge z, sprung slider, sprung hinge x): mixed joints, nonlinear
/// gravity torques, but a constant mass matrix.
inline Model decoupledMixedJoints() {
  ModelBuilder b("decoupled");
  b.setGravity(Vec3(0.0, -9.81, 0.0));
  Vec3 c;
  Mat3 I;
  rod(1.0, 0.5, c, I);
  b.addBody("a", 1.0, c, I, -1, "ja", Revolute{Vec3::UnitZ()});
  b.addBody("b", 1.2, c, I, -1, "jb", Prismatic{Vec3(0.6, 0.8, 0.0)}, makeTranslation(Vec3(1, 0, 0)));
  b.addBody("c", 0.8, c, I, -1, "jc", Revolute{Vec3::UnitX()}, makeTranslation(Vec3(2, 0, 0)));
  Model m = b.finalize();
  m.coordinates[1].stiffness = 100.0;
  m.coordinates[2].stiffness = 3.0;
  return m;
}

inline double totalEnergy(const System& sys, const State& s) {
  DynamicsWorkspace ws(sys.model());
  return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
}

/// double pendulum with joint springs and dampers (so bdf1 differs from euler)
inline Model springDampedPendulum(double k = 5.0, double d = 0.3) {
  Model m = scenes::doublePendulum();
  for (auto& c : m.coordinates) {
    c.stiffness = k;
    c.damping = d;
  }
  return m;
}

/// integrate with `name` from s to t_end in one advance() call
inline State integrate(const std::string& name, const IntegratorOptions& opt, const System& sys,
                       State s, double t_end, IntegratorStats* stats = nullptr) {
  auto integ = makeIntegrator(name, opt);
  integ->advance(sys, s, t_end);
  if (stats) *stats = integ->stats();
  return s;
}

inline VecX stacked(const State& s) {
  VecX y(s.q.size() + s.qdot.size());
  y << s.q, s.qdot;
  return y;
}

/// A ForceTerm from a lambda (tests only): adds fn(t, q, qdot) to f.
class LambdaForce final : public ForceTerm {
 public:
  using Fn = std::function<void(const State&, VecX&)>;
  explicit LambdaForce(Fn fn) : fn_(std::move(fn)) {}
  std::string name() const override { return "lambda_force"; }
  void addForce(const Model&, const State& s, const TermContext&, VecX& f) const override { fn_(s, f); }

 private:
  Fn fn_;
};

/// Reduced-coordinate coupling q[a] - q[b] = 0 [D Eq. 4.103]: G = e_a - e_b, Gdot = 0.
class CouplingConstraint final : public Constraint {
 public:
  CouplingConstraint(int a, int b) : a_(a), b_(b) {}
  std::string name() const override { return "coupling"; }
  int rows() const override { return 1; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override {
    G.setZero();
    G(0, a_) = 1.0;
    G(0, b_) = -1.0;
    rhs.setZero();
  }
  void calcErrors(const Model&, const State& s, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override {
    pos_err[0] = s.q[a_] - s.q[b_];
    vel_err[0] = s.qdot[a_] - s.qdot[b_];
  }

 private:
  int a_, b_;
};

}  // namespace redmax::testing_util
