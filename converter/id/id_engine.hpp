#pragma once
// The inverse-dynamics engine interface lives in the core (core/dynamics/id_engine.hpp); these
// names keep the converter's spelling of it.
#include "core/dynamics/id_engine.hpp"

namespace redmax::osim {

using redmax::IdEngine;
using redmax::IdEngineError;
using redmax::IdEngineOptions;
using redmax::IdLoadSample;
using redmax::resolveLoads;

}  // namespace redmax::osim
