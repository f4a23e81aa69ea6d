#pragma once
// OpenSim ExternalLoads files (.xml holding ExternalForce objects and a data file), read as
// OpenSim 4.x reads them (docs/opensim_compatibility.md §7.8).
#include <array>
#include <string>
#include <vector>

#include "converter/error.hpp"
#include "converter/model_description.hpp"
#include "converter/signal/load_interpolant.hpp"
#include "converter/storage.hpp"
#include "core/dynamics/id_engine.hpp"

namespace redmax::osim {

struct ExternalForceDesc {
  std::string name;
  bool applies_force = true;
  std::string applied_to_body;
  std::string force_expressed_in_body = "ground";
  std::string point_expressed_in_body = "ground";
  std::string force_identifier, point_identifier, torque_identifier;  ///< "" when absent
  std::string data_source_name;
  /// data columns (indices into ExternalLoads::data.labels) of x, y, z, in file column order;
  /// -1 when the identifier is absent. Without a point the force acts at the body origin.
  std::array<int, 3> force_columns{-1, -1, -1};
  std::array<int, 3> point_columns{-1, -1, -1};
  std::array<int, 3> torque_columns{-1, -1, -1};
  bool hasForce() const { return force_columns[0] >= 0; }
  bool hasPoint() const { return point_columns[0] >= 0; }
  bool hasTorque() const { return torque_columns[0] >= 0; }
  int line = 0;
};

struct ExternalLoads {
  std::string name;
  std::string source_file;
  std::string datafile;       ///< as written in the XML
  std::string datafile_path;  ///< the file that was read
  Storage data;               ///< not filtered: OpenSim interpolates it as is
  std::vector<ExternalForceDesc> forces;
  std::vector<std::string> warnings;  ///< e.g. 3.x-only settings that 4.x ignores
};

/// Read an ExternalLoads XML and its data file. The data file is looked up first relative to
/// working_dir (OpenSim's working directory; for a tool setup this is the setup file's folder;
/// "" means the current directory), then relative to the XML's folder. Each identifier must match
/// exactly three columns by case-sensitive prefix. Throws ConvertError ("FILE:LINE: what").
ExternalLoads readExternalLoads(const std::string& xml_path, const std::string& working_dir = "");

/// Check the loads against a model: an unknown applied_to_body is an error (ConvertError on the
/// ExternalForce's line); an unknown expressed-in body falls back to ground with a warning.
void checkExternalLoads(ExternalLoads& loads, const ModelDescription& model);

/// One ExternalForce ready to sample: its bodies (core indices; -1 ground) and flags, and the
/// interpolants of its columns.
struct LoadSource {
  std::string name;
  IdLoadSample frame;  ///< bodies and flags (values are filled per sample)
  std::array<signal::LoadInterpolant, 3> force, point, torque;
};

/// The loads of `loads` (checked against d with checkExternalLoads first) as sources on a built
/// model (body_index: ModelDescription::bodies -> core body, BuildResult::body_index). Forces on
/// ground are left out with a warning; a body the core model lacks is a ConvertError naming
/// loads.source_file and the force's line; unusable data a ConvertError naming the data file.
std::vector<LoadSource> makeLoadSources(const ExternalLoads& loads, const ModelDescription& d,
                                        const std::vector<int>& body_index, std::vector<std::string>& warnings);
/// the loads of every source at time t (OpenSim's interpolation, not filtered)
void sampleLoads(const std::vector<LoadSource>& sources, double t, std::vector<IdLoadSample>& out);

}  // namespace redmax::osim
