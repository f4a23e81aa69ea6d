#pragma once
// Hyper-reduced coordinates [D Sec. 4.6.2, Eq. 4.84-4.86]: the skeleton's reduced coordinates q_r
// become functions of fewer independent coordinates q_R,
//   q_r = g(q_R),   qdot_r = J_rR qdot_R,   qddot_r = J_rR qddot_R + Jdot_rR qdot_R,
// so the equations of motion are solved in q_R:
//   M_R = J_rR^T M_r J_rR,   f_R = J_rR^T (f_r - M_r Jdot_rR qdot_R)      (J_mR = J_mr J_rR [D Eq. 4.85])
//
// The map starts as the identity on the model's nr coordinates. Each addDependent() turns one
// skeleton coordinate into q_dep = scale * f(q_args...) (an OpenSim coupler, eliminated instead of
// enforced); the independent coordinates q_R are the remaining ones, in skeleton order. Arguments
// may themselves be dependent (chains are evaluated in dependency order; cycles are rejected).
// The dissertation's example, a chain whose joint angles are all equal, is
//   for k >= 1: addDependent(k, {0}, makeLinearFunction({1.0})).
#include <string>
#include <vector>

#include "core/dynamics/constraints/constraint_function.hpp"
#include "core/spatial/types.hpp"

namespace redmax {

class Model;

class CoordinateMap {
 public:
  /// identity map on the model's coordinates (names are taken for error messages)
  explicit CoordinateMap(const Model& model);

  /// q_r[dependent] = scale * f(q_r[args]). Throws ModelError on bad indices, an argument count
  /// that does not match f, a coordinate made dependent twice, or a dependency cycle.
  void addDependent(int dependent, std::vector<int> args, ConstraintFunctionPtr f, double scale = 1.0);

  int nr() const { return nr_; }
  /// number of independent (hyper-reduced) coordinates
  int nR() const { return static_cast<int>(independent_.size()); }
  /// skeleton index of each q_R entry (nR)
  const std::vector<int>& independent() const { return independent_; }
  /// q_R index of skeleton coordinate r, or -1 if r is dependent
  int reducedIndex(int r) const { return r_to_R_[r]; }
  bool isIdentity() const { return deps_.empty(); }
  /// true if skeleton coordinate r is an argument of some dependent coordinate
  bool isArgument(int r) const { return is_arg_[r] != 0; }

  /// q_r = g(q_R)   (q_r resized to nr)
  void calcPosition(const VecX& q_R, VecX& q_r) const;
  /// q_r, qdot_r = J_rR qdot_R, J_rR (nr x nR) and Jdot_rR (nr x nR) [D Eq. 4.84-4.85]
  void calc(const VecX& q_R, const VecX& qdot_R, VecX& q_r, VecX& qdot_r, MatX& J_rR, MatX& Jdot_rR) const;
  /// independent entries of a skeleton vector (q_r or qdot_r -> q_R or qdot_R)
  VecX reduce(const VecX& v_r) const;

 private:
  struct Dependent {
    int index;                 // skeleton coordinate
    std::vector<int> args;     // skeleton coordinates it depends on
    ConstraintFunctionPtr f;
    double scale;
  };
  void rebuild();
  int nr_;
  std::vector<std::string> names_;
  std::vector<Dependent> deps_;     // in evaluation order after rebuild()
  std::vector<int> independent_;    // (nR)
  std::vector<int> r_to_R_;         // (nr)
  std::vector<char> is_arg_;        // (nr)
};

}  // namespace redmax
