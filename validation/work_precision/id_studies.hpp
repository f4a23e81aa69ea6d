#pragma once
// Inverse-dynamics studies of the work-precision report (`redmax work-precision --studies
// masspoints,reduction`), on a real gait trial solved by the core (converter/id/core_id_engine.hpp)
// with physiological muscle mass (converter/build/muscle_mass.hpp):
//
//   masspoints  ID torques with N mass points per muscle against a converged reference (500 points),
//               N = 2, 5, 10, 20, 50, 100; cost = CPU time per frame of the engine.
//   reduction   only the top-K muscles by inertia contribution carry mass (MuscleMassOptions::muscles =
//               "top:K"), K = 0, 1, 2, 5, 10, all, against all muscles with mass; K = 0 is the model
//               without muscle mass (Source::None: top:K needs K >= 1), K = all is top:<candidates>.
//
// Error of a result tau against a reference tau_ref (both frames x columns):
//   err_effect = max over columns c with an inertial effect of
//                  max_k |tau(k,c) - tau_ref(k,c)| / max_k |tau_ref(k,c) - tau_0(k,c)|
//                where tau_0 is the zero-mass result and "with an inertial effect" means
//                max_k |tau_ref - tau_0| > 1e-12 (max_k |tau_ref| + 1)
//   err_peak   = max over columns of max_k |tau - tau_ref| / max_k |tau_ref|
// Mass points sit at the midpoints of N equal cells of each fibre [D Sec. 5.2], so the muscles' mass
// matrix is a midpoint-rule quadrature of the continuous fibre: its error falls as 1/N^2 where the
// integrand is smooth; the body each point's mass is taken from (nearest bone at the default pose)
// changes discretely with N and adds a part that falls only as 1/N.
//
// Trial: set F of ../shared/opensim (gait10dof18musc, 151 frames with GRFs, 0-2.5 s, 6 Hz lowpass);
// when the shared data is absent, or in quick mode, the project's running leg
// (osim_models/running_leg.osim with running_leg_swing.mot, no external loads), and the report
// says so.
#include <iosfwd>
#include <string>
#include <vector>

#include "converter/build/muscle_mass.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "validation/report/report.hpp"

namespace redmax::validation {

struct IdStudyOptions {
  std::string models_dir;   ///< osim_models (the running leg)
  std::string shared_dir;   ///< the shared data folder holding opensim/ ("" or absent: running leg)
  bool quick = false;       ///< the running leg and N = 2, 5, 10, 20, 50
  std::vector<int> mass_points = {2, 5, 10, 20, 50, 100};  ///< N per muscle (quick: 2, 5, 10, 20, 50)
  int reference_points = 500;                               ///< the converged reference
  std::vector<int> top_k = {0, 1, 2, 5, 10};                ///< K; "all" is always added
  double target = 0.01;     ///< the recommendation: smallest N with err_effect below this
  double min_timing_s = 0.05;  ///< each timing repeats the frames until this much CPU time (<= 5 times)
};

/// The trial both studies use.
struct IdStudyTrial {
  std::string name;          ///< "set F" or "running leg"
  std::string description;   ///< model, motion, loads, frames
  bool fallback = false;     ///< the running leg because the shared data was absent
  std::string note;          ///< why the running leg was used ("" for set F)
  osim::IdToolSettings settings;  ///< muscle mass none; the studies set it per run
};

/// Set F when shared_dir/opensim has its files and !quick, else the running leg (note says why).
/// Throws std::invalid_argument when models_dir lacks the running leg in that case.
IdStudyTrial chooseIdStudyTrial(const IdStudyOptions& options);

/// Errors of one result (see the file comment).
struct IdStudyError {
  double err_effect = 0.0;
  double err_peak = 0.0;
  std::string worst_column;  ///< the column of err_effect
};

/// err_effect and err_peak of tau against tau_ref with zero-mass tau_0 (same shapes; labels name the
/// columns). Throws std::invalid_argument on shape mismatches.
IdStudyError calcIdStudyError(const MatX& tau, const MatX& tau_ref, const MatX& tau_0,
                              const std::vector<std::string>& labels);

/// One run of a study.
struct IdStudyRow {
  std::string label;           ///< "N" or "K" ("all" for every candidate)
  int value = 0;               ///< N or K
  int muscles_with_mass = 0;
  int points_total = 0;        ///< mass points over all muscles
  double muscle_mass = 0.0;    ///< kg on mass points
  IdStudyError error;
  double cpu_per_frame_s = 0.0;  ///< engine only (inputs precomputed), fastest repeat, thread CPU
  MatX tau;                      ///< frames x columns
};

struct IdStudiesResult {
  IdStudyTrial trial;
  int frames = 0, ndof = 0;
  std::vector<std::string> labels;
  MatX tau_0;                       ///< zero-mass result
  double cpu_per_frame_zero_s = 0;  ///< the zero-mass engine
  // masspoints
  bool has_masspoints = false;
  IdStudyRow reference;             ///< N = reference_points
  std::vector<IdStudyRow> masspoints;
  int recommended_points = -1;      ///< smallest N with err_effect < target (-1: none)
  double target = 0.01;
  // reduction
  bool has_reduction = false;
  IdStudyRow all_muscles;           ///< MuscleMassOptions::muscles = "all"
  std::vector<IdStudyRow> reduction;
  std::vector<std::pair<std::string, double>> ranking;  ///< top:K ranking (muscle, inertia share)
};

/// Run the chosen studies ("masspoints", "reduction") on the trial. progress (may be null) gets a
/// line per run. Throws osim::ConvertError for unreadable trial files, std::invalid_argument for an
/// unknown study name.
IdStudiesResult runIdStudies(const IdStudyOptions& options, const std::vector<std::string>& studies,
                             std::ostream* progress = nullptr);

/// CSV tables id_masspoints.csv / id_reduction.csv, plots id_masspoints (error and CPU per frame
/// against N, log-log) and id_reduction (error against CPU per frame), report.md sections with the
/// recommendation, summary.json "id_studies".
void addIdStudiesToReport(const IdStudiesResult& r, Report& report);

}  // namespace redmax::validation
