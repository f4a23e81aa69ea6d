#pragma once
// Hard unilateral constraints [D Sec. 3.11.2, Eq. 3.46-3.47; Sec. 6.1]: joint limits as reduced
// unilateral constraints (a coordinate's range) and collisions as maximal unilateral constraints
// (points of bodies against half-spaces and spheres) with Coulomb friction (a four-sided
// pyramid), restitution and a small stabilisation of penetration, solved in the linearly implicit
// Euler step (core/integrators/linearly_implicit_euler.hpp) together with the bilateral
// constraints. docs/contact.md §6 describes the method; the symbols:
//
//   step without contact (the bilateral KKT step):  A v_f + G^T mu_f = a,  G v_f = b
//   contact rows J (normals J_n, tangents J_t), impulses p:  A v + G^T mu = a + J^T p,  G v = b
//     so v = v_f + W J^T p with W the constrained inverse of A, and the contact velocities
//     w = J v = J v_f + (J W J^T) p.
//   The QP over p (the dual of [D Eq. 3.47], where friction bounds can be written):
//     min 1/2 p^T (J W J^T + eps I) p + p^T (J v_f - target)
//     s.t. p_n >= 0,  -mu pbar_n <= p_t <= mu pbar_n   (per tangent direction: the pyramid)
//   whose KKT conditions are w_n >= target, p_n >= 0, p_n (w_n - target) = 0 and maximal
//   dissipation for the tangential impulse. pbar_n is the normal impulse of the previous
//   fixed-point iteration (staggered projections, Kaufman et al. 2008); the first is
//   frictionless. eps (a 1e-9 fraction of the mean of diag J W J^T) makes the QP strictly convex
//   for rank-deficient contact sets (four corners of a box on the floor): the velocities change
//   by eps p, the impulses are the regularised (least-norm-like) split.
//   target per normal row: -gap / h while apart (a contact may close, not pass, within the step),
//   stabilization max(0, penetration - slop) / h when penetrating, and at least -e w_n^- (e the
//   restitution, w_n^- the approach velocity at the step's start) for an impact faster than
//   restitution_threshold.
#include <memory>
#include <string>
#include <vector>

#include "core/skeleton/model.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

enum class CollisionShape { Sphere, Capsule, Box, HalfSpace, Ellipsoid };

/// A collision shape fixed in a body (-1: the ground). The half-space fills x > 0 of its frame
/// (OpenSim's ContactHalfSpace; outward normal -x); the capsule's axis is the frame's x axis; the
/// ellipsoid's semi-axes lie along the frame's axes.
struct CollisionGeometry {
  std::string name;
  CollisionShape shape = CollisionShape::Sphere;
  int body = -1;
  Mat4 X_body = Mat4::Identity();     ///< geometry frame in the body frame
  double radius = 0.0;                ///< Sphere, Capsule
  double half_length = 0.0;           ///< Capsule: half the distance between the cap centres
  Vec3 half_extents = Vec3::Zero();   ///< Box: half extents; Ellipsoid: semi-axes
};

/// Two geometries that may touch: a half-space with a sphere, capsule (its two cap spheres), box
/// (its eight corners) or ellipsoid (its deepest point: the support point along the inward
/// normal, o - R A^2 R^T n / |A R^T n| for semi-axes A), two spheres, or a capsule and a sphere
/// (the sphere against the nearest point of the capsule's axis segment, a sphere-sphere contact
/// of radii r_capsule and r_sphere there). One contact point per sphere, cap, corner or ellipsoid,
/// its rows the point's velocity on each body along the normal (and two tangents).
struct CollisionPair {
  int first = -1, second = -1;  ///< indices into the geometry list
  double friction = 0.0;        ///< Coulomb coefficient mu (>= 0)
  double restitution = 0.0;     ///< e in [0, 1]
};

/// lower <= q[coordinate] <= upper (a reduced unilateral constraint)
struct JointLimit {
  std::string name;
  int coordinate = -1;  ///< system coordinate index
  double lower = 0.0, upper = 0.0;
  double restitution = 0.0;
};

