// Forward kinematics of every shared OpenSim model with mass: the core model built by the
// converter (converter/build) and the Simbody system built from that core model
// (plugin/simbody/model_to_simbody.hpp) give the same world pose of every body at the default
// pose and at 100 random coordinate vectors within range (fixed seed; ranges wider than +-pi rad
// or +-1 m clamped to those). Metric: max abs difference over the 9 rotation entries and the 3
// translation entries (metres) of X_GB; tolerance 1e-12. Bodies whose inertia Debian's Simbody
// refuses get OpenSim's isotropic fallback in both engines (poses do not depend on inertia).
// Models that do not convert, have no body with mass, or that Simbody's builder rejects are
// printed with the reason; rejections are a fixed list below, so a new one fails the test.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/build/inertia_fallback.hpp"
#include "converter/osim_reader.hpp"
#include "core/skeleton/kinematics.hpp"
#include "plugin/simbody/model_to_simbody.hpp"

namespace redmax {
namespace {

namespace fs = std::filesystem;
constexpr double kTol = 1e-12;
constexpr int kRandomPoses = 100;

std::string sharedOpenSimDir() { return std::string(REDMAX_SHARED_DIR) + "/opensim"; }

std::vector<std::string> allSharedModels() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(sharedOpenSimDir(), ec))
    if (e.is_regular_file() && e.path().extension() == ".osim") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

// the shared-folder-relative name, for messages
std::string rel(const std::string& path) { return fs::relative(path, sharedOpenSimDir()).string(); }

VecX defaultQ(const osim::ModelDescription& d) {
  VecX q(d.numDofs());
  for (int k = 0; k < d.numDofs(); ++k) q[k] = d.coordinates[k].default_value;
  return q;
}

// uniform within range; wide ranges clamped to +-pi (angles) or +-1 m (translations)
VecX randomQ(const osim::ModelDescription& d, std::mt19937& rng) {
  VecX q(d.numDofs());
  for (int k = 0; k < d.numDofs(); ++k) {
    const auto& c = d.coordinates[k];
    const double lim = c.motion_type == osim::MotionType::Translational ? 1.0 : std::numbers::pi;
    const double lo = std::clamp(c.range_min, -lim, lim);
    const double hi = std::clamp(c.range_max, -lim, lim);
    q[k] = hi > lo ? std::uniform_real_distribution<double>(lo, hi)(rng) : lo;
  }
  return q;
}

// max abs over rotation entries and translation (m) of X_GB, Simbody vs core, over all bodies
double poseDifference(const simbody::SimbodyModel& sm, const Model& m, const VecX& q,
                      int& worst_body) {
  State s{0.0, q, VecX::Zero(q.size())};
  SimTK::State sb = sm.default_state;
  simbody::setSimbodyState(sm, m, s, sb);
  sm.system.realize(sb, SimTK::Stage::Position);
  std::vector<Mat4> E;
  calcBodyPoses(m, q, E);
  double worst = 0.0;
  for (int i = 0; i < m.nb(); ++i) {
    const SimTK::Transform& X = sm.mobods[i].getBodyTransform(sb);
    double diff = 0.0;
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) diff = std::max(diff, std::abs(X.R()[r][k] - E[i](r, k)));
      diff = std::max(diff, std::abs(X.p()[r] - E[i](r, 3)));
    }
    if (!(diff <= worst)) {  // NaN counts as worst
      worst = diff;
      worst_body = i;
    }
  }
  return worst;
}

