#pragma once
// Flag declarations for the `redmax` commands, over CLI11 (Debian libcli11-dev). Each command
// declares every flag once on its CLI::App, with its help text and its validator; main.cpp parses,
// prints the generated --help and maps CLI11's errors to `error: ...` with exit code 2.
//
// The validators' messages complete a sentence that starts with the flag: CLI11 reports a failed
// check as "--dt: must be positive" and main.cpp prints it as "error: --dt must be positive", the
// wording the CLI tests hold (docs/commands.md §1).
#include <CLI/CLI.hpp>

#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "converter/error.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::cli {

/// a finite real number: "expects a number, got 'x'"
CLI::Validator number();
/// a whole number: "expects an integer, got 'x'"
CLI::Validator integer();
/// a number > 0: "must be positive", or with `what` "must be a positive WHAT"
CLI::Validator positive(const std::string& what = "");
/// a number >= 0: "must be >= 0"
CLI::Validator nonNegative();
/// a number in [lo, hi] (whole numbers when `whole`): "must be between LO and HI, got V"; `text_lo` and
/// `text_hi` print the bounds ("1e8")
CLI::Validator between(double lo, double hi, bool whole = false, const std::string& text_lo = "",
                       const std::string& text_hi = "");
/// an existing file (CLI::ExistingFile): "FILE: no such file" (main.cpp prints it as
/// "error: FILE: no such file (--flag)", the FILE-first form of docs/commands.md §1)
CLI::Validator existingFile();
/// one of `names` (CLI::IsMember): "must be a, b or c, got 'x'"
CLI::Validator oneOf(const std::vector<std::string>& names);

/// true when `flag` ("--name") was given on the command line
bool given(const CLI::App& app, const std::string& flag);

/// Runs `load` (reading `file` and building what the command needs). Bad input is printed as
/// `error: ...` and gives exit code 2: osim::ConvertError ("FILE:LINE: what"), ModelError (named
/// by `file`), std::invalid_argument (bad settings, the message names them). 0 when it loaded.
template <class F>
int loadOrExit2(const std::string& file, F&& load) {
  try {
    load();
    return 0;
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
  } catch (const ModelError& e) {
    std::cerr << "error: " << file << ": " << e.what() << "\n";
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
  }
  return 2;
}

/// Where `redmax view` and `validate --view` look for the page's files (view/view.hpp
/// findViewAssets), in order: $REDMAX_VIEW_ASSETS, build/view/ beside this executable's build tree
/// (CMake copies them there), then view/web/ of the source tree it was built from.
std::vector<std::string> viewAssetFolders();

/// A parsed command's flags by name, for commands whose defaults depend on a mode flag
/// (`train-wrap --study` trains smaller networks by default than plain training). Values were
/// checked by the flags' validators during the parse.
class FlagValues {
 public:
  explicit FlagValues(const CLI::App& app) : app_(app) {}
  /// names without the leading dashes, as declared ("samples" for --samples)
  bool has(const std::string& name) const { return given(app_, "--" + name); }
  std::string get(const std::string& name, const std::string& fallback) const;
  long getInt(const std::string& name, long fallback) const;
  double getDouble(const std::string& name, double fallback) const;

 private:
  const CLI::App& app_;
};

/// "redmax COMMAND" and the flags as parsed, in their order (what a written file records as the
/// command that made it)
std::string commandLine(const CLI::App& app);

/// The non-empty items of `text` split at any of `separators` (",": "a,,b" -> {a, b}).
std::vector<std::string> splitList(const std::string& text, const std::string& separators = ",");

/// "a, b or c"
std::string joinChoices(const std::vector<std::string>& names);

/// Column width of the option names in every command's --help.
constexpr int kHelpColumn = 30;

}  // namespace redmax::cli
