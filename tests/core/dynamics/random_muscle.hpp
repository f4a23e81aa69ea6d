#pragma once
// Muscles for the dynamics tests (muscle_term_test, thread_safety_test, the ID derivatives' and the
// adjoint's): random Type I/II ones (the same rng draws in the same order wherever used) and a
// Type III one on a 3-D chain.
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/muscles/mass_points.hpp"
#include "core/spatial/se3.hpp"
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

// a Type III muscle on scenes::revoluteChain(3): origin on link 0, insertion on link 2, the
// surface on link 1 (tilted and offset, so that the path wraps over part of the joints' range)
inline Muscle chainWrapMuscle(const WrapSurface& surface, WrapModel model, const std::string& name = "chain",
                              double mass = 0.3) {
  Muscle mu;
  mu.name = name;
  mu.path.points = {makeFixedPoint(0, Vec3(0.35, -0.25, 0.05)), makeFixedPoint(2, Vec3(-0.3, -0.4, -0.05))};
  PathWrap w;
  w.name = name + "_surface";
  w.surface = surface;
  w.body = 1;
  w.E_bs = makeE(expSO3(Vec3(0.3, -0.2, 0.1)), Vec3(0.02, -0.3, 0.01));
  mu.path.wraps = {w};
  mu.path.num_wraps = 1;
  mu.mass_points = makeMassPoints(mass, 0.5, 0.2, {7});
  mu.wrap.model = model;
  return mu;
}

}  // namespace redmax::test
