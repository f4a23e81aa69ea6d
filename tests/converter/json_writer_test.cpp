// The JSON writer and the description `redmax convert --json` writes: the output is parsed back
// with an independent minimal parser and checked field by field; escaping is checked on names
// with quotes, backslashes, control characters and UTF-8; the summary names the key numbers.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <variant>

#include "converter/json_writer.hpp"
#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

// ---- a minimal strict JSON parser (RFC 8259 subset: no exponent-less leading '+', etc.) ----
struct Json;
using JsonObject = std::map<std::string, Json>;
using JsonArray = std::vector<Json>;
struct Json {
  std::variant<std::nullptr_t, bool, double, std::string, std::shared_ptr<JsonArray>,
               std::shared_ptr<JsonObject>>
      v;
  const JsonObject& obj() const { return *std::get<std::shared_ptr<JsonObject>>(v); }
  const JsonArray& arr() const { return *std::get<std::shared_ptr<JsonArray>>(v); }
  const std::string& str() const { return std::get<std::string>(v); }
  double num() const { return std::get<double>(v); }
  bool boolean() const { return std::get<bool>(v); }
  const Json& operator[](const std::string& k) const {
    auto it = obj().find(k);
    if (it == obj().end()) throw std::runtime_error("missing key " + k);
    return it->second;
  }
  bool has(const std::string& k) const { return obj().count(k) > 0; }
};

class Parser {
 public:
  explicit Parser(const std::string& s) : s_(s) {}
  Json parse() {
    Json j = value();
    ws();
    if (i_ != s_.size()) throw std::runtime_error("trailing characters");
    return j;
  }

 private:
  void ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\n' || s_[i_] == '\t' || s_[i_] == '\r')) ++i_;
  }
  char peek() {
    ws();
    if (i_ >= s_.size()) throw std::runtime_error("unexpected end");
    return s_[i_];
  }
  void expect(char c) {
    if (peek() != c) throw std::runtime_error(std::string("expected ") + c + " at " + std::to_string(i_));
    ++i_;
  }
  Json value() {
    const char c = peek();
    if (c == '{') {
      ++i_;
      auto o = std::make_shared<JsonObject>();
      if (peek() == '}') return ++i_, Json{o};
      while (true) {
        const std::string k = string();
        expect(':');
        if (o->count(k)) throw std::runtime_error("duplicate key " + k);
        (*o)[k] = value();
        if (peek() == ',') { ++i_; continue; }
        expect('}');
        return Json{o};
      }
    }
    if (c == '[') {
      ++i_;
      auto a = std::make_shared<JsonArray>();
      if (peek() == ']') return ++i_, Json{a};
      while (true) {
        a->push_back(value());
        if (peek() == ',') { ++i_; continue; }
        expect(']');
        return Json{a};
      }
    }
    if (c == '"') return Json{string()};
    if (s_.compare(i_, 4, "true") == 0) return i_ += 4, Json{true};
    if (s_.compare(i_, 5, "false") == 0) return i_ += 5, Json{false};
    if (s_.compare(i_, 4, "null") == 0) return i_ += 4, Json{nullptr};
    size_t j = i_;
    if (s_[j] == '-') ++j;
    if (j >= s_.size() || !std::isdigit(static_cast<unsigned char>(s_[j])))
      throw std::runtime_error("bad value at " + std::to_string(i_));
    while (j < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[j])) || s_[j] == '.' ||
                             s_[j] == 'e' || s_[j] == 'E' || s_[j] == '+' || s_[j] == '-'))
      ++j;
    const double x = std::stod(s_.substr(i_, j - i_));
    i_ = j;
    return Json{x};
  }
  std::string string() {
    expect('"');
    std::string out;
    while (true) {
      if (i_ >= s_.size()) throw std::runtime_error("unterminated string");
      const unsigned char c = static_cast<unsigned char>(s_[i_++]);
      if (c == '"') return out;
      if (c < 0x20) throw std::runtime_error("raw control character in string");
      if (c != '\\') { out += static_cast<char>(c); continue; }
      const char e = s_[i_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          const int code = std::stoi(s_.substr(i_, 4), nullptr, 16);
          i_ += 4;
          if (code >= 0x80) throw std::runtime_error("test parser handles only ASCII \\u");
          out += static_cast<char>(code);
          break;
        }
        default: throw std::runtime_error("bad escape");
      }
    }
  }
  const std::string& s_;
  size_t i_ = 0;
};

