#pragma once
// Errors raised while reading OpenSim files. The message carries the file and, where known, the
// line, so that the command line prints `error: FILE:LINE: what is wrong` (docs/commands.md §1).
#include <stdexcept>
#include <string>

namespace redmax::osim {

/// A file is missing, malformed, or asks for something the converter cannot do.
/// what() is "FILE:LINE: message" (":LINE" is left out when line is 0).
class ConvertError : public std::runtime_error {
 public:
  ConvertError(std::string file, int line, std::string message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  int line_ = 0;
  std::string message_;
};

}  // namespace redmax::osim
