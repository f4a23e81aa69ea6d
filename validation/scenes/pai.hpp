#pragma once
// Scenes for the comparison with Pai 2010 [D Sec. 6.2.2, Fig. 6.4], with their closed-form
// solutions. Pai's own geometry and rat data are not available to us, so both scenes are our own
// reconstructions, stated here in full; what is compared is the core against the closed form of the
// scene as set up.
//
// (a) Two bones and one muscle of equal mass ("scissors"). Two thin uniform rods (length L, mass
//     m_b) are each hinged to the world at the origin about z (two independent Revolute joints,
//     coordinates q1, q2 = the angle of each rod from +x). A straight (Type I) muscle of mass m_m
//     runs from the tip of rod 1 to the tip of rod 2; its N mass points sit at the midpoints
//     alpha_k = (k + 1/2) / N of the whole path (Region::WholePath), m_m / N each. No gravity, no
//     muscle force. Start: q = (theta0, -theta0), qdot = (-omega0, +omega0): the rods close
//     symmetrically and both angles reach zero together (the bones straighten out).
//     By the mirror symmetry q2 = -q1 = -theta for all t, and with x_a = L ((1 - a) e(q1) + a e(q2))
//       T = 1/2 J(theta) thetadot^2,  J = A + B sin^2(theta),
//       A = 2 m_b L^2 / 3 + L^2 sum_k m_k (1 - 2 a_k)^2,   B = L^2 sum_k 4 m_k a_k (1 - a_k),
//     (continuum: sum m (1-2a)^2 -> m_m / 3, sum 4 m a (1-a) -> 2 m_m / 3). Energy conservation gives
//       t(theta) = (G(theta0) - G(theta)) / (omega0 sqrt(J(theta0))),  G(x) = int_0^x sqrt(J(s)) ds
//               = sqrt(A + B) (E(pi/2 | k) - E(pi/2 - x | k)),  k^2 = B / (A + B)
//     (E the incomplete elliptic integral of the second kind, std::ellint_2). omega0 is chosen so
//     that the continuum muscle reaches theta = 0 at t_zero (0.3 s as in the dissertation); the
//     N-point scene then reaches zero at t_zero + O(1/N^2).
//     Lumped variant (the dissertation's dotted lines): each mass point is welded to the bone it is
//     closest to at t = 0 (a < 1/2: rod 1), so each bone's inertia about the pivot is constant and
//     theta(t) = theta0 - omega0 t.
//
// (b) Knee self-inertia, muscle vs bones. One hinge (the knee, z axis) between a fixed thigh (the
//     world) and the shank: the bones of the shank as a thin uniform rod of length L_s and mass
//     m_b hanging along -y (knee inertia m_b L_s^2 / 3). A straight muscle of mass m_m from an
//     origin on the thigh to an insertion on the shank at distance r from the knee axis. Its mass
//     point at fraction a moves with a times the insertion's velocity, so its share of the knee's
//     self-inertia (the muscle's part of M in [D Eq. 5.7b]) is
//       M_muscle = r^2 sum_k m_k a_k^2 -> m_m r^2 (a1^3 - a0^3) / (3 (a1 - a0))   (continuum, uniform
//     density on a in [a0, a1]); for the whole path m_m r^2 / 3, and the midpoint rule gives exactly
//     m_m r^2 (1/3 - 1/(12 N^2)): relative error 1 / (4 N^2).
#include <vector>

#include "core/muscles/mass_points.hpp"
#include "core/skeleton/model.hpp"
#include "core/skeleton/state.hpp"

namespace redmax::scenes {

struct PaiScissorsParams {
  double bone_length = 1.0;   // L, m
  double bone_mass = 1.0;     // m_b per rod, kg
  double muscle_mass = 1.0;   // m_m, kg ("all with the same mass")
  int mass_points = 20;       // N
  double theta0 = 1.0471975511965976;  // initial half-opening, rad (60 deg)
  double t_zero = 0.3;        // s, when the continuum muscle straightens out
};

/// Closed-form motion of the symmetric scissors (see the file comment): theta = q1 = -q2.
class PaiScissorsSolution {
 public:
  /// A and B of J(theta) = A + B sin^2(theta) (kg m^2), the initial angle and rate
  PaiScissorsSolution(double A, double B, double theta0, double omega0);
  double inertia(double theta) const;           // J(theta), kg m^2
  double timeAt(double theta) const;            // t at which the angle is theta (theta <= theta0)
  double angleAt(double t) const;               // theta(t), t >= 0 (Newton on timeAt)
  double rateAt(double t) const;                // thetadot(t) (negative)
  double zeroTime() const { return timeAt(0.0); }
  double A() const { return A_; }
  double B() const { return B_; }
  double omega0() const { return omega0_; }

 private:
  double G(double x) const;                     // int_0^x sqrt(J(s)) ds
  double A_, B_, theta0_, omega0_;
};

/// The scene, ready for a System (add a MuscleTerm with `muscles` unless lumped).
struct PaiScissors {
  Model model;                  // gravity zero; bodies "bone1", "bone2"
  std::vector<Muscle> muscles;  // one straight muscle (empty when lumped)
  State initial;                // q = (theta0, -theta0), qdot = (-omega0, omega0)
  PaiScissorsSolution solution; // closed form of this scene (N points, or lumped)
  double omega0 = 0.0;          // rad/s
};

/// A(muscle sums) and B for a muscle of N uniform midpoint masses (N = 0: the continuum).
void paiScissorsCoefficients(const PaiScissorsParams& p, int N, double& A, double& B);
/// omega0 such that the continuum scene straightens out at p.t_zero
double paiScissorsOmega0(const PaiScissorsParams& p);
/// The scene; lumped = the muscle's points welded to the closest bone at t = 0 (no muscle).
PaiScissors makePaiScissors(const PaiScissorsParams& p, bool lumped = false);

struct KneeInertiaParams {
  double shank_length = 0.040;    // L_s, m
  double shank_bone_mass = 1.5e-3;  // m_b, kg
  double muscle_mass = 2.0e-3;    // m_m, kg
  Vec3 origin_w = Vec3(-0.030, 0.025, 0.0);   // muscle origin on the (fixed) thigh, world frame, m
  double insertion_depth = 0.024; // r: insertion on the shank axis, below the knee, m
  int mass_points = 20;
  MassPointOptions::Region region = MassPointOptions::Region::WholePath;
  double optimal_fiber_length = 0.030, tendon_slack_length = 0.010;  // Region::Fibre only, m
};

/// The knee scene: body "shank" on a Revolute "knee" (z) at the world origin, one muscle.
struct KneeInertiaScene {
  Model model;
  std::vector<Muscle> muscles;
};
KneeInertiaScene makeKneeInertiaScene(const KneeInertiaParams& p);
/// Continuum (uniform density) muscle contribution to the knee's self-inertia, kg m^2
double kneeMuscleInertiaContinuum(const KneeInertiaParams& p);
/// Bones' knee self-inertia m_b L_s^2 / 3, kg m^2
double kneeBoneInertia(const KneeInertiaParams& p);

}  // namespace redmax::scenes
