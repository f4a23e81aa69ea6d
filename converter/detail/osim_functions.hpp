#pragma once
// Reading OpenSim Function objects (semantics §4) into FunctionDesc (internal).
#include <optional>
#include <string>

#include "converter/detail/xml_util.hpp"
#include "converter/model_description.hpp"

namespace redmax::osim::detail {

/// true if tag names an OpenSim Function class or one of its registered aliases
bool isFunctionTag(const std::string& tag);

/// read the function whose concrete element is e (tag = class); fails on unknown classes and
/// inconsistent data (x/y sizes, too few points, bad numbers)
FunctionDesc parseFunction(const XmlDocument& doc, const XMLElement* e);

/// find an object-valued function property of owner: either the wrapper form
/// <prop><Type .../></prop> or the named form <Type name="prop">; nullopt when absent or empty
std::optional<FunctionDesc> findFunctionProperty(const XmlDocument& doc, const XMLElement* owner,
                                                 const char* prop);

}  // namespace redmax::osim::detail