TEST(JsonWriter, EscapesAndStructure) {
  JsonWriter w;
  const std::string nasty = "q\"uote\\back\nnew\ttab\x01" "ctl \xC3\xA9";
  w.beginObject().key(nasty).value(nasty).key("n").value(1.5).key("i").value(-3);
  w.key("inf").value(std::numeric_limits<double>::infinity()).key("b").value(false);
  w.key("e").beginArray().endArray().key("o").beginObject().endObject().key("z").null();
  w.endObject();
  const Json j = Parser(w.str()).parse();
  EXPECT_EQ(j[nasty].str(), nasty);
  EXPECT_EQ(j["n"].num(), 1.5);
  EXPECT_EQ(j["i"].num(), -3.0);
  EXPECT_TRUE(std::holds_alternative<std::nullptr_t>(j["inf"].v));  // JSON has no infinity
  EXPECT_FALSE(j["b"].boolean());
  EXPECT_TRUE(j["e"].arr().empty());
  EXPECT_NE(w.str().find("\\u0001"), std::string::npos);
  // doubles survive exactly (%.17g)
  JsonWriter w2;
  w2.beginArray().value(0.1).value(1.0 / 3.0).value(-9.80665).endArray();
  const Json a = Parser(w2.str()).parse();
  EXPECT_EQ(a.arr()[1].num(), 1.0 / 3.0);
  EXPECT_EQ(a.arr()[2].num(), -9.80665);
  // misuse is refused
  JsonWriter bad;
  bad.beginObject();
  EXPECT_THROW(bad.value(1), std::logic_error);
  EXPECT_THROW(bad.endArray(), std::logic_error);
  EXPECT_THROW((void)bad.str(), std::logic_error);
}

