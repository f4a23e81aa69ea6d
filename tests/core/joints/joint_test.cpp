// Typed finite-difference suite over EVERY JointVariant alternative (the type list is generated
// from the variant, so a new joint inherits it): S against Q, Sdot against S, Q rigid, the chart
// switch keeps the motion. Instances come from scenes::randomJoint plus hand-picked extras.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <string>
#include <variant>

#include "tests/core/joints/joint_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using namespace redmax::test;

template <class V>
struct VariantTypes;
template <class... Ts>
struct VariantTypes<std::variant<Ts...>> {
  using type = ::testing::Types<Ts...>;
};

template <class T, class... Ts>
constexpr std::size_t indexIn(std::variant<Ts...>*) {
  std::size_t i = 0;
  (void)((std::is_same_v<T, Ts> || (++i, false)) || ...);
  return i;
}
template <class T>
constexpr std::size_t kIndex = indexIn<T>(static_cast<JointVariant*>(nullptr));

// hand-picked instances beyond the random ones
template <class T>
std::vector<Joint> extraSamples() { return {}; }
template <>
std::vector<Joint> extraSamples<SphericalEuler>() {
  std::vector<Joint> v;
  for (int s = 0; s < 12; ++s) v.push_back(SphericalEuler{static_cast<EulerSequence>(s)});
  return v;
}
template <>
std::vector<Joint> extraSamples<Free3D>() {
  std::vector<Joint> v;
  for (int r = 0; r < 2; ++r)
    for (int o = 0; o < 2; ++o)
      for (int l = 0; l < 2; ++l)
        v.push_back(Free3D{static_cast<FreeRotation>(r), EulerSequence::ZXY, static_cast<FreeOrder>(o),
                           static_cast<FreeLayout>(l)});
  v.push_back(Free3D::opensim());
  return v;
}

template <class T>
std::vector<Joint> samples(std::mt19937& rng) {
  std::vector<Joint> v = extraSamples<T>();
  for (int i = 0; i < 8; ++i) v.push_back(scenes::randomJoint(kIndex<T>, rng));
  return v;
}

// coordinates in the joint's natural range (spline curves span several segments and a bit beyond)
VecJ randomQ(const Joint& j, std::mt19937& rng) {
  if (const auto* sc = std::get_if<SplineCurve>(&j.v))
    return randomVecJ(1, rng, -0.5, sc->numSegments() + 0.5);
  return randomVecJ(j.nq(), rng, -1.2, 1.2);
}

template <class T>
class JointFd : public ::testing::Test {};
using AllJointTypes = VariantTypes<JointVariant>::type;
TYPED_TEST_SUITE(JointFd, AllJointTypes);

TYPED_TEST(JointFd, ShapesAndRigidTransform) {
  std::mt19937 rng(11);
  for (const Joint& j : samples<TypeParam>(rng)) {
    ASSERT_TRUE(std::holds_alternative<TypeParam>(j.v));
    const int n = j.nq();
    ASSERT_GE(n, 0);
    ASSERT_LE(n, 6);
    for (int t = 0; t < 5; ++t) {
      const JointKinematics k = calcJoint(j, randomQ(j, rng), randomVecJ(n, rng));
      EXPECT_EQ(k.S.cols(), n);
      EXPECT_EQ(k.Sdot.cols(), n);
      EXPECT_TRUE(isRigid(k.Q)) << j.typeName() << "\n" << k.Q;
      EXPECT_TRUE(k.S.allFinite() && k.Sdot.allFinite());
    }
  }
}

TYPED_TEST(JointFd, SMatchesTransformDifferences) {
  std::mt19937 rng(12);
  for (const Joint& j : samples<TypeParam>(rng)) {
    for (int t = 0; t < 5; ++t) {
      const VecJ q = randomQ(j, rng);
      const JointKinematics k = calcJoint(j, q);
      for (int c = 0; c < j.nq(); ++c) {
        const Mat4 fd = fdBracketColumn(j, q, c);
        EXPECT_TRUE(nearRel(bracket6(k.S.col(c)), fd, kFdTol))
            << j.typeName() << " column " << c << " q = " << q.transpose() << "\nS_k = "
            << k.S.col(c).transpose() << "\nfd  = " << unbracket6(fd).transpose();
      }
    }
  }
}

TYPED_TEST(JointFd, SdotMatchesJacobianDifferences) {
  std::mt19937 rng(13);
  for (const Joint& j : samples<TypeParam>(rng)) {
    for (int t = 0; t < 5; ++t) {
      const VecJ q = randomQ(j, rng), qdot = randomVecJ(j.nq(), rng, -2.0, 2.0);
      const Mat6X Sdot = calcJoint(j, q, qdot).Sdot;
      const Mat6X fd = fdSdot(j, q, qdot);
      EXPECT_TRUE(nearRel(Sdot, fd, kFdTol))
          << j.typeName() << " q = " << q.transpose() << "\nSdot =\n" << Sdot << "\nfd =\n" << fd;
    }
  }
}

