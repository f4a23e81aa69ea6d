#pragma once
// tinyxml2 helpers shared by the converter's readers (internal: include only from converter/*.cpp).
// Every parse failure is reported as a ConvertError naming the file and the element's line.
#include <optional>
#include <string>
#include <vector>

#include <tinyxml2.h>

#include "converter/error.hpp"
#include "core/spatial/types.hpp"

namespace redmax::osim::detail {

using tinyxml2::XMLElement;

/// A parsed XML file. Loading fails with a ConvertError (with the parser's line) on unreadable or
/// malformed files.
class XmlDocument {
 public:
  explicit XmlDocument(const std::string& path);
  /// parses `text`, read from `path` by the caller (errors name `path` and the line in `text`)
  XmlDocument(const std::string& path, const std::string& text);
  XmlDocument(const XmlDocument&) = delete;
  XmlDocument& operator=(const XmlDocument&) = delete;

  const XMLElement* root() const { return doc_.RootElement(); }
  const std::string& path() const { return path_; }
  /// throws ConvertError(path, line of e, what)
  [[noreturn]] void fail(const XMLElement* e, const std::string& what) const;

 private:
  void check(tinyxml2::XMLError err) const;
  std::string path_;
  tinyxml2::XMLDocument doc_;
};

/// line of an element (0 for null)
int lineOf(const XMLElement* e);
/// first direct child element with this tag, or null
const XMLElement* firstChild(const XMLElement* e, const char* tag);
/// direct child elements, all or those with this tag, in document order
std::vector<const XMLElement*> childElements(const XMLElement* e, const char* tag = nullptr);
/// value of an attribute, "" when absent
std::string attribute(const XMLElement* e, const char* name);
/// text content with leading/trailing white space removed ("" for null or empty elements)
std::string textOf(const XMLElement* e);
/// white-space separated words of a text
std::vector<std::string> splitWords(const std::string& text);
std::string trim(const std::string& s);
std::string toLower(std::string s);
/// the tool element of a setup file: <OpenSimDocument><tag> or a bare <tag> root (doc.fail
/// otherwise)
const XMLElement* toolRoot(const XmlDocument& doc, const char* tag);
/// the document's version as OpenSim's XMLDocument takes it: the <OpenSimDocument> Version, 10500
/// for a document without that root (its objects then get the conversions of old documents);
/// 40000 for an <OpenSimDocument> without a Version (OpenSim refuses it)
int documentVersion(const XmlDocument& doc);
/// the folder of a file path ("." for a bare name)
std::string folderOf(const std::string& file);
/// "a, b, c", at most max_names of them, then ", ... (N in all)"
std::string joinNames(const std::vector<std::string>& names, size_t max_names = 12);

/// parse one number as OpenSim does (also inf, infinity, nan); fails with the element's line
double parseNumber(const XmlDocument& doc, const XMLElement* e, const std::string& word);
/// all numbers of an element's text; separators are white space, ',' and the brackets of "~[a,b]"
std::vector<double> parseNumbers(const XmlDocument& doc, const XMLElement* e);
/// exactly n numbers
std::vector<double> parseNumbersExactly(const XmlDocument& doc, const XMLElement* e, size_t n);
bool parseBool(const XmlDocument& doc, const XMLElement* e);
int parseInt(const XmlDocument& doc, const XMLElement* e);

/// child value helpers: the fallback is returned when the child element is absent or empty
double childDouble(const XmlDocument& doc, const XMLElement* parent, const char* tag,
                   double fallback);
Vec3 childVec3(const XmlDocument& doc, const XMLElement* parent, const char* tag,
               const Vec3& fallback);
bool childBool(const XmlDocument& doc, const XMLElement* parent, const char* tag, bool fallback);
std::string childText(const XMLElement* parent, const char* tag, const std::string& fallback = "");

/// round to 6 significant digits, as a default std::ostringstream writes a double
/// (OpenSim's legacy upgrades pass some values through such a stream, docs/opensim_compatibility.md §1.4)
double roundLikeOstream(double x);

}  // namespace redmax::osim::detail
