#pragma once
// Minimal flag parser: `--name value`, `--name=value`, boolean `--name`, and positionals.
// Unknown flags are usage errors, so typos never pass silently.
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cli/command.hpp"

namespace redmax::cli {

class Args {
 public:
  /// value_flags take a value; bool_flags do not. Names without the leading dashes.
  Args(const std::vector<std::string>& argv, const std::set<std::string>& value_flags,
       const std::set<std::string>& bool_flags);
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::optional<std::string> get(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback) const;
  double getDouble(const std::string& name, double fallback) const;
  long getInt(const std::string& name, long fallback) const;
  const std::vector<std::string>& positionals() const { return positionals_; }

 private:
  std::map<std::string, std::string> values_;
  std::vector<std::string> positionals_;
};

/// The non-empty items of `text` split at any of `separators` (",": "a,,b" -> {a, b}).
std::vector<std::string> splitList(const std::string& text, const std::string& separators = ",");

}  // namespace redmax::cli
