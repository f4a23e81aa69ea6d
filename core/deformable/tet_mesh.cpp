#include "core/deformable/tet_mesh.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace redmax {

namespace {

int nodeIndex(int i, int j, int k, int nx, int ny) { return i + (nx + 1) * (j + (ny + 1) * k); }

void orient(const std::vector<Vec3>& x, std::array<int, 4>& t) {
  if (tetVolume(x, t) < 0) std::swap(t[2], t[3]);
}

// whitespace-separated tokens with the line each sits on
struct Tokens {
  std::string file;
  std::vector<std::pair<std::string, int>> tok;
  size_t pos = 0;
  int lastLine() const { return tok.empty() ? 1 : tok.back().second; }
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw MeshError(file + ":" + std::to_string(line) + ": " + what);
  }
  bool done() const { return pos >= tok.size(); }
  size_t remaining() const { return tok.size() - pos; }
  int line() const { return done() ? lastLine() : tok[pos].second; }
  const std::string& next(const std::string& what) {
    if (done()) fail(lastLine(), "unexpected end of file, expected " + what);
    return tok[pos++].first;
  }
  long long integer(const std::string& what) {
    const int ln = line();
    const std::string& s = next(what);
    try {
      size_t used = 0;
      const long long v = std::stoll(s, &used);
      if (used == s.size()) return v;
    } catch (const std::exception&) {
    }
    fail(ln, "expected " + what + ", got '" + s + "'");
  }
  double real(const std::string& what) {
    const int ln = line();
    const std::string& s = next(what);
    double v = 0;
    try {
      size_t used = 0;
      v = std::stod(s, &used);
      if (used != s.size()) fail(ln, "expected " + what + ", got '" + s + "'");
    } catch (const std::exception&) {
      fail(ln, "expected " + what + ", got '" + s + "'");
    }
    if (!std::isfinite(v)) fail(ln, what + " is not finite: '" + s + "'");
    return v;
  }
};

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

void writeAtomically(const std::string& path, const std::string& body) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error(path + ": cannot write");
    out << body;
    if (!out) throw std::runtime_error(path + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(path + ": cannot rename the temporary file: " + ec.message());
}

double tetVolume(const std::vector<Vec3>& x, const std::array<int, 4>& t) {
  Mat3 D;
  D << x[t[1]] - x[t[0]], x[t[2]] - x[t[0]], x[t[3]] - x[t[0]];
  return D.determinant() / 6.0;
}

TetMesh makeBoxTetMesh(const Vec3& size, int nx, int ny, int nz, const Vec3& origin, CubeSplit split) {
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("makeBoxTetMesh: cube counts must be >= 1");
  if (!(size.minCoeff() > 0) || !size.allFinite())
    throw std::invalid_argument("makeBoxTetMesh: the box size must be positive");
  TetMesh m;
  m.nodes.reserve(static_cast<size_t>(nx + 1) * (ny + 1) * (nz + 1));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        m.nodes.push_back(origin + Vec3(size[0] * i / nx, size[1] * j / ny, size[2] * k / nz));
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        // corner c = bits (x, y, z) of the cube at (i, j, k)
        int c[8];
        for (int b = 0; b < 8; ++b) c[b] = nodeIndex(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1), nx, ny);
        std::vector<std::array<int, 4>> cube;
        if (split == CubeSplit::Six) {
          // Kuhn: the six paths 000 -> 111 along the axes in every order
          const int perm[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4}, {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
          for (const auto& p : perm) cube.push_back({c[0], c[p[0]], c[p[0] | p[1]], c[7]});
        } else if ((i + j + k) % 2 == 0) {
          cube = {{c[0], c[1], c[2], c[4]}, {c[3], c[1], c[2], c[7]}, {c[5], c[1], c[4], c[7]},
                  {c[6], c[2], c[4], c[7]}, {c[1], c[2], c[4], c[7]}};
        } else {
          cube = {{c[1], c[0], c[3], c[5]}, {c[2], c[0], c[3], c[6]}, {c[4], c[0], c[5], c[6]},
                  {c[7], c[3], c[5], c[6]}, {c[0], c[3], c[5], c[6]}};
        }
        for (auto& t : cube) {
          orient(m.nodes, t);
          m.tets.push_back(t);
        }
      }
  return m;
}

