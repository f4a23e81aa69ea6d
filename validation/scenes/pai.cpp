#include "validation/scenes/pai.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/muscles/path.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::scenes {

namespace {

// thin uniform rod along +x from the joint (a tiny radius keeps the inertia positive definite)
void rodAlongX(double m, double L, Vec3& com, Mat3& I) {
  com = Vec3(0.5 * L, 0, 0);
  I = Mat3::Zero();
  I(1, 1) = I(2, 2) = m * L * L / 12.0;
  I(0, 0) = 1e-6 * m * L * L;
}

// add point masses (positions in the body frame) to a body's mass, COM and inertia about its COM
void addPoints(double& m, Vec3& com, Mat3& I, const std::vector<Vec3>& x, const std::vector<double>& mx) {
  // inertia about the body origin, then back to the new COM (parallel axis)
  auto shift = [](double mass, const Vec3& c) {
    return mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  };
  Mat3 I_o = I + shift(m, com);
  Vec3 mc = m * com;
  double M = m;
  for (std::size_t k = 0; k < x.size(); ++k) {
    I_o += shift(mx[k], x[k]);
    mc += mx[k] * x[k];
    M += mx[k];
  }
  com = mc / M;
  I = I_o - shift(M, com);
  m = M;
}

}  // namespace

PaiScissorsSolution::PaiScissorsSolution(double A, double B, double theta0, double omega0)
    : A_(A), B_(B), theta0_(theta0), omega0_(omega0) {
  if (!(A > 0.0) || !(B >= 0.0) || !(omega0 > 0.0))
    throw std::invalid_argument("PaiScissorsSolution: need A > 0, B >= 0, omega0 > 0");
}

double PaiScissorsSolution::inertia(double theta) const {
  const double s = std::sin(theta);
  return A_ + B_ * s * s;
}

double PaiScissorsSolution::G(double x) const {
  // sqrt(A + B sin^2 s) = sqrt(A + B) sqrt(1 - k^2 sin^2(pi/2 - s)), k^2 = B / (A + B)
  const double k = std::sqrt(B_ / (A_ + B_));
  const double half_pi = 0.5 * std::numbers::pi;
  return std::sqrt(A_ + B_) * (std::ellint_2(k, half_pi) - std::ellint_2(k, half_pi - x));
}

double PaiScissorsSolution::timeAt(double theta) const {
  // energy: J(theta) thetadot^2 = J(theta0) omega0^2, thetadot < 0
  return (G(theta0_) - G(theta)) / (omega0_ * std::sqrt(inertia(theta0_)));
}

double PaiScissorsSolution::angleAt(double t) const {
  // timeAt is strictly decreasing in theta with d t / d theta = -sqrt(J(theta)) / (omega0 sqrt(J0))
  const double c = omega0_ * std::sqrt(inertia(theta0_));
  double theta = theta0_ - omega0_ * t;
  for (int it = 0; it < 50; ++it) {
    const double r = timeAt(theta) - t;
    const double step = r * c / std::sqrt(inertia(theta));
    theta += step;
    if (std::abs(step) <= 1e-15 * (1.0 + std::abs(theta))) break;
  }
  return theta;
}

double PaiScissorsSolution::rateAt(double t) const {
  return -omega0_ * std::sqrt(inertia(theta0_) / inertia(angleAt(t)));
}

void paiScissorsCoefficients(const PaiScissorsParams& p, int N, double& A, double& B) {
  const double L2 = p.bone_length * p.bone_length;
  double s_a = 0.0, s_b = 0.0;
  if (N <= 0) {
    // uniform line density over a in [0, 1]: int (1-2a)^2 = 1/3, int 4 a (1-a) = 2/3
    s_a = p.muscle_mass / 3.0;
    s_b = 2.0 * p.muscle_mass / 3.0;
  } else {
    for (int k = 0; k < N; ++k) {
      const double a = (k + 0.5) / N, m = p.muscle_mass / N;
      s_a += m * (1 - 2 * a) * (1 - 2 * a);
      s_b += 4 * m * a * (1 - a);
    }
  }
  A = 2.0 * p.bone_mass * L2 / 3.0 + L2 * s_a;
  B = L2 * s_b;
}

double paiScissorsOmega0(const PaiScissorsParams& p) {
  double A, B;
  paiScissorsCoefficients(p, 0, A, B);
  // t_zero = G(theta0) / (omega0 sqrt(J(theta0))) is linear in 1 / omega0
  const PaiScissorsSolution unit(A, B, p.theta0, 1.0);
  return unit.zeroTime() / p.t_zero;
}

