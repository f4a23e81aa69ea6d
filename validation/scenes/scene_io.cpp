#include "validation/scenes/scene_io.hpp"

#include <cstdio>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace redmax::scenes {

void writeCsv(const std::filesystem::path& path, const std::vector<std::string>& columns,
              const std::vector<VecX>& rows) {
  std::ostringstream o;
  o << std::setprecision(17);
  for (size_t c = 0; c < columns.size(); ++c) o << (c ? "," : "") << columns[c];
  o << '\n';
  for (const VecX& r : rows) {
    if (r.size() != static_cast<int>(columns.size()))
      throw std::logic_error(path.string() + ": a row has " + std::to_string(r.size()) + " values for " +
                             std::to_string(columns.size()) + " columns");
    for (int c = 0; c < r.size(); ++c) o << (c ? "," : "") << r[c];
    o << '\n';
  }
  writeAtomically(path.string(), o.str());
}

void writeSeries(const std::filesystem::path& dir, const std::string& name, const TetMesh& mesh,
                 const std::vector<std::array<int, 2>>& lines, const std::vector<double>& t,
                 const std::vector<std::vector<Vec3>>& points) {
  std::vector<std::pair<double, std::string>> frames;
  for (size_t k = 0; k < points.size(); ++k) {
    char file[64];
    std::snprintf(file, sizeof file, "%s_%04zu.vtk", name.c_str(), k);
    TetMesh m = mesh;
    m.nodes = points.front();
    std::vector<Vec3> u(points[k].size());
    for (size_t n = 0; n < u.size(); ++n) u[n] = points[k][n] - points.front()[n];
    writeVtkTetMesh((dir / file).string(), m, points[k], {{"displacement", u}}, lines);
    frames.emplace_back(t[k], file);
  }
  writePvd((dir / (name + ".pvd")).string(), frames);
}

}  // namespace redmax::scenes
