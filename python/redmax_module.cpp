// The `redmax` Python module's compiled half (redmax._core, pybind11; docs/python.md). Thin: every
// computation is a library entry point the CLI uses too (converter/osim_reader.hpp,
// converter/id/inverse_dynamics_tool.hpp, validation/lengths/path_lengths.hpp,
// validation/forward/forward_tool.hpp, converter/analyze/analyze_tool.hpp,
// validation/id_validation.hpp, converter/storage.hpp), and the keywords are parsed by the CLI's
// own flag declarations (cli/*_flags.hpp). Long calls release the GIL; errors raise
// redmax.ConvertError (bad input, message "FILE[:LINE]: what", as the CLI prints it) or
// redmax.Error (a run that failed).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/numpy.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/analyze_flags.hpp"
#include "cli/forward_flags.hpp"
#include "cli/id_flags.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "cli/validate_flags.hpp"
#include "converter/analyze/analyze_tool.hpp"
#include "converter/error.hpp"
#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/json_writer.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/forward/forward_tool.hpp"
#include "validation/id_validation.hpp"
#include "validation/lengths/path_lengths.hpp"

namespace py = pybind11;
using namespace redmax;

namespace {

// --- NumPy without copies: the arrays own what the library computed --------------------------

// a matrix as a NumPy array (rows x columns, Fortran order) that keeps the matrix alive
py::array_t<double> ownedMatrix(MatX m) {
  auto* heap = new MatX(std::move(m));
  py::capsule owner(heap, [](void* p) { delete static_cast<MatX*>(p); });
  const auto r = static_cast<py::ssize_t>(heap->rows()), c = static_cast<py::ssize_t>(heap->cols());
  const py::ssize_t s = sizeof(double);
  return py::array_t<double>({r, c}, {s, s * std::max<py::ssize_t>(r, 1)}, heap->data(), owner);
}

py::array_t<double> ownedVector(std::vector<double> v) {
  auto* heap = new std::vector<double>(std::move(v));
  py::capsule owner(heap, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return py::array_t<double>({static_cast<py::ssize_t>(heap->size())}, {sizeof(double)}, heap->data(), owner);
}

// a Storage as the Python-side Table's parts: (name, labels, time, values rows x columns, in_degrees)
py::tuple toPython(osim::Storage s) {
  return py::make_tuple(s.name, s.labels, ownedVector(std::move(s.time)), ownedMatrix(std::move(s.data)),
                        s.in_degrees);
}

using InArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

osim::Storage fromPython(const std::string& name, const std::vector<std::string>& labels, InArray time,
                         InArray values, bool in_degrees) {
  if (time.ndim() != 1 || values.ndim() != 2 || values.shape(0) != time.shape(0) ||
      values.shape(1) != static_cast<py::ssize_t>(labels.size()))
    throw std::invalid_argument("values must be len(time) x len(labels)");
  osim::Storage s;
  s.name = name;
  s.version = 1;
  s.in_degrees = in_degrees;
  s.labels = labels;
  s.time.assign(time.data(), time.data() + time.shape(0));
  s.data = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      values.data(), values.shape(0), values.shape(1));
  return s;
}

// row k of a C-ordered (frames x n) array
VecX row(const InArray& a, py::ssize_t k) {
  return Eigen::Map<const VecX>(a.data() + k * a.shape(1), a.shape(1));
}

// --- the CLI's flag declarations parse the keywords --------------------------------------------

// parse `flags` (keywords turned into flags by python/redmax/__init__.py) on `app`; CLI11 and
// usage errors become ValueError with the command line's message
void parseFlags(CLI::App& app, std::vector<std::string> flags) {
  try {
    std::reverse(flags.begin(), flags.end());  // CLI11 parses a reversed vector
    app.parse(flags);
  } catch (const CLI::ParseError& e) {
    throw std::invalid_argument(e.what());
  }
}

template <class F>
auto usage(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const cli::UsageError& e) {
    throw std::invalid_argument(e.message);
  }
}

