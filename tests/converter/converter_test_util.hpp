#pragma once
// Helpers for the converter tests: paths into ../shared/opensim (skipped with a message when the
// folder is absent), temporary folders, and small file writers for generated inputs.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include "converter/error.hpp"
#include "converter/osim_reader.hpp"

namespace redmax::osim::test {

inline std::string sharedOpenSim(const std::string& rel) {
  return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel;
}

inline bool haveSharedOpenSim() {
  return std::filesystem::is_directory(std::string(REDMAX_SHARED_DIR) + "/opensim");
}

#define REDMAX_REQUIRE_SHARED()                                                            \
  do {                                                                                     \
    if (!::redmax::osim::test::haveSharedOpenSim())                                        \
      GTEST_SKIP() << "shared OpenSim data not found at " REDMAX_SHARED_DIR "/opensim; " \
                      "this test needs the real OpenSim files";                           \
  } while (0)

/// a fresh folder under the system temp dir, removed with its contents on destruction
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("redmax_converter_test_" + std::to_string(::getpid()) + "_" +
             std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string str() const { return path_.string(); }
  /// write a file under this folder (creating sub-folders) and return its path
  std::string write(const std::string& name, const std::string& content) const {
    const auto p = path_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << content;
    return p.string();
  }

 private:
  std::filesystem::path path_;
};

}  // namespace redmax::osim::test

namespace redmax::osim::test {

/// 1-based number of the first line of text containing needle (0 if absent)
inline int lineContaining(const std::string& text, const std::string& needle) {
  const size_t at = text.find(needle);
  if (at == std::string::npos) return 0;
  int line = 1;
  for (size_t i = 0; i < at; ++i) line += text[i] == '\n';
  return line;
}

/// a 4.0-format model: bodies, joints and any further Model children given as XML
inline std::string modernOsim(const std::string& bodies, const std::string& joints,
                              const std::string& extra = "", const std::string& version = "40000") {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n"
         "<OpenSimDocument Version=\"" + version + "\">\n"
         "<Model name=\"synthetic\">\n"
         "<Ground name=\"ground\"/>\n"
         "<gravity>0 -9.80665 0</gravity>\n"
         "<BodySet name=\"bodyset\"><objects>\n" + bodies +
         "</objects></BodySet>\n"
         "<JointSet name=\"jointset\"><objects>\n" + joints +
         "</objects></JointSet>\n" + extra +
         "</Model>\n</OpenSimDocument>\n";
}

/// a body element with the given mass (unit inertia)
inline std::string bodyXml(const std::string& name, double mass = 1.0) {
  return "<Body name=\"" + name + "\">\n<mass>" + std::to_string(mass) +
         "</mass>\n<mass_center>0 0 0</mass_center>\n<inertia>1 1 1 0 0 0</inertia>\n</Body>\n";
}

/// a PinJoint between two frame paths with one coordinate
inline std::string pinXml(const std::string& name, const std::string& parent,
                          const std::string& child, const std::string& coord = "") {
  return "<PinJoint name=\"" + name + "\">\n<socket_parent_frame>" + parent +
         "</socket_parent_frame>\n<socket_child_frame>" + child +
         "</socket_child_frame>\n<coordinates><Coordinate name=\"" +
         (coord.empty() ? name + "_q" : coord) + "\"/></coordinates>\n</PinJoint>\n";
}

inline std::string weldXml(const std::string& name, const std::string& parent,
                           const std::string& child) {
  return "<WeldJoint name=\"" + name + "\">\n<socket_parent_frame>" + parent +
         "</socket_parent_frame>\n<socket_child_frame>" + child +
         "</socket_child_frame>\n</WeldJoint>\n";
}

/// read `text` as a .osim file in a temporary folder; expect a ConvertError whose message starts
/// "FILE:LINE: " at the first line containing `at` ("" for any line) and contains `what`
inline void expectReadError(const std::string& text, const std::string& at, const std::string& what) {
  TempDir dir;
  const std::string path = dir.write("bad.osim", text);
  const int line = at.empty() ? 0 : lineContaining(text, at);
  ASSERT_TRUE(at.empty() || line > 0) << "test bug: '" << at << "' not in the text";
  try {
    readOsimModel(path);
    ADD_FAILURE() << "no error for: " << what;
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.file(), path);
    if (line > 0) {
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(path + ":" + std::to_string(line) + ": ", 0), 0u) << e.what();
    }
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

}  // namespace redmax::osim::test
