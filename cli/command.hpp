#pragma once
// Subcommands of the `redmax` executable. Each lives in its own cli/cmd_*.cpp and registers
// itself with a static CommandRegistration; main.cpp dispatches. Exit codes (docs/commands.md §1):
// 0 success, 1 the run failed (e.g. diverged), 2 bad input or usage.
#include <functional>
#include <string>
#include <vector>

namespace redmax::cli {

struct Command {
  std::string name;
  std::string summary;  // one line for `redmax --help`
  std::string usage;    // full help for `redmax NAME --help`
  std::function<int(const std::vector<std::string>& args)> run;
};

std::vector<Command>& registry();

struct CommandRegistration {
  explicit CommandRegistration(Command c) { registry().push_back(std::move(c)); }
};

/// Usage error: printed as `error: message` with exit code 2.
struct UsageError {
  std::string message;
};

}  // namespace redmax::cli