// ModelError, MuscleModelError and bad settings of a setup-driven tool, named by the setup file
// as the CLI prints them
template <class F>
auto namedBySetup(const std::string& setup, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const osim::ConvertError&) {
    throw;
  } catch (const ModelError& e) {
    throw osim::ConvertError(setup, 0, e.what());
  } catch (const hill::MuscleModelError& e) {
    throw osim::ConvertError(setup, 0, e.what());
  } catch (const std::invalid_argument& e) {
    throw osim::ConvertError(setup, 0, e.what());
  }
}

struct PyModel {
  std::string path;
  osim::ModelDescription description;
};

PyModel loadModel(const std::string& path) {
  PyModel m;
  m.path = path;
  py::gil_scoped_release release;
  m.description = osim::readOsimModel(path);
  return m;
}

// --- inverse dynamics of a trial ------------------------------------------------------------

// `redmax id`'s input flags (cli/id_flags.hpp), parsed by the CLI's own declarations: the same
// defaults, checks and messages as the command line. With `with_inputs` also what the tool gave
// the engine per frame: q, qdot, qddot (frames x nr) and the external loads.
py::tuple inverseDynamics(std::vector<std::string> flags, bool with_inputs) {
  CLI::App app("redmax.inverse_dynamics", "inverse_dynamics");
  cli::IdInputFlags f;
  cli::addIdInputFlags(app, f);
  parseFlags(app, std::move(flags));
  osim::IdToolSettings s = usage([&] {
    osim::IdToolSettings x = cli::parseIdInputFlags(f, app, "inverse_dynamics");
    x.muscle_mass = cli::parseMuscleMassFlags(f.muscle_mass);
    return x;
  });
  osim::Storage result;
  MatX Q, V, A;
  std::vector<std::vector<osim::IdLoadSample>> loads;
  std::vector<std::string> body_names;
  {
    py::gil_scoped_release release;
    // what `redmax id` (engine core) does, from the same entry points
    const osim::IdToolConfig config = osim::resolveIdSettings(s);
    osim::InverseDynamicsTool tool(config);
    osim::CoreIdEngine engine(tool.musculoskeletalModel(), tool.engineOptions());
    result = tool.run(engine);
    if (with_inputs) {
      const int n = tool.numFrames(), nr = tool.model().nr();
      Q.resize(n, nr);
      V.resize(n, nr);
      A.resize(n, nr);
      VecX q, v, vdot;
      for (int k = 0; k < n; ++k) {
        loads.emplace_back();
        tool.calcInputs(tool.frameTime(k), q, v, vdot, loads.back());
        Q.row(k) = q.transpose();
        V.row(k) = v.transpose();
        A.row(k) = vdot.transpose();
      }
      for (const Body& b : tool.model().bodies()) body_names.push_back(b.name);
    }
  }
  py::object inputs = py::none();
  if (with_inputs) {
    // the loads as (body, force, point, torque) per ExternalForce, each (frames x 3) or None, in
    // ground; a load expressed in a body frame is not representable here and is refused
    py::list py_loads;
    const size_t nl = loads.empty() ? 0 : loads.front().size();
    for (size_t j = 0; j < nl; ++j) {
      const osim::IdLoadSample& l0 = loads.front()[j];
      if (l0.force_frame >= 0 || (l0.has_point && l0.point_frame >= 0))
        throw std::invalid_argument("the external loads are expressed in a body frame: the inputs hold loads in ground only");
      MatX F(loads.size(), 3), P(loads.size(), 3), T(loads.size(), 3);
      for (size_t k = 0; k < loads.size(); ++k) {
        F.row(k) = loads[k][j].force.transpose();
        P.row(k) = loads[k][j].point.transpose();
        T.row(k) = loads[k][j].torque.transpose();
      }
      py::dict d;
      d["body"] = body_names.at(l0.body);
      d["force"] = l0.has_force ? py::object(ownedMatrix(F)) : py::none();
      d["point"] = l0.has_point ? py::object(ownedMatrix(P)) : py::none();
      d["torque"] = l0.has_torque ? py::object(ownedMatrix(T)) : py::none();
      py_loads.append(d);
    }
    py::dict in;
    in["q"] = ownedMatrix(std::move(Q));
    in["qdot"] = ownedMatrix(std::move(V));
    in["qddot"] = ownedMatrix(std::move(A));
    in["loads"] = py_loads;
    inputs = in;
  }
  return py::make_tuple(toPython(std::move(result)), inputs);
}

