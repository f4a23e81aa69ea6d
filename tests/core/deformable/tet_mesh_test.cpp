// The box tet mesher (volumes, conforming faces, orientation) and legacy VTK reading/writing,
// including malformed files, which must fail as "FILE:LINE: what".
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include <unistd.h>

#include "core/deformable/tet_mesh.hpp"
#include "mesh_checks.hpp"

namespace redmax {
namespace {

namespace fs = std::filesystem;

// this process's scratch folder, removed at exit
fs::path tempDir() {
  struct Dir {
    fs::path path = fs::temp_directory_path() / ("redmax_tet_mesh_test_" + std::to_string(::getpid()));
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir d;
  fs::create_directories(d.path);
  return d.path;
}

TEST(TetMesh, BoxMeshesFillTheBoxWithConformingPositiveTets) {
  for (CubeSplit split : {CubeSplit::Five, CubeSplit::Six}) {
    const TetMesh m = makeBoxTetMesh(Vec3(2, 1, 0.5), 3, 2, 2, Vec3(1, 1, 1), split);
    EXPECT_EQ(m.numNodes(), 4 * 3 * 3);
    EXPECT_EQ(m.numTets(), (split == CubeSplit::Five ? 5 : 6) * 12);
    double vol = 0;
    for (const auto& t : m.tets) {
      const double v = tetVolume(m.nodes, t);
      EXPECT_GT(v, 0);
      vol += v;
    }
    EXPECT_NEAR(vol, 1.0, 1e-13);
    // conforming: every face is shared by two tets, or lies on the boundary (2 triangles per
    // boundary square of the 3 x 2 x 2 grid: 2 (6 + 6 + 4) squares)
    EXPECT_EQ(testing::boundaryFaces(m), 2 * 2 * (3 * 2 + 3 * 2 + 2 * 2));
  }
  EXPECT_THROW(makeBoxTetMesh(Vec3(1, 1, 1), 0, 1, 1), std::invalid_argument);
  EXPECT_THROW(makeBoxTetMesh(Vec3(1, -1, 1), 1, 1, 1), std::invalid_argument);
}

TEST(TetMesh, VtkRoundTripKeepsNodesAndTets) {
  const TetMesh m = makeBoxTetMesh(Vec3(1, 0.3, 0.2), 4, 2, 1, Vec3(0.1, 0.2, 0.3), CubeSplit::Five);
  const fs::path p = tempDir() / "box.vtk";
  std::vector<Vec3> u(m.nodes.size(), Vec3(0.5, 0, 0));
  writeVtkTetMesh(p.string(), m, {}, {{"displacement", u}});
  EXPECT_FALSE(fs::exists(p.string() + ".tmp"));
  const TetMesh r = readVtkTetMesh(p.string());
  ASSERT_EQ(r.numNodes(), m.numNodes());
  ASSERT_EQ(r.numTets(), m.numTets());
  for (int n = 0; n < m.numNodes(); ++n) EXPECT_EQ(r.nodes[n], m.nodes[n]);  // 17 digits: exact
  for (int t = 0; t < m.numTets(); ++t) EXPECT_EQ(r.tets[t], m.tets[t]);
}

TEST(TetMesh, VtkReaderSkipsSurfaceCellsAndReordersInvertedTets) {
  const fs::path p = tempDir() / "mixed.vtk";
  std::ofstream(p) << "# vtk DataFile Version 2.0\nmesher output\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                      "POINTS 4 float\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                      "CELLS 3 12\n4 0 2 1 3\n3 0 1 2\n2 0 1\nCELL_TYPES 3\n10\n5\n3\n";
  VtkReadInfo info;
  const TetMesh m = readVtkTetMesh(p.string(), &info);
  ASSERT_EQ(m.numTets(), 1);
  EXPECT_GT(tetVolume(m.nodes, m.tets[0]), 0);
  EXPECT_EQ(info.skipped_cells, 2);
}

// the message of reading `text` as FILE, which must fail
std::string readError(const std::string& text) {
  const fs::path p = tempDir() / "bad.vtk";
  std::ofstream(p) << text;
  try {
    readVtkTetMesh(p.string());
  } catch (const MeshError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TetMesh, MalformedVtkFilesNameFileAndLine) {
  const std::string head = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  const std::string pts = "POINTS 4 double\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  const std::string f = (tempDir() / "bad.vtk").string();
  struct Case {
    std::string text;
    int line;
    std::string what;
  };
  const std::vector<Case> cases = {
      {"hello\n", 1, "not a legacy VTK file"},
      {"# vtk DataFile Version 3.0\nt\nBINARY\n", 3, "BINARY"},
      {"# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n", 4, "not supported"},
      {head + "POINTS 4 double\n0 0 0\n1 0 0\n0 1 nan\n0 0 1\n", 8, "not finite"},
      {head + "POINTS 4 double\n0 0 0\n1 0 0\n0 1 x\n0 0 1\n", 8, "expected a point coordinate"},
      {head + "POINTS 4 double\n0 0 0\n1 0 0\n", 5, "the file ends before their coordinates"},
      {head + "POINTS 99999999 double\n0 0 0\n", 5, "the file ends before"},
      {head + pts + "CELLS 1 999999\n4 0 1 2 3\nCELL_TYPES 1\n10\n", 10, "the file ends before them"},
      {head + pts + "CELLS 2 10\n4 0 1 2 3\n", 10, "the file ends before them"},
      {head + pts + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n", 12, "unexpected end of file"},
      {head + pts + "CELLS 1 5\n4 0 1 2 9\nCELL_TYPES 1\n10\n", 11, "node index 9 out of range"},
      {head + pts + "CELLS 1 6\n4 0 1 2 3\nCELL_TYPES 1\n10\n", 10, "does not match"},
      {head + pts + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 2\n10\n10\n", 12, "differs from CELLS count"},
      {head + pts + "CELLS 1 9\n8 0 1 2 3 0 1 2 3\nCELL_TYPES 1\n12\n", 13, "cell type 12"},
      {head + pts + "CELLS 1 5\n4 0 1 2 2\nCELL_TYPES 1\n10\n", 11, "degenerate"},
      {head + pts + "CELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n10\n", 11, "tetra cell 0 has 3 nodes"},
      {head + pts + "CELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n5\n", 13, "no tetra cells"},
      {head + pts, 9, "no CELLS"},
      {head + pts + "BOGUS\n", 10, "unexpected 'BOGUS'"},
  };
  for (const Case& c : cases) {
    const std::string msg = readError(c.text);
    EXPECT_EQ(msg.rfind(f + ":" + std::to_string(c.line) + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(c.what), std::string::npos) << msg;
  }
  EXPECT_EQ(std::string(readError("")).rfind(f + ":1: ", 0), 0u);
  try {
    readVtkTetMesh((tempDir() / "missing.vtk").string());
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos);
  }
}

}  // namespace
}  // namespace redmax