struct UnilateralOptions {
  double stabilization = 0.2;          ///< fraction of the penetration beyond slop removed per step
  double slop = 1e-5;                  ///< m (rad for limits): penetration left alone
  double restitution_threshold = 0.05; ///< m/s (rad/s): slower impacts do not bounce
  double margin = 1e-3;                ///< rows enter the QP when gap + h min(0, w_n^-, w_n^free) < margin
  double regularization = 1e-9;        ///< eps relative to the mean of diag J W J^T
  int friction_iterations = 30;        ///< fixed-point iterations on the friction bounds
  double friction_tolerance = 1e-9;    ///< converged: max |p_n - pbar_n| <= tol max |p_n|
};

/// The candidate rows of one step (UnilateralConstraints::detect).
struct UnilateralRows {
  struct Candidate {
    int source = 0;      ///< pair index, or limit index for limits
    int sub = 0;         ///< which point of the pair (capsule end, box corner) or 0/1 lower/upper
    bool limit = false;
    double gap = 0.0;    ///< signed distance (negative: penetration)
    double target = 0.0; ///< lower bound on the normal velocity after the step
    double approach = 0.0; ///< normal velocity at the step's start (negative: approaching)
    double mu = 0.0;
    int tangent_row = -1;  ///< first of its two rows in Jt, or -1 without friction
    Vec3 point = Vec3::Zero(), normal = Vec3::Zero();
  };
  std::vector<Candidate> c;
  MatX Jn;  ///< (candidates x ndof)
  MatX Jt;  ///< (2 x frictional candidates, x ndof)
  double max_penetration = 0.0;  ///< over all geometry points examined (m or rad)
  double h = 0.0;                ///< the step they were made for
};

struct UnilateralStepStats {
  int candidates = 0;           ///< normal rows in the QP (those that can close within the step)
  int contacts = 0;             ///< rows with a positive normal impulse
  int qp_iterations = 0;        ///< active-set changes, summed over the friction iterations
  int friction_iterations = 0;  ///< QPs solved
  bool friction_converged = true;
};

/// what one step leaves to the next (the QP's warm start)
struct UnilateralWarmStart {
  std::vector<long> active_keys;  ///< identities of the rows active at the last solve
};

class UnilateralConstraints {
 public:
  /// throws ModelError for bodies or coordinates outside the model, unsupported pairs,
  /// lower > upper, negative radii or friction, restitution outside [0, 1], bad options
  UnilateralConstraints(const Model& model, std::vector<CollisionGeometry> geometry,
                        std::vector<CollisionPair> pairs, std::vector<JointLimit> limits,
                        UnilateralOptions options = {});
  const std::vector<CollisionGeometry>& geometry() const { return geometry_; }
  const std::vector<CollisionPair>& pairs() const { return pairs_; }
  const std::vector<JointLimit>& limits() const { return limits_; }
  const UnilateralOptions& options() const { return options_; }

  /// the candidate rows at state s (every point of every pair and both sides of every limit;
  /// solveUnilateralStep keeps those that can close within the step) (sk at Stage::Velocity for s's skeleton part; ndof system
  /// coordinates, the first nr the skeleton's) for a step of size h. With `only`, just the pairs
  /// and limits it marks (the same rows as the full detection gives them)
  struct Subset {
    std::vector<char> pairs, limits;  ///< one flag per pair / limit
  };
  void detect(const Model& model, const State& s, const SkeletonWorkspace& sk, int ndof, double h,
              UnilateralRows& out, const Subset* only = nullptr) const;
  /// the signed distances of every geometry point of every pair and of every limit (negative:
  /// penetration), for reports and tests; needs Stage::Position
  std::vector<double> gaps(const Model& model, const State& s, const SkeletonWorkspace& sk) const;

 private:
  std::vector<CollisionGeometry> geometry_;
  std::vector<CollisionPair> pairs_;
  std::vector<JointLimit> limits_;
  UnilateralOptions options_;
};

/// The contact-constrained step: v (ndof) from the bilateral KKT step data (A, a, G, b as in
/// detail::solveImplicit) and the candidate rows. mu_bilateral (if given) receives the bilateral
/// multipliers with the contact impulses included. Throws QpError if the QP fails.
VecX solveUnilateralStep(const MatX& A, const VecX& a, const MatX& G, const VecX& b, const UnilateralRows& rows,
                         const UnilateralOptions& opt, UnilateralWarmStart* warm, VecX* mu_bilateral,
                         UnilateralStepStats* stats);

}  // namespace redmax