PaiScissors makePaiScissors(const PaiScissorsParams& p, bool lumped) {
  if (p.mass_points < 1) throw std::invalid_argument("makePaiScissors: mass_points must be >= 1");
  const double L = p.bone_length, omega0 = paiScissorsOmega0(p);
  const MassPoints mp = makeMassPoints(p.muscle_mass, 1.0, 0.0, {p.mass_points, MassPointOptions::Region::WholePath});

  // bone masses; lumped: each point welded where it is at t = 0, to the closer bone
  double m1 = p.bone_mass, m2 = p.bone_mass;
  Vec3 c1, c2;
  Mat3 I1, I2;
  rodAlongX(p.bone_mass, L, c1, I1);
  rodAlongX(p.bone_mass, L, c2, I2);
  double A = 0.0, B = 0.0;
  if (lumped) {
    const Vec3 e1(std::cos(p.theta0), std::sin(p.theta0), 0), e2(std::cos(p.theta0), -std::sin(p.theta0), 0);
    std::vector<Vec3> x1, x2;
    std::vector<double> w1, w2;
    for (int k = 0; k < mp.size(); ++k) {
      const double a = mp.alpha[k];
      const Vec3 x_w = L * ((1 - a) * e1 + a * e2);
      // world -> body frame: rotate by -q_i about z
      if (a < 0.5) {
        x1.push_back(rotationAxisAngle(Vec3::UnitZ(), -p.theta0) * x_w);
        w1.push_back(mp.mass[k]);
      } else {
        x2.push_back(rotationAxisAngle(Vec3::UnitZ(), p.theta0) * x_w);
        w2.push_back(mp.mass[k]);
      }
    }
    addPoints(m1, c1, I1, x1, w1);
    addPoints(m2, c2, I2, x2, w2);
    // constant inertia about the pivot: J = I_zz,1 + I_zz,2 about the origin
    const double J = I1(2, 2) + m1 * (c1.x() * c1.x() + c1.y() * c1.y()) + I2(2, 2) +
                     m2 * (c2.x() * c2.x() + c2.y() * c2.y());
    A = J;
    B = 0.0;
  } else {
    paiScissorsCoefficients(p, p.mass_points, A, B);
  }

  ModelBuilder b(lumped ? "pai_scissors_lumped" : "pai_scissors");
  b.setGravity(Vec3::Zero());
  const int bone1 = b.addBody("bone1", m1, c1, I1, -1, "hinge1", Revolute{Vec3::UnitZ()});
  const int bone2 = b.addBody("bone2", m2, c2, I2, -1, "hinge2", Revolute{Vec3::UnitZ()});
  b.setCoordinateNames(bone1, {"q1"});
  b.setCoordinateNames(bone2, {"q2"});

  PaiScissors s{b.finalize(), {}, State{}, PaiScissorsSolution(A, B, p.theta0, omega0), omega0};
  if (!lumped) {
    Muscle mu;
    mu.name = "muscle";
    mu.path.points = {makeFixedPoint(bone1, Vec3(L, 0, 0), "origin"), makeFixedPoint(bone2, Vec3(L, 0, 0), "insertion")};
    mu.optimal_fiber_length = 1.0;
    mu.mass_points = mp;
    s.muscles.push_back(std::move(mu));
  }
  s.initial.t = 0.0;
  s.initial.q = Vec2(p.theta0, -p.theta0);
  s.initial.qdot = Vec2(-omega0, omega0);
  return s;
}

KneeInertiaScene makeKneeInertiaScene(const KneeInertiaParams& p) {
  Vec3 com(0, -0.5 * p.shank_length, 0);
  Mat3 I = Mat3::Zero();
  I(0, 0) = I(2, 2) = p.shank_bone_mass * p.shank_length * p.shank_length / 12.0;
  I(1, 1) = 1e-6 * p.shank_bone_mass * p.shank_length * p.shank_length;
  ModelBuilder b("knee_inertia");
  const int shank = b.addBody("shank", p.shank_bone_mass, com, I, -1, "knee", Revolute{Vec3::UnitZ()});
  b.setCoordinateNames(shank, {"knee_angle"});
  KneeInertiaScene s{b.finalize(), {}};
  Muscle mu;
  mu.name = "biceps_femoris_posterior";
  mu.path.points = {makeFixedPoint(-1, p.origin_w, "origin"),
                    makeFixedPoint(shank, Vec3(0, -p.insertion_depth, 0), "insertion")};
  mu.optimal_fiber_length = p.optimal_fiber_length;
  mu.tendon_slack_length = p.tendon_slack_length;
  mu.mass_points = makeMassPoints(p.muscle_mass, p.optimal_fiber_length, p.tendon_slack_length,
                                  {p.mass_points, p.region});
  s.muscles.push_back(std::move(mu));
  return s;
}

double kneeMuscleInertiaContinuum(const KneeInertiaParams& p) {
  double a0 = 0.0, a1 = 1.0;
  if (p.region == MassPointOptions::Region::Fibre) {
    const double phi = p.optimal_fiber_length / (p.optimal_fiber_length + p.tendon_slack_length);
    a0 = 0.5 * (1 - phi);
    a1 = 0.5 * (1 + phi);
  }
  const double r2 = p.insertion_depth * p.insertion_depth;
  return p.muscle_mass * r2 * (a1 * a1 * a1 - a0 * a0 * a0) / (3.0 * (a1 - a0));
}

double kneeBoneInertia(const KneeInertiaParams& p) {
  return p.shank_bone_mass * p.shank_length * p.shank_length / 3.0;
}

}  // namespace redmax::scenes
