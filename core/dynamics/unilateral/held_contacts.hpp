#pragma once
// The contacts and joint limits that hold between events, as one bilateral constraint for the
// adaptive integrators (core/integrators/event_driven.hpp, docs/contact.md §6.1).
//
// Each held contact (a candidate of UnilateralConstraints::detect, identified by its key) keeps
// its normal row J_n (the gap's rate) and, per tangent direction of the four-sided friction
// pyramid, either a sticking row J_t,k (no relative tangential velocity) or slides with sign
// s_k = sign(w_t,k): its friction force -mu p_n s_k along t_k is tied to the normal force p_n,
// so the normal row's multiplier acts through H_n = J_n - mu sum_k s_k J_t,k
// (Constraint::hasForceRows; the pyramid's directions slide independently, as in the bdf1 QP).
//
// Rows and signs (System convention M qddot = f - G^T lambda): G = J (the rows of detect), so the
// contact force along a row is p = -lambda (p_n >= 0 pushes the bodies apart).
// Right-hand side: J qddot = -Jdot qdot - 2 w0 (J qdot) - w0^2 gap (normal rows; tangent rows
// without the gap term), a critically damped Baumgarte term (w0 = HeldContactOptions::omega) that
// holds the drift of the rows' bias, which is a central difference of the rows' velocities along
// the motion, d/dt (J(q) qdot) at qddot = 0 = (J(q + e qdot) - J(q - e qdot)) qdot / (2 e): one
// construction for every shape pair (the ellipsoid's moving support point, a capsule's cap, two
// spheres' turning normal), at two extra kinematics per evaluation; its error is about 1e-11 of
// |w|^2 / length.
#include <memory>
#include <vector>

#include "core/dynamics/constraint.hpp"
#include "core/dynamics/unilateral/unilateral.hpp"

namespace redmax {

/// which candidate of detect(): limit or pair, source index, sub point (as the QP's warm-start keys)
struct ContactKey {
  bool limit = false;
  int source = 0;
  int sub = 0;
  bool operator==(const ContactKey& o) const { return limit == o.limit && source == o.source && sub == o.sub; }
  static ContactKey of(const UnilateralRows::Candidate& c) { return {c.limit, c.source, c.sub}; }
};

/// a held contact: its key and, per tangent direction, sticking (0) or sliding with sign +1 / -1
struct HeldContact {
  ContactKey key;
  double mu = 0.0;             ///< the pair's friction (0 for limits)
  int slide[2] = {0, 0};
};

struct HeldContactOptions {
  double omega = 50.0;         ///< 1/s: Baumgarte rate of the held rows' drift correction
};

/// index of the candidate with `key` in rows.c, or -1
int findCandidate(const UnilateralRows& rows, const ContactKey& key);

class HeldContacts final : public Constraint {
 public:
  /// throws ModelError for a sliding or sticking tangent on a frictionless contact
  HeldContacts(std::shared_ptr<const UnilateralConstraints> u, std::vector<HeldContact> held,
               HeldContactOptions opt = {});

  std::string name() const override { return "held contacts"; }
  int rows() const override { return rows_; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override;
  /// normal rows: pos_err = gap, vel_err = J_n qdot; sticking rows: 0 and J_t qdot
  void calcErrors(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override;
  bool hasForceRows() const override { return sliding_; }
  void calcForceRows(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> H) const override;

  const std::vector<HeldContact>& held() const { return held_; }
  /// first row of held contact k (its normal row; its sticking rows follow in direction order)
  int firstRow(int k) const { return first_[k]; }

 private:
  /// rows (G, in this constraint's row order) and their velocities at s
  void rowsAt(const Model& model, const State& s, const SkeletonWorkspace& sk, MatX& G, VecX& gap) const;
  std::shared_ptr<const UnilateralConstraints> u_;
  std::vector<HeldContact> held_;
  HeldContactOptions opt_;
  std::vector<int> first_;
  UnilateralConstraints::Subset sources_;  // the pairs and limits with a held point: all that is detected
  int rows_ = 0;
  bool sliding_ = false;
};

}  // namespace redmax
