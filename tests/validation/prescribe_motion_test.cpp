// Hybrid dynamics from a motion file (validation/simulate/prescribe_motion.hpp, `redmax simulate
// --prescribe`): with every coordinate prescribed the prescriptions' forces are the motion's inverse
// dynamics (the ID tool, a different code path: recursive Newton-Euler on the same splines), with and
// without muscle mass; with some prescribed, the prescribed coordinates follow the splines, the free
// ones move, and the work of the prescription forces equals the change of the system's energy.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "converter/error.hpp"
#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/storage.hpp"
#include "validation/simulate/prescribe_motion.hpp"

namespace redmax::validation {
namespace {

const std::string kModel = std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg.osim";
const std::string kMotion = std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg_swing.mot";

struct PrescribedRun {
  SimulationModel model;
  MotionPrescription p;
  SimulationResult res;
  osim::Storage forces;
};

PrescribedRun runPrescribed(const std::vector<std::string>& coordinates, bool muscle_mass, double output_dt) {
  PrescribedRun r;
  SimulationModelOptions mo;
  if (muscle_mass) mo.muscle_mass.source = osim::MuscleMassOptions::Source::Physiological;
  r.model = loadSimulationModel(kModel, mo);
  MotionPrescriptionOptions po;
  po.coordinates = coordinates;
  r.p = prescribeMotion(r.model, osim::readStorage(kMotion), kMotion, po);
  State s0 = defaultInitialState(r.model);
  s0.t = r.p.t_first;
  applyPrescription(r.model, r.p, s0);
  SimulateOptions so;
  so.integrator = "rk45";
  so.integrator_options.rtol = so.integrator_options.atol = 1e-10;
  so.duration = r.p.t_last - r.p.t_first;
  so.output_dt = output_dt;
  PrescribedForceRecorder rec(r.model, r.p);
  so.check = rec.check();
  r.res = simulate(r.model, s0, so);
  r.forces = rec.table();
  return r;
}

osim::Storage inverseDynamics(bool muscle_mass) {
  osim::IdToolSettings s;
  s.model_file = kModel;
  s.coordinates_file = kMotion;
  s.opensim_compat = false;  // the exact kinematics the simulation integrates
  if (muscle_mass) s.muscle_mass.source = osim::MuscleMassOptions::Source::Physiological;
  const osim::InverseDynamicsTool tool(osim::resolveIdSettings(s));
  osim::CoreIdEngine engine(tool.musculoskeletalModel(), tool.engineOptions());
  return tool.run(engine);
}

TEST(PrescribeMotion, EveryCoordinatePrescribedGivesTheInverseDynamics) {
  for (const bool mass : {false, true}) {
    SCOPED_TRACE(mass ? "physiological muscle mass" : "lumped");
    const PrescribedRun r = runPrescribed({}, mass, 0.005);
    ASSERT_FALSE(r.res.failed) << r.res.failure;
    ASSERT_EQ(r.p.coordinates.size(), 11u);
    const osim::Storage id = inverseDynamics(mass);
    ASSERT_EQ(id.labels.size(), r.forces.labels.size());
    int compared = 0;
    double worst = 0.0;
    for (int c = 0; c < id.numColumns(); ++c) {
      const int j = r.forces.findColumn(id.labels[c]);
      ASSERT_GE(j, 0) << id.labels[c];
      const double peak = id.data.col(c).cwiseAbs().maxCoeff();
      for (int row = 0; row < id.numRows(); ++row)
        for (int k = 0; k < r.forces.numRows(); ++k)
          if (std::abs(r.forces.time[k] - id.time[row]) < 1e-9) {
            worst = std::max(worst, std::abs(r.forces.data(k, j) - id.data(row, c)) / peak);
            ++compared;
          }
    }
    // measured 3.2e-9 (lumped) and 1.1e-8 (with mass) of each column's peak: the simulated state
    // departs from the splines by the rk45 error at 1e-10; muscle mass changes them by 10%
    EXPECT_LT(worst, 1e-7);
    EXPECT_EQ(compared, id.numRows() * id.numColumns());
  }
}

TEST(PrescribeMotion, PartlyPrescribedFollowsTheMotionAndItsForcesDoTheWork) {
  const std::vector<std::string> driven = {"pelvis_tilt", "pelvis_list", "pelvis_rotation", "pelvis_tx", "pelvis_ty",
                                           "pelvis_tz",   "hip_flexion_r", "hip_adduction_r", "hip_rotation_r"};
  const PrescribedRun r = runPrescribed(driven, false, 0.001);
  ASSERT_FALSE(r.res.failed) << r.res.failure;
  ASSERT_EQ(r.p.coordinates, driven);
  const osim::Storage& st = r.res.states;
  const int nr = r.model.system->model().nr();
  // the prescribed coordinates are the splines to the integration error; the knee swings freely
  double follow = 0.0, knee_lo = 1e9, knee_hi = -1e9;
  int knee = -1;
  for (int i = 0; i < nr; ++i)
    if (r.model.coordinate_names[i] == "knee_angle_r") knee = i;
  ASSERT_GE(knee, 0);
  VecX qp, qdp;
  for (int row = 0; row < st.numRows(); ++row) {
    r.p.values(st.time[row], qp, qdp);
    for (size_t c = 0; c < r.p.q_index.size(); ++c)
      follow = std::max(follow, std::abs(st.data(row, r.p.q_index[c]) - qp[static_cast<Eigen::Index>(c)]));
    knee_lo = std::min(knee_lo, st.data(row, knee));
    knee_hi = std::max(knee_hi, st.data(row, knee));
  }
  EXPECT_LT(follow, 1e-8);
  EXPECT_GT(knee_hi - knee_lo, 1.0);  // measured -0.70 .. 0.79 rad
  // E(t) - E(t0) = integral of sum_k tau_k qdot_k over the prescribed coordinates (no other force
  // does work: gravity is in E); trapezoid rule on the 1 ms rows
  const int e_col = st.findColumn("total_energy");
  ASSERT_GE(e_col, 0);
  double work = 0.0, worst = 0.0, change = 0.0;
  auto power = [&](int row) {
    double p = 0.0;
    for (size_t c = 0; c < r.p.q_index.size(); ++c)
      p += r.forces.data(row, static_cast<Eigen::Index>(c)) * st.data(row, nr + r.p.q_index[c]);
    return p;
  };
  ASSERT_EQ(r.forces.numRows(), st.numRows());
  for (int row = 1; row < st.numRows(); ++row) {
    work += 0.5 * (power(row) + power(row - 1)) * (st.time[row] - st.time[row - 1]);
    const double dE = st.data(row, e_col) - st.data(0, e_col);
    change = std::max(change, std::abs(dE));
    worst = std::max(worst, std::abs(dE - work));
  }
  // measured: 4.3e-4 J against a 26 J change (the trapezoid rule's O(h^2) error)
  EXPECT_GT(change, 10.0);
  EXPECT_LT(worst, 1e-4 * change);
}

TEST(PrescribeMotion, BadRequestsNameTheFile) {
  auto expectError = [](const std::vector<std::string>& coords, const std::string& want) {
    SimulationModel m = loadSimulationModel(kModel, {});
    MotionPrescriptionOptions po;
    po.coordinates = coords;
    try {
      prescribeMotion(m, osim::readStorage(kMotion), kMotion, po);
      ADD_FAILURE() << "no error for " << want;
    } catch (const osim::ConvertError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(kMotion + ":", 0), 0u) << what;
      EXPECT_NE(what.find(want), std::string::npos) << what;
    }
  };
  expectError({"no_such_coordinate"}, "the model has no coordinate 'no_such_coordinate'");
  expectError({"knee_angle_r", "knee_angle_r"}, "named twice");
  // a motion without the coordinate's column
  SimulationModel m = loadSimulationModel(kModel, {});
  osim::Storage motion = osim::readStorage(kMotion);
  const int knee = motion.findColumn("knee_angle_r");
  ASSERT_GE(knee, 0);
  motion.labels[knee] = "something_else";
  MotionPrescriptionOptions po;
  po.coordinates = {"knee_angle_r"};
  EXPECT_THROW(prescribeMotion(m, motion, kMotion, po), osim::ConvertError);
}

}  // namespace
}  // namespace redmax::validation
