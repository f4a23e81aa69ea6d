#pragma once
// Extension points of the equations of motion. Later layers (muscle mass points, external loads,
// deformables) add to the reduced mass matrix and force without touching joint code [D Eq. 4.76,
// 4.82, 5.7]: each ForceTerm adds its share of
//   M_r qddot = f_r,    and for linearly implicit integrators K_r = -df_r/dq, D_r = -df_r/dqdot.
#include <string>

#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  virtual std::string name() const = 0;
  /// add this term's inertia to M (ndof x ndof); needs Stage::Velocity
  virtual void addMass(const Model&, const State&, const SkeletonWorkspace&, MatX& M) const {}
  /// add this term's generalized force (including its quadratic-velocity part) to f (ndof)
  virtual void addForce(const Model&, const State&, const SkeletonWorkspace&, VecX& f) const = 0;
  /// add K = -df/dq and D = -df/dqdot (ndof x ndof); default: explicit term (adds nothing)
  virtual void addStiffnessDamping(const Model&, const State&, const SkeletonWorkspace&, MatX& K,
                                   MatX& D) const {}
  virtual double kineticEnergy(const Model&, const State&, const SkeletonWorkspace&) const { return 0.0; }
  virtual double potentialEnergy(const Model&, const State&, const SkeletonWorkspace&) const { return 0.0; }
};

}  // namespace redmax