TEST(FkSharedModels, CoreAndSimbodyAgreeOnEveryBodyPose) {
  if (!fs::is_directory(sharedOpenSimDir()))
    GTEST_SKIP() << "shared OpenSim data not found at " << sharedOpenSimDir()
                 << "; this test needs the real OpenSim files";
  // models Simbody's builder is known to reject, with the reason investigated (see the report
  // printed below); any other rejection fails
  // ScapulothoracicJoint: the core joint is a Composite{Ellipsoid, offset, Revolute}, which
  // model_to_simbody does not map (OpenSim builds it as an Ellipsoid + massless bodies + Pin chain)
  const std::set<std::string> known_rejections = {
      "opensim-core/OpenSim/Tests/shared/ThoracoscapularShoulderModel.osim"};
  int compared = 0;
  std::vector<std::string> skipped, rejected, fallbacks;
  double worst_all = 0.0;
  for (const std::string& path : allSharedModels()) {
    SCOPED_TRACE(rel(path));
    osim::ModelDescription d;
    try {
      d = osim::readOsimModel(path);
    } catch (const std::exception& e) {
      skipped.push_back(rel(path) + ": does not convert: " + e.what());
      continue;
    }
    const bool has_mass = std::any_of(d.bodies.begin(), d.bodies.end(),
                                      [](const osim::BodyDesc& b) { return b.mass > 0.0; });
    if (!has_mass) {
      skipped.push_back(rel(path) + ": no body with mass");
      continue;
    }
    osim::BuildOptions opt;
    opt.simbody_compat = true;  // Simbody's FunctionBased mobilizer; poses are the same either way
    opt.constraints = false;    // kinematics of the tree only
    opt.muscles = false;
    osim::BuildResult r = osim::buildCoreModel(d, opt);
    // Debian's Simbody refuses inertias that break the triangle inequality (gait2392's toes);
    // poses do not depend on inertia, so use OpenSim's own fallback for those bodies
    const auto changed = osim::applyOpenSimInertiaFallback(r.model);
    for (const auto& b : changed) fallbacks.push_back(rel(path) + ": " + b);
    std::unique_ptr<simbody::SimbodyModel> sm;
    try {
      sm = simbody::makeSimbodyModel(r.model);
    } catch (const simbody::SimbodyBuildError& e) {
      rejected.push_back(rel(path) + ": " + e.what());
      EXPECT_TRUE(known_rejections.count(rel(path))) << "Simbody rejects: " << e.what();
      continue;
    }
    ++compared;
    double worst = 0.0;
    int body = -1;
    const double d0 = poseDifference(*sm, r.model, defaultQ(d), body);
    EXPECT_LE(d0, kTol) << "default pose, body " << r.model.skeleton().bodies()[std::max(body, 0)].name;
    worst = std::max(worst, d0);
    std::mt19937 rng(20261123);
    for (int t = 0; t < kRandomPoses; ++t) {
      const double dt = poseDifference(*sm, r.model, randomQ(d, rng), body);
      EXPECT_LE(dt, kTol) << "random pose " << t << ", body "
                          << r.model.skeleton().bodies()[std::max(body, 0)].name;
      worst = std::max(worst, dt);
    }
    worst_all = std::max(worst_all, worst);
    std::cout << "[fk] " << rel(path) << ": " << r.model.nb() << " bodies, " << r.model.nr()
              << " coordinates, max |X_GB(core) - X_GB(Simbody)| = " << worst << "\n";
  }
  for (const auto& s : skipped) std::cout << "[fk] skipped " << s << "\n";
  for (const auto& s : fallbacks) std::cout << "[fk] OpenSim inertia fallback for Simbody: " << s << "\n";
  for (const auto& s : rejected) std::cout << "[fk] Simbody rejects " << s << "\n";
  std::cout << "[fk] " << compared << " models compared at " << kRandomPoses + 1
            << " poses each, worst difference " << worst_all << "\n";
  // the shared data holds a few dozen models with mass: nearly all must be compared
  EXPECT_GE(compared, 25);
}


// ---------------------------------------------------------------------------------------------
// Legacy vs 4.0 copies of the same model: the 2017 files (opensim-models@a26e12c) and the current
// ones give the same body poses, body by body (by name), at the default pose and 100 random
// coordinate vectors (by coordinate name, within the current file's ranges). The current files
// were written by OpenSim 4 with 6 significant digits (docs/opensim_compatibility.md §1.4), and the reader
// applies the same 6-digit rounding to the legacy offsets, so the trees agree to round-off except
// where the newer file was edited afterwards (arm26's massless base body; gait2392 re-rounded).
struct LegacyPair {
  const char* legacy;
  const char* current;
  const char* current_root;  // body of the current file that stands where the legacy ground is
  double tol;                // max abs over rotation entries and translation (m)
  const char* why;
};

