#include "converter/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <unistd.h>

#include "converter/error.hpp"

namespace redmax::osim {

void writeFileAtomic(const std::string& path, const std::string& content) {
  if (path.empty()) throw ConvertError("(output)", 0, "empty output path");
  // the temporary sits in the target's directory so that rename() stays on one file system
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw ConvertError(path, 0, std::string("cannot write: ") + std::strerror(errno));
  const size_t n = std::fwrite(content.data(), 1, content.size(), f);
  bool ok = n == content.size();
  ok = (std::fflush(f) == 0) && ok;
  ok = (::fsync(::fileno(f)) == 0) && ok;
  const int err = errno;
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) {
    std::remove(tmp.c_str());
    throw ConvertError(path, 0, std::string("cannot write: ") + std::strerror(err ? err : EIO));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp.c_str());
    throw ConvertError(path, 0, std::string("cannot write: ") + std::strerror(e));
  }
}

}  // namespace redmax::osim
