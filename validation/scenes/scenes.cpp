#include "validation/scenes/scenes.hpp"

#include <random>
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
}  // namespace

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
    const int kind = static_cast<int>(rng() % 3);
    if (kind == 0) j = Revolute{rvec().normalized()};
    else if (kind == 1) j = Prismatic{rvec().normalized()};
    else j = Fixed{};
    (void)kinds;
    b.addBody("body" + std::to_string(i), m, rvec() * 0.3, Ic, p, "joint" + std::to_string(i), j,
              rpose(0.5), rpose(0.3));
  }
  return b.finalize();
}

}  // namespace redmax::scenes
