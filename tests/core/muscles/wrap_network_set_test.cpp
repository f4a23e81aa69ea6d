// Wrap-network manifests (core/muscles/wrap/network_set.hpp, issue 22): a file, a manifest or a
// folder; each wrap object takes its own network, else its surface type's, else the single one;
// every malformed line is named as FILE:LINE.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "core/muscles/mass_points.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/network_set.hpp"

namespace redmax {
namespace {
namespace fs = std::filesystem;

class WrapNetworkSetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("wrap_network_set_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "nets");
    net("nets/a.txt", "cylinder", 1);
    net("nets/b.txt", "cylinder", 2);
    net("nets/s.txt", "sphere", 3);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void net(const std::string& rel, const std::string& surface, unsigned seed) {
    Mlp m(8, {4}, 3, seed);
    m.input_min = VecX::Constant(8, -4.0);
    m.input_max = VecX::Constant(8, 4.0);
    m.meta["surface"] = surface;
    m.meta["wrap_map"] = formatCompactWrapMap(4.0);
    m.save((dir_ / rel).string());
  }
  std::string write(const std::string& rel, const std::string& text) {
    std::ofstream((dir_ / rel).string()) << text;
    return (dir_ / rel).string();
  }
  // the error's text; "" when it loaded
  std::string error(const std::string& text) {
    const std::string f = write("m.txt", text);
    try {
      loadWrapNetworks(f);
    } catch (const NetworkFormatError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(WrapNetworkSetTest, ManifestFolderAndSingleFile) {
  const std::string text =
      "# networks of a model\n"
      "redmax-wrap-networks 1\n"
      "\n"
      "wrap KnExt_at_fem_r nets/a.txt\n"
      "  # an indented comment\n"
      "wrap PS_at_brim_r nets/b.txt\n"
      "surface sphere nets/s.txt\n";
  const std::string m = write("wrap_networks.txt", text);
  EXPECT_TRUE(isWrapNetworkManifest(m));
  EXPECT_FALSE(isWrapNetworkManifest((dir_ / "nets/a.txt").string()));
  for (const std::string& path : {m, dir_.string()}) {  // the manifest, or its folder
    const WrapNetworkSet set = loadWrapNetworks(path);
    ASSERT_EQ(set.by_wrap.size(), 2u);
    ASSERT_EQ(set.by_type.size(), 1u);
    EXPECT_EQ(set.single, nullptr);
    WrapMassOptions o;
    set.applyTo(o);
    EXPECT_TRUE(o.hasNetwork());
    const Mlp* a = o.networkFor("KnExt_at_fem_r", "cylinder");
    const Mlp* b = o.networkFor("PS_at_brim_r", "cylinder");
    ASSERT_NE(a, nullptr);
    ASSERT_NE(b, nullptr);
    EXPECT_TRUE(a->identical(Mlp::load((dir_ / "nets/a.txt").string())));
    EXPECT_TRUE(b->identical(Mlp::load((dir_ / "nets/b.txt").string())));
    // an unlisted sphere takes the sphere network; an unlisted cylinder none
    EXPECT_EQ(o.networkFor("Other", "sphere"), set.by_type.at("sphere").get());
    EXPECT_EQ(o.networkFor("Other", "cylinder"), nullptr);
  }
  // a plain network file: every surface takes it
  const WrapNetworkSet one = loadWrapNetworks((dir_ / "nets/a.txt").string());
  ASSERT_NE(one.single, nullptr);
  WrapMassOptions o;
  one.applyTo(o);
  EXPECT_EQ(o.networkFor("anything", "sphere"), one.single.get());
}

TEST_F(WrapNetworkSetTest, MalformedManifestsNameTheLine) {
  const std::string m = (dir_ / "m.txt").string();
  const std::string head = "redmax-wrap-networks 1\n";
  struct Case {
    std::string text;
    int line;
    std::string what;
  };
  const std::vector<Case> cases = {
      {"redmax-wrap-networks 2\n", 1, "unsupported manifest version"},
      {head, 1, "lists no network"},
      {head + "network X nets/a.txt\n", 2, "unknown keyword 'network'"},
      {head + "wrap X\n", 2, "takes a name and a file, got 1"},
      {head + "wrap X nets/a.txt extra\n", 2, "got 3"},
      {head + "wrap X nets/a.txt\nwrap X nets/b.txt\n", 3, "'wrap X' is listed twice"},
      {head + "surface cone nets/a.txt\n", 2, "unknown surface type 'cone'"},
      {head + "surface sphere nets/a.txt\n", 2, "is a cylinder network, listed for sphere"},
      {head + "# c\nwrap X nets/missing.txt\n", 3, "network 'nets/missing.txt'"},
  };
  for (const Case& c : cases) {
    const std::string e = error(c.text);
    EXPECT_EQ(e.rfind(m + ":" + std::to_string(c.line) + ": ", 0), 0u) << "case:\n" << c.text << "error: " << e;
    EXPECT_NE(e.find(c.what), std::string::npos) << "case:\n" << c.text << "error: " << e;
  }
  // a file is a manifest by its header (else it is read as a network); the parser itself checks it
  for (const auto& [text, what] : {std::pair<std::string, std::string>{"# nothing else\n", "1: empty manifest"},
                                   {"\nwrap X nets/a.txt\n", "2: expected the header"}}) {
    try {
      parseWrapNetworkManifest(text, "M", dir_.string());
      ADD_FAILURE() << text;
    } catch (const NetworkFormatError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("M:" + what, 0), 0u) << e.what();
    }
  }
  // a malformed network names the manifest's line, then the network's own
  write("nets/broken.txt", "redmax-mlp 1\ninputs 8\noutputs three\n");
  const std::string e = error(head + "wrap X nets/broken.txt\n");
  EXPECT_EQ(e.rfind(m + ":2: network 'nets/broken.txt': ", 0), 0u) << e;
  EXPECT_NE(e.find("broken.txt:3: 'three' is not an integer"), std::string::npos) << e;
  // paths that are neither
  EXPECT_THROW(loadWrapNetworks((dir_ / "absent").string()), std::runtime_error);
  EXPECT_THROW(loadWrapNetworks((dir_ / "nets").string()), std::runtime_error);  // a folder without a manifest
}

}  // namespace
}  // namespace redmax