TetMesh readVtkTetMesh(const std::string& path, VtkReadInfo* info) {
  std::ifstream in(path);
  if (!in) throw MeshError(path + ": cannot open");
  Tokens t;
  t.file = path;
  std::string line;
  int ln = 0;
  // the header's first three lines are fixed: version, title, ASCII/BINARY
  std::string header[3];
  for (int i = 0; i < 3; ++i) {
    if (!std::getline(in, header[i])) throw MeshError(path + ":" + std::to_string(i + 1) + ": truncated VTK header");
    ++ln;
    if (!header[i].empty() && header[i].back() == '\r') header[i].pop_back();
    if (i == 0 && header[0].rfind("# vtk DataFile Version", 0) != 0)
      t.fail(1, "not a legacy VTK file (expected '# vtk DataFile Version ...')");
  }
  const std::string fmt = upper(header[2]);
  if (fmt.find("BINARY") != std::string::npos) t.fail(3, "BINARY VTK files are not supported (write ASCII)");
  if (fmt.find("ASCII") == std::string::npos) t.fail(3, "expected ASCII, got '" + header[2] + "'");
  while (std::getline(in, line)) {
    ++ln;
    std::istringstream ls(line);
    std::string w;
    while (ls >> w) t.tok.emplace_back(w, ln);
  }
  TetMesh m;
  bool have_points = false, have_cells = false, have_types = false;
  std::vector<std::vector<int>> cells;
  std::vector<int> cell_lines;
  while (!t.done()) {
    const int kl = t.line();
    const std::string key = upper(t.next("a section keyword"));
    if (key == "DATASET") {
      const std::string kind = upper(t.next("a dataset type"));
      if (kind != "UNSTRUCTURED_GRID") t.fail(kl, "dataset " + kind + " is not supported (expected UNSTRUCTURED_GRID)");
    } else if (key == "POINTS") {
      if (have_points) t.fail(kl, "second POINTS section");
      const long long n = t.integer("the number of points");
      if (n < 1 || n > 100000000) t.fail(kl, "bad number of points " + std::to_string(n));
      t.next("the points' data type");
      // never allocate for more than the file holds
      if (static_cast<unsigned long long>(3 * n) > t.remaining())
        t.fail(kl, std::to_string(n) + " points announced, the file ends before their coordinates");
      m.nodes.resize(static_cast<size_t>(n));
      for (auto& p : m.nodes)
        for (int c = 0; c < 3; ++c) p[c] = t.real("a point coordinate");
      have_points = true;
    } else if (key == "CELLS") {
      if (have_cells) t.fail(kl, "second CELLS section");
      const long long n = t.integer("the number of cells");
      const long long size = t.integer("the CELLS list size");
      if (n < 0 || n > 100000000 || size < n) t.fail(kl, "bad CELLS counts " + std::to_string(n) + " " + std::to_string(size));
      if (static_cast<unsigned long long>(size) > t.remaining())
        t.fail(kl, "CELLS list of " + std::to_string(size) + " entries, the file ends before them");
      long long read = 0;
      cells.resize(static_cast<size_t>(n));
      cell_lines.resize(static_cast<size_t>(n));
      for (long long c = 0; c < n; ++c) {
        cell_lines[c] = t.line();
        const long long k = t.integer("a cell's node count");
        if (k < 1 || k > 1000) t.fail(cell_lines[c], "bad node count " + std::to_string(k) + " of cell " + std::to_string(c));
        read += k + 1;
        for (long long a = 0; a < k; ++a) {
          const int al = t.line();
          const long long idx = t.integer("a node index");
          if (!have_points) t.fail(al, "CELLS before POINTS");
          if (idx < 0 || idx >= m.numNodes())
            t.fail(al, "node index " + std::to_string(idx) + " out of range (" + std::to_string(m.numNodes()) + " points)");
          cells[c].push_back(static_cast<int>(idx));
        }
      }
      if (read != size) t.fail(kl, "CELLS list size " + std::to_string(size) + " does not match its " + std::to_string(read) + " entries");
      have_cells = true;
    } else if (key == "CELL_TYPES") {
      if (!have_cells) t.fail(kl, "CELL_TYPES before CELLS");
      const long long n = t.integer("the number of cell types");
      if (n != static_cast<long long>(cells.size()))
        t.fail(kl, "CELL_TYPES count " + std::to_string(n) + " differs from CELLS count " + std::to_string(cells.size()));
      for (long long c = 0; c < n; ++c) {
        const int tl = t.line();
        const long long type = t.integer("a cell type");
        if (type == 10) {
          if (cells[c].size() != 4) t.fail(cell_lines[c], "tetra cell " + std::to_string(c) + " has " + std::to_string(cells[c].size()) + " nodes");
          std::array<int, 4> tet{cells[c][0], cells[c][1], cells[c][2], cells[c][3]};
          const double v = tetVolume(m.nodes, tet);
          if (!(std::abs(v) > 0)) t.fail(cell_lines[c], "tetra cell " + std::to_string(c) + " is degenerate (zero volume)");
          orient(m.nodes, tet);
          m.tets.push_back(tet);
        } else if (type == 1 || type == 3 || type == 5) {
          if (info) ++info->skipped_cells;
        } else {
          t.fail(tl, "cell type " + std::to_string(type) + " of cell " + std::to_string(c) +
                         " is not supported (tetra 10; vertex 1, line 3, triangle 5 are skipped)");
        }
      }
      have_types = true;
    } else if (key == "POINT_DATA" || key == "CELL_DATA" || key == "FIELD" || key == "METADATA") {
      break;  // attributes after the geometry: not read
    } else {
      t.fail(kl, "unexpected '" + key + "'");
    }
  }
  if (!have_points) t.fail(t.lastLine(), "no POINTS section");
  if (!have_cells || !have_types) t.fail(t.lastLine(), "no CELLS and CELL_TYPES sections");
  if (m.tets.empty()) t.fail(t.lastLine(), "no tetra cells (type 10)");
  return m;
}

