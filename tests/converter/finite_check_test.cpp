// buildCoreModel refuses numbers the reader takes as OpenSim's parser does ("nan", "inf") but no
// model can use, and non-positive sizes of wrap objects a path uses: each is an error at the
// element's line of the file, and the unmodified file builds.
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"

namespace redmax::osim {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class FiniteCheck : public ::testing::Test {
 protected:
  void SetUp() override {
    src_ = slurp(std::string(REDMAX_SOURCE_DIR) + "/osim_models/double_pendulum_wrap.osim");
    ASSERT_FALSE(src_.empty());
    // ctest runs each test in its own process at the same time; the pid and the test name keep
    // their scratch folders apart (gtest's random seed is time-based and can coincide)
    dir_ = fs::temp_directory_path() /
           ("redmax_finite_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // the file with the first occurrence of `from` on line `line` replaced by `to`; returns the
  // ConvertError message of buildCoreModel ("" if it builds)
  std::string buildWith(int line, const std::string& from, const std::string& to) {
    std::istringstream in(src_);
    std::string out, l;
    for (int k = 1; std::getline(in, l); ++k) {
      if (k == line) {
        const auto at = l.find(from);
        EXPECT_NE(at, std::string::npos) << "line " << line << " has no '" << from << "'";
        if (at != std::string::npos) l.replace(at, from.size(), to);
      }
      out += l + "\n";
    }
    path_ = (dir_ / "m.osim").string();
    std::ofstream(path_) << out;
    try {
      buildCoreModel(readOsimModel(path_));
    } catch (const ConvertError& e) {
      return e.what();
    }
    return "";
  }
  std::string src_, path_;
  fs::path dir_;
};

int lineOf(const std::string& text, const std::string& needle, int nth = 1) {
  std::istringstream in(text);
  std::string l;
  for (int k = 1; std::getline(in, l); ++k)
    if (l.find(needle) != std::string::npos && --nth == 0) return k;
  return -1;
}

TEST_F(FiniteCheck, UnmodifiedModelBuilds) { EXPECT_EQ(buildWith(1, "", ""), ""); }

TEST_F(FiniteCheck, NonFiniteNumbersAreErrorsAtTheirLine) {
  struct Case {
    std::string needle;
    std::string from, to, expect;
  };
  const Case cases[] = {
      {"<default_value>0.785", "0.785398163397448", "nan", "default value or speed is not finite"},
      {"<default_value>0.5235", "0.523598775598299", "inf", "default value or speed is not finite"},
      {"<location>-0.1 -0.6 0", "-0.6", "nan", "is not finite"},
      {"<translation>0 -1 0", "-1", "-inf", "not finite"},
  };
  for (const Case& c : cases) {
    const int line = lineOf(src_, c.needle);
    ASSERT_GT(line, 0) << c.needle;
    const std::string msg = buildWith(line, c.from, c.to);
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.needle << " -> " << msg;
    // the message names the file; the element's line is the one edited or its enclosing element
    EXPECT_EQ(msg.rfind(path_ + ":", 0), 0u) << msg;
  }
}

TEST_F(FiniteCheck, UsedWrapObjectNeedsAPositiveSize) {
  const int line = lineOf(src_, "<radius>0.08</radius>");
  ASSERT_GT(line, 0);
  const std::string msg = buildWith(line, "0.08", "-0.08");
  EXPECT_NE(msg.find("its size must be positive"), std::string::npos) << msg;
  EXPECT_EQ(buildWith(line, "0.08", "nan").find("not finite") != std::string::npos, true);
}

}  // namespace
}  // namespace redmax::osim
