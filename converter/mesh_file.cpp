#include "converter/mesh_file.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "converter/detail/xml_util.hpp"

namespace redmax::osim {

namespace fs = std::filesystem;
using detail::XMLElement;

namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& why) { throw std::runtime_error(path + ": " + why); }

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse(path, "cannot open file");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// polygon (indices) -> triangles (a, b, c) fanned from its first vertex
void addFan(const std::vector<int>& poly, std::vector<int>& tri) {
  for (size_t k = 2; k < poly.size(); ++k) tri.insert(tri.end(), {poly[0], poly[k - 1], poly[k]});
}

void checkMesh(const std::string& path, const TriangleMesh& m) {
  if (m.triangles.empty()) refuse(path, "no triangles");
  const int n = m.numVertices();
  for (int i : m.triangles)
    if (i < 0 || i >= n) refuse(path, "a face names vertex " + std::to_string(i + 1) + " of " + std::to_string(n));
}

// --- .vtp ----------------------------------------------------------------------------------

std::vector<unsigned char> decodeBase64(const std::string& path, const std::string& text) {
  static const std::string chars = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  unsigned value = 0;
  int bits = 0;
  for (char c : text) {
    if (c == '=' || std::isspace(static_cast<unsigned char>(c))) continue;
    const size_t v = chars.find(c);
    if (v == std::string::npos) refuse(path, "binary DataArray is not base64");
    value = (value << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((value >> bits) & 0xff));
    }
  }
  return out;
}

// the numbers of one DataArray (ascii, or VTK's uncompressed binary: a UInt32/UInt64 byte count
// then the raw little-endian values, base64 encoded as one block)
std::vector<double> dataArray(const std::string& path, const XMLElement* a, const std::string& header_type) {
  const std::string format = detail::attribute(a, "format");
  const std::string type = detail::attribute(a, "type");
  std::vector<double> v;
  if (format == "ascii" || format.empty()) {
    std::istringstream in(detail::textOf(a));
    double x;
    while (in >> x) v.push_back(x);
    return v;
  }
  if (format != "binary")
    refuse(path, "line " + std::to_string(detail::lineOf(a)) + ": DataArray format '" + format + "' is not read");
  const std::vector<unsigned char> bytes = decodeBase64(path, detail::textOf(a));
  const size_t header = header_type == "UInt64" ? 8 : 4;
  size_t size = 0;
  if (type == "Float32" || type == "Int32" || type == "UInt32") size = 4;
  else if (type == "Float64" || type == "Int64" || type == "UInt64") size = 8;
  else refuse(path, "DataArray type '" + type + "' is not read");
  if (bytes.size() < header) refuse(path, "binary DataArray shorter than its header");
  const size_t n = (bytes.size() - header) / size;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char* p = bytes.data() + header + i * size;
    if (type == "Float32") { float f; std::memcpy(&f, p, 4); v.push_back(f); }
    else if (type == "Float64") { double d; std::memcpy(&d, p, 8); v.push_back(d); }
    else if (type == "Int32") { std::int32_t k; std::memcpy(&k, p, 4); v.push_back(k); }
    else if (type == "UInt32") { std::uint32_t k; std::memcpy(&k, p, 4); v.push_back(k); }
    else if (type == "Int64") { std::int64_t k; std::memcpy(&k, p, 8); v.push_back(static_cast<double>(k)); }
    else { std::uint64_t k; std::memcpy(&k, p, 8); v.push_back(static_cast<double>(k)); }
  }
  return v;
}

const XMLElement* namedArray(const XMLElement* parent, const char* name) {
  for (const XMLElement* a : detail::childElements(parent, "DataArray"))
    if (detail::attribute(a, "Name") == name) return a;
  return nullptr;
}

