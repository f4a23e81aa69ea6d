// The report's JSON tree and CSV tables (validation/report/json_value.hpp, csv.hpp): nested
// building, printing and parsing back, escaping, exact number round trips, non-finite numbers,
// malformed input, CSV quoting.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "validation/report/csv.hpp"
#include "validation/report/json_value.hpp"

namespace redmax::validation {
namespace {

TEST(ReportJson, NestedSectionsRoundTrip) {
  JsonValue root = JsonValue::object();
  root["title"] = "a \"quoted\" title\nwith a line break and \\ backslash";
  root["passed"] = false;
  root["count"] = 42;
  JsonValue& sweeps = root["sweeps"]["tibia"];  // nested objects created on first use
  sweeps["fraction"] = std::vector<double>{0, 0.1, 0.2};
  sweeps["labels"] = std::vector<std::string>{"knee", "hip"};
  JsonValue& runs = root["work_precision"]["runs"];
  runs.push(JsonValue::object())["error"] = 1e-8;
  runs.push(JsonValue::object())["error"] = 2.5e-300;
  root["nothing"] = nullptr;

  const std::string text = root.dump();
  const JsonValue back = JsonValue::parse(text);
  EXPECT_EQ(back.at("title").asString(), root.at("title").asString());
  EXPECT_FALSE(back.at("passed").asBool());
  EXPECT_EQ(back.at("count").asNumber(), 42.0);
  EXPECT_EQ(back.at("sweeps").at("tibia").at("fraction").at(1).asNumber(), 0.1);
  EXPECT_EQ(back.at("sweeps").at("tibia").at("labels").at(1).asString(), "hip");
  EXPECT_EQ(back.at("work_precision").at("runs").size(), 2u);
  EXPECT_EQ(back.at("work_precision").at("runs").at(1).at("error").asNumber(), 2.5e-300);
  EXPECT_TRUE(back.at("nothing").isNull());
  // keys keep their insertion order, and printing again gives the same text
  EXPECT_EQ(back.keys(), (std::vector<std::string>{"title", "passed", "count", "sweeps", "work_precision", "nothing"}));
  EXPECT_EQ(back.dump(), text);
}

TEST(ReportJson, NumbersRoundTripExactly) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mant(-1, 1);
  std::uniform_int_distribution<int> ex(-300, 300);
  JsonValue arr = JsonValue::array();
  std::vector<double> xs;
  for (int i = 0; i < 500; ++i) {
    const double x = std::ldexp(mant(rng), ex(rng));
    xs.push_back(x);
    arr.push(x);
  }
  const JsonValue back = JsonValue::parse(arr.dump());
  for (size_t i = 0; i < xs.size(); ++i) EXPECT_EQ(back.at(i).asNumber(), xs[i]) << i;
  EXPECT_EQ(formatNumber(0.1), "0.1");
  EXPECT_EQ(formatNumber(3.0), "3");
  EXPECT_EQ(formatNumber(std::numeric_limits<double>::infinity()), "inf");
}

TEST(ReportJson, NonFiniteNumbersBecomeNull) {
  JsonValue v = JsonValue::object();
  v["inf"] = std::numeric_limits<double>::infinity();
  v["nan"] = std::numeric_limits<double>::quiet_NaN();
  const JsonValue back = JsonValue::parse(v.dump());
  EXPECT_TRUE(back.at("inf").isNull());
  EXPECT_TRUE(back.at("nan").isNull());
}

TEST(ReportJson, ParsesEscapesAndUnicode) {
  const JsonValue v = JsonValue::parse(R"( {"s": "a\u00e9\ud83d\ude00\t\"\/", "n": -1.5e-3, "e": [], "o": {}} )");
  EXPECT_EQ(v.at("s").asString(), "a\xC3\xA9\xF0\x9F\x98\x80\t\"/");
  EXPECT_EQ(v.at("n").asNumber(), -1.5e-3);
  EXPECT_TRUE(v.at("e").isArray());
  EXPECT_EQ(v.at("e").size(), 0u);
  EXPECT_TRUE(v.at("o").isObject());
}

TEST(ReportJson, MalformedTextThrowsWithOffset) {
  for (const char* bad : {"", "{", "{\"a\":1,}", "[1 2]", "\"abc", "01", "1.", "tru", "{\"a\" 1}", "[1]x",
                          "\"\\q\"", "{1:2}", "-"}) {
    EXPECT_THROW(JsonValue::parse(bad), JsonParseError) << bad;
  }
  try {
    JsonValue::parse("[1, 2, ?]");
    FAIL();
  } catch (const JsonParseError& e) {
    EXPECT_EQ(e.offset(), 7u);
  }
  // a deep nesting is refused, not a stack overflow
  EXPECT_THROW(JsonValue::parse(std::string(100000, '[')), JsonParseError);
}

TEST(ReportJson, WrongKindThrows) {
  JsonValue n = 3.0;
  EXPECT_THROW(n.asString(), std::logic_error);
  EXPECT_THROW(n["key"], std::logic_error);
  EXPECT_THROW(n.push(1), std::logic_error);
  const JsonValue o = JsonValue::object();
  EXPECT_THROW(o.at("missing"), std::out_of_range);
  EXPECT_EQ(o.find("missing"), nullptr);
}

TEST(ReportCsv, QuotingRoundTrip) {
  CsvTable t;
  t.header = {"column", "value", "note"};
  t.addRow({"plain", "1", "x"});
  t.addRow({"with,comma", "2", "say \"hi\""});
  t.addRow({"multi\nline", "3", ""});
  t.addRow(std::string("numbers"), std::vector<double>{0.1, std::numeric_limits<double>::quiet_NaN()});
  const std::string text = formatCsv(t);
  EXPECT_NE(text.find("\"with,comma\""), std::string::npos);
  EXPECT_NE(text.find("\"say \"\"hi\"\"\""), std::string::npos);
  const CsvTable back = parseCsv(text);
  EXPECT_EQ(back.header, t.header);
  ASSERT_EQ(back.rows.size(), 4u);
  EXPECT_EQ(back.rows[1][0], "with,comma");
  EXPECT_EQ(back.rows[1][2], "say \"hi\"");
  EXPECT_EQ(back.rows[2][0], "multi\nline");
  EXPECT_EQ(back.rows[3][1], "0.1");
  EXPECT_EQ(back.rows[3][2], "nan");
}

TEST(ReportCsv, RaggedRowsAndBadQuotesThrow) {
  CsvTable t;
  t.header = {"a", "b"};
  t.addRow({"1"});
  EXPECT_THROW(formatCsv(t), std::invalid_argument);
  EXPECT_THROW(parseCsv("a,b\n1\n"), std::invalid_argument);
  EXPECT_THROW(parseCsv("a,b\n\"1,2\n"), std::invalid_argument);
}

}  // namespace
}  // namespace redmax::validation