TYPED_TEST(JointFd, ReparameterizeKeepsRotationAndTwist) {
  // large coordinates make exponential-coordinate joints switch chart; for every joint, whenever
  // reparameterize() reports a change, Q and the twist S qdot must be unchanged
  std::mt19937 rng(14);
  int fired = 0;
  for (const Joint& j : samples<TypeParam>(rng)) {
    for (int t = 0; t < 5; ++t) {
      VecJ q = randomQ(j, rng) * 4.0, qdot = randomVecJ(j.nq(), rng);
      const JointKinematics before = calcJoint(j, q, qdot);
      const VecJ q0 = q, qdot0 = qdot;
      if (!j.reparameterize(q, qdot)) {
        EXPECT_EQ(q, q0);
        EXPECT_EQ(qdot, qdot0);
        continue;
      }
      ++fired;
      const JointKinematics after = calcJoint(j, q, qdot);
      EXPECT_TRUE(nearRel(after.Q, before.Q, 1e-12)) << j.typeName();
      EXPECT_TRUE(nearRel(Vec6(after.S * qdot), Vec6(before.S * qdot0), 1e-12)) << j.typeName();
      EXPECT_LT(q.norm(), q0.norm());
    }
  }
  // the exponential-coordinate joints must actually have been exercised
  if constexpr (std::is_same_v<TypeParam, SphericalExp> || std::is_same_v<TypeParam, Free3D>) {
    EXPECT_GT(fired, 0);
  }
}

TEST(Joint, SingularityDistance) {
  std::mt19937 rng(17);
  const VecJ q3 = randomVecJ(3, rng);
  EXPECT_EQ(Joint(Revolute{}).singularityDistance(VecJ::Constant(1, 0.3)), 1.0);
  EXPECT_EQ(Joint(Universal{}).singularityDistance(VecJ(Vec2(0.3, 1.5))), 1.0);
  const Joint zyz = SphericalEuler{EulerSequence::ZYZ};
  EXPECT_DOUBLE_EQ(zyz.singularityDistance(q3), std::abs(std::sin(q3[1])));
  // exponential coordinates: sigma_min(S)/sigma_max(S), 0 on the 2 pi shell
  const Joint ex = SphericalExp{};
  for (double len : {0.0, 1.0, M_PI, 1.5 * M_PI, 2 * M_PI}) {
    const VecJ q = VecJ(Vec3(q3.normalized() * len));
    const Eigen::JacobiSVD<Mat3> svd(Mat3(calcJoint(ex, q).S.topRows<3>()));
    EXPECT_NEAR(ex.singularityDistance(q), svd.singularValues()[2] / svd.singularValues()[0], 1e-12) << len;
  }
  EXPECT_LT(ex.singularityDistance(VecJ(Vec3(0, 2 * M_PI, 0))), 1e-15);
  // free joint: its rotation part; composite: the smallest part
  VecJ qf(6);
  qf << 0.2, M_PI / 2, -0.3, 1.0, 2.0, 3.0;
  EXPECT_LT(Joint(Free3D::opensim()).singularityDistance(qf), 1e-15);
  const Joint comp = Composite({Revolute{}, Composite({Prismatic{}, zyz})});
  VecJ qc(5);
  qc << 0.4, 0.1, q3;
  EXPECT_DOUBLE_EQ(comp.singularityDistance(qc), std::abs(std::sin(q3[1])));
  // function-based with three driven orthonormal rotations: the Euler measure
  std::array<TransformAxis, 6> ax;
  for (int k = 0; k < 3; ++k) ax[k] = {Vec3::Unit(k), {k}, nullptr};
  for (int k = 0; k < 3; ++k) ax[3 + k] = {Vec3::Unit(k), {}, nullptr};
  EXPECT_NEAR(Joint(FunctionBased(3, ax)).singularityDistance(q3),
              Joint(SphericalEuler{EulerSequence::XYZ}).singularityDistance(q3), 1e-15);
  ax[2].coordinates.clear();
  EXPECT_EQ(Joint(FunctionBased(3, ax)).singularityDistance(q3), 1.0);
}

TEST(Joint, NonFiniteCoordinatesDoNotCrash) {
  // a diverged state must come back as non-finite numbers for the caller to report, not a crash
  std::mt19937 rng(18);
  for (std::size_t i = 0; i < std::variant_size_v<JointVariant>; ++i) {
    const Joint j = scenes::randomJoint(i, rng);
    for (double bad : {std::nan(""), 1e300, -1e300}) {
      JointKinematics k;
      VecJ q = VecJ::Constant(j.nq(), bad), qd = VecJ::Zero(j.nq());
      j.calc(q, qd, k);
      j.reparameterize(q, qd);
      EXPECT_EQ(k.S.cols(), j.nq());
    }
  }
}

TEST(Joint, TypeNamesAreDistinct) {
  std::mt19937 rng(15);
  std::set<std::string> names;
  for (std::size_t i = 0; i < std::variant_size_v<JointVariant>; ++i)
    names.insert(scenes::randomJoint(i, rng).typeName());
  EXPECT_EQ(names.size(), std::variant_size_v<JointVariant>);
  EXPECT_THROW(scenes::randomJoint(std::variant_size_v<JointVariant>, rng), std::out_of_range);
}

TEST(Joint, ModelCopiesShareImmutableFunctions) {
  // a copy of a function-based joint computes the same kinematics (functions are shared, const)
  std::mt19937 rng(16);
  const Joint a = scenes::randomJoint(kIndex<FunctionBased>, rng);
  const Joint b = a;
  const VecJ q = randomVecJ(a.nq(), rng), qd = randomVecJ(a.nq(), rng);
  EXPECT_EQ(calcJoint(a, q, qd).Sdot, calcJoint(b, q, qd).Sdot);
}

}  // namespace
}  // namespace redmax
