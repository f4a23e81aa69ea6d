#include "validation/scenes/scenes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace redmax::scenes {

namespace {
// thin rod of length L along -y from the body origin (joint at the origin)
void rodInertia(double m, double L, Vec3& com, Mat3& I) {
  com = Vec3(0, -0.5 * L, 0);
  I = Mat3::Zero();
  I(0, 0) = I(2, 2) = m * L * L / 12.0;
  I(1, 1) = 1e-6 * m * L * L;  // a rod with a tiny radius, keeps the inertia positive definite
}

double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
Vec3 randomVec(std::mt19937& rng, double scale = 1.0) {
  return Vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)) * scale;
}
Vec3 randomUnit(std::mt19937& rng) {
  Vec3 v;
  do v = randomVec(rng);
  while (v.norm() < 0.2);
  return v.normalized();
}
Mat3 randomRotation(std::mt19937& rng) { return expSO3(randomVec(rng, 2.0)); }
int pick(std::mt19937& rng, int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); }

// smooth one-coordinate coupling of amplitude <= amp (knee-like SimmSpline, etc.)
AxisFunctionPtr randomCoupling(std::mt19937& rng, double amp) {
  const double A = uniform(rng, -amp, amp), w = uniform(rng, 0.5, 1.5), ph = uniform(rng, -1, 1);
  switch (pick(rng, 4)) {
    case 0: {
      const int n = 4 + pick(rng, 4);
      std::vector<double> x(n), y(n);
      for (int i = 0; i < n; ++i) {
        x[i] = -1.6 + 3.2 * i / (n - 1) + (i > 0 && i < n - 1 ? uniform(rng, -0.1, 0.1) : 0.0);
        y[i] = A * std::sin(w * x[i] + ph);
      }
      return std::make_shared<const SimmSpline>(x, y);
    }
    case 1: {
      std::vector<double> x{-1.5, -0.4, 0.3, 1.5}, y(4);
      for (int i = 0; i < 4; ++i) y[i] = A * std::cos(w * x[i] + ph);
      return std::make_shared<const NaturalCubicSpline>(x, y);
    }
    case 2:
      return std::make_shared<const PolynomialFunction>(
          std::vector<double>{0.3 * A, -0.5 * A, A, uniform(rng, -0.2, 0.2)});
    default: {
      std::vector<double> x{-1.5, 0.0, 1.5}, y{A, -A * 0.5, A * ph};
      return std::make_shared<const MultiplierFunction>(std::make_shared<const SimmSpline>(x, y),
                                                        uniform(rng, 0.5, 1.5));
    }
  }
}

Joint randomFunctionBased(std::mt19937& rng) {
  const int nq = 1 + pick(rng, 3);
  std::array<TransformAxis, 6> ax;
  // orthonormal rotation axes (no gimbal lock in range), translation axes only non-parallel
  const Mat3 Rr = randomRotation(rng);
  for (int k = 0; k < 3; ++k) ax[k].axis = Rr.col(k);
  const Mat3 Rt = randomRotation(rng);
  for (int k = 0; k < 3; ++k) ax[3 + k].axis = (Rt.col(k) + randomVec(rng, 0.3)).normalized();
  // every coordinate drives its own axis linearly (S keeps full rank)...
  std::vector<int> slots{0, 1, 2, 3, 4, 5};
  std::shuffle(slots.begin(), slots.end(), rng);
  for (int j = 0; j < nq; ++j) {
    TransformAxis& a = ax[slots[j]];
    a.coordinates = {j};
    const double s = uniform(rng, 0.6, 1.0) * (rng() % 2 ? 1.0 : -1.0);
    a.function = std::make_shared<const LinearFunction>(s, uniform(rng, -0.2, 0.2));
  }
  // ...and the other axes get couplings, multi-argument linears or constants
  for (int j = nq; j < 6; ++j) {
    TransformAxis& a = ax[slots[j]];
    const double amp = slots[j] < 3 ? 0.3 : 0.1;
    switch (pick(rng, 3)) {
      case 0:
        a.coordinates = {pick(rng, nq)};
        a.function = randomCoupling(rng, amp);
        break;
      case 1:
        if (nq >= 2) {
          a.coordinates = {0, nq - 1};
          a.function = std::make_shared<const LinearFunction>(
              std::vector<double>{uniform(rng, -amp, amp), uniform(rng, -amp, amp), uniform(rng, -0.1, 0.1)});
          break;
        }
        [[fallthrough]];
      default:
        a.function = std::make_shared<const ConstantFunction>(uniform(rng, -0.2, 0.2));
    }
  }
  return FunctionBased(nq, ax);
}

// a small joint for composites, within budgets of rotational and translational freedoms (a
// composite with more than 3 of either would have a singular S everywhere)
Joint randomPart(std::mt19937& rng, int& rot_left, int& trans_left) {
  for (;;) {
    Joint j;
    int r = 0, t = 0;
    switch (pick(rng, 6)) {
      case 0: j = Revolute{randomUnit(rng)}, r = 1; break;
      case 1: j = Prismatic{randomUnit(rng)}, t = 1; break;
      case 2: j = Universal{}, r = 2; break;
      case 3: j = SphericalEuler{static_cast<EulerSequence>(pick(rng, 6))}, r = 3; break;
      case 4: j = Planar{}, t = 2; break;
      default: j = SphericalExp{}, r = 3; break;
    }
    if (r <= rot_left && t <= trans_left) {
      rot_left -= r;
      trans_left -= t;
      return j;
    }
  }
}
}  // namespace

