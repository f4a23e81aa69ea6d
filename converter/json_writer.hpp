#pragma once
// A small JSON writer (RFC 8259 escaping, pretty-printed) and the JSON form of a
// ModelDescription that `redmax convert --json` writes.
#include <string>
#include <vector>

#include "converter/model_description.hpp"

namespace redmax::osim {

/// Streaming writer. Usage: w.beginObject().key("a").value(1).endObject(); misuse (a value where
/// a key is due, unbalanced ends) throws std::logic_error. Non-finite numbers are written as null.
class JsonWriter {
 public:
  JsonWriter& beginObject();
  JsonWriter& endObject();
  JsonWriter& beginArray();
  JsonWriter& endArray();
  JsonWriter& key(const std::string& k);
  JsonWriter& value(const std::string& s);
  JsonWriter& value(const char* s) { return value(std::string(s)); }
  JsonWriter& value(double x);
  JsonWriter& value(int x);
  JsonWriter& value(bool b);
  JsonWriter& null();
  JsonWriter& numbers(const double* x, int n);  ///< an array of numbers
  /// an array of numbers on one line, each with `digits` significant digits (large data arrays)
  JsonWriter& compactNumbers(const double* x, int n, int digits);
  /// an array of integers on one line
  JsonWriter& compactIntegers(const int* x, int n);
  /// the document; throws std::logic_error if containers are still open
  const std::string& str() const;

  static std::string escape(const std::string& s);

 private:
  void beforeValue();
  void newline();
  std::string out_;
  struct Level {
    bool object;
    int count;
    bool key_pending;
  };
  std::vector<Level> stack_;
  bool done_ = false;
};

/// The intermediate description as JSON: name, osim_version, gravity, bodies, joints,
/// coordinates (q order), constraints, muscles, forces, markers, wrap_objects, tree,
/// unsupported (strings "line N: what"), warnings.
std::string describeAsJson(const ModelDescription& d);

/// A human-readable summary: bodies, DoF, joints by type, muscles by path type, constraints,
/// unsupported items and warnings.
std::string formatSummary(const ModelDescription& d);

}  // namespace redmax::osim
