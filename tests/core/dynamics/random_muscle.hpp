#pragma once
// A random Type II muscle for the dynamics tests (muscle_term_test, thread_safety_test): the same
// rng draws in the same order wherever it is used.
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/muscles/mass_points.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"

namespace redmax::test {

inline // random Type II muscle: origin anywhere, 2 via points (one moving), insertion on a body
Muscle randomViaMuscle(const Model& m, std::mt19937& rng, double mass, const std::string& name) {
  auto body = [&](bool world) {
    const int lo = world ? -1 : 0;
    return lo + static_cast<int>(rng() % static_cast<unsigned>(m.nb() - lo));
  };
  Muscle mu;
  mu.name = name;
  auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.05, -0.1, 0.2, 0.1});
  mu.path.points = {makeFixedPoint(body(true), randomVec(rng, 0.3)),
                    makeFixedPoint(body(false), randomVec(rng, 0.3)),
                    makeMovingPoint(body(false), static_cast<int>(rng() % m.nr()), {cubic, nullptr, cubic},
                                    Vec3(0, 0.1, 0)),
                    makeFixedPoint(body(false), randomVec(rng, 0.3))};
  mu.optimal_fiber_length = 0.3;
  mu.tendon_slack_length = 0.2;
  MassPointOptions opt;
  opt.count = 8;
  mu.mass_points = makeMassPoints(mass, 0.3, 0.2, opt);
  return mu;
}

// a straight (Type I) muscle from the world to the last body, and a Type II one with a conditional
// point, active for q_0 in [-10, 0.3] (random states switch it on and off)
inline Muscle straightMuscle(const Model& m, std::mt19937& rng, double mass) {
  Muscle mu;
  mu.name = "straight";
  mu.path.points = {makeFixedPoint(-1, randomVec(rng, 0.3)), makeFixedPoint(m.nb() - 1, randomVec(rng, 0.3))};
  mu.mass_points = makeMassPoints(mass, 0.3, 0.2);
  return mu;
}

inline Muscle conditionalMuscle(const Model& m, std::mt19937& rng, double mass) {
  Muscle mu;
  mu.name = "conditional";
  mu.path.points = {makeFixedPoint(0, randomVec(rng, 0.3)),
                    makeConditionalPoint(m.nb() / 2, randomVec(rng, 0.3), 0, -10.0, 0.3),
                    makeFixedPoint(m.nb() / 2, randomVec(rng, 0.3)), makeFixedPoint(m.nb() - 1, randomVec(rng, 0.3))};
  MassPointOptions opt;
  opt.count = 13;
  mu.mass_points = makeMassPoints(mass, 0.3, 0.1, opt);
  return mu;
}

}  // namespace redmax::test
