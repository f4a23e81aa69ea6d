#pragma once
// What the adjoint tests share: a Problem on a fixed system.
#include <memory>
#include <string>

#include "core/adjoint/adjoint.hpp"

namespace redmax::test {

/// a run of `sys` from its default state, with the system as its own factory
inline adjoint::Problem problemFor(std::shared_ptr<const System> sys, const std::string& integrator, double duration,
                                   double dt) {
  adjoint::Problem pr;
  pr.integrator = integrator;
  pr.duration = duration;
  pr.dt = dt;
  pr.initial = sys->defaultState();
  pr.make_system = [sys](const VecX&) { return sys; };
  return pr;
}

}  // namespace redmax::test
