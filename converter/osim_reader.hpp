#pragma once
// Reader for OpenSim model files (.osim): the 4.0 layout (Version 40000 and later) and the legacy
// layouts 10901 ... 30000, upgraded as OpenSim upgrades them (docs/opensim_compatibility.md §1).
#include <string>

#include "converter/error.hpp"
#include "converter/model_description.hpp"

namespace redmax::osim {

/// Read and resolve a .osim file. Sockets, offset-frame chains and legacy upgrades are resolved;
/// coordinates come out in OpenSim's multibody-tree order (§3.1). Items that are read but not
/// modelled are listed in ModelDescription::unsupported. Throws ConvertError ("FILE:LINE: what")
/// on unreadable, malformed or inconsistent input; never leaves a partial result.
ModelDescription readOsimModel(const std::string& path);
/// The same with every muscle read as OpenSim class `muscle_class` ("": as written), as
/// OpenSim's Object::renameType does: the XML properties are read, checked and defaulted as that
/// class's, so a check of the written class does not apply (`--muscle-class`).
ModelDescription readOsimModel(const std::string& path, const std::string& muscle_class);

/// Append the ForceSet of a force_set_files file (OpenSimDocument/ForceSet, or a bare ForceSet)
/// to model's forces and muscles, as OpenSim's tools append it; each entry's source_file is
/// `path`. Bodies, frames and coordinates are the model's; an unknown body or coordinate, a zero
/// direction, a negative stiffness are errors at their line of that file (ConvertError); the model
/// is then unchanged. An entry whose name the force set already holds is dropped with a warning
/// (OpenSim's ForceSet::append keeps the first): the model's forces and muscles count unless
/// `model_forces_replaced` (the tool's replace_force_set), the earlier files' entries always.
void appendForceSetFile(ModelDescription& model, const std::string& path, bool model_forces_replaced = false);

/// Build the multibody tree as Simbody's MultibodyGraphMaker does for OpenSim (§3.1): fills
/// d.tree, appends FreeJoints for unconnected bodies and loop-closure constraints, and reorders
/// d.coordinates (with the joints' indices) into mobilizer order. Expects d.joints with resolved
/// parent_body/child_body and d.coordinates in any order. Throws ConvertError on bodies or joints
/// that cannot form a tree (e.g. a joint naming an unknown body).
void buildMultibodyTree(ModelDescription& d);

}  // namespace redmax::osim