Joint randomJoint(std::size_t index, std::mt19937& rng) {
  switch (index) {
    case 0: return Fixed{};
    case 1: return Revolute{randomUnit(rng)};
    case 2: return Prismatic{randomUnit(rng)};
    case 3: return Planar{};
    case 4: return Translational{};
    case 5: return SphericalEuler{static_cast<EulerSequence>(pick(rng, 12))};
    case 6: return Universal{};
    case 7: return SphericalExp{};
    case 8: {
      // two or three parts, sometimes nested: Q1 (Q2 Q3)
      int rot = 3, trans = 3;
      Joint a = randomPart(rng, rot, trans);
      Joint b = randomPart(rng, rot, trans);
      if (rot + trans > 0 && rng() % 2) {
        Joint c = randomPart(rng, rot, trans);
        return Composite({a, Composite({b, c})});
      }
      return Composite({a, b});
    }
    case 9: return Free2D{};
    case 10:
      return Free3D{static_cast<FreeRotation>(pick(rng, 2)), static_cast<EulerSequence>(pick(rng, 6)),
                    static_cast<FreeOrder>(pick(rng, 2)), static_cast<FreeLayout>(pick(rng, 2))};
    case 11: {
      const int n = 4 + pick(rng, 4);
      std::vector<Mat4> frames{makeE(randomRotation(rng), randomVec(rng, 0.2))};
      for (int i = 1; i < n; ++i)
        frames.push_back(frames.back() * makeE(expSO3(randomVec(rng, 0.6)), randomVec(rng, 0.3)));
      return SplineCurve(frames);
    }
    case 12: {
      std::array<Mat4, 6> C;
      for (int k = 0; k < 6; ++k) {
        const double amp = k < 3 ? 0.3 : 0.5;
        // a tilted plane plus noise, so both coordinates move every spatial coordinate
        const double gx = uniform(rng, -amp, amp), gy = uniform(rng, -amp, amp);
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) C[k](i, j) = gx * i + gy * j + uniform(rng, -0.3, 0.3) * amp - 1.5 * (gx + gy);
      }
      return SplineSurface(C);
    }
    case 13: return randomFunctionBased(rng);
    case 14: {
      // semi-axes of either sign and unequal, so p = D n exercises every radius
      Vec3 r;
      for (int k = 0; k < 3; ++k) r[k] = (pick(rng, 4) == 0 ? -1.0 : 1.0) * uniform(rng, 0.05, 0.4);
      return Ellipsoid{r};
    }
    case 15: return Reversed(randomJoint(static_cast<std::size_t>(pick(rng, 15)), rng));
    default:
      throw std::out_of_range("randomJoint: no generator for joint alternative " + std::to_string(index));
  }
}

Model doublePendulum(double L, double m) {
  ModelBuilder b("double_pendulum");
  b.setGravity(Vec3(0, -9.81, 0));
  Vec3 c;
  Mat3 I;
  rodInertia(m, L, c, I);
  const int b1 = b.addBody("link1", m, c, I, -1, "pin1", Revolute{Vec3::UnitZ()});
  const int b2 = b.addBody("link2", m, c, I, b1, "pin2", Revolute{Vec3::UnitZ()},
                           makeTranslation(Vec3(0, -L, 0)));
  b.setCoordinateNames(b1, {"q1"});
  b.setCoordinateNames(b2, {"q2"});
  return b.finalize();
}

Model revoluteChain(int n) {
  ModelBuilder b("revolute_chain");
  Vec3 c;
  Mat3 I;
  rodInertia(1.0, 0.5, c, I);
  int parent = -1;
  const Vec3 axes[3] = {Vec3::UnitZ(), Vec3::UnitX(), Vec3::UnitY()};
  for (int i = 0; i < n; ++i) {
    const Mat4 E_pf = parent < 0 ? Mat4::Identity() : makeTranslation(Vec3(0, -0.5, 0));
    parent = b.addBody("link" + std::to_string(i), 1.0, c, I, parent, "joint" + std::to_string(i),
                       Revolute{axes[i % 3]}, E_pf);
  }
  return b.finalize();
}

Model randomTree(int n, std::uint32_t seed, TreeJoints kinds) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto rvec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  auto rpose = [&](double scale) {
    return makeE(expSO3(rvec() * 1.5), rvec() * scale);
  };
  ModelBuilder b("random_tree");
  b.setGravity(Vec3(0.3, -9.81, 0.2));
  for (int i = 0; i < n; ++i) {
    // mostly attached to an earlier body; sometimes a second root on the world
    const int p = (i == 0 || rng() % 6 == 0) ? -1 : static_cast<int>(rng() % i);
    const double m = 0.5 + 2.0 * std::abs(u(rng));
    // random positive-definite inertia satisfying the triangle inequality: R diag R^T
    const Vec3 d(0.05 + 0.1 * std::abs(u(rng)), 0.05 + 0.1 * std::abs(u(rng)), 0.05 + 0.1 * std::abs(u(rng)));
    const Mat3 R = expSO3(rvec() * 2.0);
    const Mat3 Ic = R * Vec3(d.y() + d.z(), d.x() + d.z(), d.x() + d.y()).asDiagonal() * R.transpose() * m;
    Joint j;
    if (kinds == TreeJoints::All) {
      j = randomJoint(rng() % std::variant_size_v<JointVariant>, rng);
    } else {
      switch (rng() % 6) {
        case 0: j = Revolute{rvec().normalized()}; break;
        case 1: j = Prismatic{rvec().normalized()}; break;
        case 2: j = Fixed{}; break;
        case 3: j = SphericalEuler{EulerSequence::XYZ}; break;
        case 4: j = Universal{}; break;
        default: j = Free3D::opensim(); break;
      }
    }
    b.addBody("body" + std::to_string(i), m, rvec() * 0.3, Ic, p, "joint" + std::to_string(i), j,
              rpose(0.5), rpose(0.3));
  }
  return b.finalize();
}

}  // namespace redmax::scenes