// --- a model with muscle mass, built as the ID tool builds it, for arrays -----------------------

struct ArrayModel {
  osim::ModelDescription description;
  std::unique_ptr<osim::BuildResult> build;
  osim::IdEngineOptions engine_options;
};

// --model, --exact and the MUSCLE-MASS OPTIONS of `redmax id` (the inputs that need a file,
// --coordinates and the others, are refused: the arrays are the motion); `samples` are the frames
// over which --muscles top:K ranks
ArrayModel arrayModel(std::vector<std::string> flags, const std::string& what, const std::vector<VecX>& samples) {
  CLI::App app("redmax." + what, what);
  cli::IdInputFlags f;
  cli::addIdInputFlags(app, f);
  parseFlags(app, std::move(flags));
  for (const char* n : {"--setup", "--coordinates", "--external-loads", "--lowpass", "--t0", "--t1", "--forces-to-exclude"})
    if (cli::given(app, n)) throw std::invalid_argument(std::string(n) + " does not apply to " + what + " of arrays");
  if (!cli::given(app, "--model")) throw std::invalid_argument(what + " needs a model");
  if (f.exact && f.opensim_compat) throw std::invalid_argument("--exact and --opensim-compat exclude each other");
  const osim::MuscleMassOptions mm = usage([&] { return cli::parseMuscleMassFlags(f.muscle_mass); });
  ArrayModel m;
  py::gil_scoped_release release;
  m.description = osim::readOsimModel(f.model);
  osim::BuildOptions bo;  // as InverseDynamicsTool builds it
  bo.simbody_compat = !f.exact;
  bo.constraints = false;
  bo.muscles = mm.source != osim::MuscleMassOptions::Source::None;
  try {
    m.build = std::make_unique<osim::BuildResult>(osim::buildCoreModel(m.description, bo));
    if (mm.source != osim::MuscleMassOptions::Source::None) {
      osim::MuscleMassModel with_mass = osim::addMuscleMass(m.description, *m.build, mm, samples);
      m.build = std::make_unique<osim::BuildResult>(std::move(with_mass.build));
    }
  } catch (const osim::ConvertError&) {
    throw;
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw osim::ConvertError(f.model, 0, std::string("the core cannot build this model: ") + e.what());
  }
  m.engine_options = osim::idEngineOptions(m.description, *m.build, !f.exact);
  return m;
}

std::vector<VecX> rows(const InArray& q) {
  std::vector<VecX> out;
  for (py::ssize_t k = 0; k < q.shape(0); ++k) out.push_back(row(q, k));
  return out;
}

void checkFrames(const InArray& a, const char* name, py::ssize_t n, int nr) {
  if (a.ndim() != 2 || a.shape(0) != n || a.shape(1) != nr)
    throw std::invalid_argument(std::string(name) + " must be frames x " + std::to_string(nr) + " (the model's coordinates in q order), got " +
                                (a.ndim() == 2 ? std::to_string(a.shape(0)) + " x " + std::to_string(a.shape(1))
                                               : std::to_string(a.ndim()) + " dimensions"));
}

