#pragma once
// Parsing helpers of the flag SPECs (`redmax simulate --impulse`, `redmax gradient --params` and
// `--objective`, docs/gradients.md §3); defined in simulate.cpp.
#include <string>
#include <vector>

#include "core/spatial/types.hpp"

namespace redmax::validation {

/// split at every `sep`, empty items kept
std::vector<std::string> split(const std::string& s, char sep);
/// a strict finite number: the whole text
bool parseNumber(const std::string& text, double& v);
/// three numbers "x,y,z"
bool parseVec3(const std::string& text, Vec3& v);

}  // namespace redmax::validation
