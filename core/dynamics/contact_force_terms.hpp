#pragma once
// OpenSim's compliant contact forces as ForceTerms (docs/contact.md), the equations of Simbody's
// SimTK::HuntCrossleyForce and SimTK::SmoothSphereHalfSpaceForce, which OpenSim 4's
// HuntCrossleyForce and SmoothSphereHalfSpaceForce build. Geometry: spheres and half-spaces (the
// half-space fills x > 0 of its frame; its outward normal is -x).
//
//   HuntCrossleyForce   per surface: stiffness k_i (Pa), dissipation c_i (s/m), friction us_i,
//                       ud_i, uv_i; per force: transition velocity vt. For a contact of depth d
//                       between surfaces 1 and 2 (normal n from 1 into 2, effective radius R):
//                         k'_i = k_i^(2/3), s1 = k'_2 / (k'_1 + k'_2), k = k'_1 s1,
//                         c = c_1 s1 + c_2 (1 - s1),  f_H = 4/3 k d sqrt(R k d)  (= 4/3 E sqrt(R)
//                         d^(3/2) with E = k^(3/2)),  V = 2/5 f_H d,
//                         f = f_H (1 + 3/2 c v_n)   (no force where f <= 0),
//                         friction f (min(v_s/vt, 1) (ud + 2 (us - ud) / (1 + (v_s/vt)^2)) + uv v_s)
//                         against the slip, u = 2 u_1 u_2 / (u_1 + u_2) for each coefficient;
//                       applied at the contact point moved by d (1/2 - s1) along n.
//   SmoothSphereHalfSpaceForce  one sphere and one half-space, one material:
//                         k = 1/2 stiffness^(2/3), x = R - height of the centre above the plane,
//                         f_H = 4/3 k sqrt(R k) (x^2 + cf)^(3/4) (1/2 + 1/2 tanh(bd x)),
//                         f = f_H (1 + 3/2 c v_n) (1/2 + 1/2 tanh(bv (v_n + 2/(3c)))),
//                         v_s = sqrt(|v_t|^2 + cf), friction as above with f, V = 2/5 f_H x
//                         (Simbody's approximate potential).
#include <string>
#include <vector>

#include "core/dynamics/force_term.hpp"

namespace redmax {

/// One contact at a state: the force the second surface (the sphere) receives from the first.
struct ContactReport {
  std::string name;          ///< "<force>: <geometry 1> - <geometry 2>"
  double penetration = 0.0;  ///< m (positive: overlapping)
  double radius = 0.0;       ///< m, the smaller sphere's radius (the deepest meaningful penetration)
  bool active = false;       ///< penetration > 0
  Vec3 point_w = Vec3::Zero();   ///< where the force acts (world)
  Vec3 force_w = Vec3::Zero();   ///< on surface 2 (world frame, N); surface 1 receives -force_w
  Vec3 normal_w = Vec3::UnitY(); ///< from surface 1 into surface 2 (world)
  int body1 = -1, body2 = -1;    ///< the surfaces' bodies (-1: ground)
  /// d f_n / d penetration of the elastic part at this depth (N/m): with the effective mass along
  /// the normal it gives the contact's frequency, which a fixed step must resolve
  double stiffness = 0.0;
};

/// What a run reports of its contacts at one state.
struct ContactSummary {
  int active = 0;
  double max_penetration = 0.0;   ///< m, over active contacts
  double max_relative = 0.0;      ///< max penetration / radius (> 1: the sphere passed its centre)
  std::string deepest;            ///< name of the contact with max_relative
};

/// A ForceTerm made of contacts: reports them (Stage::Velocity for the forces, Stage::Position
/// suffices for penetrations).
class ContactForceTerm : public ForceTerm {
 public:
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const final;
  double potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const final;
  void contacts(const SkeletonWorkspace& sk, std::vector<ContactReport>& out) const;
  ContactSummary summary(const SkeletonWorkspace& sk) const;

 protected:
  /// one pass over the contacts: each report into `out`, the potential added to `V`, the forces
  /// added to `f` (with `model`); null outputs are skipped
  virtual void evaluate(const SkeletonWorkspace& sk, std::vector<ContactReport>* out, double* V,
                        const Model* model, VecX* f) const = 0;
};

enum class ContactShape { Sphere, HalfSpace };

/// a contact surface fixed in a body (-1: ground)
struct ContactSurface {
  std::string name;
  ContactShape shape = ContactShape::Sphere;
  int body = -1;
  Mat4 X_body = Mat4::Identity();  ///< geometry frame in the body
  double radius = 0.0;             ///< Sphere
};

class HuntCrossleyForceTerm final : public ContactForceTerm {
 public:
  struct Material {
    double stiffness = 0.0;  ///< Pa (the plane-strain modulus as OpenSim writes it), > 0
    double dissipation = 0.0, static_friction = 0.0, dynamic_friction = 0.0, viscous_friction = 0.0;
  };
  struct Force {
    std::string name;
    std::vector<ContactSurface> surfaces;  ///< the contact set
    std::vector<Material> materials;       ///< one per surface
    double transition_velocity = 0.01;     ///< m/s, > 0
  };
  /// throws ModelError for a body outside the model, a non-positive stiffness, radius or
  /// transition velocity, negative coefficients, non-finite values
  HuntCrossleyForceTerm(const Model& model, std::vector<Force> forces);
  std::string name() const override { return "hunt_crossley_forces"; }
  const std::vector<Force>& forces() const { return forces_; }

  /// the normal force law alone: f_H at depth d, effective radius R, for two stiffnesses (Pa)
  static double hertzForce(double k1, double k2, double R, double d);
  /// the friction coefficient (times the normal force) at slip speed vs: Simbody's Stribeck-like law
  static double frictionCoefficient(double us, double ud, double uv, double vt, double vs);

 private:
  struct Pair {
    int force, i, j;  ///< surfaces i (first: the half-space) and j of force
  };
  /// every overlapping pair
  void evaluate(const SkeletonWorkspace& sk, std::vector<ContactReport>* out, double* V, const Model* model,
                VecX* f) const override;
  std::vector<Force> forces_;
  std::vector<Pair> pairs_;
};

class SmoothSphereHalfSpaceForceTerm final : public ContactForceTerm {
 public:
  struct Contact {
    std::string name;
    ContactSurface sphere, half_space;
    double stiffness = 1.0, dissipation = 0.0;  ///< Pa, s/m (OpenSim's defaults)
    double static_friction = 0.0, dynamic_friction = 0.0, viscous_friction = 0.0;
    double transition_velocity = 0.01;  ///< m/s
    double constant_contact_force = 1e-5, hertz_smoothing = 300.0, hunt_crossley_smoothing = 50.0;
  };
  /// throws ModelError for shapes that are not a sphere and a half-space, bodies outside the
  /// model, both on one body, negative or non-finite parameters, a non-positive radius or
  /// transition velocity
  SmoothSphereHalfSpaceForceTerm(const Model& model, std::vector<Contact> contacts);
  std::string name() const override { return "smooth_sphere_half_space_forces"; }
  const std::vector<Contact>& contactList() const { return contacts_; }

 private:
  void evaluate(const SkeletonWorkspace& sk, std::vector<ContactReport>* out, double* V, const Model* model,
                VecX* f) const override;
  std::vector<Contact> contacts_;
};

}  // namespace redmax
