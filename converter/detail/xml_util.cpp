#include "converter/detail/xml_util.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>

namespace redmax::osim {

namespace {
std::string locate(const std::string& file, int line, const std::string& message) {
  std::string s = file;
  if (line > 0) s.append(":").append(std::to_string(line));
  s.append(": ").append(message);
  return s;
}
}  // namespace

ConvertError::ConvertError(std::string file, int line, std::string message)
    : std::runtime_error(locate(file, line, message)),
      file_(std::move(file)),
      line_(line),
      message_(std::move(message)) {}

namespace detail {

XmlDocument::XmlDocument(const std::string& path) : path_(path) {
  // check readability first so that a missing file is not reported as an XML error
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw ConvertError(path, 0, "cannot open file");
  probe.close();
  check(doc_.LoadFile(path.c_str()));
}

XmlDocument::XmlDocument(const std::string& path, const std::string& text) : path_(path) {
  check(doc_.Parse(text.data(), text.size()));
}

void XmlDocument::check(tinyxml2::XMLError err) const {
  if (err != tinyxml2::XML_SUCCESS) {
    const char* s = doc_.ErrorStr();
    throw ConvertError(path_, doc_.ErrorLineNum(),
                       std::string("malformed XML: ") + (s ? s : doc_.ErrorName()));
  }
  if (!doc_.RootElement()) throw ConvertError(path_, 0, "malformed XML: no root element");
}

void XmlDocument::fail(const XMLElement* e, const std::string& what) const {
  throw ConvertError(path_, lineOf(e), what);
}

int lineOf(const XMLElement* e) { return e ? e->GetLineNum() : 0; }

const XMLElement* firstChild(const XMLElement* e, const char* tag) {
  return e ? e->FirstChildElement(tag) : nullptr;
}

std::vector<const XMLElement*> childElements(const XMLElement* e, const char* tag) {
  std::vector<const XMLElement*> out;
  if (!e) return out;
  for (const XMLElement* c = e->FirstChildElement(tag); c; c = c->NextSiblingElement(tag))
    out.push_back(c);
  return out;
}

std::string attribute(const XMLElement* e, const char* name) {
  if (!e) return {};
  const char* v = e->Attribute(name);
  return v ? std::string(v) : std::string();
}

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

std::string toLower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string textOf(const XMLElement* e) {
  if (!e) return {};
  const char* t = e->GetText();
  return t ? trim(t) : std::string();
}

std::vector<std::string> splitWords(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!cur.empty()) out.push_back(cur), cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

namespace {
// "<tag>: " built by appending (GCC 12 warns falsely on "literal" + std::string temporaries)
std::string tagPrefix(const XMLElement* e) {
  std::string s = "<";
  s += e ? e->Name() : "value";
  s += ">: ";
  return s;
}
}  // namespace

double parseNumber(const XmlDocument& doc, const XMLElement* e, const std::string& word) {
  const std::string w = toLower(word);
  if (w == "inf" || w == "infinity" || w == "+inf" || w == "+infinity")
    return std::numeric_limits<double>::infinity();
  if (w == "-inf" || w == "-infinity") return -std::numeric_limits<double>::infinity();
  if (w == "nan") return std::numeric_limits<double>::quiet_NaN();
  const char* s = word.c_str();
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(s, &end);
  // strtod also accepts hex floats and "infinity" prefixes; demand the whole word be a number
  if (end == s || *end != '\0' || errno == ERANGE) doc.fail(e, tagPrefix(e) + "'" + word + "' is not a number");
  return x;
}

std::vector<double> parseNumbers(const XmlDocument& doc, const XMLElement* e) {
  std::string t = textOf(e);
  // SimTK also writes vectors as "~[a,b,c]"
  for (auto& c : t)
    if (c == ',' || c == '[' || c == ']' || c == '~' || c == '(' || c == ')') c = ' ';
  std::vector<double> out;
  for (const auto& w : splitWords(t)) out.push_back(parseNumber(doc, e, w));
  return out;
}

std::vector<double> parseNumbersExactly(const XmlDocument& doc, const XMLElement* e, size_t n) {
  auto v = parseNumbers(doc, e);
  if (v.size() != n)
    doc.fail(e, tagPrefix(e) + "needs " + std::to_string(n) + " numbers, found " +
                    std::to_string(v.size()));
  return v;
}

bool parseBool(const XmlDocument& doc, const XMLElement* e) {
  const std::string t = toLower(textOf(e));
  if (t == "true" || t == "1" || t == "yes") return true;
  if (t == "false" || t == "0" || t == "no") return false;
  doc.fail(e, tagPrefix(e) + "'" + textOf(e) + "' is not true or false");
}

int parseInt(const XmlDocument& doc, const XMLElement* e) {
  const std::string t = textOf(e);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(t.c_str(), &end, 10);
  if (t.empty() || *end != '\0' || errno == ERANGE || v < -2147483647L || v > 2147483647L)
    doc.fail(e, tagPrefix(e) + "'" + t + "' is not an integer");
  return static_cast<int>(v);
}

double childDouble(const XmlDocument& doc, const XMLElement* parent, const char* tag,
                   double fallback) {
  const XMLElement* c = firstChild(parent, tag);
  if (!c || textOf(c).empty()) return fallback;
  return parseNumbersExactly(doc, c, 1)[0];
}

Vec3 childVec3(const XmlDocument& doc, const XMLElement* parent, const char* tag,
               const Vec3& fallback) {
  const XMLElement* c = firstChild(parent, tag);
  if (!c || textOf(c).empty()) return fallback;
  const auto v = parseNumbersExactly(doc, c, 3);
  return Vec3(v[0], v[1], v[2]);
}

bool childBool(const XmlDocument& doc, const XMLElement* parent, const char* tag, bool fallback) {
  const XMLElement* c = firstChild(parent, tag);
  if (!c || textOf(c).empty()) return fallback;
  return parseBool(doc, c);
}

std::string childText(const XMLElement* parent, const char* tag, const std::string& fallback) {
  const XMLElement* c = firstChild(parent, tag);
  if (!c) return fallback;
  return textOf(c);
}

double roundLikeOstream(double x) {
  if (!std::isfinite(x)) return x;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", x);
  return std::strtod(buf, nullptr);
}

int documentVersion(const XmlDocument& doc) {
  const XMLElement* root = doc.root();
  if (!root || std::string(root->Name()) != "OpenSimDocument") return 10500;
  const char* v = root->Attribute("Version");
  return v ? std::atoi(v) : 40000;  // OpenSim requires the attribute; a wrapper without one reads as current
}

const XMLElement* toolRoot(const XmlDocument& doc, const char* tag) {
  const XMLElement* root = doc.root();
  if (std::string(root->Name()) == tag) return root;
  if (std::string(root->Name()) == "OpenSimDocument") {
    if (const XMLElement* e = firstChild(root, tag)) return e;
    doc.fail(root, std::string("no <") + tag + "> element in <OpenSimDocument>");
  }
  doc.fail(root, "root element is <" + std::string(root->Name()) + ">, expected <" + tag +
                     "> or <OpenSimDocument>");
}

std::string folderOf(const std::string& file) {
  const std::filesystem::path p = std::filesystem::path(file).parent_path();
  return p.empty() ? std::string(".") : p.string();
}

std::string joinNames(const std::vector<std::string>& names, size_t max_names) {
  std::string out;
  for (size_t k = 0; k < names.size() && k < max_names; ++k) out += (k ? ", " : "") + names[k];
  if (names.size() > max_names) out += ", ... (" + std::to_string(names.size()) + " in all)";
  return out;
}

}  // namespace detail
}  // namespace redmax::osim