TriangleMesh readVtp(const std::string& path) {
  detail::XmlDocument doc(path);  // ConvertError on malformed XML
  const XMLElement* vtk = doc.root();
  if (!vtk || std::string(vtk->Name()) != "VTKFile" || detail::attribute(vtk, "type") != "PolyData")
    refuse(path, "not a VTK XML PolyData file");
  if (!detail::attribute(vtk, "compressor").empty()) refuse(path, "compressed data is not read");
  const std::string header_type = detail::attribute(vtk, "header_type");
  const XMLElement* poly = detail::firstChild(vtk, "PolyData");
  const std::vector<const XMLElement*> pieces = detail::childElements(poly, "Piece");
  if (pieces.empty()) refuse(path, "no Piece");
  TriangleMesh m;
  for (const XMLElement* piece : pieces) {
    for (const char* other : {"Strips", "Lines", "Verts"})
      if (const XMLElement* e = detail::firstChild(piece, other))
        if (std::atoi(detail::attribute(piece, (std::string("NumberOf") + other).c_str()).c_str()) > 0)
          refuse(path, "line " + std::to_string(detail::lineOf(e)) + ": " + other + " are not read");
    const XMLElement* pts = detail::firstChild(detail::firstChild(piece, "Points"), "DataArray");
    const XMLElement* polys = detail::firstChild(piece, "Polys");
    const XMLElement* conn = namedArray(polys, "connectivity");
    const XMLElement* offs = namedArray(polys, "offsets");
    if (!pts || !conn || !offs) refuse(path, "a Piece without Points or Polys connectivity/offsets");
    const std::vector<double> x = dataArray(path, pts, header_type);
    const std::vector<double> c = dataArray(path, conn, header_type), o = dataArray(path, offs, header_type);
    const int base = m.numVertices();
    m.vertices.insert(m.vertices.end(), x.begin(), x.end() - static_cast<long>(x.size() % 3));
    size_t begin = 0;
    for (double end_d : o) {
      const auto end = static_cast<size_t>(end_d);
      if (end < begin || end > c.size()) refuse(path, "Polys offsets out of order");
      std::vector<int> face;
      for (size_t k = begin; k < end; ++k) face.push_back(base + static_cast<int>(c[k]));
      addFan(face, m.triangles);
      begin = end;
    }
  }
  return m;
}

// --- .obj ----------------------------------------------------------------------------------

TriangleMesh readObj(const std::string& path) {
  std::istringstream in(readAll(path));
  TriangleMesh m;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      double x = 0, y = 0, z = 0;
      ls >> x >> y >> z;
      m.vertices.insert(m.vertices.end(), {x, y, z});
    } else if (tag == "f") {
      std::vector<int> face;
      std::string word;
      while (ls >> word) {
        const int k = std::atoi(word.c_str());  // "7/2/3" -> 7
        face.push_back(k < 0 ? m.numVertices() + k : k - 1);
      }
      addFan(face, m.triangles);
    }
  }
  return m;
}

// --- .stl ----------------------------------------------------------------------------------

TriangleMesh readStl(const std::string& path) {
  const std::string s = readAll(path);
  TriangleMesh m;
  // binary: 80-byte header, a count, 50 bytes per triangle (some binary files also start "solid")
  if (s.size() >= 84) {
    std::uint32_t n;
    std::memcpy(&n, s.data() + 80, 4);
    if (s.size() == 84 + 50ull * n) {
      for (std::uint32_t t = 0; t < n; ++t)
        for (int v = 0; v < 3; ++v) {
          float x[3];
          std::memcpy(x, s.data() + 84 + 50ull * t + 12 + 12 * v, 12);
          m.vertices.insert(m.vertices.end(), {x[0], x[1], x[2]});
          m.triangles.push_back(static_cast<int>(3 * t + v));
        }
      return m;
    }
  }
  if (s.rfind("solid", 0) != 0) refuse(path, "neither ASCII nor binary STL");
  std::istringstream in(s);
  std::string word;
  std::vector<int> face;
  while (in >> word) {
    if (word == "vertex") {
      double x = 0, y = 0, z = 0;
      in >> x >> y >> z;
      face.push_back(m.numVertices());
      m.vertices.insert(m.vertices.end(), {x, y, z});
    } else if (word == "endloop") {
      addFan(face, m.triangles);
      face.clear();
    }
  }
  return m;
}

// --- attachments ---------------------------------------------------------------------------

// the body a frame name or path names, and the frame's pose in it
bool placeFrame(const ModelDescription& d, const std::string& frame, std::string& body, Mat4& X) {
  const std::string name = frame.substr(frame.find_last_of('/') == std::string::npos ? 0 : frame.find_last_of('/') + 1);
  if (name == d.ground_name || d.findBody(name) >= 0) {
    body = name;
    X = Mat4::Identity();
    return true;
  }
  for (const FrameDesc& f : d.frames)
    if (f.path == frame || f.name == name) {
      body = f.base_body;
      X = f.X_base;
      return true;
    }
  return false;
}

