// Rajagopal2016's gastrocnemii (and subject_walk_armless's med_gas) under the smooth composition
// of two cylinders on one segment (issue 22, core/muscles/wrap/smooth_composite.hpp): each muscle's
// path is origin (femur) -> Gastroc_at_condyles (femur) -> Gas*_at_shank (tibia, quadrant -y) ->
// insertion (calcaneus). The smooth model takes them; J_ar and Jdot_ar match central differences
// near the default pose; where both cylinders are outside their bands the mass points lie on the
// exact library's converged path, and their distance to OpenSim's own passes (calcWrappedPath) is
// measured. Skips without ../shared.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/muscles/wrap/smooth_composite.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/muscles/wrap_composite.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "tests/core/muscles/wrap_composite_reference.hpp"

namespace redmax {
namespace {

namespace fs = std::filesystem;

std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }

// the composition's surfaces of a two-point muscle at q (world poses) and its weights
std::vector<CompositeWrapSurface> surfacesAt(const Muscle& mu, const std::vector<Mat4>& E_wi) {
  std::vector<CompositeWrapSurface> s;
  for (const PathWrap& w : mu.path.wraps) {
    const Mat4 E = w.body >= 0 ? Mat4(E_wi[w.body] * w.E_bs) : w.E_bs;
    CompositeWrapSurface c;
    c.surface = &w.surface;
    c.R = E.topLeftCorner<3, 3>();
    c.p = E.topRightCorner<3, 1>();
    s.push_back(c);
  }
  return s;
}

struct ModelTally {
  int muscles = 0, wrapping = 0, smooth = 0, checked_fd = 0;
  double worst_J = 0.0, worst_Jdot = 0.0;
  int poses = 0, clean = 0, both = 0, banded = 0, mismatch = 0;
  double worst_lib = 0.0, worst_opensim = 0.0;
};

ModelTally checkTwoCylinderMuscles(const std::string& file, const char* label) {
  const osim::ModelDescription d = osim::readOsimModel(file);
  osim::BuildOptions bo;
  bo.constraints = false;
  const osim::BuildResult br = osim::buildCoreModel(d, bo);
  const Model& m = br.model;
  ModelTally t;
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const Muscle& base : br.model.muscles()) {
    if (base.path.wraps.empty()) continue;
    ++t.wrapping;
    Muscle mu = base;
    mu.mass_points = makeMassPoints(1.0, 0.0, 0.0, {10, MassPointOptions::Region::WholePath});
    mu.wrap.model = WrapModel::Smooth;
    const std::string why = wrapMassPointsUnsupportedReason(mu);
    EXPECT_EQ(why, "") << label << " " << mu.name;
    t.smooth += why.empty();
    if (!why.empty() || !hasSharedWrapSegments(mu)) continue;
    ++t.muscles;
    // J_ar, Jdot_ar against central differences near the default pose (seeded offset 0.1)
    State s;
    s.q = m.defaultQ() + 0.1 * VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
    s.qdot = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
    const MuscleKinematics mk = test::evalMuscle(m, mu, s);
    const MatX J_fd = test::calcJarFd(m, mu, s, 1e-6), Jdot_fd = test::calcJdotArFd(m, mu, s, 1e-6);
    const double eJ = (mk.J_ar - J_fd).norm() / (1.0 + J_fd.norm());
    const double eJd = (mk.Jdot_ar - Jdot_fd).norm() / (1.0 + Jdot_fd.norm());
    t.worst_J = std::max(t.worst_J, eJ);
    t.worst_Jdot = std::max(t.worst_Jdot, eJd);
    ++t.checked_fd;
    EXPECT_LE(eJ, 1e-6) << mu.name;
    EXPECT_LE(eJd, 1e-6) << mu.name;
    // random poses (default +- 0.6): on the converged library path outside the bands
    for (int k = 0; k < 200; ++k) {
      State r;
      r.q = m.defaultQ() + 0.6 * VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
      r.qdot = VecX::Zero(m.nr());
      ++t.poses;
      const MuscleKinematics mr = test::evalMuscle(m, mu, r, false);
      std::vector<Mat4> E_wi;
      calcBodyPoses(m, r.q, E_wi);
      const std::vector<CompositeWrapSurface> cs = surfacesAt(mu, E_wi);
      CompositeWrapResult cr;
      calcSmoothCompositeWrap(cs, mr.x_w.front(), mr.x_w.back(), Vec3::Zero(), Vec3::Zero(), {}, {}, mu.wrap.width, cr);
      bool outside = true;
      for (double w : cr.weights) outside = outside && (w == 0.0 || w == 1.0);
      if (!outside) {
        ++t.banded;
        continue;
      }
      const test::ConvergedLibraryPath lib = test::convergeLibraryPath(cs, cr.order, mr.x_w.front(), mr.x_w.back());
      bool same = lib.converged;
      for (size_t w = 0; w < cs.size(); ++w) same = same && lib.wraps[w] == (cr.weights[w] == 1.0);
      if (!same) {
        ++t.mismatch;
        continue;
      }
      ++t.clean;
      const bool both = cr.weights[0] == 1.0 && cr.weights[1] == 1.0;
      t.both += both;
      const WrappedPath wp = calcWrappedPath(m, mu.path, r.q, E_wi);
      for (int a = 0; a < mu.mass_points.size(); ++a) {
        const double alpha = mu.mass_points.alpha[a];
        t.worst_lib = std::max(t.worst_lib, (mr.x_a[a] - test::convergedLibraryPoint(cs, lib, alpha)).norm());
        t.worst_opensim =
            std::max(t.worst_opensim, (mr.x_a[a] - calcWrappedPathPointWorld(mu.path, wp, E_wi, alpha)).norm());
      }
    }
  }
  std::printf("[ measured ] %s: %d wrapping muscles, %d taken by the smooth model, %d with two wraps on one segment; "
              "J_ar / Jdot_ar vs central differences %.1e / %.1e; %d random poses: %d outside the bands (%d both "
              "wrapped), %d in a band, %d where the library wraps other surfaces; max distance to the converged "
              "library path %.1e m, to OpenSim's passes %.1e m\n",
              label, t.wrapping, t.smooth, t.muscles, t.worst_J, t.worst_Jdot, t.poses, t.clean, t.both, t.banded,
              t.mismatch, t.worst_lib, t.worst_opensim);
  return t;
}

