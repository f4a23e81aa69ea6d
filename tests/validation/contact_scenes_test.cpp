// The contact scenes of osim_models/ through the simulate driver (validation/simulate,
// docs/contact.md): the 2-D walker standing on its four SmoothSphereHalfSpaceForce foot spheres
// carries its weight in the vertical contact forces, and the run's contact statistics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/dynamics/contact_force_terms.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/forward/forward_tool.hpp"
#include "validation/simulate/simulate.hpp"

namespace redmax::validation {
namespace {

std::string scene(const std::string& f) { return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + f; }

TEST(ContactScenes, WalkerAtRestCarriesItsWeightOnTheFootSpheres) {
  SimulationModel m = loadSimulationModel(scene("walker2d.osim"), {});
  std::vector<std::string> warnings, not_applied;
  addPassiveTerms(m, warnings, not_applied);
  EXPECT_TRUE(not_applied.empty()) << not_applied.front();
  SimulateOptions o;
  o.integrator = "rk45";
  o.integrator_options.rtol = 1e-8;
  o.integrator_options.atol = 1e-10;
  o.duration = 3.0;
  o.output_dt = 0.05;
  const SimulationResult r = simulate(m, defaultInitialState(m), o);
  ASSERT_FALSE(r.failed) << r.failure;
  EXPECT_EQ(r.contacts.contacts, 4);
  EXPECT_EQ(r.contacts.active_final, 4);
  // the largest penetration (measured 11.5 mm in the first settling; 9.2 mm at rest)
  EXPECT_GT(r.contacts.max_penetration, 0.005);
  EXPECT_LT(r.contacts.max_penetration, 0.03);
  // sum of the vertical forces the spheres receive at the end
  const System& sys = *m.system;
  const State s = sys.expandState(r.final_state);
  SkeletonWorkspace sk(sys.model());
  calcKinematics(sys.model(), s, sk);
  std::vector<ContactReport> reports;
  for (const auto& t : sys.terms())
    if (auto c = dynamic_cast<const ContactForceTerm*>(t.get())) c->contacts(sk, reports);
  ASSERT_EQ(reports.size(), 4u);
  double fy = 0.0, fx = 0.0, mass = 0.0;
  for (const ContactReport& c : reports) {
    fy += c.force_w.y();
    fx += c.force_w.x();
  }
  for (int b = 0; b < sys.model().nb(); ++b) mass += sys.model().bodies()[b].mass;
  const double weight = mass * 9.80665;
  EXPECT_NEAR(mass, 31.0, 1e-12);
  std::printf("walker: sum F_y %.9g N, weight %.9g N, relative %.2g; sum F_x %.2g N; max penetration %.4g m\n", fy,
              weight, std::abs(fy - weight) / weight, fx, r.contacts.max_penetration);
  // at rest the ground carries the weight: measured 1.7e-14 relative (5.6e-16 on the dense forward
  // route: the settled state differs by round-off between the routes), sum F_x 1.1e-7 N
  EXPECT_NEAR(fy, weight, 1e-13 * weight) << fy;
  EXPECT_LT(std::abs(fx), 1e-6) << fx;
  EXPECT_LT(r.final_state.qdot.norm(), 1e-3);
}

}  // namespace
}  // namespace redmax::validation
