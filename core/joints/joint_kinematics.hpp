#pragma once
// What every joint computes [D Sec. 4.5]: the joint transform Q(q) (child-side frame M in
// parent-side frame F), the joint Jacobian S(q) with columns [S_k] = Q^-1 dQ/dq_k [D Eq. 4.29]
// expressed in M, and its time derivative Sdot(q, qdot).
#include <stdexcept>

#include "core/spatial/types.hpp"

namespace redmax {

/// at most 6 x 6, stored inline: Hessians of joint functions, per-joint blocks.
using MatJ = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

struct JointKinematics {
  Mat4 Q = Mat4::Identity();  // pose of M in F                       (4 x 4)
  Mat6X S;                    // twist of M relative to F, in M, per qdot (6 x nq)
  Mat6X Sdot;                 // dS/dt                                  (6 x nq)
  void resize(int nq) {
    S.setZero(6, nq);
    Sdot.setZero(6, nq);
  }
};

/// Invalid joint parameters (bad axes, too few spline frames, function/coordinate mismatch...).
/// Thrown by joint constructors, never from calc() on a validly constructed joint.
class JointError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace redmax
