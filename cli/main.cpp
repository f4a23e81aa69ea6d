// The `redmax` executable: one CLI11 subcommand per cli/cmd_*.cpp. Parse errors and usage errors
// are `error: message` on stderr with exit code 2; --help (of redmax or of a command) exits 0.
#include <algorithm>
#include <exception>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "cli/command.hpp"
#include "cli/flags.hpp"

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

using redmax::cli::registry;

// CLI11 words a failed check "--dt: must be positive"; our validators' messages continue the
// flag's name (cli/flags.hpp), so print "--dt must be positive", and put a message that starts with
// a file name first: "--model: m.osim: no such file" -> "m.osim: no such file (--model)"
std::string parseErrorMessage(const CLI::ParseError& e) {
  const std::string m = e.what();
  if (dynamic_cast<const CLI::ValidationError*>(&e) == nullptr || m.rfind("--", 0) != 0) return m;
  const auto colon = m.find(": ");
  if (colon == std::string::npos || colon + 2 >= m.size()) return m;
  const std::string flag = m.substr(0, colon), rest = m.substr(colon + 2);
  if (rest.rfind("must ", 0) == 0 || rest.rfind("expects ", 0) == 0) return flag + " " + rest;
  return rest + " (" + flag + ")";
}

// flags CLI11 left over (allow_extras): the first unknown option or positional is the error
void checkExtras(const CLI::App& sub) {
  for (const std::string& x : sub.remaining()) {
    if (x.size() > 1 && x[0] == '-') {
      const std::string name = x.substr(0, x.find('='));
      throw redmax::cli::UsageError{"unknown option " + name};
    }
    throw redmax::cli::UsageError{sub.get_name() + " takes no positional arguments (got '" + x + "')"};
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace redmax::cli;
  CLI::App root("redmax " REDMAX_VERSION " - REDMAX musculoskeletal simulation with inertial musculotendons",
                "redmax");
  root.set_version_flag("--version", "redmax " REDMAX_VERSION, "print the version and exit");
  root.footer("`redmax COMMAND --help` describes a command's options.\n"
              "exit codes: 0 success, 1 the run failed (e.g. diverged), 2 bad input or usage");
  root.get_formatter()->column_width(kHelpColumn);
  // a repeated flag takes its last value, as before CLI11 (flags meant to repeat say so)
  root.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  root.require_subcommand(0, 1);

  auto cmds = registry();
  std::sort(cmds.begin(), cmds.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::vector<std::pair<CLI::App*, std::function<int()>>> runs;
  for (const Command& c : cmds) {
    CLI::App* sub = root.add_subcommand(c.name, c.summary);
    sub->allow_extras();
    sub->get_formatter()->column_width(kHelpColumn);
    runs.emplace_back(sub, c.declare(*sub));
  }

  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "help") {
    std::cout << root.help();
    return args.empty() ? 2 : 0;
  }
  if (args[0][0] != '-' && std::none_of(cmds.begin(), cmds.end(), [&](const auto& c) { return c.name == args[0]; })) {
    std::cerr << "error: unknown command '" << args[0] << "' (see `redmax --help`)\n";
    return 2;
  }

  try {
    root.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << root.help();  // the selected command's help, when one was named
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    std::cout << root.help("", CLI::AppFormatMode::All);
    return 0;
  } catch (const CLI::CallForVersion& e) {
    std::cout << e.what() << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    const auto chosen = root.get_subcommands();
    std::cerr << "error: " << parseErrorMessage(e) << "\n";
    if (!chosen.empty()) std::cerr << "(see `redmax " << chosen.front()->get_name() << " --help`)\n";
    return 2;
  }

  for (auto& [sub, run] : runs) {
    if (!sub->parsed()) continue;
    try {
      checkExtras(*sub);
      return run();
    } catch (const UsageError& e) {
      std::cerr << "error: " << e.message << "\n(see `redmax " << sub->get_name() << " --help`)\n";
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
  std::cout << root.help();  // options of redmax itself only, no command
  return 2;
}
