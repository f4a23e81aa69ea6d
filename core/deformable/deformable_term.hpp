#pragma once
// A deformable body in a System [D Sec. 4.6.3, Eq. 4.90-4.95]: its free nodes' world positions are
// extra coordinates of the System (System::addExtraCoordinates), its attached nodes are points
// fixed on skeleton bodies (x_a = E_wi X_i, xdot_a = J_a qdot_r with J_a = R Gamma(X_i) J_mr(i,:)
// [D Eq. 4.90], Jdot_a = R ([omega] Gamma J_i + Gamma Jdot_i) [D Eq. 4.91]) and nodes fixed in the
// world take no part. With J_MR the stack of identity (free) and J_a (attached) rows:
//   M += J_MR^T M_x J_MR,   f += J_MR^T (f_x - M_x Jdot_MR qdot)          [D Eq. 4.95]
// M_x is diagonal for lumped mass and couples the nodes of each tet for consistent mass
// (DeformableBody::node_mass); every product with it below is the general sparse one.
// where f_x = elastic + Rayleigh damping -(alpha M_x + beta K_x(x)) xdot + gravity m g.
//
// Stiffness and damping for the linearly implicit integrators (K = -df/dq, D = -df/dqdot):
//   D = J_MR^T (alpha M_x + beta K_x) J_MR                         exact for f above
//   K = J_MR^T K_x J_MR - sum_a (dJ_a/dq)^T f_a + J_MR^T D_x (dJ_MR/dq qdot)
// K_x the exact Hessian of the elastic energy (co-rotation included); the second term is the
// geometric stiffness of the attached nodes' forces (elastic, damping and gravity), the third the
// position dependence of attached nodes' velocities in the damping. dJ_a/dq_k is exact: Jdot_mr
// evaluated at qdot = e_k is dJ_mr/dq_k (one kinematics pass per skeleton coordinate).
// Left out of K and D, by the integrators' convention (core/integrators/linearly_implicit_euler.hpp):
// the attached nodes' quadratic velocity terms -m J_a^T Jdot_a qdot (explicit, as in MuscleTerm)
// and the position derivative of the Rayleigh damping's beta K_x(x) xdot (a third derivative of
// the energy, proportional to the velocity; docs/deformable.md §2 measures it).
#include <memory>
#include <vector>

#include "core/deformable/deformable_body.hpp"
#include "core/dynamics/force_term.hpp"
#include "core/muscles/path.hpp"

namespace redmax {

class System;

/// How node n of a deformable body enters the System.
struct NodeBinding {
  enum class Kind { Free, Body, World };
  Kind kind = Kind::Free;
  int index = -1;  // Free: first of its 3 coordinates in q; Body: the body
  Vec3 point = Vec3::Zero();  // Body: position in body coordinates; World: position in the world
};

struct DeformableTermOptions {
  bool gravity = true;             // m g on every node (the model's gravity)
  bool quadratic_velocity = true;  // -m J_a^T Jdot_a qdot of attached nodes (false: dropped)
};

/// Scratch of a DeformableTerm (one per DynamicsWorkspace).
struct DeformableScratch final : TermScratch {
  VecX x, v;                 // node positions and velocities                         (3N)
  std::vector<MatX> J, Jdot; // per node: J_a, Jdot_a for attached nodes, else empty (3 x nr)
  ElasticEvaluation el;      // elastic energy, force, K_x (when has_K)
  bool has_K = false;
  VecX F;                    // total node force f_x (elastic, damping, gravity)     (3N)
};

class DeformableTerm final : public ForceTerm {
 public:
  /// One binding per node of `body`; throws ModelError for a count mismatch, a body index out of
  /// range, or free coordinates that are not 3 consecutive entries.
  DeformableTerm(const Model& model, DeformableBody body, std::vector<NodeBinding> nodes,
                 DeformableTermOptions options = {});

  std::string name() const override { return "deformable"; }
  std::unique_ptr<TermScratch> makeScratch(const Model& model) const override;
  void addMass(const Model& model, const State& s, const TermContext& ctx, MatX& M) const override;
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  void addStiffnessDamping(const Model& model, const State& s, const TermContext& ctx, MatX& K, MatX& D) const override;
  /// analytic: sum_a m_a (Jdot_a^T J_a + J_a^T Jdot_a) qdot over attached nodes
  void addMassDotTimesVelocity(const Model& model, const State& s, const TermContext& ctx, VecX& Mdot_v) const override;
  double kineticEnergy(const Model& model, const State& s, const TermContext& ctx) const override;
  /// elastic energy plus -sum m g . x (world origin reference)
  double potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const override;