TEST(JsonDescription, FieldsOfASyntheticModel) {
  test::TempDir dir;
  const std::string muscle =
      "<ForceSet><objects>\n<Thelen2003Muscle name=\"mu&quot;s\\cle\">\n<GeometryPath name=\"path\">"
      "<PathPointSet><objects>\n<PathPoint name=\"o\"><socket_parent_frame>/ground"
      "</socket_parent_frame><location>0 1 0</location></PathPoint>\n"
      "<PathPoint name=\"i\"><socket_parent_frame>/bodyset/a</socket_parent_frame>"
      "<location>0 0 0</location></PathPoint>\n</objects></PathPointSet></GeometryPath>\n"
      "<max_isometric_force>500</max_isometric_force>\n</Thelen2003Muscle>\n"
      "<ElasticFoundationForce name=\"contact\"/>\n</objects></ForceSet>\n";
  const auto d = readOsimModel(dir.write(
      "m.osim", test::modernOsim(test::bodyXml("a", 2.0), test::pinXml("j", "/ground", "/bodyset/a"),
                                 muscle)));
  const Json j = Parser(describeAsJson(d)).parse();
  EXPECT_EQ(j["name"].str(), "synthetic");
  EXPECT_EQ(j["osim_version"].num(), 40000.0);
  ASSERT_EQ(j["bodies"].arr().size(), 1u);
  EXPECT_EQ(j["bodies"].arr()[0]["name"].str(), "a");
  EXPECT_EQ(j["bodies"].arr()[0]["mass"].num(), 2.0);
  const Json& joint = j["joints"].arr().at(0);
  EXPECT_EQ(joint["name"].str(), "j");
  EXPECT_EQ(joint["type"].str(), "PinJoint");
  EXPECT_EQ(joint["parent"].str(), "ground");
  EXPECT_EQ(joint["child"].str(), "a");
  EXPECT_EQ(joint["X_PF"].arr().size(), 16u);
  const Json& coord = j["coordinates"].arr().at(0);
  EXPECT_EQ(coord["name"].str(), "j_q");
  EXPECT_EQ(coord["motion_type"].str(), "Rotational");
  EXPECT_FALSE(coord["locked"].boolean());
  EXPECT_TRUE(j["constraints"].arr().empty());
  const Json& m = j["muscles"].arr().at(0);
  EXPECT_EQ(m["name"].str(), "mu\"s\\cle");
  EXPECT_EQ(m["class"].str(), "Thelen2003Muscle");
  EXPECT_EQ(m["path_type"].str(), "I");
  EXPECT_EQ(m["path_points"].num(), 2.0);
  EXPECT_EQ(m["wraps"].num(), 0.0);
  EXPECT_EQ(m["max_isometric_force"].num(), 500.0);
  // the contact force is listed and reported as not modelled
  ASSERT_EQ(j["unsupported"].arr().size(), 1u);
  EXPECT_NE(j["unsupported"].arr()[0].str().find("ElasticFoundationForce"), std::string::npos);
  EXPECT_EQ(j["unsupported"].arr()[0].str().rfind("line ", 0), 0u);
  EXPECT_EQ(j["forces"].arr().at(0)["class"].str(), "ElasticFoundationForce");
  // the summary carries the same numbers
  const std::string sum = formatSummary(d);
  EXPECT_NE(sum.find("DoF          1"), std::string::npos) << sum;
  EXPECT_NE(sum.find("Type I 1, Type II 0, Type III 0"), std::string::npos) << sum;
  EXPECT_NE(sum.find("unsupported  1"), std::string::npos) << sum;
}

TEST(JsonDescription, SharedModelRoundTrip) {
  REDMAX_REQUIRE_SHARED();
  for (const char* model : {"opensim-models/Models/Arm26/arm26.osim",
                            "opensim-models/Models/Rajagopal/Rajagopal2016.osim",
                            "opensim-core/OpenSim/Tests/shared/ThoracoscapularShoulderModel.osim"}) {
    SCOPED_TRACE(model);
    const auto d = readOsimModel(test::sharedOpenSim(model));
    const Json j = Parser(describeAsJson(d)).parse();
    ASSERT_EQ(j["bodies"].arr().size(), d.bodies.size());
    ASSERT_EQ(j["joints"].arr().size(), d.joints.size());
    ASSERT_EQ(j["coordinates"].arr().size(), d.coordinates.size());
    ASSERT_EQ(j["muscles"].arr().size(), d.muscles.size());
    ASSERT_EQ(j["constraints"].arr().size(), d.constraints.size());
    for (size_t i = 0; i < d.coordinates.size(); ++i)
      EXPECT_EQ(j["coordinates"].arr()[i]["name"].str(), d.coordinates[i].name);
    for (size_t i = 0; i < d.muscles.size(); ++i) {
      const Json& m = j["muscles"].arr()[i];
      EXPECT_EQ(m["path_points"].num(), static_cast<double>(d.muscles[i].points.size()));
      EXPECT_EQ(m["wraps"].num(), static_cast<double>(d.muscles[i].wraps.size()));
      EXPECT_EQ(m["path_type"].str(), toString(d.muscles[i].path_type));
    }
    for (size_t i = 0; i < d.bodies.size(); ++i)
      EXPECT_EQ(j["bodies"].arr()[i]["mass"].num(), d.bodies[i].mass);
    EXPECT_TRUE(j.has("unsupported"));
  }
}

}  // namespace
}  // namespace redmax::osim