void writeVtkTetMesh(const std::string& path, const TetMesh& mesh, const std::vector<Vec3>& x,
                     const std::vector<std::pair<std::string, std::vector<Vec3>>>& point_vectors,
                     const std::vector<std::array<int, 2>>& lines) {
  const std::vector<Vec3>& p = x.empty() ? mesh.nodes : x;
  if (p.size() != mesh.nodes.size()) throw std::invalid_argument("writeVtkTetMesh: positions do not match the nodes");
  std::ostringstream o;
  o << std::setprecision(17);
  o << "# vtk DataFile Version 3.0\nredmax tetrahedral mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  o << "POINTS " << p.size() << " double\n";
  for (const Vec3& v : p) o << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
  const size_t cells = mesh.tets.size() + lines.size();
  o << "CELLS " << cells << ' ' << 5 * mesh.tets.size() + 3 * lines.size() << '\n';
  for (const auto& t : mesh.tets) o << "4 " << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
  for (const auto& l : lines) {
    if (l[0] < 0 || l[1] < 0 || l[0] >= static_cast<int>(p.size()) || l[1] >= static_cast<int>(p.size()))
      throw std::invalid_argument("writeVtkTetMesh: line cell with a node out of range");
    o << "2 " << l[0] << ' ' << l[1] << '\n';
  }
  o << "CELL_TYPES " << cells << '\n';
  for (size_t i = 0; i < mesh.tets.size(); ++i) o << "10\n";
  for (size_t i = 0; i < lines.size(); ++i) o << "3\n";
  if (!point_vectors.empty()) {
    o << "POINT_DATA " << p.size() << '\n';
    for (const auto& [name, values] : point_vectors) {
      if (values.size() != p.size()) throw std::invalid_argument("writeVtkTetMesh: point data '" + name + "' has the wrong size");
      o << "VECTORS " << name << " double\n";
      for (const Vec3& v : values) o << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
    }
  }
  writeAtomically(path, o.str());
}

void writePvd(const std::string& path, const std::vector<std::pair<double, std::string>>& frames) {
  std::ostringstream o;
  o << std::setprecision(17);
  o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (const auto& [time, file] : frames)
    o << "    <DataSet timestep=\"" << time << "\" part=\"0\" file=\"" << file << "\"/>\n";
  o << "  </Collection>\n</VTKFile>\n";
  writeAtomically(path, o.str());
}

}  // namespace redmax
