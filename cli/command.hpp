#pragma once
// Subcommands of the `redmax` executable. Each lives in its own cli/cmd_*.cpp and registers
// itself with a static CommandRegistration; main.cpp makes one CLI11 subcommand per entry, lets it
// declare its flags, parses, and runs it. Exit codes (docs/commands.md §1): 0 success, 1 the run failed
// (e.g. diverged), 2 bad input or usage.
#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace redmax::cli {

struct Command {
  std::string name;
  std::string summary;  // one line for `redmax --help`
  /// Declares the command's flags (with help text and validators) on its subcommand `app` and
  /// returns the run, called once `app` has parsed; the flags' values live in state the run owns.
  std::function<std::function<int()>(CLI::App& app)> declare;
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