Vec3 scaleOf(const detail::XmlDocument& doc, const XMLElement* e) {
  return detail::childVec3(doc, e, "scale_factors", Vec3::Ones());
}

}  // namespace

TriangleMesh readMeshFile(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (!fs::is_regular_file(path)) refuse(path, "cannot open file");
  TriangleMesh m;
  try {
    if (ext == ".vtp") m = readVtp(path);
    else if (ext == ".obj") m = readObj(path);
    else if (ext == ".stl") m = readStl(path);
    else refuse(path, "mesh format '" + ext + "' is not read (.vtp, .obj, .stl are)");
  } catch (const ConvertError& e) {
    throw std::runtime_error(e.what());
  }
  checkMesh(path, m);
  return m;
}

std::vector<MeshAttachment> readMeshAttachments(const ModelDescription& d, std::vector<std::string>& dropped) {
  detail::XmlDocument doc(d.source_file);
  std::vector<MeshAttachment> out;
  // walk every element; `owner` is the nearest enclosing Body or PhysicalOffsetFrame
  struct Item {
    const XMLElement* e;
    const XMLElement* owner;
  };
  std::vector<Item> stack{{doc.root(), nullptr}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const std::string tag = it.e->Name();
    const XMLElement* owner = (tag == "Body" || tag == "PhysicalOffsetFrame" || tag == "Ground") ? it.e : it.owner;
    auto place = [&](const std::string& file, const Vec3& scale, const Mat4& X_local, const XMLElement* e) {
      MeshAttachment a;
      a.mesh_file = file;
      a.scale = scale;
      a.line = detail::lineOf(e);
      Mat4 X_frame = Mat4::Identity();
      const std::string socket = detail::childText(e, "socket_frame");
      // OpenSim 4 writes the owning frame as ".." (a relative path); absent in older files
      const bool own = socket.empty() || socket == ".." || socket == "../";
      std::string frame = !own ? socket : owner ? detail::attribute(owner, "name") : std::string();
      if (std::string(owner ? owner->Name() : "") == "Ground" && own) frame = d.ground_name;
      if (frame.empty() || !placeFrame(d, frame, a.body, X_frame)) {
        dropped.push_back(std::to_string(a.line) + ": mesh '" + file + "': frame '" + frame + "' is not a body or frame");
        return;
      }
      a.X_body = X_frame * X_local;
      out.push_back(a);
    };
    if (tag == "Mesh") {
      place(detail::childText(it.e, "mesh_file"), scaleOf(doc, it.e), Mat4::Identity(), it.e);
    } else if (tag == "VisibleObject") {  // OpenSim 3: files in the body frame
      for (const std::string& f : detail::splitWords(detail::childText(it.e, "geometry_files")))
        place(f, scaleOf(doc, it.e), Mat4::Identity(), it.e);
    } else if (tag == "DisplayGeometry") {  // OpenSim 3: rotations then translation
      Mat4 X = Mat4::Identity();
      if (const XMLElement* t = detail::firstChild(it.e, "transform")) {
        const std::vector<double> v = detail::parseNumbersExactly(doc, t, 6);
        X = makePose(Vec3(v[3], v[4], v[5]), Vec3(v[0], v[1], v[2]));
      }
      place(detail::childText(it.e, "geometry_file"), scaleOf(doc, it.e), X, it.e);
    }
    std::vector<const XMLElement*> kids = detail::childElements(it.e);
    for (auto k = kids.rbegin(); k != kids.rend(); ++k) stack.push_back({*k, owner});
  }
  return out;
}

std::string findMeshFile(const std::string& model_dir, const std::string& mesh_file) {
  if (mesh_file.empty()) return "";
  const fs::path f(mesh_file);
  std::error_code ec;
  for (const fs::path& c : {f.is_absolute() ? f : fs::path(model_dir) / f, fs::path(model_dir) / "Geometry" / f})
    if (fs::is_regular_file(c, ec)) return c.string();
  return "";
}

}  // namespace redmax::osim