// tau = ID(q, qdot, qddot, loads) per frame with the core engine `redmax id` uses (muscle mass
// included); loads: dicts {body, force, point, torque}, arrays (frames x 3) in ground or None
py::tuple inverseDynamicsArrays(std::vector<std::string> flags, InArray time, InArray q, InArray qdot, InArray qddot,
                                const py::list& py_loads) {
  if (q.ndim() != 2) throw std::invalid_argument("q must be frames x coordinates");
  const ArrayModel m = arrayModel(std::move(flags), "inverse_dynamics", rows(q));
  const Model& skel = m.build->model.skeleton();
  const int nr = skel.nr();
  const py::ssize_t n = q.shape(0);
  checkFrames(q, "q", n, nr);
  checkFrames(qdot, "qdot", n, nr);
  checkFrames(qddot, "qddot", n, nr);
  if (time.ndim() != 1 || time.shape(0) != n) throw std::invalid_argument("time must have one entry per frame");
  struct Load {
    osim::IdLoadSample sample;
    std::optional<InArray> force, point, torque;
  };
  std::vector<Load> loads;
  for (const py::handle h : py_loads) {
    const py::dict d = py::reinterpret_borrow<py::dict>(h);
    Load l;
    const std::string body = py::cast<std::string>(d["body"]);
    l.sample.body = skel.findBody(body);
    if (l.sample.body < 0) throw std::invalid_argument("a load on '" + body + "': no such body in the model");
    auto take = [&](const char* key, std::optional<InArray>& out, bool& has) {
      if (!d.contains(key) || d[key].is_none()) return;
      out = py::cast<InArray>(d[key]);
      if (out->ndim() != 2 || out->shape(0) != n || out->shape(1) != 3)
        throw std::invalid_argument("a load's " + std::string(key) + " must be frames x 3");
      has = true;
    };
    take("force", l.force, l.sample.has_force);
    take("point", l.point, l.sample.has_point);
    take("torque", l.torque, l.sample.has_torque);
    loads.push_back(std::move(l));
  }
  MatX tau_all(n, nr);
  {
    py::gil_scoped_release release;
    osim::CoreIdEngine engine(m.build->model, m.engine_options);
    osim::CoreIdWorkspace ws(engine.system());
    std::vector<osim::IdLoadSample> samples(loads.size());
    VecX tau;
    for (py::ssize_t k = 0; k < n; ++k) {
      for (size_t j = 0; j < loads.size(); ++j) {
        samples[j] = loads[j].sample;
        if (loads[j].force) samples[j].force = Eigen::Map<const Vec3>(loads[j].force->data() + 3 * k);
        if (loads[j].point) samples[j].point = Eigen::Map<const Vec3>(loads[j].point->data() + 3 * k);
        if (loads[j].torque) samples[j].torque = Eigen::Map<const Vec3>(loads[j].torque->data() + 3 * k);
      }
      engine.calcGeneralizedForces(time.data()[k], row(q, k), row(qdot, k), row(qddot, k), samples, tau, ws);
      tau_all.row(k) = tau.transpose();
    }
  }
  osim::Storage s;
  s.name = osim::kIdStorageName;
  s.version = 1;
  s.labels = osim::idOutputLabels(m.description, skel);
  s.time.assign(time.data(), time.data() + n);
  s.data = std::move(tau_all);
  return toPython(std::move(s));
}

// --- mass points --------------------------------------------------------------------------

