#pragma once
// Errors of the signal-processing layer (splines, filters, resampling). They are input errors:
// too few samples, times that do not increase, mismatched lengths. The command line maps them
// to exit code 2 (docs/commands.md §1).
#include <stdexcept>
#include <string>

namespace redmax::signal {

/// bad input to a signal routine; what() says what is wrong and with which values
class SignalError : public std::invalid_argument {
 public:
  explicit SignalError(const std::string& message) : std::invalid_argument(message) {}
};

}  // namespace redmax::signal
