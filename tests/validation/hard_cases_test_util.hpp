#pragma once
// Helpers shared by the hard-case tests (hard_cases_test.cpp, hard_cases_wrap_flick_test.cpp).
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

namespace redmax_test {

/// the project's osim_models/ folder
inline std::string modelsDir() { return std::string(REDMAX_SOURCE_DIR) + "/osim_models"; }

/// records a measured number as a test property (and prints it), three significant digits
inline void record(const std::string& key, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  ::testing::Test::RecordProperty(key, buf);
  std::printf("%s = %s\n", key.c_str(), buf);
}

}  // namespace redmax_test