// every muscle with mass points: its name, alpha, masses, the points' world positions (frames x
// N x 3) and its active path points per frame (P x 3 each), at the rows of q (zero speeds)
py::list massPoints(std::vector<std::string> flags, InArray q) {
  if (q.ndim() != 2) throw std::invalid_argument("q must be frames x coordinates");
  const ArrayModel m = arrayModel(std::move(flags), "mass_points", rows(q));
  const Model& skel = m.build->model.skeleton();
  checkFrames(q, "q", q.shape(0), skel.nr());
  const std::vector<Muscle>& muscles = m.build->model.muscles();
  const py::ssize_t n = q.shape(0);
  std::vector<std::vector<double>> pts(muscles.size());
  std::vector<std::vector<MatX>> paths(muscles.size());
  {
    py::gil_scoped_release release;
    SkeletonWorkspace sk(skel);
    State s;
    s.qdot = VecX::Zero(skel.nr());
    MuscleKinematics mk;
    for (py::ssize_t k = 0; k < n; ++k) {
      s.q = row(q, k);
      calcKinematics(skel, s, sk);
      for (size_t i = 0; i < muscles.size(); ++i) {
        if (muscles[i].mass_points.size() == 0) continue;
        mk = MuscleKinematics();
        try {
          calcMuscleKinematics(skel, s, sk, muscles[i], mk, false);
        } catch (const MuscleError& e) {
          throw std::runtime_error("frame " + std::to_string(k) + ": " + e.what());
        }
        for (const Vec3& x : mk.x_a) pts[i].insert(pts[i].end(), x.data(), x.data() + 3);
        MatX P(mk.x_w.size(), 3);
        for (size_t j = 0; j < mk.x_w.size(); ++j) P.row(j) = mk.x_w[j].transpose();
        paths[i].push_back(std::move(P));
      }
    }
  }
  py::list out;
  for (size_t i = 0; i < muscles.size(); ++i) {
    const Muscle& mu = muscles[i];
    if (mu.mass_points.size() == 0) continue;
    const auto N = static_cast<py::ssize_t>(mu.mass_points.size());
    py::array_t<double> x = ownedVector(std::move(pts[i]));
    py::dict d;
    d["name"] = mu.name;
    d["alpha"] = mu.mass_points.alpha;
    d["mass"] = mu.mass_points.mass;
    d["points"] = x.reshape({n, N, static_cast<py::ssize_t>(3)});
    py::list path;
    for (MatX& P : paths[i]) path.append(ownedMatrix(std::move(P)));
    d["path"] = path;
    d["path_type"] = pathType(mu.path) == PathType::I ? "I" : pathType(mu.path) == PathType::II ? "II" : "III";
    out.append(d);
  }
  return out;
}

// --- path lengths -------------------------------------------------------------------------

py::tuple pathLengths(const std::string& model_file, const std::string& coordinates, const std::string& wrap) {
  validation::PathLengthOptions po;
  if (wrap == "exact") po.wrap = validation::LengthWrap::Exact;
  else if (wrap == "none") po.wrap = validation::LengthWrap::None;
  else throw std::invalid_argument("wrap must be exact or none, got '" + wrap + "'");
  validation::PathLengthResult res;
  {
    py::gil_scoped_release release;
    // what `redmax lengths` does (cli/cmd_lengths.cpp), from the same entry points
    const osim::ModelDescription d = osim::readOsimModel(model_file);
    osim::BuildOptions opt;
    opt.constraints = false;
    const osim::BuildResult build = osim::buildCoreModel(d, opt);
    const osim::Storage coords = osim::readStorage(coordinates);
    res = validation::calcPathLengths(d, build, coords, model_file, coordinates, po);
  }
  if (res.failed) throw std::runtime_error(res.failure);
  return toPython(std::move(res.lengths));
}

// --- forward, analyze, validate -----------------------------------------------------------

