#pragma once
// Atomic file output: write everything to a temporary file beside the target, then rename it,
// so that a failed or interrupted write never leaves a half-written output (docs/commands.md §1).
#include <string>

namespace redmax::osim {

/// Write content to path atomically. Throws ConvertError(path, 0, why) on failure; the target
/// is then untouched and the temporary file removed.
void writeFileAtomic(const std::string& path, const std::string& content);

}  // namespace redmax::osim