  /// free nodes are extra coordinates: M, K, D reach them (addSparseMatrices gives them sparse)
  bool matricesOnSkeletonOnly() const override { return false; }
  /// the same M, K, D as addMass and addStiffnessDamping, as triplets (System::calcSparseMatrices)
  bool addSparseMatrices(const Model& model, const State& s, const TermContext& ctx, bool stiffness, Triplets& M,
                         Triplets& K, Triplets& D) const override;
  const DeformableBody& body() const { return body_; }
  const std::vector<NodeBinding>& nodes() const { return nodes_; }
  const DeformableTermOptions& options() const { return options_; }
  /// node world positions at s (3N); needs the skeleton at Stage::Position in ctx
  VecX nodePositions(const Model& model, const State& s, const TermContext& ctx) const;
  /// write the free nodes' rest positions into s.q and zero their velocities
  void setRestState(State& s) const;
  /// the free nodes at rest carried rigidly by body `follow` from the model's default pose to its
  /// pose at s.q, moving with its velocity at s.qdot (a soft body starting undeformed on a moved link)
  void setRestState(const Model& model, State& s, int follow) const;

 private:
  DeformableScratch& evaluate(const Model& model, const State& s, const TermContext& ctx, bool stiffness,
                              DeformableScratch& local) const;
  // add J_MR^T F (node force 3N) to f (ndof)
  void mapForce(const VecX& F, Eigen::Ref<VecX> f, const DeformableScratch& sc, int nr) const;
  // add J_MR^T A J_MR (A: 3N x 3N) to out (ndof x ndof)
  void mapMatrix(const SparseMat& A, MatX& out, const DeformableScratch& sc, int nr) const;
  // the same as triplets (the q_r block summed densely first)
  void mapMatrix(const SparseMat& A, Triplets& out, const DeformableScratch& sc, int nr) const;
  // the walk both mapMatrix forms share: one callback per kind of node pair
  template <class FreeFree, class FreeBody, class BodyFree, class BodyBody>
  void forEachMappedEntry(const SparseMat& A, const DeformableScratch& sc, FreeFree&& ff, FreeBody&& fb,
                          BodyFree&& bf, BodyBody&& bb) const;
  // the attached nodes' part of K (geometric stiffness and the damping's q-dependence): column k
  // (< nr) of it, over all coordinates, handed to `add(k, column)` for each coordinate that moves one
  template <class Add>
  void forEachAttachedStiffnessColumn(const Model& model, const State& s, const TermContext& ctx,
                                      const DeformableScratch& sc, const SparseMat& Dx, int ndof, Add&& add) const;
  // D_x = alpha M_x + beta K_x (needs sc.el.K)
  SparseMat dampingMatrix(const DeformableScratch& sc) const;

  // Jdot_MR qdot stacked per node (3N): Jdot_a qdot for attached nodes, zero for the others
  VecX nodeBiasAcceleration(const DeformableScratch& sc, const VecX& qdot_r) const;

  DeformableBody body_;
  SparseMat Mx_;  // node-coordinate mass matrix (3N x 3N): diagonal (lumped) or consistent
  std::vector<NodeBinding> nodes_;
  DeformableTermOptions options_;
  bool has_body_nodes_ = false;
};

/// A muscle path point at node `node` of `term`'s body, for a muscle that inserts on (or runs
/// through) soft tissue: a Node point on the node's three coordinates when it is free, the body
/// point it is fixed to when carried by a body through J_am, a world point when fixed in the world
/// (core/muscles/path.hpp). The muscle's mass points and force then reach the node's coordinates
/// through the same chain J_ar = J_ax J_xr as on bones. ModelError for a node out of range.
PathPoint musclePointAtNode(const DeformableTerm& term, int node, std::string name = "");

/// Which nodes of a deformable body are attached, and to what: body index, or -1 for the world.
struct NodeAttachment {
  int node = 0;
  int body = -1;
};

/// How nodes attached to a body are held: carried by the body through J_am [D Eq. 4.90-4.91]
/// (no coordinates of their own), or free nodes tied to the body point by a NodeConstraint
/// (core/deformable/node_constraint.hpp; 3 constraint rows each, the multipliers are the forces).
enum class AttachBy { Jacobian, Constraint };

/// Add `body` to `sys`: the nodes in `attach` are fixed to their bodies where they are at the
/// model's default pose (or to the world), every other node becomes 3 extra coordinates of sys.
/// Returns the term added (its setRestState puts the free nodes at rest in a state; with
/// AttachBy::Constraint, project the state onto the constraints afterwards).
std::shared_ptr<const DeformableTerm> addDeformableBody(System& sys, DeformableBody body,
                                                        const std::vector<NodeAttachment>& attach,
                                                        DeformableTermOptions options = {},
                                                        AttachBy attach_by = AttachBy::Jacobian);

}  // namespace redmax