// `redmax forward` (cli/forward_flags.hpp): the ForwardTool; the files are written only when the
// keywords name --out-dir
py::dict forward(std::vector<std::string> flags) {
  CLI::App app("redmax.forward", "forward");
  cli::ForwardFlags f;
  cli::addForwardFlags(app, f);
  parseFlags(app, std::move(flags));
  if (f.view && !cli::given(app, "--out-dir"))
    throw std::invalid_argument("view=True needs out_dir (the folder the view is written into)");
  const validation::ForwardToolSettings s = usage([&] { return cli::parseForwardFlags(f, app); });
  std::unique_ptr<validation::ForwardTool> tool;
  validation::ForwardResult r;
  {
    py::gil_scoped_release release;
    tool = namedBySetup(f.setup, [&] { return std::make_unique<validation::ForwardTool>(s); });
    try {
      r = tool->run();
    } catch (const std::exception& e) {
      throw std::runtime_error(f.setup + ": " + e.what());
    }
    if (r.failed) throw std::runtime_error(f.setup + ": " + r.failure);
    if (s.out_dir) tool->write(r);
  }
  py::dict out;
  out["name"] = tool->setup().name;
  std::vector<std::string> warnings = tool->warnings();
  for (const std::string& w : tool->notApplied()) warnings.push_back("not applied: " + w);
  out["warnings"] = warnings;
  out["steps"] = r.stats.steps;
  out["rhs_evals"] = r.stats.rhs_evals;
  out["failed_steps"] = r.stats.failed_steps;
  out["wall_s"] = r.wall_s;
  out["decimals"] = std::max(8, tool->setup().output_precision);  // as ForwardTool::write: %.{decimals}e
  std::vector<std::string> files;
  if (s.out_dir) files = {tool->statesPath(), tool->controlsPath()};
  if (s.out_dir && f.view) files.push_back(tool->viewPath() + "/index.html");
  out["files"] = files;
  out["states"] = toPython(std::move(r.states));
  out["controls"] = toPython(std::move(r.controls));
  return out;
}

// `redmax analyze` (cli/analyze_flags.hpp): static optimization per frame; files only with --out-dir
py::dict analyze(std::vector<std::string> flags) {
  CLI::App app("redmax.analyze", "analyze");
  cli::AnalyzeFlags f;
  cli::addAnalyzeFlags(app, f);
  parseFlags(app, std::move(flags));
  const osim::AnalyzeToolSettings s = usage([&] { return cli::parseAnalyzeFlags(f, app); });
  std::unique_ptr<osim::AnalyzeTool> tool;
  osim::StaticOptimizationRun run;
  std::vector<std::string> files;
  {
    py::gil_scoped_release release;
    tool = namedBySetup(f.setup, [&] { return std::make_unique<osim::AnalyzeTool>(s); });
    // MuscleAnalysis / Actuation: written as the CLI writes them (files only with out_dir)
    if (tool->runsMuscleAnalyses()) {
      const osim::MuscleAnalysisRun mrun = tool->runMuscleAnalyses();
      if (s.out_dir) files = tool->writeMuscleAnalyses(mrun);
    }
    if (tool->runsStaticOptimization()) {
      run = tool->runStaticOptimization();
      if (s.out_dir) {
        const std::vector<std::string> so_files = tool->writeStaticOptimization(run);
        files.insert(files.end(), so_files.begin(), so_files.end());
      }
    }
  }
  const auto nf = static_cast<Eigen::Index>(run.frames.size()), na = static_cast<Eigen::Index>(run.actuators.size());
  MatX act(nf, na), force(nf, na);
  std::vector<double> time, violation;
  std::vector<int> iterations;
  std::vector<bool> converged;
  std::vector<std::string> status;
  for (Eigen::Index k = 0; k < nf; ++k) {
    const osim::StaticOptimizationFrame& fr = run.frames[static_cast<size_t>(k)];
    act.row(k) = fr.activation.transpose();
    force.row(k) = fr.force.transpose();
    time.push_back(fr.time);
    iterations.push_back(fr.iterations);
    violation.push_back(fr.constraint_violation);
    converged.push_back(fr.converged);
    status.push_back(fr.status);
  }
  py::dict out;
  out["name"] = tool->setup().name + "_" + tool->setup().static_optimization.name;
  out["labels"] = run.actuators;
  out["is_muscle"] = run.is_muscle;
  out["time"] = ownedVector(time);
  out["activation"] = ownedMatrix(std::move(act));
  out["force"] = ownedMatrix(std::move(force));
  out["iterations"] = iterations;
  out["constraint_violation"] = ownedVector(std::move(violation));
  out["converged"] = converged;
  out["status"] = status;
  out["failed"] = run.failed;
  out["muscle_mass"] = tool->muscleMass();
  out["decimals"] = tool->setup().output_precision;  // as writeStaticOptimization: %.{decimals}f
  out["warnings"] = tool->warnings();
  out["unsupported_analyses"] = tool->unsupportedAnalyses();
  out["files"] = files;
  return out;
}

