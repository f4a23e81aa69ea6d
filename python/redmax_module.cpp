// The `redmax` Python module's compiled half (redmax._core, pybind11; docs/python.md). Thin: every
// computation is a library entry point the CLI uses too (converter/osim_reader.hpp,
// converter/id/inverse_dynamics_tool.hpp, validation/lengths/path_lengths.hpp,
// converter/storage.hpp). Long calls release the GIL; errors raise redmax.ConvertError (bad input,
// message "FILE[:LINE]: what", as the CLI prints it) or redmax.Error (a run that failed).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/numpy.h>

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include <algorithm>

#include "cli/id_flags.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "converter/error.hpp"
#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/json_writer.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "validation/lengths/path_lengths.hpp"

namespace py = pybind11;
using namespace redmax;

namespace {

// a Storage as the Python-side Table's parts: (name, labels, time, values rows x columns)
py::tuple toPython(const osim::Storage& s) {
  const py::ssize_t n = s.numRows(), m = s.numColumns();
  py::array_t<double> time(n), values({n, m});
  auto t = time.mutable_unchecked<1>();
  auto v = values.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    t(i) = s.time[i];
    for (py::ssize_t j = 0; j < m; ++j) v(i, j) = s.data(i, j);
  }
  return py::make_tuple(s.name, s.labels, time, values, s.in_degrees);
}

osim::Storage fromPython(const std::string& name, const std::vector<std::string>& labels,
                         py::array_t<double, py::array::c_style | py::array::forcecast> time,
                         py::array_t<double, py::array::c_style | py::array::forcecast> values, bool in_degrees) {
  if (time.ndim() != 1 || values.ndim() != 2 || values.shape(0) != time.shape(0) ||
      values.shape(1) != static_cast<py::ssize_t>(labels.size()))
    throw std::invalid_argument("values must be len(time) x len(labels)");
  osim::Storage s;
  s.name = name;
  s.version = 1;
  s.in_degrees = in_degrees;
  s.labels = labels;
  s.time.assign(time.data(), time.data() + time.shape(0));
  s.data.resize(values.shape(0), values.shape(1));
  auto v = values.unchecked<2>();
  for (py::ssize_t i = 0; i < values.shape(0); ++i)
    for (py::ssize_t j = 0; j < values.shape(1); ++j) s.data(i, j) = v(i, j);
  return s;
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

// `redmax id`'s input flags (cli/id_flags.hpp, cli/muscle_mass_flags.hpp), parsed by the CLI's own
// declarations from the keywords redmax.inverse_dynamics turned into flags: the same defaults, checks
// and messages as the command line, nothing re-implemented here
py::tuple inverseDynamics(std::vector<std::string> flags) {
  CLI::App app("redmax.inverse_dynamics", "inverse_dynamics");
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  cli::IdInputFlags f;
  cli::addIdInputFlags(app, f);
  osim::IdToolSettings s;
  try {
    std::reverse(flags.begin(), flags.end());  // CLI11 parses a reversed vector
    app.parse(flags);
    s = cli::parseIdInputFlags(f, app, "inverse_dynamics");
    s.muscle_mass = cli::parseMuscleMassFlags(f.muscle_mass);
  } catch (const CLI::ParseError& e) {
    throw std::invalid_argument(e.what());
  } catch (const cli::UsageError& e) {
    throw std::invalid_argument(e.message);
  }
  osim::Storage result;
  {
    py::gil_scoped_release release;
    // what `redmax id` (engine core) does, from the same entry points
    const osim::IdToolConfig config = osim::resolveIdSettings(s);
    osim::InverseDynamicsTool tool(config);
    osim::CoreIdEngine engine(tool.musculoskeletalModel(), tool.engineOptions());
    result = tool.run(engine);
  }
  return toPython(result);
}

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
  return toPython(res.lengths);
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
  m.def("inverse_dynamics", &inverseDynamics, py::arg("flags"), "redmax id (engine core) on `redmax id` input flags");
  m.def("path_lengths", &pathLengths, py::arg("model"), py::arg("coordinates"), py::arg("wrap"));
  m.def("read_storage", [](const std::string& path) {
    osim::Storage s;
    {
      py::gil_scoped_release release;
      s = osim::readStorage(path);
    }
    return toPython(s);
  });
  m.def("write_storage", [](const std::string& path, const std::string& name, const std::vector<std::string>& labels,
                            py::array_t<double, py::array::c_style | py::array::forcecast> time,
                            py::array_t<double, py::array::c_style | py::array::forcecast> values, bool in_degrees,
                            bool full_precision) {
    const osim::Storage s = fromPython(name, labels, time, values, in_degrees);
    py::gil_scoped_release release;
    osim::writeResultStorage(path, s, full_precision);
  });
}
