#include "converter/mesh_file.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <zlib.h>

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

// Base64 as VTK writes it: header and data may be separate streams, each padded with '=', so
// padding ends a group and the next character starts a new stream
std::vector<unsigned char> decodeBase64(const std::string& path, const char* text, size_t size) {
  static const std::string chars = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  unsigned value = 0;
  int bits = 0;
  for (size_t i = 0; i < size; ++i) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    if (c == '=') {
      value = 0;
      bits = 0;
      continue;
    }
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

// base64 characters (white space skipped) that encode n bytes, padding included
size_t base64Chars(size_t n) { return 4 * ((n + 2) / 3); }

// the position in text after `count` base64 characters from `from` (white space not counted)
size_t skipBase64(const std::string& text, size_t from, size_t count) {
  size_t i = from;
  for (; i < text.size() && count > 0; ++i)
    if (!std::isspace(static_cast<unsigned char>(text[i]))) --count;
  return i;
}

// How the file's binary arrays are stored: VTK's header integer size, zlib or no compression, and
// the <AppendedData> bytes (raw, or the base64 text) that `appended` arrays point into.
struct VtpEncoding {
  size_t header = 4;       // header_type UInt32 (default) or UInt64
  bool zlib = false;       // compressor="vtkZLibDataCompressor"
  std::string appended;    // after the '_' marker, up to </AppendedData>
  bool appended_base64 = true;
};

std::uint64_t headerWord(const unsigned char* p, size_t header) {
  if (header == 8) {
    std::uint64_t k;
    std::memcpy(&k, p, 8);
    return k;
  }
  std::uint32_t k;
  std::memcpy(&k, p, 4);
  return k;
}

// zlib blocks -> bytes: the header (number of blocks, block size, last block's size, compressed
// size of each block) then the compressed blocks
std::vector<unsigned char> inflateBlocks(const std::string& path, const std::vector<unsigned char>& header_bytes,
                                         const unsigned char* data, size_t data_size, size_t header) {
  const size_t nblocks = headerWord(header_bytes.data(), header);
  const size_t block = headerWord(header_bytes.data() + header, header);
  const size_t last = headerWord(header_bytes.data() + 2 * header, header);
  std::vector<unsigned char> out;
  size_t at = 0;
  for (size_t b = 0; b < nblocks; ++b) {
    const size_t csize = headerWord(header_bytes.data() + (3 + b) * header, header);
    const size_t usize = b + 1 == nblocks && last != 0 ? last : block;
    if (csize > data_size - at) refuse(path, "compressed DataArray shorter than its header says");
    // deflate expands by at most 1032:1, so a larger claim is a damaged header (not a huge array)
    if (usize > 1032 * csize + 64) refuse(path, "a zlib block's size does not fit its compressed size");
    const size_t start = out.size();
    out.resize(start + usize);
    uLongf got = static_cast<uLongf>(usize);
    if (uncompress(out.data() + start, &got, data + at, static_cast<uLong>(csize)) != Z_OK || got != usize)
      refuse(path, "a zlib block of a DataArray does not inflate");
    at += csize;
  }
  return out;
}

// the bytes of one binary array: (header, data) base64 in `text` from `from`, or raw in `raw`
std::vector<unsigned char> arrayBytes(const std::string& path, const VtpEncoding& enc, const std::string& text,
                                      size_t from, bool base64) {
  const size_t h = enc.header;
  if (!enc.zlib) {
    // uncompressed: a byte count, then the bytes (one base64 stream, or two: both are read)
    std::vector<unsigned char> decoded;
    const unsigned char* b = reinterpret_cast<const unsigned char*>(text.data()) + from;
    size_t size = text.size() - from;
    if (base64) {
      decoded = decodeBase64(path, text.data() + from, text.size() - from);
      b = decoded.data();
      size = decoded.size();
    }
    if (size < h) refuse(path, "binary DataArray shorter than its header");
    const std::uint64_t n = headerWord(b, h);
    if (n > size - h) refuse(path, "binary DataArray shorter than its byte count");
    return std::vector<unsigned char>(b + h, b + h + n);
  }
  if (!base64) {
    if (text.size() < from + h) refuse(path, "compressed DataArray shorter than its header");
    const auto* p = reinterpret_cast<const unsigned char*>(text.data()) + from;
    const std::uint64_t nblocks = headerWord(p, h);
    if (nblocks > text.size() || (3 + nblocks) * h > text.size() - from)
      refuse(path, "compressed DataArray shorter than its header");
    const size_t nh = (3 + nblocks) * h;
    const std::vector<unsigned char> header_bytes(p, p + nh);
    return inflateBlocks(path, header_bytes, p + nh, text.size() - from - nh, h);
  }
  // base64: the header is its own padded stream; its first word says how long it is
  const size_t first_end = skipBase64(text, from, base64Chars(h));
  const std::vector<unsigned char> first = decodeBase64(path, text.data() + from, first_end - from);
  if (first.size() < h) refuse(path, "compressed DataArray shorter than its header");
  const std::uint64_t nblocks = headerWord(first.data(), h);
  if (nblocks > text.size()) refuse(path, "compressed DataArray shorter than its header");
  const size_t nh = (3 + nblocks) * h;
  const size_t header_end = skipBase64(text, from, base64Chars(nh));
  const std::vector<unsigned char> header_bytes = decodeBase64(path, text.data() + from, header_end - from);
  if (header_bytes.size() < nh) refuse(path, "compressed DataArray shorter than its header");
  const std::vector<unsigned char> data = decodeBase64(path, text.data() + header_end, text.size() - header_end);
  return inflateBlocks(path, header_bytes, data.data(), data.size(), h);
}

template <class T>
void appendValues(const std::vector<unsigned char>& bytes, std::vector<double>& v) {
  for (size_t i = 0; i + sizeof(T) <= bytes.size(); i += sizeof(T)) {
    T k;
    std::memcpy(&k, bytes.data() + i, sizeof(T));
    v.push_back(static_cast<double>(k));
  }
}

// the numbers of one DataArray: ascii, inline binary (base64) or appended (an offset into
// <AppendedData>), each binary form uncompressed or zlib-compressed
std::vector<double> dataArray(const std::string& path, const XMLElement* a, const VtpEncoding& enc) {
  const std::string format = detail::attribute(a, "format");
  const std::string type = detail::attribute(a, "type");
  const std::string at = "line " + std::to_string(detail::lineOf(a)) + ": ";
  std::vector<double> v;
  if (format == "ascii" || format.empty()) {
    std::istringstream in(detail::textOf(a));
    double x;
    while (in >> x) v.push_back(x);
    return v;
  }
  std::vector<unsigned char> bytes;
  if (format == "binary") {
    bytes = arrayBytes(path, enc, detail::textOf(a), 0, true);
  } else if (format == "appended") {
    const std::string offset = detail::attribute(a, "offset");
    char* end = nullptr;
    const unsigned long long off = std::strtoull(offset.c_str(), &end, 10);
    if (offset.empty() || *end != '\0' || off >= enc.appended.size())
      refuse(path, at + "appended DataArray offset '" + offset + "' is outside the AppendedData");
    bytes = arrayBytes(path, enc, enc.appended, static_cast<size_t>(off), enc.appended_base64);
  } else {
    refuse(path, at + "DataArray format '" + format + "' is not read");
  }
  if (type == "Float32") appendValues<float>(bytes, v);
  else if (type == "Float64") appendValues<double>(bytes, v);
  else if (type == "Int8") appendValues<std::int8_t>(bytes, v);
  else if (type == "UInt8") appendValues<std::uint8_t>(bytes, v);
  else if (type == "Int16") appendValues<std::int16_t>(bytes, v);
  else if (type == "UInt16") appendValues<std::uint16_t>(bytes, v);
  else if (type == "Int32") appendValues<std::int32_t>(bytes, v);
  else if (type == "UInt32") appendValues<std::uint32_t>(bytes, v);
  else if (type == "Int64") appendValues<std::int64_t>(bytes, v);
  else if (type == "UInt64") appendValues<std::uint64_t>(bytes, v);
  else refuse(path, at + "DataArray type '" + type + "' is not read");
  return v;
}

const XMLElement* namedArray(const XMLElement* parent, const char* name) {
  for (const XMLElement* a : detail::childElements(parent, "DataArray"))
    if (detail::attribute(a, "Name") == name) return a;
  return nullptr;
}

// Cuts <AppendedData>'s bytes out of the file's text (raw bytes are not XML) into enc.appended;
// returns the XML that is left.
std::string cutAppendedData(const std::string& path, std::string text, VtpEncoding& enc) {
  const size_t tag = text.find("<AppendedData");
  if (tag == std::string::npos) return text;
  const size_t close = text.find('>', tag);
  const size_t marker = close == std::string::npos ? close : text.find('_', close);
  const size_t end = text.rfind("</AppendedData>");
  if (marker == std::string::npos || end == std::string::npos || end < marker)
    refuse(path, "AppendedData without its '_' marker or closing tag");
  const std::string head = text.substr(tag, close - tag);
  enc.appended_base64 = head.find("encoding=\"raw\"") == std::string::npos;
  // raw data is followed by white space before the closing tag: the headers' sizes bound each array
  enc.appended = text.substr(marker + 1, end - marker - 1);
  text.erase(marker + 1, end - marker - 1);
  return text;
}

TriangleMesh readVtp(const std::string& path) {
  VtpEncoding enc;
  const std::string xml = cutAppendedData(path, readAll(path), enc);
  detail::XmlDocument doc(path, xml);  // ConvertError on malformed XML
  const XMLElement* vtk = doc.root();
  if (!vtk || std::string(vtk->Name()) != "VTKFile" || detail::attribute(vtk, "type") != "PolyData")
    refuse(path, "not a VTK XML PolyData file");
  const std::string compressor = detail::attribute(vtk, "compressor");
  if (compressor == "vtkZLibDataCompressor") enc.zlib = true;
  else if (!compressor.empty())
    refuse(path, "compressor '" + compressor + "' is not read (only vtkZLibDataCompressor: zlib)");
  if (detail::attribute(vtk, "byte_order") == "BigEndian") refuse(path, "big-endian data is not read");
  const std::string header_type = detail::attribute(vtk, "header_type");
  if (header_type == "UInt64") enc.header = 8;
  else if (!header_type.empty() && header_type != "UInt32")
    refuse(path, "header_type '" + header_type + "' is not read (UInt32 or UInt64)");
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
    const std::vector<double> x = dataArray(path, pts, enc);
    const std::vector<double> c = dataArray(path, conn, enc), o = dataArray(path, offs, enc);
    const int base = m.numVertices();
    m.vertices.insert(m.vertices.end(), x.begin(), x.end() - static_cast<long>(x.size() % 3));
    size_t begin = 0;
    for (double end_d : o) {
      if (!(end_d >= static_cast<double>(begin) && end_d <= static_cast<double>(c.size())))
        refuse(path, "Polys offsets out of order");
      const auto end = static_cast<size_t>(end_d);
      std::vector<int> face;
      for (size_t k = begin; k < end; ++k) {
        if (!(c[k] >= 0 && c[k] < static_cast<double>(x.size() / 3)))
          refuse(path, "Polys connectivity names vertex " + std::to_string(c[k]) + " of " + std::to_string(x.size() / 3));
        face.push_back(base + static_cast<int>(c[k]));
      }
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
