// Path data model and mass-point placement: OpenSim's conditional-point rule, path types, input
// validation (clear errors, no crash), and the mass-point convention of mass_points.hpp.
#include "core/muscles/path.hpp"

#include <gtest/gtest.h>

#include <numeric>

#include "core/muscles/mass_points.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

// expects a ModelError whose message contains `part`
template <class F>
void expectModelError(F&& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no ModelError (expected one mentioning '" << part << "')";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(PathPoint, ConditionalRuleIsInclusiveWithOpenSimTolerance) {
  const PathPoint p = makeConditionalPoint(0, Vec3::Zero(), 1, -0.5, 0.25);
  VecX q = VecX::Zero(2);
  const double tol = kConditionalTolerance;
  for (double v : {-0.5, 0.25, 0.0, -0.5 - 0.9 * tol, 0.25 + 0.9 * tol}) {
    q[1] = v;
    EXPECT_TRUE(isPathPointActive(p, q)) << v;
  }
  for (double v : {-0.5 - 1.1 * tol, 0.25 + 1.1 * tol, 3.0}) {
    q[1] = v;
    EXPECT_FALSE(isPathPointActive(p, q)) << v;
  }
  // an unconnected coordinate is never active (OpenSim)
  EXPECT_FALSE(isPathPointActive(makeConditionalPoint(0, Vec3::Zero(), -1, -1.0, 1.0), q));
  EXPECT_TRUE(isPathPointActive(makeFixedPoint(0, Vec3::Zero()), q));
}

TEST(PathPoint, PathTypes) {
  MusclePath p;
  p.points = {makeFixedPoint(-1, Vec3::Zero()), makeFixedPoint(0, Vec3::UnitX())};
  EXPECT_EQ(pathType(p), PathType::I);
  p.points.insert(p.points.begin() + 1, makeFixedPoint(0, Vec3::UnitY()));
  EXPECT_EQ(pathType(p), PathType::II);
  MusclePath moving;
  moving.points = {makeFixedPoint(-1, Vec3::Zero()),
                   makeMovingPoint(0, 0, {std::make_shared<LinearFunction>(1.0, 0.0), nullptr, nullptr})};
  EXPECT_EQ(pathType(moving), PathType::II);  // moving points are Type II with extra terms
  p.num_wraps = 1;
  EXPECT_EQ(pathType(p), PathType::III);
  EXPECT_STREQ(pathTypeName(PathType::II), "II");
}

TEST(PathPoint, ValidationGivesClearErrors) {
  const Model m = scenes::doublePendulum();
  auto path = [](std::vector<PathPoint> pts) {
    MusclePath p;
    p.points = std::move(pts);
    return p;
  };
  const PathPoint o = makeFixedPoint(-1, Vec3::Zero()), i = makeFixedPoint(1, Vec3::UnitX());
  expectModelError([&] { validatePath(m, path({o}), "m1"); }, "at least two points");
  expectModelError([&] { validatePath(m, path({o, makeFixedPoint(2, Vec3::Zero())}), "m2"); }, "body index 2");
  expectModelError([&] { validatePath(m, path({o, makeFixedPoint(-3, Vec3::Zero())}), "m2"); }, "body index -3");
  expectModelError([&] { validatePath(m, path({o, makeFixedPoint(0, Vec3(NAN, 0, 0))}), "m3"); }, "non-finite");
  expectModelError([&] { validatePath(m, path({o, makeConditionalPoint(0, Vec3::Zero(), 5, 0, 1), i}), "m4"); },
                   "coordinate index 5");
  expectModelError([&] { validatePath(m, path({o, makeConditionalPoint(0, Vec3::Zero(), 0, 1, 0), i}), "m5"); },
                   "lo <= hi");
  expectModelError([&] { validatePath(m, path({makeConditionalPoint(0, Vec3::Zero(), 0, 0, 1), i}), "m6"); },
                   "origin cannot be a conditional");
  auto two_args = std::make_shared<LinearFunction>(std::vector<double>{1.0, 2.0, 0.0});
  expectModelError([&] { validatePath(m, path({o, makeMovingPoint(0, 0, {two_args, nullptr, nullptr}), i}), "m7"); },
                   "2 arguments");
  // the muscle name is in every message
  expectModelError([&] { validatePath(m, path({o}), "biceps"); }, "muscle 'biceps'");
  EXPECT_NO_THROW(validatePath(m, path({o, makeConditionalPoint(0, Vec3::Zero(), 1, -1, 1), i}), "ok"));
}

TEST(MassPoints, FibreConventionCentresAndMasses) {
  MassPointOptions opt;
  opt.count = 20;
  const MassPoints mp = makeMassPoints(0.8, 0.3, 0.2, opt);
  ASSERT_EQ(mp.size(), 20);
  // fibre share 0.6, tendon 0.2 at each end: alpha in [0.2, 0.8], centres of 20 sub-intervals
  for (int k = 0; k < 20; ++k) {
    EXPECT_NEAR(mp.alpha[k], 0.2 + 0.6 * (k + 0.5) / 20, 1e-15);
    EXPECT_DOUBLE_EQ(mp.mass[k], 0.04);
  }
  EXPECT_NEAR(mp.totalMass(), 0.8, 1e-15);
  // symmetric about the middle of the path
  EXPECT_NEAR(mp.alpha.front() + mp.alpha.back(), 1.0, 1e-15);

  opt.region = MassPointOptions::Region::WholePath;
  opt.count = 4;
  const MassPoints whole = makeMassPoints(1.0, 0.3, 0.2, opt);
  EXPECT_EQ(whole.alpha, (std::vector<double>{0.125, 0.375, 0.625, 0.875}));
}

TEST(MassPoints, BadInputThrows) {
  MassPointOptions opt;
  expectModelError([&] { makeMassPoints(-1.0, 0.3, 0.2, opt); }, "mass");
  expectModelError([&] { makeMassPoints(NAN, 0.3, 0.2, opt); }, "mass");
  expectModelError([&] { makeMassPoints(1.0, 0.0, 0.2, opt); }, "optimal fibre length");
  expectModelError([&] { makeMassPoints(1.0, 0.3, -0.1, opt); }, "tendon slack length");
  opt.count = 0;
  expectModelError([&] { makeMassPoints(1.0, 0.3, 0.2, opt); }, "number of mass points");
  expectModelError([&] { makeMassPoints({0.5, 1.2}, {1.0, 1.0}); }, "not in [0, 1]");
  expectModelError([&] { makeMassPoints({0.5}, {1.0, 1.0}); }, "alpha values");
  expectModelError([&] { makeMassPoints({0.5}, {-1.0}); }, "mass must be finite");
}

TEST(MassPoints, WrappedMusclesMustStayLumped) {
  const Model m = scenes::doublePendulum();
  Muscle mu;
  mu.name = "wrapped";
  mu.path.points = {makeFixedPoint(-1, Vec3::Zero()), makeFixedPoint(1, Vec3::UnitX())};
  mu.path.num_wraps = 1;
  EXPECT_NO_THROW(validateMuscle(m, mu));  // massless: fine
  mu.mass_points = makeMassPoints({0.5}, {0.1});
  expectModelError([&] { validateMuscle(m, mu); }, "Type III");
}

}  // namespace
}  // namespace redmax
