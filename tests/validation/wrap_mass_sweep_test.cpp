// Graceful degradation with wrapping muscles ([D Sec. 6.2.8-6.2.9] extended to Type III): on
// Rajagopal 2016 (40 WrapCylinders; ../shared/opensim) with the walking coordinates of OpenSim's
// wrapping test, every muscle of the supported shape (origin, one wrap object, insertion) takes
// its physiological mass over the smooth wrap model, and the inverse-dynamics torques go to the
// massless (OpenSim) torques linearly in the mass:
//   - ratio test: (tau(s) - tau(0)) / s equals tau(1) - tau(0) for s = 1e-4 and 0.5, every column
//     and frame, to 5e-10 (s = 1e-4: round-off ~1e-14 / 1e-4) and 2e-13 (s = 0.5) of the column peak;
//   - at zero mass the sweep reproduces the massless torques to 1e-12 of the peak;
//   - the wrapping muscles' own share is not zero (the same sweep without wrap mass differs);
//   - the sweep reports how many wrapping muscles carry mass and why each other one stays lumped.
// Skipped with a message when ../shared is absent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "validation/mass_sweep.hpp"

namespace {

namespace fs = std::filesystem;
using redmax::MatX;
using redmax::osim::MuscleMassOptions;
using Source = MuscleMassOptions::Source;

struct SharedTrial {
  std::string model, coordinates;
};

SharedTrial rajagopal() {
  const std::string base = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  return {base + "opensim-models/Models/Rajagopal/Rajagopal2016.osim",
          base + "opensim-core/OpenSim/Moco/Test/subject_walk_armless_coordinates.mot"};
}

TEST(WrapMassSweep, RajagopalWrappingMusclesGoToTheMasslessTorquesLinearly) {
  const SharedTrial t = rajagopal();
  for (const auto& f : {t.model, t.coordinates})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  redmax::osim::IdToolSettings st;
  st.model_file = t.model;
  st.coordinates_file = t.coordinates;
  st.lowpass_cutoff_hz = 6.0;
  st.t0 = 0.2;
  st.t1 = 0.6;  // 41 frames: enough poses for the wrap events, a few seconds of test time
  const redmax::osim::InverseDynamicsTool tool(redmax::osim::resolveIdSettings(st));
  redmax::osim::CoreIdEngine massless(tool.model(), tool.engineOptions());
  redmax::osim::Storage tau0 = tool.run(massless);
  tau0.name = redmax::osim::kIdStorageName;

  redmax::validation::MassSweepOptions so;
  so.base.source = Source::Physiological;
  so.base.mass_points = 10;
  so.base.wrap_mass = true;  // smooth model, default width
  // 0.85 of the default density: since the smooth model composes the gastrocnemii's two cylinders
  // (issue 22) all 42 wrapping muscles carry mass, and at full density tibia_r's inertia would
  // break the triangle inequality (the converter refuses, as it does for the exact model)
  so.base.density = 0.85 * redmax::osim::kDefaultMuscleDensity;
  so.values = {0.0, 1e-4, 0.5, 1.0};
  const auto r = redmax::validation::runMassSweep(tool, tau0, so);
  ASSERT_EQ(r.torques.size(), 4u);

  // who carries mass
  const redmax::osim::WrapMassCount& wc = r.points.back().wrap;
  EXPECT_GE(wc.wrapping, 40) << "Rajagopal 2016 has 40 wrap cylinders used by more than 40 paths";
  EXPECT_GE(wc.with_mass, 1);
  EXPECT_EQ(wc.with_mass + static_cast<int>(wc.lumped.size()), wc.wrapping);
  for (const auto& [name, why] : wc.lumped) EXPECT_FALSE(why.empty()) << name;
  std::printf("[ measured ] Rajagopal2016 %s", redmax::validation::formatWrapMassCount(wc).c_str());

  // linear in the mass, to the massless torques at zero. Round-off scales with the torques, so the
  // ratio defects are relative to the larger of the zero-mass peak and the peak at full mass (the
  // knee_angle_*_beta columns carry almost no load without muscle mass, 0.09 N)
  const MatX& t0 = r.torques[0].data;
  const MatX d1 = r.torques[3].data - t0;
  const Eigen::VectorXd peak = tau0.data.cwiseAbs().colwise().maxCoeff().transpose();
  const Eigen::VectorXd peak1 = r.torques[3].data.cwiseAbs().colwise().maxCoeff().transpose();
  double zero = 0, ratio_small = 0, ratio_half = 0, effect = 0;
  std::string effect_col;
  for (int c = 0; c < t0.cols(); ++c) {
    if (!(peak(c) > 1e-9)) continue;  // columns without load (locked or absent coordinates)
    const double scale = std::max(peak(c), peak1(c));
    zero = std::max(zero, (t0.col(c) - tau0.data.col(c)).cwiseAbs().maxCoeff() / peak(c));
    ratio_small =
        std::max(ratio_small, ((r.torques[1].data.col(c) - t0.col(c)) / 1e-4 - d1.col(c)).cwiseAbs().maxCoeff() / scale);
    ratio_half =
        std::max(ratio_half, ((r.torques[2].data.col(c) - t0.col(c)) / 0.5 - d1.col(c)).cwiseAbs().maxCoeff() / scale);
    const std::string& name = tau0.labels[static_cast<size_t>(c)];
    const double e = d1.col(c).cwiseAbs().maxCoeff() / peak(c);
    if (name.find("_moment") != std::string::npos && e > effect) effect = e, effect_col = name;
  }
  EXPECT_LE(zero, 1e-12);
  EXPECT_LE(r.analysis.zero_max_rel, 1e-12);
  EXPECT_LE(ratio_small, 5e-10);  // measured 4.7e-11 (difference quotient at 1e-4: round-off / 1e-4)
  EXPECT_LE(ratio_half, 2e-13);   // measured 1.1e-14
  EXPECT_GT(effect, 1e-4);

  // the wrapping muscles' share: the same largest value without wrap mass
  MuscleMassOptions lumped = so.base;
  lumped.wrap_mass = false;
  auto e = redmax::validation::makeCoreMassEngineFactory(tool)(lumped);
  const redmax::osim::Storage tl = tool.run(*e.engine);
  double wrap_share = 0;
  std::string wrap_col;
  for (int c = 0; c < t0.cols(); ++c) {
    const std::string& name = tau0.labels[static_cast<size_t>(c)];
    if (!(peak(c) > 1e-9) || name.find("_moment") == std::string::npos) continue;
    const double s = (r.torques[3].data.col(c) - tl.data.col(c)).cwiseAbs().maxCoeff() / peak(c);
    if (s > wrap_share) wrap_share = s, wrap_col = name;
  }
  EXPECT_GT(wrap_share, 1e-2);
  EXPECT_EQ(e.wrap.with_mass, 0);
  std::printf("[ measured ] Rajagopal2016 physiological, %d frames, %.3f kg in %d muscles (%.3f kg without wrap "
              "mass): largest change of a moment %.3g of the %s peak; wrapping muscles' share up to %.3g of the %s "
              "peak; zero %.2g, ratio defects %.2g (1e-4) %.2g (0.5)\n",
              tool.numFrames(), r.points.back().muscle_mass, r.points.back().muscles_with_mass, e.muscle_mass, effect,
              effect_col.c_str(), wrap_share, wrap_col.c_str(), zero, ratio_small, ratio_half);
}

}  // namespace
