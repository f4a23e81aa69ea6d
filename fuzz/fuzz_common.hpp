#pragma once
// Shared pieces of the reader fuzz targets (fuzz/*_fuzz.cpp). The readers take paths, so every
// input is written to a file in a per-process temporary folder before it is read. An input may
// end in a successful read or in a std::exception with a message; anything else (a crash, a
// sanitizer report, a hang, an exception of another type, an empty message) is a bug.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <string>

namespace redmax::fuzz {

/// this process's temporary folder (created on first use, removed at exit)
const std::string& tempDir();

/// write bytes to tempDir()/name and return the full path
std::string writeInput(const std::string& name, const std::uint8_t* data, std::size_t size);

/// an accepted failure: a std::exception must carry a message; an empty one aborts (a bug)
void acceptError(const std::exception& e);

}  // namespace redmax::fuzz
