// The landing leg of issue 21 (osim_models/landing_leg.osim, docs/contact.md §5.2): running_leg's
// right leg dropped 5 cm onto three foot contact spheres, run by `redmax simulate` with the muscles
// lumped into the bones and carrying their physiological mass as mass points. Checks the first
// contact against free fall, the peak ground reaction from the summary, how far the spheres sink,
// the difference the muscles' inertia makes at the peak, and that the leg ends standing still.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <regex>
#include <string>

#include "converter/storage.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;
namespace fs = std::filesystem;
using redmax::osim::readStorage;
using redmax::osim::Storage;

constexpr double kG = 9.80665;
constexpr double kDrop = 0.05;      // the sole starts 5 cm above the ground (the model's header)
constexpr double kOutputDt = 2e-4;  // rows: the first contact and the peak force are sampled here

const std::string kTy = "/jointset/ground_pelvis/pelvis_ty/value";
const std::string kVy = "/jointset/ground_pelvis/pelvis_ty/speed";
const std::string kKnee = "/jointset/knee_r/knee_angle_r/value";

class LandingLegCli : public CliTempDirTest {
 protected:
  LandingLegCli() : CliTempDirTest("landing_leg_cli") {}
  CmdResult run(const std::string& args) const { return runRedmax(dir_, args); }
};

struct Landing {
  double first_contact = NAN;  // first row whose pelvis speed is no longer free fall (s)
  double peak_force = NAN;     // the summary's largest net contact force, y component (N)
  double peak_time = NAN;
  double penetration = NAN;    // the summary's largest penetration (m)
  double lowest = NAN;         // lowest pelvis height (m)
  double knee = NAN;           // largest knee flexion (rad, positive)
  double end_speed = NAN;      // largest |speed| of any coordinate at the end
  double end_knee = NAN;
};

Landing measure(const CmdResult& r, const Storage& s) {
  Landing l;
  const std::regex force(R"(largest net contact force [-0-9.e+]+ N \(y ([-0-9.e+]+) N\) at t = ([-0-9.e+]+))");
  const std::regex pen(R"(largest penetration ([-0-9.e+]+) m)");
  std::smatch m;
  if (std::regex_search(r.out, m, force)) {
    l.peak_force = std::stod(m[1]);
    l.peak_time = std::stod(m[2]);
  }
  if (std::regex_search(r.out, m, pen)) l.penetration = std::stod(m[1]);
  const int ty = s.findColumn(kTy), vy = s.findColumn(kVy), knee = s.findColumn(kKnee);
  if (ty < 0 || vy < 0 || knee < 0) return l;
  for (int i = 0; i < s.numRows(); ++i)
    if (std::abs(s.data(i, vy) + kG * s.time[i]) > 1e-6) {  // free fall: v = -g t from rest
      l.first_contact = s.time[i];
      break;
    }
  l.lowest = s.data.col(ty).minCoeff();
  l.knee = -s.data.col(knee).minCoeff();
  l.end_speed = 0.0;
  for (size_t j = 0; j < s.labels.size(); ++j)
    if (s.labels[j].size() > 6 && s.labels[j].compare(s.labels[j].size() - 6, 6, "/speed") == 0)
      l.end_speed = std::max(l.end_speed, std::abs(s.data(s.numRows() - 1, static_cast<int>(j))));
  l.end_knee = -s.data(s.numRows() - 1, knee);
  return l;
}

