// converter/mesh_file.hpp: the display meshes `redmax view` draws. Each format is written here with
// known triangles and read back; variants that are not read must say why.
#include "converter/mesh_file.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <tuple>

#include <unistd.h>

namespace redmax::osim {
namespace {

namespace fs = std::filesystem;

// a unit square in z = 0 as two triangles, or as one quad where a format has polygons
const std::vector<double> kSquare = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const std::vector<int> kFan = {0, 1, 2, 0, 2, 3};

fs::path write(const std::string& name, const std::string& bytes) {
  const fs::path dir = fs::temp_directory_path() / ("redmax_mesh_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << bytes;
  return dir / name;
}

std::string base64(const std::string& raw) {
  static const char* c = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < raw.size(); i += 3) {
    std::uint32_t v = 0;
    const size_t n = std::min<size_t>(3, raw.size() - i);
    for (size_t k = 0; k < 3; ++k) v = (v << 8) | (k < n ? static_cast<unsigned char>(raw[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? c[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

template <class T>
std::string block(const std::vector<T>& v) {  // VTK binary: UInt32 byte count, then the values
  std::string raw(4 + sizeof(T) * v.size(), '\0');
  const std::uint32_t bytes = static_cast<std::uint32_t>(sizeof(T) * v.size());
  std::memcpy(raw.data(), &bytes, 4);
  std::memcpy(raw.data() + 4, v.data(), bytes);
  return base64(raw);
}

std::string vtp(const std::string& points, const std::string& conn, const std::string& offs, const std::string& fmt,
                const std::string& extra = "") {
  return "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\"" + extra +
         "><PolyData><Piece NumberOfPoints=\"4\" NumberOfPolys=\"1\">"
         "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"" + fmt + "\">" + points +
         "</DataArray></Points><Polys>"
         "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"" + fmt + "\">" + conn + "</DataArray>"
         "<DataArray type=\"Int32\" Name=\"offsets\" format=\"" + fmt + "\">" + offs + "</DataArray>"
         "</Polys></Piece></PolyData></VTKFile>\n";
}

void expectSquare(const TriangleMesh& m) {
  ASSERT_EQ(m.numVertices(), 4);
  for (size_t i = 0; i < kSquare.size(); ++i) EXPECT_DOUBLE_EQ(m.vertices[i], kSquare[i]);
  EXPECT_EQ(m.triangles, kFan);
}

TEST(MeshFile, VtpAscii) {
  expectSquare(readMeshFile(write("a.vtp", vtp("0 0 0 1 0 0 1 1 0 0 1 0", "0 1 2 3", "4", "ascii")).string()));
}

TEST(MeshFile, VtpBinaryBase64) {
  const std::vector<float> p(kSquare.begin(), kSquare.end());
  expectSquare(readMeshFile(
      write("b.vtp", vtp(block(p), block(std::vector<std::int32_t>{0, 1, 2, 3}), block(std::vector<std::int32_t>{4}),
                         "binary"))
          .string()));
}

TEST(MeshFile, VtpCompressedIsRefusedWithTheReason) {
  const std::string f =
      write("c.vtp", vtp("x", "x", "x", "binary", " compressor=\"vtkZLibDataCompressor\"")).string();
  try {
    readMeshFile(f);
    FAIL() << "a compressed .vtp was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("compressed data is not read"), std::string::npos) << e.what();
  }
}

TEST(MeshFile, ObjWithTexturesNormalsAndNegativeIndices) {
  expectSquare(readMeshFile(write("d.obj", "# square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n"
                                           "f 1/1/1 2/2/1 3/3/1\nf -4//1 -2//1 -1//1\n")
                                .string()));
}

TEST(MeshFile, StlAsciiAndBinary) {
  std::string ascii = "solid s\n";
  for (int t = 0; t < 2; ++t) {
    ascii += "facet normal 0 0 1\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      const int v = kFan[3 * t + k];
      ascii += "vertex " + std::to_string(kSquare[3 * v]) + " " + std::to_string(kSquare[3 * v + 1]) + " 0\n";
    }
    ascii += "endloop\nendfacet\n";
  }
  std::string binary(84 + 2 * 50, '\0');
  const std::uint32_t n = 2;
  std::memcpy(binary.data() + 80, &n, 4);
  for (int t = 0; t < 2; ++t)
    for (int k = 0; k < 3; ++k) {
      const int v = kFan[3 * t + k];
      const float x[3] = {float(kSquare[3 * v]), float(kSquare[3 * v + 1]), 0.0f};
      std::memcpy(binary.data() + 84 + 50 * t + 12 + 12 * k, x, 12);
    }
  for (const auto& file : {write("e.stl", ascii), write("f.stl", binary)}) {
    const TriangleMesh m = readMeshFile(file.string());
    ASSERT_EQ(m.numTriangles(), 2) << file;
    // STL repeats vertices per triangle: the second triangle's last vertex is the square's (0, 1)
    EXPECT_DOUBLE_EQ(m.vertices[3 * m.triangles[5]], 0.0);
    EXPECT_DOUBLE_EQ(m.vertices[3 * m.triangles[5] + 1], 1.0);
  }
}

TEST(MeshFile, BadInputSaysWhy) {
  for (const auto& [name, text, why] :
       {std::tuple<std::string, std::string, std::string>{"g.obj", "v 0 0 0\nf 1 2 3\n", "names vertex"},
        {"h.obj", "v 0 0 0\n", "no triangles"},
        {"i.ply", "ply\n", "is not read"},
        {"j.vtp", "<VTKFile type=\"UnstructuredGrid\"/>", "not a VTK XML PolyData"}}) {
    try {
      readMeshFile(write(name, text).string());
      ADD_FAILURE() << name << " was read";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(readMeshFile("/nonexistent/x.vtp"), std::runtime_error);
}

TEST(MeshFile, FindsMeshesBesideTheModelOrInGeometry) {
  const fs::path f = write("k.obj", "v 0 0 0\n");
  const fs::path dir = f.parent_path();
  fs::create_directories(dir / "Geometry");
  std::ofstream(dir / "Geometry" / "l.obj") << "v 0 0 0\n";
  EXPECT_EQ(findMeshFile(dir.string(), "k.obj"), (dir / "k.obj").string());
  EXPECT_EQ(findMeshFile(dir.string(), "l.obj"), (dir / "Geometry" / "l.obj").string());
  EXPECT_EQ(findMeshFile(dir.string(), "m.obj"), "");
}

}  // namespace
}  // namespace redmax::osim
