#pragma once
// Shared pieces of the reader fuzz targets (fuzz/*_fuzz.cpp). The readers take paths, so every
// input is written to a file in a per-process temporary folder before it is read. An input may
// end in a successful read or in one of the project's own error types with a message
// (acceptingProjectErrors); anything else (a crash, a sanitizer report, a hang, std::out_of_range,
// std::bad_alloc, a bare std::runtime_error, an empty message) is a bug.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <string>

#include "converter/error.hpp"
#include "converter/id/id_engine.hpp"
#include "converter/signal/signal_error.hpp"
#include "core/deformable/tet_mesh.hpp"
#include "core/joints/joint_kinematics.hpp"
#include "core/muscles/muscle_workspace.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::fuzz {

/// this process's temporary folder (created on first use, removed at exit)
const std::string& tempDir();

/// write bytes to tempDir()/name and return the full path
std::string writeInput(const std::string& name, const std::uint8_t* data, std::size_t size);

/// an accepted failure must carry a message; an empty one aborts (a bug)
void acceptError(const std::exception& e);

/// Run one step of a target. The project's error types (osim::ConvertError: bad input with
/// FILE:LINE; ModelError, JointError, MuscleError from the core; signal::SignalError from the ID
/// tool's signal processing; osim::IdEngineError; MeshError from the VTK mesh reader) are the
/// readers' answer to bad input: accepted
/// (acceptError) and false returned. Any other exception is not caught: it leaves the target and
/// ends the run through std::terminate, which libFuzzer and the driver report as a crash.
template <class Step>
bool acceptingProjectErrors(Step&& step) {
  try {
    step();
    return true;
  } catch (const osim::ConvertError& e) {
    acceptError(e);
  } catch (const ModelError& e) {
    acceptError(e);
  } catch (const JointError& e) {
    acceptError(e);
  } catch (const MuscleError& e) {
    acceptError(e);
  } catch (const signal::SignalError& e) {
    acceptError(e);
  } catch (const osim::IdEngineError& e) {
    acceptError(e);
  } catch (const MeshError& e) {
    acceptError(e);
  }
  return false;
}

}  // namespace redmax::fuzz