// Properties, not the runs' own numbers (those are in docs/contact.md §5.2, measured): free fall
// until the closed-form contact time, a peak well above the weight, the spheres sinking less than
// their radius, rest at the end in the crouch the hard-contact run also reaches, and a difference
// the muscles' inertia makes that is no larger than the share of mass it moves into the muscles.
TEST_F(LandingLegCli, LandsAtTheFreeFallTimeAndTheMusclesInertiaChangesThePeak) {
  const std::string base = "simulate --model " + scene("landing_leg.osim") +
                           " --duration 1 --rtol 1e-8 --atol 1e-10 --output-dt " + std::to_string(kOutputDt) +
                           " --full-precision --out ";
  const CmdResult rl = run(base + path("lumped.sto"));
  ASSERT_EQ(rl.code, 0) << rl.err;
  const CmdResult ri = run(base + path("inertial.sto") + " --muscle-mass physiological");
  ASSERT_EQ(ri.code, 0) << ri.err;
  const CmdResult rh = run("simulate --model " + scene("landing_leg.osim") +
                           " --integrator bdf1 --contact hard --dt 1e-3 --output-dt 1e-3 --duration 1 --full-precision "
                           "--out " + path("hard.sto"));
  ASSERT_EQ(rh.code, 0) << rh.err;
  EXPECT_NE(rl.out.find("contacts: 3 pairs, 3 active at the end"), std::string::npos) << rl.out;
  const Landing a = measure(rl, readStorage(path("lumped.sto")));
  const Landing b = measure(ri, readStorage(path("inertial.sto")));
  const Landing hard = measure(rh, readStorage(path("hard.sto")));
  std::printf("[ measured ] first contact %.4f / %.4f s (closed form %.5f s); peak GRF %.2f / %.2f N at %.4f / %.4f s;"
              " penetration %.4e / %.4e m; lowest pelvis %.5f / %.5f m; knee flexion %.4f / %.4f rad; at the end"
              " knee %.4f / %.4f rad (hard contact %.4f), largest speed %.2e / %.2e (lumped / inertial)\n",
              a.first_contact, b.first_contact, std::sqrt(2 * kDrop / kG), a.peak_force, b.peak_force, a.peak_time,
              b.peak_time, a.penetration, b.penetration, a.lowest, b.lowest, a.knee, b.knee, a.end_knee, b.end_knee,
              hard.end_knee, a.end_speed, b.end_speed);
  for (const Landing& l : {a, b}) {
    ASSERT_TRUE(std::isfinite(l.first_contact) && std::isfinite(l.peak_force) && std::isfinite(l.penetration) &&
                std::isfinite(l.lowest) && std::isfinite(l.knee) && std::isfinite(l.end_speed));
    // free fall until the sole touches at sqrt(2 h / g) = 0.10098 s; the first row off free fall
    // comes after it, once the Hertz force has changed the speed by 1e-6 m/s
    EXPECT_GT(l.first_contact, std::sqrt(2 * kDrop / kG));
    EXPECT_LT(l.first_contact, std::sqrt(2 * kDrop / kG) + 5 * kOutputDt);
    // the landing: a peak after the touch and well above the weight (22.655 kg, the model's mass)
    EXPECT_GT(l.peak_time, std::sqrt(2 * kDrop / kG));
    EXPECT_GT(l.peak_force, 2.0 * 22.655 * kG);
    // no sphere sinks as deep as its radius (the heel's 30 mm is the largest)
    EXPECT_GT(l.penetration, 0.0);
    EXPECT_LT(l.penetration, 0.03);
    // at rest at the end, in the crouch that the hard-contact run (no penetration) reaches too:
    // the compliant feet sit a few mm deep, so the two crouches differ a little (5.5e-3 rad, measured)
    EXPECT_LT(l.end_speed, 1e-3);
    EXPECT_NEAR(l.end_knee, hard.end_knee, 0.01);
  }
  // the muscles' inertia changes the landing: by a visible amount (above 0.1 % of the peak), but by
  // less than the share of the mass it moves from the bones into the muscles (0.712 kg of 22.655)
  const double share = 0.712 / 22.655;
  EXPECT_GT(std::abs(b.peak_force - a.peak_force), 1e-3 * a.peak_force);
  EXPECT_LT(std::abs(b.peak_force - a.peak_force), share * a.peak_force);
  EXPECT_GT(std::abs(b.knee - a.knee), 1e-4);
}

// the same drop with hard contact (docs/contact.md §6): the impact at the step that closes the
// contact, no penetration, at rest at the end
TEST_F(LandingLegCli, HardContactLandsWithoutPenetrationAndRests) {
  const CmdResult r = run("simulate --model " + scene("landing_leg.osim") +
                          " --integrator bdf1 --contact hard --dt 1e-3 --output-dt 1e-3 --duration 1 --full-precision --out " +
                          path("hard.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("unilateral: 0 joint limits, 3 contact pairs;"), std::string::npos) << r.out;
  const Storage s = readStorage(path("hard.sto"));
  const Landing l = measure(r, s);
  const std::regex pen(R"(unilateral: .* largest penetration ([-0-9.e+]+) \(m or rad\))");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, pen)) << r.out;
  const double penetration = std::stod(m[1]);
  std::printf("[ measured ] hard: first row off free fall %.4f s, lowest pelvis %.6f m, largest penetration %.2e m,"
              " knee flexion %.4f rad, at the end knee %.4f rad, largest speed %.2e\n",
              l.first_contact, l.lowest, penetration, l.knee, l.end_knee, l.end_speed);
  // the contact closes at 0.10098 s, in the step [0.100, 0.101] s, which takes the impact (§6.2):
  // its end is the first row off free fall (bdf1's free fall is v = -g t exactly)
  EXPECT_NEAR(l.first_contact, 0.101, 1e-3 / 2);
  // no sinking beyond the contact step's 1e-5 m slop; at rest at the end
  EXPECT_LT(penetration, 1e-5);
  EXPECT_LT(l.end_speed, 1e-5);
}

}  // namespace
