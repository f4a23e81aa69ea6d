#include "cli/flags.hpp"

#include <dlfcn.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>

#ifndef REDMAX_SOURCE_DIR
#define REDMAX_SOURCE_DIR ""
#endif

namespace redmax::cli {
namespace {

// the whole of `s` as a finite double
bool parseNumber(const std::string& s, double& x) {
  char* end = nullptr;
  errno = 0;
  x = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0' && errno != ERANGE && std::isfinite(x);
}

std::string show(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

}  // namespace

CLI::Validator number() {
  return CLI::Validator(
      [](std::string& s) {
        double x;
        return parseNumber(s, x) ? std::string() : "expects a number, got '" + s + "'";
      },
      "");
}

CLI::Validator integer() {
  return CLI::Validator(
      [](std::string& s) {
        char* end = nullptr;
        errno = 0;
        (void)std::strtol(s.c_str(), &end, 10);
        return end != s.c_str() && *end == '\0' && errno != ERANGE ? std::string()
                                                                   : "expects an integer, got '" + s + "'";
      },
      "");
}

CLI::Validator positive(const std::string& what) {
  const std::string message = what.empty() ? "must be positive" : "must be a positive " + what;
  return CLI::Validator(
      [message](std::string& s) {
        double x;
        if (!parseNumber(s, x)) return "expects a number, got '" + s + "'";
        return x > 0.0 ? std::string() : message + ", got '" + s + "'";
      },
      "");
}

CLI::Validator nonNegative() {
  return CLI::Validator(
      [](std::string& s) {
        double x;
        if (!parseNumber(s, x)) return "expects a number, got '" + s + "'";
        return x >= 0.0 ? std::string() : std::string("must be >= 0");
      },
      "");
}

CLI::Validator between(double lo, double hi, bool whole, const std::string& text_lo, const std::string& text_hi) {
  const std::string range =
      "must be between " + (text_lo.empty() ? show(lo) : text_lo) + " and " + (text_hi.empty() ? show(hi) : text_hi);
  return CLI::Validator(
      [=](std::string& s) {
        double x;
        if (whole) {
          char* end = nullptr;
          errno = 0;
          const long n = std::strtol(s.c_str(), &end, 10);
          if (end == s.c_str() || *end != '\0' || errno == ERANGE) return "expects an integer, got '" + s + "'";
          x = static_cast<double>(n);
        } else if (!parseNumber(s, x)) {
          return "expects a number, got '" + s + "'";
        }
        return x >= lo && x <= hi ? std::string() : range + ", got " + s;
      },
      "");
}

CLI::Validator existingFile() {
  return CLI::Validator(
      [](std::string& s) {
        std::string copy = s;
        const std::string why = CLI::ExistingFile(copy);
        if (why.empty()) return why;
        return s + (why.rfind("File is actually a directory", 0) == 0 ? ": is a folder, not a file" : ": no such file");
      },
      "");
}

CLI::Validator oneOf(const std::vector<std::string>& names) {
  // CLI11's membership test; our wording for the failure
  const CLI::Validator member = CLI::IsMember(names);
  const std::string expected = joinChoices(names);
  CLI::Validator v(
      [member, expected](std::string& s) {
        std::string copy = s;
        return member(copy).empty() ? std::string() : "must be " + expected + ", got '" + s + "'";
      },
      "");  // the flag's type name lists the choices
  return v;
}

bool given(const CLI::App& app, const std::string& flag) { return app.count(flag) > 0; }

std::string FlagValues::get(const std::string& name, const std::string& fallback) const {
  return has(name) ? app_.get_option("--" + name)->as<std::string>() : fallback;
}

long FlagValues::getInt(const std::string& name, long fallback) const {
  return has(name) ? app_.get_option("--" + name)->as<long>() : fallback;
}

double FlagValues::getDouble(const std::string& name, double fallback) const {
  return has(name) ? app_.get_option("--" + name)->as<double>() : fallback;
}

std::string commandLine(const CLI::App& app) {
  std::string s = "redmax " + app.get_name();
  std::map<const CLI::Option*, size_t> next;  // per option, its next result
  for (const CLI::Option* o : app.parse_order()) {
    s += " " + o->get_name();
    if (o->get_type_size() == 0) continue;  // a flag
    const CLI::results_t& r = o->results();
    size_t& i = next[o];
    if (i < r.size()) s += " " + r[i++];
  }
  return s;
}

std::vector<std::string> splitList(const std::string& text, const std::string& separators) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text) {
    if (separators.find(c) != std::string::npos) {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

std::string joinChoices(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i > 0) s += i + 1 == names.size() ? " or " : ", ";
    s += names[i];
  }
  return s;
}

std::vector<std::string> viewAssetFolders() {
  namespace fs = std::filesystem;
  std::vector<std::string> folders;
  if (const char* env = std::getenv("REDMAX_VIEW_ASSETS"); env && *env) folders.push_back(env);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) folders.push_back((exe.parent_path().parent_path() / "view").string());
  // inside the Python module the executable is Python's: the build's view/ beside the module's
  // folder (build/python/redmax/_core*.so -> build/view)
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&viewAssetFolders), &info) && info.dli_fname) {
    const fs::path object = fs::absolute(info.dli_fname, ec);
    if (!ec && object != exe) folders.push_back((object.parent_path().parent_path().parent_path() / "view").string());
  }
  if (*REDMAX_SOURCE_DIR) folders.push_back((fs::path(REDMAX_SOURCE_DIR) / "view" / "web").string());
  return folders;
}

}  // namespace redmax::cli
