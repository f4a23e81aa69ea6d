// The `redmax` executable: thin dispatch to the subcommands in cli/cmd_*.cpp.
#include <algorithm>
#include <exception>
#include <stdexcept>
#include <iostream>

#include "cli/command.hpp"

#ifndef REDMAX_VERSION
#define REDMAX_VERSION "unknown"
#endif

namespace redmax::cli {
std::vector<Command>& registry() {
  static std::vector<Command> r;
  return r;
}
}  // namespace redmax::cli

namespace {
void printHelp() {
  using redmax::cli::registry;
  std::cout << "redmax " << REDMAX_VERSION
            << " - REDMAX musculoskeletal simulation with inertial musculotendons\n\n"
               "usage: redmax [--version] [--help] COMMAND [ARGS]\n\ncommands:\n";
  auto cmds = registry();
  std::sort(cmds.begin(), cmds.end(), [](auto& a, auto& b) { return a.name < b.name; });
  for (const auto& c : cmds) {
    std::cout << "  " << c.name << std::string(c.name.size() < 12 ? 12 - c.name.size() : 1, ' ')
              << c.summary << "\n";
  }
  std::cout << "\n`redmax COMMAND --help` describes a command's options.\n"
               "exit codes: 0 success, 1 the run failed (e.g. diverged), 2 bad input or usage\n";
}
}  // namespace

int main(int argc, char** argv) {
  using namespace redmax::cli;
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    printHelp();
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version") {
    std::cout << "redmax " << REDMAX_VERSION << "\n";
    return 0;
  }
  for (const auto& c : registry()) {
    if (c.name != args[0]) continue;
    std::vector<std::string> rest(args.begin() + 1, args.end());
    if (std::find(rest.begin(), rest.end(), "--help") != rest.end()) {
      std::cout << c.usage;
      return 0;
    }
    try {
      return c.run(rest);
    } catch (const UsageError& e) {
      std::cerr << "error: " << e.message << "\n(see `redmax " << c.name << " --help`)\n";
      return 2;
    } catch (const std::invalid_argument& e) {
      // bad option values reach the libraries as invalid_argument: still the user's input
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 1;
    }
  }
  std::cerr << "error: unknown command '" << args[0] << "' (see `redmax --help`)\n";
  return 2;
}
