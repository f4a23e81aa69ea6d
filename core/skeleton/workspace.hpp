#pragma once
// Everything derived from (Model, State) for the skeleton, grouped by stage (MuJoCo/Drake).
// Sized once by the constructor; the algorithms do not allocate afterwards.
#include <vector>

#include "core/joints/joint_kinematics.hpp"
#include "core/skeleton/model.hpp"

namespace redmax {

enum class Stage { None = 0, Position = 1, Velocity = 2 };

struct SkeletonWorkspace {
  explicit SkeletonWorkspace(const Model& model);

  // position stage: written by calcKinematics()
  std::vector<JointKinematics> jk;  // per joint Q, S (and Sdot at velocity stage)   (nb)
  std::vector<Mat4> E_wi;           // body poses in world                           (nb)
  std::vector<Mat6> Ad_ip;          // Ad of the parent body frame in body i         (nb)
  std::vector<Mat6> Ad_ij;          // Ad of joint frame M in body i (constant)      (nb)
  MatX J_mr;                        // reduced -> maximal velocities                (nm x nr)

  // velocity stage
  std::vector<Vec6> phi;            // body twists, in body coordinates             (nb)
  std::vector<Vec6> psi;            // joint twist relative to parent, in body i    (nb)
  MatX Jdot_mr;                     // d/dt J_mr                                     (nm x nr)

  Stage stage = Stage::None;
};

/// Body motion up to the acceleration level, as recursive inverse dynamics computes it (body
/// coordinates): what a ForceTerm needs to give its share of inverse dynamics as body wrenches
/// without J_mr (core/dynamics/skeleton_dynamics.hpp, RecursiveIdWorkspace).
struct BodyMotion {
  const std::vector<Mat4>& E_wi;    // poses in world                                 (nb)
  const std::vector<Vec6>& phi;     // twists                                         (nb)
  const std::vector<Vec6>& phidot;  // d/dt phi = J_mr qddot + Jdot_mr qdot           (nb)
};

}  // namespace redmax
