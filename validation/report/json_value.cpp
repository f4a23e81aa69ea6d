#include "validation/report/json_value.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "converter/json_writer.hpp"

namespace redmax::validation {

JsonParseError::JsonParseError(size_t offset, const std::string& message)
    : std::runtime_error("JSON at byte " + std::to_string(offset) + ": " + message), offset_(offset) {}

std::string formatNumber(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[32];
  // shortest round-trip form (C++17 to_chars), so files stay compact and exact
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

JsonValue::JsonValue(const std::vector<std::string>& v) : kind_(Kind::Array) {
  for (const auto& s : v) items_.emplace_back(s);
}

JsonValue::JsonValue(const std::vector<double>& v) : kind_(Kind::Array) {
  for (double x : v) items_.emplace_back(x);
}

bool JsonValue::asBool() const {
  if (kind_ != Kind::Bool) throw std::logic_error("JsonValue: not a bool");
  return bool_;
}

double JsonValue::asNumber() const {
  if (kind_ != Kind::Number) throw std::logic_error("JsonValue: not a number");
  return number_;
}

const std::string& JsonValue::asString() const {
  if (kind_ != Kind::String) throw std::logic_error("JsonValue: not a string");
  return string_;
}

size_t JsonValue::size() const {
  return (kind_ == Kind::Array || kind_ == Kind::Object) ? items_.size() : 0;
}

JsonValue& JsonValue::push(JsonValue v) {
  if (kind_ == Kind::Null) kind_ = Kind::Array;
  if (kind_ != Kind::Array) throw std::logic_error("JsonValue: push on a non-array");
  items_.push_back(std::move(v));
  return items_.back();
}

const JsonValue& JsonValue::at(size_t i) const {
  if (kind_ != Kind::Array || i >= items_.size()) throw std::out_of_range("JsonValue: no element " + std::to_string(i));
  return items_[i];
}

JsonValue& JsonValue::at(size_t i) {
  if (kind_ != Kind::Array || i >= items_.size()) throw std::out_of_range("JsonValue: no element " + std::to_string(i));
  return items_[i];
}

JsonValue& JsonValue::operator[](const std::string& key) {
  if (kind_ == Kind::Null) kind_ = Kind::Object;
  if (kind_ != Kind::Object) throw std::logic_error("JsonValue: member '" + key + "' of a non-object");
  if (JsonValue* v = find(key)) return *v;
  keys_.push_back(key);
  items_.emplace_back();
  return items_.back();
}

const JsonValue* JsonValue::find(const std::string& key) const {
  if (kind_ != Kind::Object) return nullptr;
  // the last occurrence wins (only parse() can create repeats, and it avoids them)
  for (size_t i = keys_.size(); i-- > 0;) {
    if (keys_[i] == key) return &items_[i];
  }
  return nullptr;
}

JsonValue* JsonValue::find(const std::string& key) {
  return const_cast<JsonValue*>(static_cast<const JsonValue*>(this)->find(key));
}

const JsonValue& JsonValue::at(const std::string& key) const {
  const JsonValue* v = find(key);
  if (!v) throw std::out_of_range("JsonValue: no member '" + key + "'");
  return *v;
}

// ---------------------------------------------------------------------------------------------
// printing

void JsonValue::dumpTo(std::string& out, int indent) const {
  auto newline = [&](int level) {
    out += '\n';
    out.append(2 * static_cast<size_t>(level), ' ');
  };
  switch (kind_) {
    case Kind::Null: out += "null"; break;
    case Kind::Bool: out += bool_ ? "true" : "false"; break;
    case Kind::Number: out += std::isfinite(number_) ? formatNumber(number_) : "null"; break;
    case Kind::String: out += osim::JsonWriter::escape(string_); break;
    case Kind::Array: {
      if (items_.empty()) {
        out += "[]";
        break;
      }
      // short arrays of scalars stay on one line (column lists, small vectors)
      bool scalars = items_.size() <= 16;
      for (const auto& v : items_) scalars = scalars && v.kind_ != Kind::Array && v.kind_ != Kind::Object;
      out += '[';
      for (size_t i = 0; i < items_.size(); ++i) {
        if (i) out += scalars ? ", " : ",";
        if (!scalars) newline(indent + 1);
        items_[i].dumpTo(out, indent + 1);
      }
      if (!scalars) newline(indent);
      out += ']';
      break;
    }
    case Kind::Object: {
      if (items_.empty()) {
        out += "{}";
        break;
      }
      out += '{';
      for (size_t i = 0; i < items_.size(); ++i) {
        if (i) out += ',';
        newline(indent + 1);
        out += osim::JsonWriter::escape(keys_[i]);
        out += ": ";
        items_[i].dumpTo(out, indent + 1);
      }
      newline(indent);
      out += '}';
      break;
    }
  }
}

std::string JsonValue::dump() const {
  std::string out;
  dumpTo(out, 0);
  out += '\n';
  return out;
}

// ---------------------------------------------------------------------------------------------
// parsing (RFC 8259; recursive descent with a depth limit)

namespace {

class Parser {
 public:
  explicit Parser(const std::string& s) : s_(s) {}

  JsonValue parseDocument() {
    JsonValue v = parseValue(0);
    skipWs();
    if (p_ != s_.size()) fail("unexpected text after the value");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const { throw JsonParseError(p_, why); }

  void skipWs() {
    while (p_ < s_.size() && (s_[p_] == ' ' || s_[p_] == '\t' || s_[p_] == '\n' || s_[p_] == '\r')) ++p_;
  }

  bool consume(const char* word) {
    size_t n = 0;
    while (word[n]) ++n;
    if (s_.compare(p_, n, word) != 0) return false;
    p_ += n;
    return true;
  }

  JsonValue parseValue(int depth) {
    if (depth > 256) fail("nesting too deep");
    skipWs();
    if (p_ >= s_.size()) fail("unexpected end of text");
    const char c = s_[p_];
    if (c == '{') return parseObject(depth);
    if (c == '[') return parseArray(depth);
    if (c == '"') return JsonValue(parseString());
    if (consume("true")) return JsonValue(true);
    if (consume("false")) return JsonValue(false);
    if (consume("null")) return JsonValue();
    if (c == '-' || (c >= '0' && c <= '9')) return JsonValue(parseNumber());
    fail(std::string("unexpected character '") + c + "'");
  }

  JsonValue parseObject(int depth) {
    ++p_;  // '{'
    JsonValue obj = JsonValue::object();
    skipWs();
    if (p_ < s_.size() && s_[p_] == '}') return ++p_, obj;
    for (;;) {
      skipWs();
      if (p_ >= s_.size() || s_[p_] != '"') fail("expected a member name");
      const std::string key = parseString();
      skipWs();
      if (p_ >= s_.size() || s_[p_] != ':') fail("expected ':'");
      ++p_;
      obj[key] = parseValue(depth + 1);
      skipWs();
      if (p_ < s_.size() && s_[p_] == ',') {
        ++p_;
        continue;
      }
      if (p_ < s_.size() && s_[p_] == '}') return ++p_, obj;
      fail("expected ',' or '}'");
    }
  }

  JsonValue parseArray(int depth) {
    ++p_;  // '['
    JsonValue arr = JsonValue::array();
    skipWs();
    if (p_ < s_.size() && s_[p_] == ']') return ++p_, arr;
    for (;;) {
      arr.push(parseValue(depth + 1));
      skipWs();
      if (p_ < s_.size() && s_[p_] == ',') {
        ++p_;
        continue;
      }
      if (p_ < s_.size() && s_[p_] == ']') return ++p_, arr;
      fail("expected ',' or ']'");
    }
  }

  double parseNumber() {
    // validate the JSON grammar, then convert with strtod
    const size_t start = p_;
    auto digits = [&] {
      const size_t d = p_;
      while (p_ < s_.size() && s_[p_] >= '0' && s_[p_] <= '9') ++p_;
      return p_ > d;
    };
    if (s_[p_] == '-') ++p_;
    if (p_ < s_.size() && s_[p_] == '0') {
      ++p_;
    } else if (!digits()) {
      fail("malformed number");
    }
    if (p_ < s_.size() && s_[p_] == '.') {
      ++p_;
      if (!digits()) fail("malformed number");
    }
    if (p_ < s_.size() && (s_[p_] == 'e' || s_[p_] == 'E')) {
      ++p_;
      if (p_ < s_.size() && (s_[p_] == '+' || s_[p_] == '-')) ++p_;
      if (!digits()) fail("malformed number");
    }
    return std::strtod(s_.substr(start, p_ - start).c_str(), nullptr);
  }

  unsigned hex4() {
    if (p_ + 4 > s_.size()) fail("truncated \\u escape");
    unsigned v = 0;
    for (int i = 0; i < 4; ++i) {
      const char c = s_[p_++];
      v <<= 4;
      if (c >= '0' && c <= '9') v |= static_cast<unsigned>(c - '0');
      else if (c >= 'a' && c <= 'f') v |= static_cast<unsigned>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F') v |= static_cast<unsigned>(c - 'A' + 10);
      else fail("bad \\u escape");
    }
    return v;
  }

  static void appendUtf8(std::string& o, unsigned cp) {
    if (cp < 0x80) {
      o += static_cast<char>(cp);
    } else if (cp < 0x800) {
      o += static_cast<char>(0xC0 | (cp >> 6));
      o += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      o += static_cast<char>(0xE0 | (cp >> 12));
      o += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      o += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      o += static_cast<char>(0xF0 | (cp >> 18));
      o += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      o += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      o += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }

  std::string parseString() {
    ++p_;  // opening quote
    std::string o;
    for (;;) {
      if (p_ >= s_.size()) fail("unterminated string");
      const char c = s_[p_++];
      if (c == '"') return o;
      if (static_cast<unsigned char>(c) < 0x20) fail("control character in a string");
      if (c != '\\') {
        o += c;
        continue;
      }
      if (p_ >= s_.size()) fail("unterminated string");
      const char e = s_[p_++];
      switch (e) {
        case '"': o += '"'; break;
        case '\\': o += '\\'; break;
        case '/': o += '/'; break;
        case 'b': o += '\b'; break;
        case 'f': o += '\f'; break;
        case 'n': o += '\n'; break;
        case 'r': o += '\r'; break;
        case 't': o += '\t'; break;
        case 'u': {
          unsigned cp = hex4();
          // a surrogate pair encodes one code point above U+FFFF
          if (cp >= 0xD800 && cp <= 0xDBFF && s_.compare(p_, 2, "\\u") == 0) {
            p_ += 2;
            const unsigned lo = hex4();
            if (lo < 0xDC00 || lo > 0xDFFF) fail("bad surrogate pair");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
          }
          appendUtf8(o, cp);
          break;
        }
        default: fail(std::string("bad escape '\\") + e + "'");
      }
    }
  }

  const std::string& s_;
  size_t p_ = 0;
};

}  // namespace

JsonValue JsonValue::parse(const std::string& text) { return Parser(text).parseDocument(); }

}  // namespace redmax::validation
