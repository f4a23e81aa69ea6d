// converter/mesh_file.hpp: the display meshes `redmax view` draws. Each format is written here with
// known triangles and read back; variants that are not read must say why.
#include "converter/mesh_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
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

// Files VTK 9.1's vtkXMLPolyDataWriter wrote (tests/converter/data/vtp/make_vtp_fixtures.py): one
// mesh, a sphere (34 points, 64 triangles) and a cube (24 points, 6 quads), in every storage VTK
// offers. Each must give the ascii file's mesh: the binary ones bit for bit among themselves.
const fs::path kVtpData = fs::path(REDMAX_SOURCE_DIR) / "tests/converter/data/vtp";

TEST(MeshFile, VtpEveryVtkStorageGivesTheSameMesh) {
  const TriangleMesh ascii = readMeshFile((kVtpData / "ascii.vtp").string());
  ASSERT_EQ(ascii.numVertices(), 34 + 24);
  ASSERT_EQ(ascii.numTriangles(), 64 + 6 * 2);
  const TriangleMesh binary = readMeshFile((kVtpData / "binary.vtp").string());
  for (const char* name : {"binary_zlib", "binary_zlib_uint64", "appended_raw", "appended_raw_zlib",
                           "appended_base64", "appended_base64_zlib"}) {
    SCOPED_TRACE(name);
    const TriangleMesh m = readMeshFile((kVtpData / (std::string(name) + ".vtp")).string());
    EXPECT_EQ(m.triangles, ascii.triangles);
    EXPECT_EQ(m.vertices, binary.vertices);
  }
  // ascii holds the Float32 values in decimal: the same numbers to float precision
  ASSERT_EQ(binary.vertices.size(), ascii.vertices.size());
  EXPECT_EQ(binary.triangles, ascii.triangles);
  for (size_t i = 0; i < ascii.vertices.size(); ++i)
    EXPECT_NEAR(binary.vertices[i], ascii.vertices[i], 1e-7 * (1 + std::abs(ascii.vertices[i]))) << i;
}

std::string readText(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void expectRefused(const std::string& name, const std::string& text, const std::string& why) {
  try {
    readMeshFile(write(name, text).string());
    ADD_FAILURE() << name << " was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << name << ": " << e.what();
  }
}

TEST(MeshFile, VtpOtherCompressorsAndDamagedDataAreRefusedWithTheReason) {
  expectRefused("lz4.vtp", readText(kVtpData / "binary_lz4.vtp"), "compressor 'vtkLZ4DataCompressor' is not read");
  // a compressed block of the Points (offset 264, after a 3-block header of 24 bytes) whose bytes
  // were changed: zlib refuses it
  std::string z = readText(kVtpData / "appended_raw_zlib.vtp");
  const size_t data = z.find('_', z.find("<AppendedData")) + 1 + 264 + 24;
  for (size_t k = 10; k < 30; ++k) z[data + k] = static_cast<char>(z[data + k] ^ 0x5a);
  expectRefused("damaged.vtp", z, "does not inflate");
  // appended data cut short: the header names more bytes than there are
  std::string cut = readText(kVtpData / "appended_raw.vtp");
  const size_t raw = cut.find('_', cut.find("<AppendedData")) + 1;
  cut = cut.substr(0, raw + 700 + 40) + "\n</AppendedData></VTKFile>\n";  // Points start at 700
  expectRefused("cut.vtp", cut, "shorter than");
  std::string offset = readText(kVtpData / "appended_base64.vtp");
  const size_t o = offset.find("offset=\"", offset.find("Name=\"Points\""));
  offset.replace(o, offset.find('"', o + 8) - o + 1, "offset=\"99999999\"");
  expectRefused("offset.vtp", offset, "outside the AppendedData");
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