// body poses by name, relative to the body `root` ("" = ground)
std::map<std::string, Mat4> posesByName(const osim::ModelDescription& d, const osim::BuildResult& r,
                                        const VecX& q, const std::string& root = "") {
  std::vector<Mat4> E;
  calcBodyPoses(r.model, q, E);
  std::map<std::string, Mat4> out;
  for (size_t b = 0; b < d.bodies.size(); ++b)
    if (r.body_index[b] >= 0) out[d.bodies[b].name] = E[r.body_index[b]];
  if (!root.empty()) {
    const Mat4 X_root_inv = inverseE(out.at(root));
    out.erase(root);
    for (auto& [name, X] : out) X = X_root_inv * X;
  }
  return out;
}

TEST(FkLegacyCopies, SameBodyPosesAsTheCurrentFiles) {
  if (!fs::is_directory(sharedOpenSimDir()))
    GTEST_SKIP() << "shared OpenSim data not found at " << sharedOpenSimDir()
                 << "; this test needs the real OpenSim files";
  // arm26: the current copies add a massless `base` welded 0.8 m above ground and write 17
  // digits, so the arm is compared relative to base and agrees to round-off. gait10dof18musc:
  // OpenSim's own 4.0 upgrade, equal to the bit. gait2392: the current file was re-rounded to 6
  // significant digits (2023): a value v carries |dv| <= 5e-7 |v|, offsets are < 0.5 m and chains
  // are <= 6 joints deep, so poses may differ by a few 1e-7; the tolerance is 1e-6.
  const LegacyPair pairs[] = {
      {"opensim-models@a26e12c/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim",
       "opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim", "base", 1e-12,
       "17-digit file, relative to base"},
      {"opensim-models@a26e12c/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim",
       "opensim-models/Models/Arm26/arm26.osim", "base", 1e-12, "17-digit file, relative to base"},
      {"opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim",
       "opensim-models/Pipelines/Gait10dof18musc/OutputReference/subject01.osim", "", 1e-12,
       "OpenSim's own upgrade"},
      {"opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim",
       "opensim-models/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim", "", 1e-6,
       "6 significant digits"},
  };
  osim::BuildOptions opt;
  opt.constraints = false;
  opt.muscles = false;
  for (const auto& p : pairs) {
    SCOPED_TRACE(std::string(p.legacy) + " vs " + p.current);
    const auto a = osim::readOsimModel(sharedOpenSimDir() + "/" + p.legacy);
    const auto b = osim::readOsimModel(sharedOpenSimDir() + "/" + p.current);
    const auto ra = osim::buildCoreModel(a, opt);
    const auto rb = osim::buildCoreModel(b, opt);
    // q of the legacy model from named values of the current one (every legacy coordinate must
    // exist in the current file; extra current ones stay at their defaults)
    auto legacyQ = [&](const VecX& qb) {
      VecX qa = defaultQ(a);
      for (int k = 0; k < a.numDofs(); ++k) {
        const int j = b.findCoordinate(a.coordinates[k].name);
        EXPECT_GE(j, 0) << a.coordinates[k].name;
        if (j >= 0) qa[k] = qb[j];
      }
      return qa;
    };
    std::mt19937 rng(4);
    double worst = 0.0;
    int compared_bodies = 0;
    for (int t = 0; t <= kRandomPoses; ++t) {
      const VecX qb = t == 0 ? defaultQ(b) : randomQ(b, rng);
      const auto Ea = posesByName(a, ra, legacyQ(qb));
      const auto Eb = posesByName(b, rb, qb, p.current_root);
      compared_bodies = 0;
      for (const auto& [name, X] : Ea) {
        const auto it = Eb.find(name);
        if (it == Eb.end()) {
          ADD_FAILURE() << "body " << name << " is missing from the current file";
          continue;
        }
        ++compared_bodies;
        const double diff = (X - it->second).cwiseAbs().maxCoeff();
        if (!(diff <= p.tol))
          ADD_FAILURE() << (t == 0 ? "default pose" : "random pose " + std::to_string(t))
                        << ", body " << name << ": " << diff << " > " << p.tol;
        worst = std::max(worst, diff);
      }
    }
    EXPECT_GE(compared_bodies, 2);
    std::cout << "[legacy] " << p.legacy << " vs " << p.current << ": " << compared_bodies
              << " bodies, worst pose difference " << worst << " (tolerance " << p.tol << ", "
              << p.why << ")\n";
  }
}

}  // namespace
}  // namespace redmax
