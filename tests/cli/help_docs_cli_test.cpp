// docs/commands.md §4 is what the commands print: every subcommand that `redmax --help` lists has
// a `### \`redmax C --help\`` block there equal to `redmax C --help`'s output (regenerate with
// scripts/regen-help-docs), so the reference cannot go stale when a flag changes.
#include <stdlib.h>

#include <regex>

#include "tests/cli/cli_test_util.hpp"

namespace redmax::cli_test {
namespace {

std::string runHelp(const std::string& args) {
  struct Dir {  // the captured output's files, removed at exit
    Dir() {
      std::string t = (fs::temp_directory_path() / "redmax_help_XXXXXX").string();
      path = mkdtemp(t.data());
    }
    ~Dir() { fs::remove_all(path); }
    fs::path path;
  };
  static const Dir dir;
  const CmdResult r = runRedmax(dir.path, args);
  EXPECT_EQ(r.code, 0) << args << "\n" << r.err;
  return r.out + r.err;
}

TEST(HelpDocs, CommandsMdHoldsEveryCommandsCurrentHelp) {
  const std::string doc = slurp(fs::path(REDMAX_SOURCE_DIR) / "docs" / "commands.md");
  ASSERT_FALSE(doc.empty());
  const std::string top = runHelp("--help");
  const size_t sub = top.find("Subcommands:");
  ASSERT_NE(sub, std::string::npos) << top;
  const std::string list = top.substr(sub);
  const std::regex name("\n  ([a-z][a-z-]*)  ");
  int commands = 0;
  for (auto it = std::sregex_iterator(list.begin(), list.end(), name); it != std::sregex_iterator(); ++it) {
    const std::string c = (*it)[1];
    ++commands;
    const std::string heading = "### `redmax " + c + " --help`\n\n```\n";
    const size_t at = doc.find(heading);
    ASSERT_NE(at, std::string::npos) << "docs/commands.md has no --help block for '" << c
                                     << "': run scripts/regen-help-docs";
    const size_t begin = at + heading.size(), end = doc.find("```", begin);
    ASSERT_NE(end, std::string::npos);
    EXPECT_EQ(doc.substr(begin, end - begin), runHelp(c + " --help"))
        << "docs/commands.md's block for '" << c << "' is stale: run scripts/regen-help-docs";
  }
  EXPECT_GE(commands, 10) << top;
}

}  // namespace
}  // namespace redmax::cli_test