TEST(WrapCompositeModels, Rajagopal2016GastrocnemiiTakeTheSmoothComposition) {
  const std::string file = shared("opensim-models/Models/Rajagopal/Rajagopal2016.osim");
  if (!fs::exists(file)) GTEST_SKIP() << "shared OpenSim data not found: " << file;
  const ModelTally t = checkTwoCylinderMuscles(file, "Rajagopal2016");
  EXPECT_EQ(t.wrapping, 42);
  EXPECT_EQ(t.smooth, 42);
  EXPECT_EQ(t.muscles, 4);  // gasmed_r/l, gaslat_r/l
  EXPECT_GT(t.both, 50);
  EXPECT_EQ(t.mismatch, 0);
  EXPECT_LE(t.worst_lib, 1e-12);
}

TEST(WrapCompositeModels, SubjectWalkMedGasTakesTheSmoothComposition) {
  const std::string file = shared("opensim-core/OpenSim/Moco/Test/subject_walk_armless_18musc.osim");
  if (!fs::exists(file)) GTEST_SKIP() << "shared OpenSim data not found: " << file;
  const ModelTally t = checkTwoCylinderMuscles(file, "subject_walk_armless_18musc");
  EXPECT_EQ(t.smooth, t.wrapping);
  EXPECT_EQ(t.muscles, 2);  // med_gas_r/l
  EXPECT_EQ(t.mismatch, 0);
  EXPECT_LE(t.worst_lib, 1e-12);
}

}  // namespace
}  // namespace redmax
