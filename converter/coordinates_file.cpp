#include "converter/coordinates_file.hpp"

#include "converter/error.hpp"

namespace redmax::osim {
namespace {

// the '/'-separated elements of a label: "/jointset/j/q/value" -> {jointset, j, q, value}
std::vector<std::string> pathElements(const std::string& label) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : label) {
    if (c == '/') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

}  // namespace

double degreesToRadians() {
  // SimTK_DEGREE_TO_RADIAN is computed in long double and used as a double
  return static_cast<double>(3.14159265358979323846264338327950288L / 180.0L);
}

std::string coordinatePath(const CoordinateDesc& c) { return "/jointset/" + c.joint + "/" + c.name; }

bool labelIsCoordinatePath(const std::string& label, const CoordinateDesc& c) {
  if (label.find('/') == std::string::npos) return false;
  const std::vector<std::string> el = pathElements(label);
  if (el.empty()) return false;
  if (el.back() == c.name) return true;
  return el.size() >= 2 && el.back() == "value" && el[el.size() - 2] == c.name;
}

int findCoordinateColumn(const Storage& table, const CoordinateDesc& c, CoordinateLabels rule) {
  int k = table.findColumn(c.name);
  if (k >= 0 || rule == CoordinateLabels::ExactName) return k;
  k = table.findColumn(coordinatePath(c) + "/value");
  if (k >= 0) return k;
  for (int j = 0; j < table.numColumns(); ++j)
    if (labelIsCoordinatePath(table.labels[j], c)) return j;
  return -1;
}

int findSpeedColumn(const Storage& table, const CoordinateDesc& c) {
  int k = table.findColumn(coordinatePath(c) + "/speed");
  if (k >= 0) return k;
  for (int j = 0; j < table.numColumns(); ++j) {
    const std::string& l = table.labels[j];
    if (l.find('/') == std::string::npos) continue;
    const std::vector<std::string> el = pathElements(l);
    if (el.size() >= 2 && el.back() == "speed" && el[el.size() - 2] == c.name) return j;
  }
  return table.findColumn(c.name + "_u");
}

double coordinateScale(const Storage& table, const CoordinateDesc& c) {
  return table.in_degrees && c.motion_type == MotionType::Rotational ? degreesToRadians() : 1.0;
}

CoordinateColumns matchCoordinateColumns(const Storage& table, const std::vector<CoordinateDesc>& coordinates,
                                         CoordinateLabels rule) {
  CoordinateColumns m;
  for (const CoordinateDesc& c : coordinates) {
    const int k = findCoordinateColumn(table, c, rule);
    m.value_column.push_back(k);
    m.scale.push_back(coordinateScale(table, c));
    m.matched += k >= 0 ? 1 : 0;
  }
  if (rule == CoordinateLabels::ExactName)
    for (const std::string& label : table.labels) {
      bool exact = false, path = false;
      for (const CoordinateDesc& c : coordinates) {
        exact = exact || label == c.name;
        path = path || labelIsCoordinatePath(label, c);
      }
      if (path && !exact) m.unused_path_labels.push_back(label);
    }
  return m;
}

CoordinateRows coordinateRows(const Storage& table, const std::vector<CoordinateDesc>& coordinates,
                              const std::vector<int>& coordinate_index, int nr, const std::string& table_file) {
  CoordinateRows out;
  VecX q0 = VecX::Zero(nr);
  const CoordinateColumns columns = matchCoordinateColumns(table, coordinates);
  std::vector<std::pair<int, int>> column_of;  // (core coordinate, data column)
  std::vector<double> scale;
  for (size_t ci = 0; ci < coordinates.size(); ++ci) {
    const int k = coordinate_index[ci];
    if (k < 0) continue;
    q0[k] = coordinates[ci].default_value;
    if (columns.value_column[ci] < 0) {
      ++out.missing;
      continue;
    }
    column_of.emplace_back(k, columns.value_column[ci]);
    scale.push_back(columns.scale[ci]);
  }
  if (column_of.empty()) throw ConvertError(table_file, 0, "no column names a coordinate of the model");
  for (int row = 0; row < table.numRows(); ++row) {
    VecX q = q0;
    for (size_t j = 0; j < column_of.size(); ++j) q[column_of[j].first] = table.data(row, column_of[j].second) * scale[j];
    out.q.push_back(std::move(q));
  }
  return out;
}

}  // namespace redmax::osim
