#pragma once
// A small JSON document tree for the report's summary.json: built in nested sections by the
// report and by later work (mass sweeps, work-precision), printed with keys in insertion order,
// and parsed back (tests, merging summaries). No third-party dependency (the brief forbids one).
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace redmax::validation {

/// Malformed JSON text; what() gives the byte offset.
class JsonParseError : public std::runtime_error {
 public:
  JsonParseError(size_t offset, const std::string& message);
  size_t offset() const { return offset_; }

 private:
  size_t offset_ = 0;
};

/// A JSON value: null, bool, number (double), string, array or object (keys kept in insertion
/// order; a repeated key in parsed text keeps the last value, as most readers do).
/// Non-finite numbers are printed as null (JSON has no inf/NaN).
class JsonValue {
 public:
  enum class Kind { Null, Bool, Number, String, Array, Object };

  JsonValue() = default;
  JsonValue(std::nullptr_t) {}
  JsonValue(bool b) : kind_(Kind::Bool), bool_(b) {}
  JsonValue(double x) : kind_(Kind::Number), number_(x) {}
  JsonValue(int x) : kind_(Kind::Number), number_(x) {}
  JsonValue(long x) : kind_(Kind::Number), number_(static_cast<double>(x)) {}
  JsonValue(long long x) : kind_(Kind::Number), number_(static_cast<double>(x)) {}
  JsonValue(unsigned long x) : kind_(Kind::Number), number_(static_cast<double>(x)) {}
  JsonValue(const char* s) : kind_(Kind::String), string_(s) {}
  JsonValue(std::string s) : kind_(Kind::String), string_(std::move(s)) {}
  /// an array of strings / numbers
  JsonValue(const std::vector<std::string>& v);
  JsonValue(const std::vector<double>& v);

  static JsonValue array() { JsonValue v; v.kind_ = Kind::Array; return v; }
  static JsonValue object() { JsonValue v; v.kind_ = Kind::Object; return v; }

  Kind kind() const { return kind_; }
  bool isNull() const { return kind_ == Kind::Null; }
  bool isBool() const { return kind_ == Kind::Bool; }
  bool isNumber() const { return kind_ == Kind::Number; }
  bool isString() const { return kind_ == Kind::String; }
  bool isArray() const { return kind_ == Kind::Array; }
  bool isObject() const { return kind_ == Kind::Object; }

  /// the value; throws std::logic_error on the wrong kind
  bool asBool() const;
  double asNumber() const;
  const std::string& asString() const;

  /// number of array elements or object members (0 otherwise)
  size_t size() const;

  /// append to an array (a null value becomes an empty array first); returns the new element
  JsonValue& push(JsonValue v);
  /// array element i; throws std::out_of_range
  const JsonValue& at(size_t i) const;
  JsonValue& at(size_t i);

  /// object member, created as null if absent (a null value becomes an empty object first);
  /// throws std::logic_error on other kinds
  JsonValue& operator[](const std::string& key);
  /// object member or nullptr
  const JsonValue* find(const std::string& key) const;
  JsonValue* find(const std::string& key);
  bool contains(const std::string& key) const { return find(key) != nullptr; }
  /// object member; throws std::out_of_range if absent
  const JsonValue& at(const std::string& key) const;
  /// object keys in order
  const std::vector<std::string>& keys() const { return keys_; }

  /// pretty-printed text (two-space indent, trailing newline at top level); numbers in the
  /// shortest form that reads back to the same double
  std::string dump() const;
  /// parse a document (one value, surrounding white space allowed); throws JsonParseError
  static JsonValue parse(const std::string& text);

 private:
  void dumpTo(std::string& out, int indent) const;

  Kind kind_ = Kind::Null;
  bool bool_ = false;
  double number_ = 0;
  std::string string_;
  std::vector<JsonValue> items_;   // array elements, or object values
  std::vector<std::string> keys_;  // object keys (parallel to items_)
};

/// Shortest decimal text that reads back to x ("nan", "inf", "-inf" for non-finite values).
std::string formatNumber(double x);

}  // namespace redmax::validation
