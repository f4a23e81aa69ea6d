#include "fuzz/fuzz_common.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>


namespace redmax::fuzz {

namespace {
struct TempDirHolder {
  std::string path;
  TempDirHolder() {
    namespace fs = std::filesystem;
    path = (fs::temp_directory_path() / ("redmax_fuzz_" + std::to_string(::getpid()))).string();
    fs::create_directories(path);
  }
  ~TempDirHolder() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};
}  // namespace

const std::string& tempDir() {
  static TempDirHolder holder;
  return holder.path;
}

std::string writeInput(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::string path = tempDir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();  // the harness itself failed: not the reader's fault, but stop loudly
  }
  return path;
}

void acceptError(const std::exception& e) {
  const char* what = e.what();
  if (what == nullptr || what[0] == '\0') {
    std::fprintf(stderr, "fuzz: exception without a message\n");
    std::abort();
  }
  // REDMAX_FUZZ_VERBOSE=1: every message (to check that seeds read)
  static const bool verbose = std::getenv("REDMAX_FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "fuzz: %s\n", what);
}

}  // namespace redmax::fuzz