// `redmax validate` (cli/validate_flags.hpp): the report folder, and the verdict and summary
py::dict validate(std::vector<std::string> flags) {
  CLI::App app("redmax.validate", "validate");
  cli::ValidateFlags f;
  cli::addValidateFlags(app, f);
  parseFlags(app, std::move(flags));
  validation::IdValidationOptions opt = usage([&] { return cli::parseValidateFlags(f, app); });
  opt.progress = false;  // no stderr lines from Python
  validation::IdValidationResult r;
  {
    py::gil_scoped_release release;
    try {
      r = validation::runIdValidation(opt);
    } catch (const osim::IdEngineError& e) {
      throw std::runtime_error(opt.settings.coordinates_file.value_or(opt.settings.setup_file) + ": " + e.what());
    }
  }
  py::dict out;
  out["passed"] = r.passed;
  out["text"] = validation::formatIdValidationSummary(r);
  out["report"] = opt.report_dir;
  out["warnings"] = r.warnings;
  out["files"] = r.files.written;
  out["plots"] = r.files.plots;
  out["plots_note"] = r.files.plots_note;
  return out;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "redmax's compiled half; use the redmax package (docs/python.md)";
  static py::exception<osim::ConvertError> convert_error(m, "ConvertError", PyExc_ValueError);
  static py::exception<std::runtime_error> error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const osim::ConvertError& e) {
      convert_error(e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const ModelError& e) {
      convert_error(e.what());
    } catch (const std::runtime_error& e) {
      error(e.what());
    }
  });

  py::class_<PyModel>(m, "_Model")
      .def_readonly("path", &PyModel::path)
      .def("summary_text", [](const PyModel& x) { return osim::formatSummary(x.description); })
      .def("description_json", [](const PyModel& x) { return osim::describeAsJson(x.description); });
  m.def("load_model", &loadModel, py::arg("path"), "read an OpenSim model (redmax convert)");
  m.def("inverse_dynamics", &inverseDynamics, py::arg("flags"), py::arg("with_inputs") = false,
        "redmax id (engine core) on `redmax id` input flags");
  m.def("inverse_dynamics_arrays", &inverseDynamicsArrays, py::arg("flags"), py::arg("time"), py::arg("q"),
        py::arg("qdot"), py::arg("qddot"), py::arg("loads"), "the core ID engine on arrays");
  m.def("mass_points", &massPoints, py::arg("flags"), py::arg("q"), "mass-point positions at the rows of q");
  m.def("path_lengths", &pathLengths, py::arg("model"), py::arg("coordinates"), py::arg("wrap"));
  m.def("forward", &forward, py::arg("flags"), "redmax forward on its flags");
  m.def("analyze", &analyze, py::arg("flags"), "redmax analyze on its flags");
  m.def("validate", &validate, py::arg("flags"), "redmax validate on its flags");
  m.def("read_storage", [](const std::string& path) {
    osim::Storage s;
    {
      py::gil_scoped_release release;
      s = osim::readStorage(path);
    }
    return toPython(std::move(s));
  });
  m.def("write_storage", [](const std::string& path, const std::string& name, const std::vector<std::string>& labels,
                            InArray time, InArray values, bool in_degrees, bool full_precision, int decimals,
                            bool scientific, const std::string& description) {
    const osim::Storage s = fromPython(name, labels, time, values, in_degrees);
    py::gil_scoped_release release;
    if (decimals < 0) {
      osim::writeResultStorage(path, s, full_precision, description);
    } else {
      osim::StorageWriteOptions o;
      o.decimals = decimals;
      o.scientific = scientific;
      o.description = description;
      osim::writeStorage(path, s, o);
    }
  });
}
